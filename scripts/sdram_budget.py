#!/usr/bin/env python3
"""SDRAM frame-store bandwidth budget and prefetch FIFO depth (docs/sdram.md §3).

For each scene, `yproc scan` at 640x480 writes the three colour streams; the words per
line (one 32-bit frame-store word per bus slot, the end-of-line marker included) are
played against an SDRAM that delivers R words per pixel clock in bursts of B words to
three per-colour prefetch FIFOs of depth D, round-robin among the FIFOs with room for a
burst. The display side takes, per colour, the words of line v+1 one per pixel clock
from the start of line v's window (h = 1 .. HTotal-1, docs/display-controller.md), the
worst case for the FIFO; a line whose words are not all taken by the window's end is
late. The smallest D with no late line, over two frames starting from full FIFOs in
vertical blanking, is the depth the colour needs.

    scripts/sdram_budget.py [--scenes teapot,cad] [--rates 2.460,2.375,1.538] [--burst 4]
                            [--fetch]

--fetch adds the depth for the fetchers' real read pattern on frames stored as tables of
lines (fetch_bursts: table bursts, blocks read in whole bursts, pads), not plain streams.

A rate is words per pixel clock: f_sdram x efficiency / 2 beats per word / 25 MHz.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENES = {"teapot": "sw/scenes/teapot/teapot.scene", "cad": "sw/scenes/cad/cad.scene"}
H_TOTAL, V_ACTIVE, V_TOTAL = 800, 480, 525


def words_per_line(path: Path) -> list[int]:
    """One frame-store word per bus slot: the slots of each line, its marker included
    (make bench-span's count, diffengine.bench.span)."""
    if str(ROOT / "sw") not in sys.path:
        sys.path.insert(0, str(ROOT / "sw"))
    from diffengine.bench.span import slots_per_line
    return slots_per_line(path)


def fetch_bursts(lines_c: list[int], burst: int, fetch: bool) -> list[tuple[int, int]]:
    """One colour's frame as the SDRAM serves it, per burst (words into the FIFO, words on
    the bus). Plain: the stream in bursts of `burst` words. `fetch`: as de_frame_fetch
    reads a frame stored as a table of lines (fpga/ulx3s/frame_pack.py): a table burst
    (no FIFO words) ahead of every `burst` lines, each line's block in ceil(len / burst)
    bursts (the words past the line's end are read and dropped), and a line that is only
    its marker as a pad (one FIFO word, no SDRAM read)."""
    if not fetch:
        return [(burst, burst)]
    out = []
    for v, n in enumerate(lines_c):
        if v % burst == 0:
            out.append((0, burst))
        if n == 1:
            out.append((1, 0))
            continue
        out += [(min(burst, n - k), burst) for k in range(0, n, burst)]
    return out


def late_lines(lines: list[list[int]], rate: float, burst: int, depth: int,
               frames: int = 2, fetch: bool = False) -> int:
    """Late lines over `frames` frames with per-colour FIFOs of `depth` words; `fetch`:
    the fetchers' read pattern (fetch_bursts) instead of plain streams."""
    nc = len(lines)
    seq = [fetch_bursts(c, burst, fetch) for c in lines]
    pos = [0] * nc
    fifo = [depth] * nc                 # full: prefetched during vertical blanking
    credit = 0.0
    rr = 0
    late = 0
    for _ in range(frames):
        for v in range(V_TOTAL):
            # The window in line v belongs to line v+1 (line 0's window is in line 524).
            nxt = (v + 1) % V_TOTAL
            want = [lines[c][nxt] if nxt < V_ACTIVE else 0 for c in range(nc)]
            for h in range(H_TOTAL):
                credit += rate
                while True:
                    for k in range(nc):
                        c = (rr + k) % nc
                        fw, bw = seq[c][pos[c] % len(seq[c])]
                        if fifo[c] + fw <= depth and bw <= credit:
                            fifo[c] += fw
                            credit -= bw
                            pos[c] += 1
                            rr = (c + 1) % nc
                            break
                    else:
                        credit = min(credit, float(burst))   # all full: the SDRAM idles
                        break
                if h == 0:
                    continue             # the Refresh slot
                for c in range(nc):
                    if want[c] and fifo[c]:
                        fifo[c] -= 1
                        want[c] -= 1
            late += sum(1 for c in range(nc) if want[c])
    return late


def min_depth(lines, rate, burst, fetch: bool = False) -> int:
    lo, hi = burst, 1 << 16
    if late_lines(lines, rate, burst, hi, fetch=fetch):
        return -1
    while lo < hi:
        mid = (lo + hi) // 2
        mid -= mid % burst
        mid = max(mid, lo)
        if late_lines(lines, rate, burst, mid, fetch=fetch):
            lo = mid + burst
        else:
            hi = mid
    return lo


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="teapot,cad")
    # Measured by tb/de_sdram_ctrl at 125 MHz; 95 % of 125 MHz; 78.125 MHz at 98.4 %.
    ap.add_argument("--rates", default="2.460,2.375,1.538")
    ap.add_argument("--burst", type=int, default=4)
    ap.add_argument("--fetch", action="store_true",
                    help="also the depth with the fetchers' read pattern: a table burst per "
                         "4 lines, each line's block in whole bursts, marker-only lines as pads")
    a = ap.parse_args()
    subprocess.run(["make", "-s", "-C", "sw/yproc", "build/yproc"], cwd=ROOT, check=True)
    tmp = Path(tempfile.mkdtemp(prefix="sdram_budget_"))
    print("| scene | words/line per colour mean / max | 3 colours: max line, words | "
          "rate, words/pixel clock | FIFO depth per colour, words |"
          + (" the same, fetch pattern |" if a.fetch else ""))
    print("|---|---|---|---|---|" + ("---|" if a.fetch else ""))
    for name in a.scenes.split(","):
        d = tmp / name
        d.mkdir()
        subprocess.run([str(ROOT / "sw/yproc/build/yproc"), "scan", SCENES[name], "-o", str(d)],
                       cwd=ROOT, check=True, capture_output=True)
        lines = [words_per_line(d / f"{ch}.de48") for ch in "rgb"]
        tot = [sum(c[v] for c in lines) for v in range(V_ACTIVE)]
        stats = " / ".join(f"{sum(c) / len(c):.0f}-{max(c)}" for c in lines)
        for rate in (float(r) for r in a.rates.split(",")):
            deps = [min_depth(lines, rate, a.burst, f) for f in ((False, True) if a.fetch
                                                                   else (False,))]
            print(f"| {name} | {stats} | {max(tot)} | {rate:.3f} | " + " | ".join(
                f"{d if d >= 0 else 'none (average exceeds the rate)'}" for d in deps) + " |",
                flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
