"""The C y-processor's command-line tool, `sw/hsr/build/yproc`, from Python: where it
is, building it once (a file lock, so parallel pytest workers and make do not build it
together), and `read`, the one scene reader (the C library's; docs/hsr.md "hsr-scene-1")."""
from __future__ import annotations

import fcntl
import json
import subprocess
import tempfile
from pathlib import Path

from .. import REPO

HSR = REPO / "sw" / "hsr"
YPROC = HSR / "build" / "yproc"


class YprocError(RuntimeError):
    """yproc could not be built, or refused its input (the message names file and line)."""


def build() -> Path:
    """Build sw/hsr/build/yproc if it is out of date; returns its path."""
    lock = Path(tempfile.gettempdir()) / "hsr_yproc_build.lock"
    with open(lock, "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            r = subprocess.run(["make", "-s", "-C", str(HSR), "build/yproc"],
                               capture_output=True, text=True)
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)
    if r.returncode or not YPROC.exists():
        raise YprocError("cannot build sw/hsr/build/yproc:\n" + r.stdout + r.stderr)
    return YPROC


def read_scene(path) -> dict:
    """The scene file and its OBJ/MTL files as the C readers understand them
    (`yproc read`, schema "hsr-scene-1"); YprocError with yproc's "file:line: message"."""
    exe = build()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "scene.json"
        r = subprocess.run([str(exe), "read", str(path), "-o", str(out)], capture_output=True,
                           text=True)
        if r.returncode:
            raise YprocError((r.stderr or r.stdout).strip() or f"{path}: yproc read failed")
        with open(out) as fh:
            return json.load(fh)
