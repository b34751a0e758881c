"""Incremental animation frames from `yproc anim` (docs/yproc.md): apply the frame deltas
(.delta, "YPD1") to frame 0's streams and check every frame against a full re-render.

Delta format (written by sw/yproc/tools/yproc_scan.c): "YPD1", u16 version 1, u16 frame,
u16 width, u16 height (big-endian); then per colour r, g, b: u32 number of changed lines
and per changed line u16 line, u32 words, words x 6-byte .de48 words (the line's commands
and its closing Refresh).
"""
from __future__ import annotations

import json
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from .. import REPO, isa
from ..formats import binfmt, frame
from ..model import fast, functional
from .demo import H_TOTAL, build_yproc

Line = list[bytes]   # the 6-byte words of one line, its Refresh last


def lines_of_de48(path) -> list[bytes]:
    """A .de48 stream as one bytes object per line (Refresh included)."""
    data = Path(path).read_bytes()
    binfmt.decode_de48(data, str(path))          # validates header and length
    words = data[8:]
    out, start = [], 0
    for i in range(0, len(words), 6):
        if (int.from_bytes(words[i:i + 2], "big") >> 4) == isa.REFRESH:
            out.append(words[start:i + 6])
            start = i + 6
    if start != len(words):
        raise ValueError(f"{path}: {(len(words) - start) // 6} word(s) after the last Refresh")
    return out


def read_delta(path) -> tuple[int, int, int, list[dict[int, bytes]]]:
    """(frame, width, height, [ {line: words} for r, g, b ])."""
    data = Path(path).read_bytes()
    if data[:4] != b"YPD1":
        raise ValueError(f"{path}: not a YPD1 frame delta")
    ver, frame, w, h = struct.unpack(">4H", data[4:12])
    if ver != 1:
        raise ValueError(f"{path}: delta version {ver}")
    pos, chans = 12, []
    for _ in range(3):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        pos += 4
        ch = {}
        for _ in range(n):
            y, k = struct.unpack(">HI", data[pos:pos + 6])
            pos += 6
            ch[y] = data[pos:pos + 6 * k]
            if len(ch[y]) != 6 * k or (int.from_bytes(ch[y][-6:-4], "big") >> 4) != isa.REFRESH:
                raise ValueError(f"{path}: line {y} is truncated or lacks its Refresh")
            pos += 6 * k
        chans.append(ch)
    if pos != len(data):
        raise ValueError(f"{path}: {len(data) - pos} trailing bytes")
    return frame, w, h, chans


def frames(outdir) -> list[list[list[bytes]]]:
    """Every frame's streams, frame 0 from frame000/ and the others by applying the
    deltas in order: result[f][c] = list of the lines of colour c in frame f."""
    outdir = Path(outdir)
    cur = [lines_of_de48(outdir / "frame000" / f"{c}.de48") for c in "rgb"]
    seq = [[list(ch) for ch in cur]]
    f = 1
    while (outdir / f"frame{f:03d}.delta").exists():
        fr, _, h, chans = read_delta(outdir / f"frame{f:03d}.delta")
        if fr != f:
            raise ValueError(f"frame{f:03d}.delta says frame {fr}")
        for c in range(3):
            for y, words in chans[c].items():
                if not 0 <= y < h or y >= len(cur[c]):
                    raise ValueError(f"frame{f:03d}.delta: line {y} outside the frame")
                cur[c][y] = words
        seq.append([list(ch) for ch in cur])
        f += 1
    return seq


def to_de48(lines: list[bytes]) -> bytes:
    return b"DE48" + struct.pack(">HH", 1, 0) + b"".join(lines)


# ---- `diffengine anim` (make anim) ----------------------------------------------------

COMMAND_HELP = """yproc anim (HSR move / opacity / light changes, then re-scan of the damaged lines only)
writes frame 0's r/g/b.de48 streams and one frame delta per later frame (docs/yproc.md
section 6). This script applies the deltas in order, re-renders only the changed lines
with the golden model (the C functional model, sw/fmodel; --model numpy for the numpy
one), and writes every frame as an 8-bit PNG and the sequence as an animated GIF. yproc
itself re-renders every frame in full and compares the streams (its
`frames_differing_from_full` must be 0, checked here); this script also checks that the
image updated line by line equals a from-scratch render of the last frame by the numpy
golden model (diffengine.model.functional, the reference).
It also writes changed.json / changed.png: the instructions changed per scanline per
frame (the slots of each new line not on the longest common subsequence of its commands
with the previous frame's line, counted by yproc), as a histogram and per frame.

    diffengine anim [--anim sw/scenes/anim/cad_drag.anim] [--out out/anim] [--model fast|numpy]
                    [--coherent] [--tol T]
    diffengine anim --anim A --out D --coh-sweep [--frames N] [--legs 8,32,..] [--runs 4:coh:aa,..]

--coherent keeps the previous frame's colour functions where they still meet the tolerance
(yproc anim --coherent, docs/yproc.md section 11). --coh-sweep runs the animation at
several light speeds (frames per `wander` leg) and tolerances, with and without it, and
plots the median changed instructions per pattern line (sweep.png, sweep.json).

The Load Monitor loop (docs/yproc.md section 10): --lod-compare runs the animation four
times (open loop, look-ahead, the loop, the loop with the check before emission) and plots
overflowing lines and quality per frame; --lod-loop runs the loop once, with --predict the
check before emission, with --rtl the Verilated display controller's Load Monitor read
back frame by frame instead of yproc's model of it:

    diffengine anim --anim A.anim --lod-loop --rtl [--htotal N] [--chips C] [--predict]
                    [--compare-model]      # + the same on the model, OUT/lod_rtl.png
    diffengine anim --plot-rtl OUT1 OUT2 ... --out DIR   # several of those in one plot

Exit status 0 only if no frame differs from its full re-render.
"""


