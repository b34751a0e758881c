"""The one way a benchmark records what it measured: out/bench/NAME.json, with the command
line, the date, the 1-minute load average before and after, the revision and the
benchmark's own figures under "data". `--write` also keeps the record in docs/bench/
(checked in: the figures of docs/performance.md are rendered from it, bench.render).
"""
from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

from .. import REPO

OUT = REPO / "out" / "bench"      # every run
KEPT = REPO / "docs" / "bench"    # the runs docs/performance.md shows (--write)


def _plain(o):
    """numpy scalars and other strays in a benchmark's figures -> JSON."""
    return o.item() if hasattr(o, "item") else str(o)


def table_head(*cols: str) -> list[str]:
    """A Markdown table's header row and rule: table_head("a", "b") -> ["| a | b |", "|---|---|"]."""
    return ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]


def add_write(ap, renders: str = "docs/performance.md") -> None:
    """The `--write` flag of every benchmark: keep the record and render what it shows."""
    ap.add_argument("--write", action="store_true",
                    help=f"keep the record in docs/bench and render {renders}")


def log(name: str, msg: str) -> None:
    print(f"bench {name}: {msg}", file=sys.stderr, flush=True)


def loadavg() -> float:
    """The 1-minute load average (these machines are shared: every figure carries it)."""
    return round(os.getloadavg()[0], 2)


def revision(rev: str = "HEAD") -> str:
    r = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", rev],
                       capture_output=True, text=True)
    return r.stdout.strip() or "unknown"


class Run:
    """A benchmark run: `Run(name)` when it starts, `save(data, write)` when it ends."""

    def __init__(self, name: str):
        self.name = name
        self.t0 = time.time()
        self.date = time.strftime("%Y-%m-%d %H:%M")
        self.load_before = loadavg()

    def log(self, msg: str) -> None:
        log(self.name, msg)

    def save(self, data: dict, write: bool = False) -> dict:
        """out/bench/NAME.json (and docs/bench/NAME.json with write); the record."""
        rec = {"bench": self.name,
               "command": shlex.join(["diffengine", *sys.argv[1:]]),
               "date": self.date, "revision": revision(),
               "load_before": self.load_before, "load_after": loadavg(),
               "seconds": round(time.time() - self.t0, 1), "data": data}
        path = OUT / f"{self.name}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(rec, indent=1, default=_plain) + "\n")
        self.log(f"wrote {path.relative_to(REPO)}")
        if write:
            KEPT.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, KEPT / path.name)
        return json.loads(json.dumps(rec, default=_plain))   # as render will read it


def load(name: str, folder: Path = KEPT) -> dict | None:
    path = Path(folder) / f"{name}.json"
    return json.loads(path.read_text()) if path.exists() else None
