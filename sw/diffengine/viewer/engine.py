"""The viewer's engine (docs/viewer.md): the scene held in one `yproc serve` process, the
changed lines of every frame through the golden model, undo/redo of the edits, and the
adaptive degradation of section 7.5 (a coarse frame while dragging, refined at rest).

Used by the web server (viewer/server.py) and the latency benchmark (bench/viewer.py);
imports nothing from the web side.
"""
from __future__ import annotations

import json
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import isa
from ..formats import binfmt
from ..model import functional
from ..pipeline.anim import to_de48

try:   # the functional model in C (issue 19 item 4, sw/fmodel), where the tree has it
    from ..model import fast as _fast
except ImportError:
    _fast = None

SHADINGS = ("flat", "gouraud", "phong")
MODELS = ("auto", "fast", "numpy")


def model_name(model: str) -> str:
    """'auto' -> 'fast' when diffengine.model.fast is there, else 'numpy'."""
    if model not in MODELS:
        raise EngineError(f"model must be one of {', '.join(MODELS)}, not {model!r}")
    if model == "fast" and _fast is None:
        raise EngineError("this tree has no diffengine.model.fast (the C functional model)")
    return "numpy" if model == "numpy" or _fast is None else "fast"


class EngineError(RuntimeError):
    """`yproc serve` refused a request (the message says why) or died."""


def split_lines(path: Path) -> list[bytes]:
    """A .de48 file of whole lines -> one bytes object per line (its Refresh last): what
    pipeline.anim.lines_of_de48 returns, vectorised (the viewer reads every frame's
    changed lines; a word at a time in Python costs more than the C model's render)."""
    data = Path(path).read_bytes()
    binfmt._check_header(data, binfmt.DE48_MAGIC, str(path))
    body = np.frombuffer(data, np.uint8, offset=binfmt.HEADER_LEN)
    if body.size % 6:
        raise EngineError(f"{path}: truncated instruction ({body.size % 6} of 6 bytes)")
    w = body.reshape(-1, 6)
    ident = ((w[:, 0].astype(np.uint16) << 8) | w[:, 1]) >> 4
    ends = np.flatnonzero(ident == isa.REFRESH) + 1
    if ends.size and ends[-1] != len(w) or (not ends.size and len(w)):
        raise EngineError(f"{path}: words after the last Refresh")
    raw, starts = data[binfmt.HEADER_LEN:], np.concatenate(([0], ends[:-1]))
    return [raw[6 * a:6 * b] for a, b in zip(starts.tolist(), ends.tolist())]


@dataclass
class State:
    """What undo/redo restores: per-object world offsets, per-material opacities, light
    directions and the render options."""
    offsets: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    opacity: dict[int, float] = field(default_factory=dict)
    lights: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    aa: bool = True
    shading: str = "phong"

    def copy(self) -> "State":
        return State(dict(self.offsets), dict(self.opacity), dict(self.lights), self.aa, self.shading)


@dataclass
class Frame:
    """One frame's result: the rows whose pixels changed and the per-stage figures."""
    rows: list[int]
    stats: dict


