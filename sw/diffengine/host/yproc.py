"""The C y-processor's command-line tool, `sw/yproc/build/yproc`, from Python: where it
is, building it once (a file lock, so parallel pytest workers and make do not build it
together), and `read`, the one scene reader (the C library's; docs/hsr.md "hsr-scene-1")."""
from __future__ import annotations

import fcntl
import json
import subprocess
import tempfile
from pathlib import Path

from .. import REPO

YPROC_DIR = REPO / "sw" / "yproc"
YPROC = YPROC_DIR / "build" / "yproc"


class YprocError(RuntimeError):
    """yproc could not be built, or refused its input (the message names file and line)."""


def make_locked(directory: Path, target: str, lock_name: str) -> subprocess.CompletedProcess:
    """`make -s -C directory target` under a file lock in the temporary folder, so that
    parallel pytest workers and make never build the same C target together."""
    lock = Path(tempfile.gettempdir()) / lock_name
    with open(lock, "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            return subprocess.run(["make", "-s", "-C", str(directory), target],
                                  capture_output=True, text=True)
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def build() -> Path:
    """Build sw/yproc/build/yproc if it is out of date; returns its path."""
    r = make_locked(YPROC_DIR, "build/yproc", "hsr_yproc_build.lock")
    if r.returncode or not YPROC.exists():
        raise YprocError("cannot build sw/yproc/build/yproc:\n" + r.stdout + r.stderr)
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