def render_lines(lines: list[bytes], width: int) -> np.ndarray:
    """Golden-model rows of the given lines (each a line's .de48 words, Refresh last)."""
    cmds, _ = binfmt.load_commands(to_de48(lines), "<delta>")
    return functional.render(cmds, width)


def golden_frame(streams: list[list[bytes]], width: int) -> np.ndarray:
    """One frame (three colours' lines) through the golden model: (H, W, 3)."""
    return np.stack([render_lines(streams[c], width) for c in range(3)], axis=-1)


def play_rtl(seq: list[list[list[bytes]]], width: int, height: int, chips: int,
             workdir: Path, test: tuple | None = None) -> tuple[np.ndarray, dict]:
    """Every frame of `seq` (frames()) one after the other through the Verilated display
    controller in test mode (diffengine.rtl.dc_harness); `test`: the geometry (default
    demo.controller_setup's, HTotal 800). Returns (frames (F, H, W, 3), harness stats)."""
    from ..rtl import dc_harness
    from .demo import controller_setup
    cfg = dc_harness.Config(chips=chips, test=test or controller_setup(width, height, chips)[1])
    paths = [Path(workdir) / f"rtl_{c}.de48" for c in "rgb"]
    for c in range(3):
        paths[c].write_bytes(to_de48([ln for fr in seq for ln in fr[c]]))
    return dc_harness.run(paths, cfg, mode=3)


