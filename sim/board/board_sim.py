#!/usr/bin/env python3
"""Whole-board full-frame simulations (issue 18 item 4, docs/board-frames.md).

    board_sim.py [--cases teapot,cad,anim] [--out out/board_sim] [--anim-frames 0,1,2]
                 [--loops 1] [--window 4] [--gain 1] [--threads 1] [--no-build]

Each case: `yproc scan` (the teapot and the CAD scene, at the board's line capacity,
as `make demo` runs it) or `yproc anim` (the shipped animation, as `make anim`) writes
the colour streams; they become frame-store words at window --window (4) with the
intensities halved --gain times (1) and rounded, as `de32_load.py --window 4 --round
--gain 1` does (the 27-bit operand holds intensities below 1,024 pixel units at window
4; the scenes' reach 4,095); `fpga/ulx3s/frame_pack.py` packs them into
tables of lines and writes the SDRAM model's preload image; the golden frames are the C
functional model (`diffengine.model.fast`) of the mapped words, through the 8-bit
output window (`O` shift 4 - gain, no saturation: with gain 1 pixel[10:3] of the halved
intensities, which is `make demo`'s 8-bit view, pixel[11:4]). Each case also renders
its .de48 streams themselves and reports how many pixels of the golden frame differ
from that 8-bit view (the frame store's loss; summary "store loss").
The Verilated board (sim/board: de_board_core, 72 chips per colour as span-serial
arrays, mode 0 = 640x480, SDRAM model at 125 MHz CL 3) starts from the preload; the
harness sends the `O`, `F` and `Q` packets over the UART at 3 Mbaud, decodes the three
TMDS streams, compares every frame with the golden frames and reads the Load Monitors'
late-line and dropped-word totals and the SDRAM model's violation count.

Checks per case: every frame after the sequence starts equals its golden frame exactly,
in the sequence's order (an animation: frames 0, 1, 2, switching at frame boundaries;
--loops > 0 also shows the wrap back to frame 0), 0 late lines, 0 dropped words,
0 SDRAM violations, sync and loader replies right, and each golden frame at most 1 % of
its pixels more than 8 levels off the streams' own view; the span arrays' FIFO overflow and
late flags are reported as warnings. Writes per case OUT/CASE/: the decoded frames as
PNG (frame_NN.png), golden_NN.png, streams_NN.png (the streams' own view), diff_NN.png (differing pixels red, each in a red
9x9 box, on the dimmed golden), strip.png (an animation's frames side by side),
stats.json (the harness's); OUT/summary.json and OUT/summary.md. Exit status 0 only if
every case passed.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "sw"))
sys.path.insert(0, str(ROOT / "fpga" / "ulx3s"))

import de32_load  # noqa: E402
import frame_pack  # noqa: E402
from diffengine import isa  # noqa: E402
from diffengine.formats import binfmt, frame  # noqa: E402
from diffengine.model import fast  # noqa: E402

WIDTH, HEIGHT, MODE = 640, 480, 0
CAPACITY = 798                    # mode 0's usable slots per line (make demo's --capacity)
WINDOW = 4                        # frame-store window (--window)
GAIN = 1                          # intensities halved this often (--gain)
SHIFT, SAT = 3, False             # the 8-bit output window (shift = window - gain), wrapping
# The frame store's loss against the streams: at most this share of a frame's pixels may
# differ from the streams' own 8-bit view by more than LOSS_LEVELS (any colour).
LOSS_LEVELS, LOSS_MAX = 8, 0.01
SCENES = {"teapot": ROOT / "sw/scenes/teapot/teapot.scene",
          "cad": ROOT / "sw/scenes/cad/cad.scene"}
ANIM = ROOT / "sw/scenes/anim/cad_drag.anim"


def log(msg: str) -> None:
    print(msg, flush=True)


# ---------------------------------------------------------------------------- inputs
def yproc_exe() -> Path:
    r = subprocess.run(["make", "-s", "-C", str(ROOT / "sw/yproc"), "build/yproc"],
                       capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(f"board_sim: cannot build sw/yproc:\n{r.stdout}{r.stderr}")
    return ROOT / "sw/yproc/build/yproc"


def streams(case: str, out: Path) -> Path:
    """The case's yproc output directory (scan: r/g/b.de48; anim: frame000/ + deltas)."""
    d = out / "streams"
    if case in SCENES:
        cmd = [str(yproc_exe()), "scan", str(SCENES[case]), "-o", str(d),
               "--capacity", str(CAPACITY)]
    else:
        cmd = [str(yproc_exe()), "anim", str(ANIM), "-o", str(d)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        raise SystemExit(f"board_sim: {' '.join(cmd)} failed:\n{r.stderr}")
    return d


def case_frames(case: str, d: Path, anim_frames: list[int]) -> list:
    """Frames [f][c] = (words, window, comp) as the host tool reads them."""
    if case in SCENES:
        return [de32_load.read_scene([str(d)], WINDOW, True, GAIN)]
    from diffengine.pipeline import anim
    every = anim.frames(d)                    # the lines of every frame (deltas applied)
    bad = [f for f in anim_frames if not 0 <= f < len(every)]
    if bad:
        raise SystemExit(f"board_sim: --anim-frames {bad}: the animation has {len(every)} frames")
    # Only the frames played become frame-store words (de32_load.read_anim's conversion).
    return [[de32_load.de48_image(anim.to_de48(every[f][c]), f"{d} frame {f} {'rgb'[c]}",
                                  WINDOW, True, GAIN) for c in range(3)] for f in anim_frames]


def stream_views(case: str, d: Path, anim_frames: list[int]) -> np.ndarray:
    """(frames, H, W, 3): the .de48 streams themselves through the C functional model,
    at `make demo`'s 8-bit view of the window (pixel[WINDOW+7:WINDOW]), no frame store."""
    if case in SCENES:
        per_frame = [[(d / f"{c}.de48").read_bytes() for c in "rgb"]]
    else:
        from diffengine.pipeline import anim
        every = anim.frames(d)
        per_frame = [[anim.to_de48(every[f][c]) for c in range(3)] for f in anim_frames]
    views = []
    for streams3 in per_frame:
        img = np.zeros((HEIGHT, WIDTH, 3), dtype=np.uint16)
        for c, de48 in enumerate(streams3):
            slots = binfmt.decode_de48(de48, f"{d} {'rgb'[c]}")
            data = b"".join(((i << isa.WORD_BITS) | x).to_bytes(6, "big") for i, x in slots)
            fast.render_words(data, WIDTH, img[..., c], name=f"colour {'rgb'[c]}")
        views.append(((img.astype(np.int32) >> WINDOW) & 0xFF).astype(np.uint8))
    return np.stack(views)


def store_loss(gold: np.ndarray, views: np.ndarray) -> list[dict]:
    """Per frame: how far the golden frame (the frame-store words) is from the streams'
    own view; levels wrap at 256 as the output window does."""
    out = []
    for g, v in zip(gold, views):
        d = np.abs(g.astype(np.int32) - v.astype(np.int32))
        d = np.minimum(d, 256 - d).max(axis=-1)
        out.append({"pixels_differing": int((d > 0).sum()),
                    f"over_{LOSS_LEVELS}_levels": round(float((d > LOSS_LEVELS).mean()), 6),
                    "over_32_levels": round(float((d > 32).mean()), 6),
                    "max_levels": int(d.max())})
    return out


def out8(p: np.ndarray) -> np.ndarray:
    """The board's 8-bit output window ('O' shift, sat) of 12-bit pixels."""
    sh = p.astype(np.int32) >> SHIFT
    if not SAT:
        return (sh & 0xFF).astype(np.uint8)
    return np.where(p & 0x800, 0, np.minimum(sh, 0xFF)).astype(np.uint8)


def golden(fr) -> np.ndarray:
    """One frame's (H, W, 3) 8-bit golden image: the functional model of the mapped
    frame-store words (the data mapper binfmt.map_word, window and compensation)."""
    img = np.zeros((HEIGHT, WIDTH, 3), dtype=np.uint16)
    for c, (words, window, comp) in enumerate(fr):
        slots = binfmt.framestore_slots(words, window, comp)
        data = b"".join(((i << isa.WORD_BITS) | d).to_bytes(6, "big") for i, d in slots)
        fast.render_words(data, WIDTH, img[..., c], name=f"colour {'rgb'[c]}")
    return out8(img)


def host_packets(plan: frame_pack.Plan) -> list[bytes]:
    # The loader's version-2 packets (docs/sdram-frames-spec.md §3), from the host tool.
    return ([de32_load.cmd_o(SHIFT, SAT)] + [de32_load.cmd_f(*s) for s in plan.slots]
            + [de32_load.cmd_q(*plan.sequence)])


def sequence_check(res: dict, n_frames: int, hold: int, want: int):
    """The harness's frames (stats.json) against the sequence: from the first frame that is
    not black, slot k for `hold` frames each, and at least `want` of them (the harness
    stops after want + 8 frames in all, so a sequence that starts late shows fewer).
    Returns (live frames, golden index of each, the index expected, errors)."""
    first = res["first_live_frame"]
    live = list(res["frames"][first:]) if first >= 0 else []
    order = [f["golden"] for f in live]
    expect = [(k // hold) % n_frames for k in range(len(live))]
    errors = list(res["errors"])
    if order != expect:
        errors.append(f"frames shown {order}, want the sequence {expect}")
    if len(live) < want:
        errors.append(f"{len(live)} frame(s) of the sequence shown (from decoded frame "
                      f"{first}), want {want}")
    return live, order, expect, errors


# ---------------------------------------------------------------------------- one case
def run_case(case: str, a, exe: Path) -> dict:
    out = Path(a.out) / case
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    d = streams(case, out)
    frames = case_frames(case, d, a.anim_frames)
    plan = frame_pack.pack(frames, HEIGHT, loop=len(frames) > 1)
    image = out / "sdram.hex"
    nwords = plan.write_image(image)
    (out / "host.txt").write_text(
        "# board_sim: the host's packets (O, F per slot and colour, Q), hex\n"
        + "".join(p.hex(" ") + "\n" for p in host_packets(plan)))
    gold = np.stack([golden(fr) for fr in frames])
    gold.tofile(out / "golden.rgb")
    for k, g in enumerate(gold):
        frame.write_rgb8(out / f"golden_{k:02d}.png", g)
    views = stream_views(case, d, a.anim_frames)
    loss = store_loss(gold, views)
    for k, v in enumerate(views):
        frame.write_rgb8(out / f"streams_{k:02d}.png", v)
    log(f"{case}: store loss (golden vs the streams' own 8-bit view): " + "; ".join(
        f"frame {k}: {x['pixels_differing']:,} pixels differ, "
        f"{x[f'over_{LOSS_LEVELS}_levels']:.2%} by more than {LOSS_LEVELS} levels"
        for k, x in enumerate(loss)))
    st = plan.stats()
    used = ", ".join(f"{s['words_used']:,}" for s in st)
    ref = ", ".join(f"{s['words_referenced']:,}" for s in st)
    log(f"{case}: {len(frames)} frame(s); SDRAM image {nwords:,} words ({used} per colour, "
        f"the frames reference {ref}); inputs in {time.monotonic() - t0:.1f} s")
    want = len(frames) * (1 + a.loops)
    cmd = [str(exe), f"+sdram_image={image}", f"+sdram_log={out / 'sdram.log'}",
           "--host", str(out / "host.txt"), "--golden", str(out / "golden.rgb"),
           "--frames", str(want), "--out", str(out / "frames.rgb"),
           "--stats", str(out / "stats.json"), "--mode", str(MODE), "--progress"]
    log(f"{case}: {' '.join(cmd)}")
    t1 = time.monotonic()
    r = subprocess.run(cmd)
    wall = time.monotonic() - t1
    if r.returncode == 2 or not (out / "stats.json").exists():
        return {"case": case, "ok": False, "errors": [f"harness exit status {r.returncode}"]}
    res = json.loads((out / "stats.json").read_text())
    live, order, expect, errors = sequence_check(res, len(frames), plan.sequence[2], want)
    for k, x in enumerate(loss):
        if x[f"over_{LOSS_LEVELS}_levels"] > LOSS_MAX:
            errors.append(f"frame {k}: the frame store loses the picture: "
                          f"{x[f'over_{LOSS_LEVELS}_levels']:.2%} of the pixels differ from the "
                          f"streams by more than {LOSS_LEVELS} levels (over {LOSS_MAX:.0%}; "
                          f"streams_{k:02d}.png against golden_{k:02d}.png; --gain)")
    dec = np.fromfile(out / "frames.rgb", dtype=np.uint8)
    dec = dec.reshape(-1, HEIGHT, WIDTH, 3) if dec.size else dec.reshape(0, HEIGHT, WIDTH, 3)
    for k, (f, img) in enumerate(zip(live, dec)):
        frame.write_rgb8(out / f"frame_{k:02d}.png", img)
        g = gold[expect[k]]
        bad = np.any(img != g, axis=-1)
        diff = (g // 3).astype(np.uint8)
        # A few wrong pixels must show at a glance: a red 9x9 box around each.
        near = np.zeros_like(bad)
        for y, x in np.argwhere(bad):
            near[max(0, y - 4):y + 5, max(0, x - 4):x + 5] = True
        diff[near] = (160, 0, 0)
        diff[bad] = (255, 64, 64)
        frame.write_rgb8(out / f"diff_{k:02d}.png", diff)
    if len(frames) > 1 and len(dec) >= len(frames):   # the sequence once, side by side
        frame.write_rgb8(out / "strip.png", np.concatenate(list(dec[:len(frames)]), axis=1))
    summary = {
        "case": case, "ok": not errors and res["ok"], "errors": errors,
        "frames_packed": len(frames), "sequence": list(plan.sequence),
        "sdram_words": nwords, "pack": st,
        "frames_shown": order, "frames_expected": expect,
        "pixels_differing": [f["pixels_differing"] for f in live],
        "late_lines": res["late_lines"], "dropped_words": res["dropped_words"],
        "sdram_violations": res["sdram"]["violations"], "sdram_refreshes": res["sdram"]["refreshes"],
        "pixel_clocks": res["pixel_clocks"], "simulated_ms": res["simulated_ms"],
        "seconds": round(wall, 1), "cpu_seconds": res["cpu_seconds"],
        "pixel_clocks_per_second": res["pixel_clocks_per_second"],
        "black_frames_before": res["first_live_frame"], "status": res["status"],
        "warnings": res["warnings"],
        "span_overflow_first": [sa["overflow_first"] for sa in res["span_arrays"]],
        "window": WINDOW, "gain": GAIN, "shift": SHIFT, "store_loss": loss,
    }
    log(f"{case}: {'PASS' if summary['ok'] else 'FAIL'}: frames {order} (want {expect}), "
        f"pixels differing {summary['pixels_differing']}, late lines {res['late_lines']}, "
        f"dropped words {res['dropped_words']}, SDRAM violations {res['sdram']['violations']}; "
        f"{res['simulated_ms']:.1f} ms simulated in {wall:.0f} s"
        + "".join(f"\n  warning: {w}" for w in res["warnings"])
        + "".join(f"\n  error: {e}" for e in errors))
    return summary


def write_summary(results: list[dict], out: Path, a) -> None:
    (out / "summary.json").write_text(json.dumps(results, indent=1) + "\n")
    rows = ["| case | frames (shown / want) | pixels differing | late lines | dropped words "
            "| SDRAM violations | span FIFO overflow (first: frame, line) | simulated "
            "| store loss (pixels > 8 levels off the streams) | wall (CPU) | result |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        if "frames_shown" not in r:
            rows.append(f"| {r['case']} | - | - | - | - | - | - | - | - | - | FAIL: {r['errors']} |")
            continue
        ovf = sorted({(o[1] - r["black_frames_before"], o[2]) for o in r["span_overflow_first"]
                      if o[0] >= 0})
        ovf_s = ", ".join(f"sequence frame {f}, line {y}" for f, y in ovf) or "none"
        shown = ", ".join("≠" if k < 0 else str(k) for k in r["frames_shown"])
        want = ", ".join(str(k) for k in r["frames_expected"])
        rows.append(f"| {r['case']} | {shown} / {want} | "
                    f"{r['pixels_differing']} | {r['late_lines']} | {r['dropped_words']} | "
                    f"{r['sdram_violations']} | {ovf_s} | {r['simulated_ms']:.1f} ms | "
                    + ", ".join(f"{x[f'over_{LOSS_LEVELS}_levels']:.2%}" for x in r["store_loss"])
                    + " | "
                    f"{r['seconds']:.0f} s ({r['cpu_seconds']:.0f} s) | "
                    f"{'PASS' if r['ok'] else 'FAIL'} |")
    (out / "summary.md").write_text(
        f"# Whole-board full-frame simulations\n\n`{' '.join(sys.argv)}`, "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}\n\n" + "\n".join(rows)
        + "\n\nFrames shown: the golden frame each decoded frame equals exactly, from the first "
        "that is not black (≠: none). Store loss: the golden frame (the frame-store words, "
        f"window {WINDOW}, gain {GAIN}, output shift {SHIFT}) against the .de48 streams' own "
        "8-bit view, per frame.\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 2)[2],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="teapot,cad,anim", help="teapot,cad,anim (all)")
    ap.add_argument("--out", default=str(ROOT / "out" / "board_sim"), help="(out/board_sim)")
    ap.add_argument("--anim-frames", default="0,1,2",
                    type=lambda s: [int(x) for x in s.split(",")],
                    help="the animation's frames to pack and play in sequence (0,1,2)")
    ap.add_argument("--loops", type=int, default=0,
                    help="extra passes through the sequence (1: see the wrap; 0)")
    ap.add_argument("--window", type=int, default=4, choices=range(5),
                    help="frame-store window of the streams (4)")
    ap.add_argument("--gain", type=int, default=1, choices=range(4),
                    help="halve the streams' intensities this often before they become "
                         "frame-store words; the output shift is window - gain (1)")
    ap.add_argument("--threads", type=int, default=1, help="Verilator threads (1)")
    ap.add_argument("--no-build", action="store_true", help="use the built harness as is")
    a = ap.parse_args(argv)
    global WINDOW, GAIN, SHIFT
    WINDOW, GAIN = a.window, a.gain
    if GAIN > WINDOW:
        ap.error(f"--gain {GAIN} over --window {WINDOW}: the output shift would be negative")
    SHIFT = WINDOW - GAIN
    cases = a.cases.split(",")
    bad = [c for c in cases if c not in (*SCENES, "anim")]
    if bad:
        ap.error(f"unknown case(s) {bad}")
    mk = ["make", "-s", "-C", str(ROOT / "sim/board"), f"THREADS={a.threads}"]
    if not a.no_build:
        log("board_sim: building the Verilated board (sim/board; the first build takes minutes)")
        if subprocess.run(mk).returncode:
            return 1
    exe = Path(subprocess.run(mk + ["path"], capture_output=True, text=True).stdout.strip())
    if not exe.exists():
        print(f"board_sim: {exe}: not built", file=sys.stderr)
        return 1
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = [run_case(c, a, exe) for c in cases]
    write_summary(results, out, a)
    log(f"board_sim: wrote {out / 'summary.md'}: "
        + ", ".join(f"{r['case']} {'PASS' if r['ok'] else 'FAIL'}" for r in results))
    return 0 if all(r["ok"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