class Engine:
    """A scene in a long-lived `yproc serve` process, pixels from the golden model.

    budget_ms: a drag frame whose estimated cost exceeds it is rendered coarse (no AA,
    flat shading on the damaged lines) and refined by `rest()`. model: the golden model
    that makes the pixels: "numpy" (functional.render, the reference), "fast" (its C
    twin, diffengine.model.fast, held equal to it by its tests) or "auto" (fast if there).
    """

    def __init__(self, scene, yproc: Path, budget_ms: float = 50.0, model: str = "auto"):
        self.model = model_name(model)
        self.scene = Path(scene)
        self.dir = Path(tempfile.mkdtemp(prefix="de_view_"))
        self.proc = subprocess.Popen([str(yproc), "serve", str(self.scene), "--dir", str(self.dir)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, bufsize=1)
        first = self.proc.stdout.readline()
        if not first:
            raise EngineError(f"{self.scene}: yproc serve: {self.proc.stderr.read().strip()}")
        self.info = self.request("info")
        self.W, self.H = self.info["width"], self.info["height"]
        self.capacity = self.info["capacity"]
        self.mats = [m["name"] for m in self.info["materials"]]
        self.state = State(lights={i: tuple(l["dir"]) for i, l in enumerate(self.info["lights"])},
                           opacity={i: m["opacity"] for i, m in enumerate(self.info["materials"])})
        self.undo_stack: list[State] = []
        self.redo_stack: list[State] = []
        self.image = np.zeros((self.H, self.W, 3), np.uint16)       # 12-bit, golden model
        self.lines: list[list[bytes]] = [[b""] * self.H for _ in range(3)]   # .de48 words
        self.budget_ms = budget_ms
        self.last_ms = 0.0            # the last full-quality frame's cost (the estimate)
        self.coarse_lines = 0
        self.frames = 0
        self.frame(coarse=False)

    # ---- the process -------------------------------------------------------------------
    def request(self, line: str) -> dict:
        if self.proc.poll() is not None:
            raise EngineError(f"yproc serve exited ({self.proc.returncode}): {self.proc.stderr.read().strip()}")
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        out = self.proc.stdout.readline()
        if not out:
            raise EngineError(f"yproc serve died: {self.proc.stderr.read().strip()}")
        rep = json.loads(out)
        if not rep.get("ok"):
            raise EngineError(rep.get("error", "yproc serve: unknown error"))
        return rep

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.request("quit")
            except (EngineError, OSError):
                pass
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        for p in self.dir.glob("*"):
            p.unlink()
        self.dir.rmdir()

    # ---- queries -----------------------------------------------------------------------
    def pick(self, x: float, y: float) -> dict:
        if not (0 <= x < self.W and 0 <= y < self.H):
            raise EngineError(f"pick ({x}, {y}) is outside the {self.W}x{self.H} frame")
        return self.request(f"pick {x!r} {y!r}")

    def world_per_pixel(self, obj: int) -> float:
        """World units per pixel at the depth of obj's centroid (its current place)."""
        o = self.info["objects"][obj]
        v = self.info["view"]
        c = np.add(o["centroid"], self.state.offsets.get(obj, (0, 0, 0)))
        depth = float(np.dot(c - np.asarray(v["eye"]), -np.asarray(v["w"])))
        return max(depth, 1e-6) / v["f"]

    def drag_offset(self, obj: int, start: tuple, dx: float, dy: float, dz: float = 0.0) -> tuple:
        """obj's world offset after a pointer move of (dx, dy) pixels in the image plane
        (y down) and dz pixels in depth (positive: away from the eye, along the ray through
        the centroid, so the part stays under the pointer) from `start`."""
        v = self.info["view"]
        s = self.world_per_pixel(obj)
        ray = (np.add(self.info["objects"][obj]["centroid"], start) - np.asarray(v["eye"]))
        ray /= max(float(np.linalg.norm(ray)), 1e-12)
        d = dx * s * np.asarray(v["u"]) - dy * s * np.asarray(v["v"]) + dz * s * ray
        return tuple(float(a) for a in np.asarray(start) + d)

    # ---- edits (each one records nothing; commit() closes an undo step) -----------------
    def move(self, obj: int, offset) -> dict:
        if not 0 <= obj < len(self.info["objects"]):
            raise EngineError(f"no object {obj} (the scene has {len(self.info['objects'])})")
        off = tuple(float(a) for a in offset)
        if not all(np.isfinite(off)):
            raise EngineError("offset must be finite")
        rep = self.request("move %d %r %r %r" % (obj, *off))
        self.state.offsets[obj] = off
        return rep

    def set_opacity(self, mat: int, a: float) -> dict:
        if not 0 <= mat < len(self.mats):
            raise EngineError(f"no material {mat}")
        if not 0.0 <= a <= 1.0:
            raise EngineError(f"opacity {a} outside [0, 1]")
        rep = self.request(f"opacity {mat} {float(a)!r}")
        self.state.opacity[mat] = float(a)
        return rep

    def set_light(self, i: int, d) -> dict:
        d = tuple(float(a) for a in d)
        rep = self.request("light %d %r %r %r" % (i, *d))
        self.state.lights[i] = d
        return rep

    def set_options(self, aa: bool, shading: str) -> dict:
        if shading not in SHADINGS:
            raise EngineError(f"shading must be one of {', '.join(SHADINGS)}, not {shading!r}")
        rep = self.request(f"options {int(bool(aa))} {shading}")
        self.state.aa, self.state.shading = bool(aa), shading
        return rep

    def apply(self, st: State) -> None:
        """Bring the scene to state st (only what differs is sent)."""
        cur = self.state
        for o in set(cur.offsets) | set(st.offsets):
            want = st.offsets.get(o, (0.0, 0.0, 0.0))
            if cur.offsets.get(o, (0.0, 0.0, 0.0)) != want:
                self.move(o, want)
        for m, a in st.opacity.items():
            if cur.opacity.get(m) != a:
                self.set_opacity(m, a)
        for i, d in st.lights.items():
            if cur.lights.get(i) != d:
                self.set_light(i, d)
        if (cur.aa, cur.shading) != (st.aa, st.shading):
            self.set_options(st.aa, st.shading)

    def checkpoint(self) -> None:
        """Call before an edit that undo should take back (a gesture's start)."""
        self.undo_stack.append(self.state.copy())
        self.redo_stack.clear()

    def _travel(self, back: list, forth: list) -> bool:
        """Undo (back = the undo stack) or redo: apply back's last state, keep the current
        one on forth; False when back is empty."""
        if not back:
            return False
        forth.append(self.state.copy())
        self.apply(back.pop())
        return True

    def undo(self) -> bool:
        return self._travel(self.undo_stack, self.redo_stack)

    def redo(self) -> bool:
        return self._travel(self.redo_stack, self.undo_stack)

    # ---- frames ------------------------------------------------------------------------
    def frame(self, coarse: bool | None = False) -> Frame:
        """Scan the damaged lines and run the changed ones through the golden model.

        coarse=None: adaptive: coarse when the last full-quality frame cost more than
        the budget (the drag path); False: full quality, refining earlier coarse lines."""
        t0 = time.perf_counter()
        if coarse is None:
            coarse = self.last_ms > self.budget_ms
        rep = self.request("frame coarse" if coarse else "frame full")
        rows: set[int] = set()
        changes: list[dict[int, bytes]] = []
        for c, name in enumerate("rgb"):
            ys = rep["changed"][c]
            got = split_lines(self.dir / f"{name}.de48") if ys else []
            if len(got) != len(ys):
                raise EngineError(f"{name}.de48 holds {len(got)} lines, the reply names {len(ys)}")
            changes.append(dict(zip(ys, got)))
            for y, words in zip(ys, got):
                self.lines[c][y] = words
            rows.update(ys)
        t1 = time.perf_counter()          # the lines are read: the rest is the model
        if rows and self.model == "fast":
            _fast.render_lines(self.image, changes)
        elif rows:
            for c, ch in enumerate(changes):
                if ch:
                    ys = list(ch)
                    cmds, _ = binfmt.load_commands(to_de48([ch[y] for y in ys]), "rgb"[c] + ".de48")
                    self.image[ys, :, c] = functional.render(cmds, self.W)
        t2 = time.perf_counter()
        serve_ms = (t1 - t0) * 1e3
        stats = {
            "frame": self.frames, "coarse": rep["coarse"], "changed": [len(x) for x in rep["changed"]],
            "rescanned": rep["rescanned"], "refined": rep["refined"], "coarse_lines": rep["coarse_lines"],
            "hsr_ms": rep["hsr_ms"], "rebuilt": rep["rebuilt"], "scan_ms": rep["scan_ms"],
            "serve_io_ms": max(serve_ms - rep["scan_ms"], 0.0), "model_ms": (t2 - t1) * 1e3,
            "max_slots": rep["max_slots"], "capacity": rep["capacity"],
            "lines_degraded": rep["lines_degraded"], "lines_overflow": rep["lines_overflow"],
            "model": self.model,
        }
        cost = rep["hsr_ms"] + serve_ms + stats["model_ms"]
        if not coarse:
            self.last_ms = cost
        self.coarse_lines = rep["coarse_lines"]
        self.frames += 1
        return Frame(sorted(rows), stats)

    def rest(self) -> Frame | None:
        """The pointer rests: refine the lines left coarse (None if there are none)."""
        return self.frame(coarse=False) if self.coarse_lines else None

    def streams(self) -> list[bytes]:
        """The current frame's three .de48 streams (for the RTL check)."""
        return [to_de48(ls) for ls in self.lines]

    def view8(self) -> np.ndarray:
        return (self.image >> 4).astype(np.uint8)