def changed_histogram(st: dict, lines: list | None = None) -> dict:
    """Changed instructions per scanline per frame from `anim_stats.json` (`changed_slots`:
    per frame, colour and line, the instruction slots of the new line that are not on the
    longest common subsequence of its commands with the previous frame's line; 0 for a
    line that did not change). `lines`: the frames' streams (frames()), for the slots per
    line. Returns per frame the median / 90th percentile / max over the 3 x H lines, the
    count of lines that changed, and a histogram over every (frame >= 1, colour, line)."""
    per = [f for f in st["frame"][1:] if "changed_slots" in f]
    if not per:
        return {}
    cs = np.array([f["changed_slots"] for f in per])            # (F-1, 3, H)
    flat = cs.reshape(len(per), -1)
    edges = [0, 1, 3, 6, 11, 21, 41, 81, 161, 10 ** 9]
    hist = np.histogram(flat.ravel(), bins=edges)[0]
    out = {
        "frames": [f["frame"] for f in per],
        "median": np.median(flat, axis=1).tolist(),
        "p90": np.percentile(flat, 90, axis=1).tolist(),
        "max": flat.max(axis=1).tolist(),
        "changed_lines": (flat > 0).sum(axis=1).tolist(),
        "bins": [f"{a}-{b - 1}" if b - 1 > a else f"{a}" for a, b in zip(edges[:-2], edges[1:-1])] + [f">={edges[-2]}"],
        "hist": hist.tolist(),
        "median_all": float(np.median(flat)),
        "median_changed_lines": float(np.median(flat[flat > 0])) if (flat > 0).any() else 0.0,
    }
    if lines is not None:
        slots = [[len(ln) // 6 - 1 for ln in ch] for ch in lines[-1]]
        out["mean_slots_per_line"] = float(np.mean(slots))
    return out


def plot_changed(h: dict, path, title: str) -> None:
    """Histogram (all frames) and per-frame median / p90 / max of changed instructions."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    ax[0].bar(range(len(h["hist"])), h["hist"], color="#4477aa")
    ax[0].set_xticks(range(len(h["hist"])), h["bins"], rotation=30)
    ax[0].set_xlabel("changed instructions (slots) on a scanline, one colour")
    ax[0].set_ylabel("scanlines x colours x frames")
    ax[0].set_yscale("log")
    ax[0].set_title("histogram over every frame")
    fr = h["frames"]
    ax[1].plot(fr, h["max"], label="max", color="#cc6677")
    ax[1].plot(fr, h["p90"], label="90th percentile", color="#ddaa33")
    ax[1].plot(fr, h["median"], label="median", color="#4477aa")
    if "mean_slots_per_line" in h:
        ax[1].axhline(h["mean_slots_per_line"], ls="--", color="grey",
                      label=f"mean slots per line ({h['mean_slots_per_line']:.0f})")
    ax[1].set_xlabel("frame")
    ax[1].set_ylabel("changed instructions per scanline")
    ax[1].set_ylim(bottom=0)
    ax[1].legend(fontsize=8)
    ax[1].set_title("per frame")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


# ---- temporally coherent fitting: the light's speed and the tolerance (docs/yproc.md 11) -

def anim_variant(anim_path, dst: Path, frames: int, leg: int | None = None) -> Path:
    """A copy of an .anim file (its scene referenced by absolute path) with `frames` frames,
    every ramp ending at the last frame, and (leg) every `wander` leg `leg` frames long."""
    src = Path(anim_path).resolve()
    out = []
    for ln in src.read_text().splitlines():
        tok = ln.split("#")[0].split()
        if tok and tok[0] == "scene":
            ln = f"scene {(src.parent / tok[1]).resolve()}"
        elif tok and tok[0] == "frames":
            ln = f"frames {frames}"
        elif tok and tok[0] == "wander":
            if leg is not None:
                tok[3] = str(leg)
            tok[-1] = str(frames - 1)
            ln = " ".join(tok)
        elif tok and tok[-4:-3] == ["from"]:
            tok[-1] = str(frames - 1)
            ln = " ".join(tok)
        out.append(ln)
    dst.write_text("\n".join(out) + "\n")
    return dst


def changed_summary(d: Path) -> dict:
    """Changed instructions of one `yproc anim` run over the lines the pattern covers (more
    than the background term in frame 0): medians of changed slots and commands per line
    and colour over every later frame, lines with no change counted as 0; the worst
    pixel against the exact shading (max_abs_err) over every frame; how far the exact
    shading moves a frame (the per-frame median and 90th percentile over the pixels that
    moved, their median over the frames)."""
    st = json.loads((Path(d) / "anim_stats.json").read_text())
    f0 = [lines_of_de48(Path(d) / "frame000" / f"{c}.de48") for c in "rgb"]
    cover = np.array([[len(ln) // 6 - 1 > 3 for ln in ch] for ch in f0])          # (3, H)
    per = st["frame"][1:]
    cs = np.array([f["changed_slots"] for f in per])[:, cover]
    cc = np.array([f["changed_cmds"] for f in per])[:, cover]
    slots = np.array([[len(ln) // 6 - 1 for ln in ch] for ch in f0])[cover]
    return {"median_slots": float(np.median(cs)), "p90_slots": float(np.percentile(cs, 90)),
            "mean_slots": float(cs.mean()), "median_cmds": float(np.median(cc)),
            "unchanged_share": float((cs == 0).mean()), "slots_per_line": float(slots.mean()),
            "max_abs_err": max(f["max_abs_err"] for f in st["frame"]), "tol": st["tol"],
            "exact_change_median": float(np.median([f["exact_change"]["median"] for f in per]))
            if all("exact_change" in f for f in per) else None,
            "exact_change_p90": float(np.median([f["exact_change"]["p90"] for f in per]))
            if all("exact_change" in f for f in per) else None,
            "frames_differing_from_full": st["frames_differing_from_full"],
            "mean_incremental_ms": st["mean_incremental_ms"], "mean_full_ms": st["mean_full_ms"],
            # YPD1 sends every changed line whole: its bytes against the changed slots' words
            "delta_bytes_per_frame": float(np.mean([(Path(d) / f"frame{f['frame']:03d}.delta").stat().st_size
                                                    for f in per])),
            "changed_words_per_frame": float(np.mean([np.sum(f["changed_slots"]) for f in per]))}


SWEEP_LEGS = (8, 32, 128, 512)
SWEEP_RUNS = ((1, True, True), (4, True, True), (32, True, True), (4, True, False), (32, True, False),
              (1, False, True), (4, False, True), (32, False, True))      # (tol, coherent, aa)


def coherence_sweep(anim_path, out: Path, frames: int = 10, legs=SWEEP_LEGS, runs=SWEEP_RUNS) -> list[dict]:
    """`yproc anim` of `anim_path` for every light speed (frames per `wander` leg) and run
    (tolerance, --coherent, anti-aliasing; the plain runs at the slowest and fastest leg
    only): changed instructions per pattern line (changed_summary). Writes sweep.json (with
    the runs of an earlier sweep into `out` that were not repeated) and sweep.png."""
    yproc = build_yproc()
    res = []
    for tol, coh, aa in runs:
        for leg in (legs if coh else sorted({legs[0], legs[-1]})):
            name = f"t{tol}_l{leg}_{'coh' if coh else 'plain'}{'' if aa else '_noaa'}"
            a = anim_variant(anim_path, out / f"{name}.anim", frames, leg)
            t0 = time.time()
            flags = ["--tol", str(tol)] + (["--coherent"] if coh else []) + ([] if aa else ["--no-aa"])
            r = subprocess.run([str(yproc), "anim", str(a), "-o", str(out / name), *flags],
                               capture_output=True, text=True)
            if r.returncode:
                raise RuntimeError(f"yproc anim {a} {' '.join(flags)} failed:\n{r.stderr}")
            row = {"tol": tol, "coherent": coh, "aa": aa, "leg": leg, **changed_summary(out / name)}
            res.append(row)
            print(f"  tol {tol:>2} {'coherent' if coh else 'plain   '} {'aa  ' if aa else 'noaa'} leg {leg:>3}: "
                  f"median {row['median_slots']:.0f} slots / {row['median_cmds']:.0f} commands changed per "
                  f"line, {100 * row['unchanged_share']:.0f} % of lines unchanged, worst pixel "
                  f"{row['max_abs_err']:.2f} ({time.time() - t0:.0f} s)", flush=True)
    # runs of an earlier sweep into the same folder stay unless re-run here
    key = lambda r: (r["tol"], r["coherent"], r["aa"], r["leg"])
    old = json.loads((out / "sweep.json").read_text()) if (out / "sweep.json").exists() else []
    new = {key(r) for r in res}
    res = sorted([r for r in old if key(r) not in new] + res, key=key)
    (out / "sweep.json").write_text(json.dumps(res, indent=1) + "\n")
    plot_sweep(res, out / "sweep.png", Path(anim_path).name, frames)
    return res


def plot_sweep(res: list[dict], path, title: str, frames: int) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 3.8))
    keys = sorted({(r["tol"], r["coherent"], r["aa"]) for r in res}, key=lambda k: (not k[1], not k[2], k[0]))
    for k in keys:
        rr = sorted((r for r in res if (r["tol"], r["coherent"], r["aa"]) == k), key=lambda r: r["leg"])
        lab = f"tol {k[0]}, {'coherent' if k[1] else 'plain refit'}{'' if k[2] else ', no AA'}"
        ls = "-" if k[1] else ":"
        for i, key in enumerate(("median_slots", "median_cmds")):
            ax[i].plot([r["leg"] for r in rr], [r[key] for r in rr], ls, marker="o", label=lab)
    for i, what in enumerate(("instruction slots", "commands")):
        ax[i].axhline(5, color="grey", lw=0.8)
        ax[i].set_xscale("log", base=2)
        ax[i].set_xlabel("frames per leg of the light's wander (50 Hz: /50 s)")
        ax[i].set_ylabel(f"median changed {what} per line")
        ax[i].set_ylim(bottom=0)
    ax[0].legend(fontsize=7)
    fig.suptitle(f"{title}: changed instructions per pattern line and colour, {frames} frames a run", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


# ---- the Load Monitor loop, before and after (docs/yproc.md section 10) -----------------

LOD_RUNS = (("open", ("--no-degrade",), "open loop: full quality, no look-ahead"),
            ("ahead", (), "look-ahead degradation inside each line (yproc's default)"),
            ("loop", ("--lod-loop",), "Load Monitor loop: per-line level from the previous frame"),
            ("predict", ("--lod-predict",), "the loop + each line checked before it is emitted"))


def lod_compare(anim_path, out: Path, extra=()) -> dict:
    """`yproc anim` four times (LOD_RUNS): per frame the lines the Load Monitor (yproc's
    model of it, equal to the RTL's: test_fig727_lod.py) reports late, the mean level of
    detail, and for the loop the level of every line. Writes lod.json and lod.png."""
    yproc = build_yproc()
    res = {}
    for name, flags, _ in LOD_RUNS:
        d = out / f"lod_{name}"
        t0 = time.time()
        r = subprocess.run([str(yproc), "anim", str(anim_path), "-o", str(d), *flags, *extra],
                           capture_output=True, text=True)
        if r.returncode:
            raise RuntimeError(f"yproc anim {' '.join(flags)} failed:\n{r.stderr}")
        res[name] = lod_run_stats(d)
        print(f"  {name}: overflowing lines per frame {res[name]['overflow_lines']} "
              f"({time.time() - t0:.0f} s)", flush=True)
    (out / "lod.json").write_text(json.dumps({k: {kk: vv for kk, vv in v.items() if kk != "levels"}
                                              for k, v in res.items()}, indent=1) + "\n")
    plot_lod(res, out / "lod.png", Path(anim_path).name)
    return res


def lod_run_stats(d: Path) -> dict:
    """Per frame of one `yproc anim` run (its anim_stats.json): late lines, mean level,
    the busiest line's count, every line's level; the capacity and the scan time."""
    st = json.loads((Path(d) / "anim_stats.json").read_text())
    fr = st["frame"]
    return {"overflow_lines": [f["overflow_lines"] for f in fr],
            "mean_level": [f["mean_level"] for f in fr],
            "max_issued": [max(f["issued"]) for f in fr],
            "levels": [f["levels"] for f in fr],
            "lowered": [f.get("lowered_before_emit", 0) for f in fr],
            "tess": [f["tess"] for f in fr] if "tess" in fr[0] else None,
            "capacity": st["capacity"], "mean_scan_ms": st["mean_incremental_scan_ms"]}


def plot_lod(res: dict, path, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(14, 3.8))
    col = {"open": "#cc6677", "ahead": "#ddaa33", "loop": "#4477aa", "predict": "#228833"}
    for name, _, label in LOD_RUNS:
        if name not in res:
            continue
        r = res[name]
        ax[0].plot(r["overflow_lines"], label=label, color=col[name], marker=".")
        if name != "ahead":     # the look-ahead lowers patterns inside a line, not line levels
            ax[1].plot(r["mean_level"], label=label, color=col[name], marker=".")
    ax[0].set_xlabel("frame")
    ax[0].set_ylabel("late (overflowing) lines")
    ax[0].set_title("overflowing lines per frame")
    ax[0].legend(fontsize=7)
    tess = res.get("predict", {}).get("tess")
    if tess:
        # tessellation (yp_tess.c): the mesh version each object shows, 0 = its own mesh
        tw = ax[1].twinx()
        for k in range(len(tess[0])):
            tw.step(range(len(tess)), [t[k] for t in tess], where="mid", color="#aa3377", ls="--",
                    label=f"object {k}: mesh version shown (0 = finest)")
        tw.set_ylabel("mesh version (predict run)", color="#aa3377")
        tw.set_ylim(-0.2, max(max(t) for t in tess) + 1.5)
        tw.legend(fontsize=7, loc="upper right")
    ax[1].set_xlabel("frame")
    ax[1].set_ylabel("mean level of detail (5 = full)")
    ax[1].set_title("quality per frame")
    ax[1].set_ylim(0, 5.3)
    last = "predict" if "predict" in res else "loop"
    lv = np.array(res[last]["levels"]).T
    im = ax[2].imshow(lv, aspect="auto", cmap="viridis", vmin=0, vmax=5, interpolation="nearest")
    ax[2].set_xlabel("frame")
    ax[2].set_ylabel("scanline")
    ax[2].set_title(f"level per line ({last})")
    fig.colorbar(im, ax=ax[2], fraction=0.05)
    fig.suptitle(f"{title}: capacity {res['loop']['capacity']} slots per line and colour", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def monitor_record(stats: dict, height: int) -> tuple[list[int], list[int]]:
    """The Load Monitor's line table of one harness run (one frame played): per line the
    largest `issued` of the three colours and 1 if any colour was late, as the loop reads
    it (yp_lod_update)."""
    lm = stats["load_monitor"]
    issued = np.max([lm[c]["line_issued"][:height] for c in "RGB"], axis=0)
    late = np.zeros(height, int)
    for c in "RGB":
        for y in lm[c]["late_line_numbers"]:
            if y < height:
                late[y] = 1
    return [int(v) for v in issued], [int(v) for v in late]


def anim_screen(anim_path) -> tuple[int, int]:
    """(width, height) of an animation: its scene file's `screen` statement (640x480
    without one)."""
    anim_path = Path(anim_path)
    for ln in anim_path.read_text().splitlines():
        t = ln.split("#")[0].split()
        if len(t) == 2 and t[0] == "scene":
            sc = Path(t[1]) if Path(t[1]).is_absolute() else anim_path.parent / t[1]
            for sl in sc.read_text().splitlines():
                u = sl.split("#")[0].split()
                if len(u) == 3 and u[0] == "screen":
                    return int(u[1]), int(u[2])
            return 640, 480
    raise ValueError(f"{anim_path}: no 'scene FILE'")


def lod_loop(anim_path, out: Path, predict: bool = False, rtl: bool = False, chips: int | None = None,
             test: tuple | None = None, capacity: int | None = None, extra=(), log=print) -> dict:
    """`yproc anim --lod-loop` (`--lod-predict` with predict) once; `capacity`: yproc's
    --capacity (default: the video mode's). With rtl, the loop reads the Verilated display
    controller instead of yproc's model of its Load Monitor: yproc runs with
    --monitor-stdin, and after each frame (frame 0's streams, then each delta applied) the
    frame is played through the controller (diffengine.rtl.dc_harness, one harness run per
    frame) and its Load Monitor's line table (monitor_record) goes back to yproc on stdin,
    which takes the next frame's levels from it. `test`: the controller's geometry (default
    demo.controller_setup's for the animation's screen, HTotal 800); the capacity is then
    the controller's (demo.capacity: HTotal - 2) unless given. `chips`: per colour (default
    the fewest that cover the width). Returns anim_stats.json, with rtl also "rtl_seconds"
    and "frames_played"."""
    from .demo import capacity as ctrl_capacity, controller_setup
    yproc = build_yproc()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    flags = ["--lod-predict" if predict else "--lod-loop", *map(str, extra)]
    if rtl:
        W, H = anim_screen(anim_path)
        chips = chips or max(1, -(-W // 9))
        mode, geom = controller_setup(W, H, chips)
        if test is not None:
            mode, geom = 3, tuple(test)
        if capacity is None:
            capacity = ctrl_capacity(mode, geom)
    if capacity is not None:
        flags += ["--capacity", str(capacity)]
    if not rtl:
        r = subprocess.run([str(yproc), "anim", str(anim_path), "-o", str(out), *flags],
                           capture_output=True, text=True)
        if r.returncode:
            raise RuntimeError(f"yproc anim {' '.join(flags)} failed:\n{r.stderr}")
        return json.loads((out / "anim_stats.json").read_text())
    from ..rtl import dc_harness
    cfg = dc_harness.Config(chips=chips, test=geom)
    errpath = out / "yproc_stderr.txt"
    with open(errpath, "w") as err:
        proc = subprocess.Popen([str(yproc), "anim", str(anim_path), "-o", str(out), *flags, "--monitor-stdin"],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err, text=True)
        cur, played, t_rtl = None, 0, 0.0
        try:
            for line in proc.stdout:
                if not line.startswith("monitor "):
                    continue
                f = int(line.split()[1])
                if f == 0:
                    cur = [lines_of_de48(out / "frame000" / f"{c}.de48") for c in "rgb"]
                else:
                    _, _, _, chans = read_delta(out / f"frame{f:03d}.delta")
                    for c in range(3):
                        for y, words in chans[c].items():
                            cur[c][y] = words
                t0 = time.time()
                paths = []
                for c, name in enumerate("rgb"):
                    paths.append(out / f"rtl_{name}.de48")
                    paths[-1].write_bytes(to_de48(cur[c]))
                _, st = dc_harness.run(paths, cfg, mode=mode)
                t_rtl += time.time() - t0
                iss, late = monitor_record(st, len(cur[0]))
                proc.stdin.write(f"{f} " + " ".join(map(str, iss)) + " " + " ".join(map(str, late)) + "\n")
                proc.stdin.flush()
                played += 1
                log(f"  frame {f}: the controller's Load Monitor: {sum(late)} late line(s), busiest "
                    f"line {max(iss)} slots ({time.time() - t0:.1f} s)")
            proc.wait()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    if proc.returncode:
        raise RuntimeError(f"yproc anim {' '.join(flags)} --monitor-stdin failed:\n" + errpath.read_text())
    st = json.loads((out / "anim_stats.json").read_text())
    st["rtl_seconds"], st["frames_played"] = t_rtl, played
    return st


def plot_lod_rtl(outs: list, path) -> dict:
    """The Verilated controller in the loop against yproc's model (`--lod-loop --rtl
    --compare-model` writes OUT/loop and OUT/loop_model): per OUT, late lines and mean level
    per frame of both runs, the lines whose level differs between them, and the mesh version
    where the animation has tessellation. Returns a summary per OUT (also lod_rtl.json)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2))
    cols = ["#4477aa", "#228833", "#cc6677", "#ddaa33"]
    summary = {}
    for i, o in enumerate(map(Path, outs)):
        A = json.loads((o / "loop" / "anim_stats.json").read_text())
        B = json.loads((o / "loop_model" / "anim_stats.json").read_text())
        col, name = cols[i % len(cols)], f"{Path(A['anim']).name}{' + check' if A.get('lod_predict') else ''}"
        diff = [sum(a != b for a, b in zip(x["levels"], y["levels"])) for x, y in zip(A["frame"], B["frame"])]
        summary[str(o)] = {"anim": A["anim"], "predict": A.get("lod_predict", 0),
                           "late_lines": sum(f["overflow_lines"] for f in A["frame"]),
                           "frames_model_agrees": sum(f.get("model_agrees", 0) for f in A["frame"]),
                           "frames": len(A["frame"]), "level_differences": sum(diff),
                           "tess_same": [f.get("tess") for f in A["frame"]] == [f.get("tess") for f in B["frame"]]}
        ax[0].plot([f["overflow_lines"] for f in A["frame"]], color=col, marker=".", label=f"{name}: RTL")
        ax[0].plot([f["overflow_lines"] for f in B["frame"]], color=col, ls=":", lw=3, alpha=.6,
                   label=f"{name}: model")
        ax[1].plot([f["mean_level"] for f in A["frame"]], color=col, marker=".")
        ax[1].plot([f["mean_level"] for f in B["frame"]], color=col, ls=":", lw=3, alpha=.6)
        ax[2].plot(diff, color=col, marker=".", label=name)
        if "tess" in A["frame"][0]:
            tw = ax[1].twinx()
            tw.step(range(len(A["frame"])), [f["tess"][0] for f in A["frame"]], where="mid", color="#aa3377",
                    ls="--", label=f"{name}: mesh version (RTL run)")
            tw.set_ylim(-0.2, 3)
            tw.set_ylabel("mesh version", color="#aa3377")
            tw.legend(fontsize=7, loc="upper right")
    ax[0].set_title("late lines per frame (the controller's record)")
    ax[0].set_xlabel("frame")
    ax[0].legend(fontsize=6, loc="upper right")
    ax[1].set_title("mean level per frame")
    ax[1].set_xlabel("frame")
    ax[1].set_ylim(0, 5.3)
    ax[2].set_title("lines whose level differs, RTL against model")
    ax[2].set_xlabel("frame")
    ax[2].set_ylim(-0.5, 5)
    ax[2].legend(fontsize=7)
    fig.suptitle("The Verilated display controller's Load Monitor read back every frame "
                 "(dotted: the same animation on yproc's model)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    Path(path).with_suffix(".json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def configure(ap) -> None:
    """The arguments of `diffengine anim` (make anim)."""
    ap.epilog = COMMAND_HELP
    ap.add_argument("--anim", default=str(REPO / "sw/scenes/anim/cad_drag.anim"))
    ap.add_argument("--out", default=str(REPO / "out" / "anim"))
    ap.add_argument("--model", choices=("fast", "numpy"), default="fast",
                    help="golden model of the changed lines: fast = the C functional model "
                         "(default), numpy = diffengine.model.functional")
    ap.add_argument("--lod-compare", action="store_true",
                    help="instead: the animation four times (open loop, look-ahead degradation, "
                         "Load Monitor loop, the loop with the check before emission): overflowing lines and quality per frame -> OUT/lod.png, "
                         "lod.json (docs/yproc.md section 10)")
    ap.add_argument("--mode", choices=("640x480", "640x485", "1280x1024"),
                    help="with --lod-compare: the video mode (raster and slots per line) for yproc")
    ap.add_argument("--lod-loop", action="store_true",
                    help="instead: the Load Monitor loop once (yproc anim --lod-loop) -> OUT/loop")
    ap.add_argument("--predict", action="store_true",
                    help="with --lod-loop: each line also checked against the capacity before it "
                         "is emitted (--lod-predict)")
    ap.add_argument("--rtl", action="store_true",
                    help="with --lod-loop: the per-line counts come from the Verilated display "
                         "controller's Load Monitor, frame by frame, instead of yproc's model "
                         f"(test-mode geometry, HTotal {H_TOTAL} unless 640x480; slow at full size)")
    ap.add_argument("--chips", type=int, help="with --rtl: chips per colour (default: the fewest "
                    "that cover the width)")
    ap.add_argument("--compare-model", action="store_true",
                    help="with --lod-loop --rtl: also the same run on yproc's model (OUT/loop_model) "
                         "and the comparison OUT/lod_rtl.png, lod_rtl.json")
    ap.add_argument("--plot-rtl", nargs="+", metavar="OUT",
                    help="instead: one plot of several --lod-loop --rtl --compare-model outputs -> "
                         "--out/lod_rtl.png")
    ap.add_argument("--htotal", type=int, help="with --rtl: the controller's HTotal in test mode, "
                    f"porches 4 + 8 (slots per line + 2; default {H_TOTAL}, or the 640x480 mode)")
    ap.add_argument("--capacity", type=int, help="with --lod-loop: yproc's slots per line "
                    "(default: the mode's, or with --rtl the controller's HTotal - 2)")
    ap.add_argument("--coherent", action="store_true",
                    help="yproc anim --coherent: keep the previous frame's colour functions where they "
                         "still meet the tolerance (docs/yproc.md section 11)")
    ap.add_argument("--tol", type=float, help="yproc's fit tolerance (pixel units; default 1)")
    ap.add_argument("--coh-sweep", action="store_true",
                    help="instead: the animation at several light speeds and tolerances, with and "
                         "without --coherent: changed instructions per line -> OUT/sweep.png, sweep.json")
    ap.add_argument("--frames", type=int, default=10, help="with --coh-sweep: frames per run (default 10)")
    ap.add_argument("--legs", help="with --coh-sweep: frames per leg of the light, comma-separated "
                                   f"(default {','.join(map(str, SWEEP_LEGS))})")
    ap.add_argument("--runs", help="with --coh-sweep: the runs as TOL:coh|plain:aa|noaa, comma-separated "
                                   "(default: every one of SWEEP_RUNS)")
    ap.set_defaults(func=command)


def command(a) -> int:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.plot_rtl:
        summary = plot_lod_rtl(a.plot_rtl, out / "lod_rtl.png")
        for k, v in summary.items():
            print(f"  {k}: {v}")
        print(f"wrote {out / 'lod_rtl.png'}")
        return 0
    if a.lod_loop:
        print(f"anim: {a.anim}: the Load Monitor loop{' + check before emission' if a.predict else ''}"
              f"{', the Verilated controller in the loop' if a.rtl else ''}", flush=True)
        try:
            test = None
            if a.htotal:
                # short porches (front 4, sync 8) as in the tests' short lines
                W, H = anim_screen(a.anim)
                test = (W, 4, 8, a.htotal - W - 12, H, 1, 2, 2)
                if test[3] < 1:
                    raise ValueError(f"--htotal {a.htotal} leaves no back porch for width {W}")
            st = lod_loop(a.anim, out / "loop", predict=a.predict, rtl=a.rtl, chips=a.chips, test=test,
                          capacity=a.capacity, extra=("--mode", a.mode) if a.mode else ())
        except (RuntimeError, ValueError) as e:
            print(f"anim: error: {e}", file=sys.stderr)
            return 1
        ov = [f["overflow_lines"] for f in st["frame"]]
        agree = [f.get("model_agrees", 1) for f in st["frame"]]
        print(f"  late lines per frame {ov} (total {sum(ov)}); mean level per frame "
              f"{[round(f['mean_level'], 2) for f in st['frame']]}")
        if a.rtl:
            print(f"  the controller's record equals yproc's model in {sum(agree)} of {len(agree)} "
                  f"frames; RTL {st['rtl_seconds']:.0f} s for {st['frames_played']} frames")
        if a.rtl and a.compare_model:
            lod_loop(a.anim, out / "loop_model", predict=a.predict, capacity=st["capacity"],
                     extra=("--mode", a.mode) if a.mode else ())
            summary = plot_lod_rtl([out], out / "lod_rtl.png")[str(out)]
            print(f"  the same on yproc's model: lines whose level differs {summary['level_differences']}, "
                  f"mesh versions the same: {summary['tess_same']} ({out / 'lod_rtl.png'})")
            agree.append(summary["level_differences"] == 0 and summary["tess_same"])
        print(f"wrote {out / 'loop'}")
        return 0 if st["frames_differing_from_full"] == 0 and all(agree) else 1
    if a.lod_compare:
        print(f"anim: {a.anim} four times (open loop, look-ahead, Load Monitor loop, loop + check)", flush=True)
        try:
            lod_compare(a.anim, out, ("--mode", a.mode) if a.mode else ())
        except RuntimeError as e:
            print(f"anim: error: {e}", file=sys.stderr)
            return 1
        print(f"wrote {out / 'lod.png'}, {out / 'lod.json'}")
        return 0
    if a.coh_sweep:
        print(f"anim: {a.anim} at light speeds {a.legs or SWEEP_LEGS} frames per leg, {a.frames} frames a run",
              flush=True)
        try:
            legs = tuple(int(v) for v in a.legs.split(",")) if a.legs else SWEEP_LEGS
            runs = SWEEP_RUNS
            if a.runs:
                runs = []
                for r in a.runs.split(","):
                    t, c, aa = r.split(":")
                    if c not in ("coh", "plain") or aa not in ("aa", "noaa"):
                        print(f"anim: --runs: '{r}' is not TOL:coh|plain:aa|noaa", file=sys.stderr)
                        return 2
                    runs.append((float(t) if "." in t else int(t), c == "coh", aa == "aa"))
            coherence_sweep(a.anim, out, a.frames, legs, runs)
        except RuntimeError as e:
            print(f"anim: error: {e}", file=sys.stderr)
            return 1
        print(f"wrote {out / 'sweep.png'}, {out / 'sweep.json'}")
        return 0
    yproc = build_yproc()
    t0 = time.time()
    flags = (["--coherent"] if a.coherent else []) + (["--tol", str(a.tol)] if a.tol else [])
    print(f"anim: yproc anim {a.anim} {' '.join(flags)} (each frame also re-rendered in full for the check)",
          flush=True)
    res = subprocess.run([str(yproc), "anim", a.anim, "-o", str(out / "streams"), *flags],
                         capture_output=True, text=True)
    if res.returncode:
        print(f"anim: error: yproc anim failed:\n{res.stderr}", file=sys.stderr)
        return 1
    st = json.loads((out / "streams" / "anim_stats.json").read_text())
    W, H = st["width"], st["height"]
    print(f"  yproc anim: {st['frames']} frames {W}x{H} in {time.time() - t0:.1f} s; "
          f"changed lines/frame {st['mean_changed_lines']:.0f} of {H}; incremental "
          f"{st['mean_incremental_ms']:.0f} ms/frame, full {st['mean_full_ms']:.0f} ms/frame (CPU)",
          flush=True)
    seq = frames(out / "streams")
    img = np.zeros((H, W, 3), dtype=np.uint16)
    pics = []
    t1 = time.time()
    for f, chans in enumerate(seq):
        for c in range(3):
            if f == 0:
                changed = list(range(len(chans[c])))
            else:
                changed = [y for y in range(len(chans[c])) if chans[c][y] != seq[f - 1][c][y]]
            if changed and a.model == "numpy":
                img[changed, :, c] = render_lines([chans[c][y] for y in changed], W)
            elif changed:
                fast.render_lines(img, [{y: chans[c][y] for y in changed} if k == c else {}
                                        for k in range(3)])
        frame.write_png8(out / f"frame{f:03d}.png", img)
        pics.append(frame.view8(img).copy())
        done = f + 1
        bar = "#" * (30 * done // len(seq))
        if sys.stdout.isatty():
            print(f"\r  golden model, changed lines only [{bar:<30}] {done}/{len(seq)}", end="", flush=True)
        elif done % 6 == 0 or done == len(seq):
            print(f"  golden model, changed lines only: {done}/{len(seq)} frames", flush=True)
    print(f"{'' if not sys.stdout.isatty() else chr(10)}  golden model ({a.model}, changed "
          f"lines only) and PNG/GIF frames: {time.time() - t1:.1f} s")
    # the image updated line by line == the last frame's streams rendered from scratch
    # by the numpy reference model
    full = np.stack([render_lines(seq[-1][c], W) for c in range(3)], axis=-1)
    pixel_ok = bool((full == img).all())
    try:
        from PIL import Image
        ims = [Image.fromarray(p) for p in pics]
        ims[0].save(out / "anim.gif", save_all=True, append_images=ims[1:], duration=80, loop=0)
        gif = f", {out / 'anim.gif'}"
    except ImportError:
        gif = ""
    h = changed_histogram(st, seq)
    if h:
        (out / "changed.json").write_text(json.dumps(h, indent=1) + "\n")
        plot_changed(h, out / "changed.png", f"{Path(a.anim).name}: instructions changed between "
                     "successive frames (LCS of each line's commands)")
        print(f"  changed instructions per scanline (one colour, frames 1..{len(seq) - 1}): median "
              f"{h['median_all']:.0f} over all lines, {h['median_changed_lines']:.0f} over the changed "
              f"ones, max {max(h['max'])}; slots per line {h.get('mean_slots_per_line', 0):.0f} on average "
              f"({out / 'changed.png'})")
    bad = st["frames_differing_from_full"]
    print(f"frames whose streams differ from yproc's full re-render: {bad}; last frame, "
          f"line-by-line update vs from-scratch render: {'identical' if pixel_ok else 'DIFFERENT'}")
    print(f"wrote {out}/frame000.png .. frame{len(seq) - 1:03d}.png{gif}")
    return 0 if bad == 0 and pixel_ok else 1
