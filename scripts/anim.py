#!/usr/bin/env python3
"""`make anim`: play a shipped animation through incremental frame updates.

yproc anim (HSR move / opacity / light changes, then re-scan of the damaged lines only)
writes frame 0's r/g/b.de48 streams and one frame delta per later frame (docs/yproc.md
section 6). This script applies the deltas in order, re-renders only the changed lines
with the golden model, and writes every frame as an 8-bit PNG and the sequence as an
animated GIF. yproc itself re-renders every frame in full and compares the streams
(its `frames_differing_from_full` must be 0, checked here); this script also checks that
the image updated line by line equals a from-scratch golden render of the last frame.

    python3 scripts/anim.py [--anim sw/scenes/anim/cad_drag.anim] [--out out/anim]

Exit status 0 only if no frame differs from its full re-render.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "sw"))

from diffengine import anim, binfmt, frame, functional, pipeline  # noqa: E402


def render_lines(lines: list[bytes], width: int) -> np.ndarray:
    """Golden-model rows of the given lines (each a line's .de48 words, Refresh last)."""
    cmds, _ = binfmt.load_commands(anim.to_de48(lines), "<delta>")
    return functional.render(cmds, width)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--anim", default=str(REPO / "sw/scenes/anim/cad_drag.anim"))
    ap.add_argument("--out", default=str(REPO / "out" / "anim"))
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    yproc = pipeline.build_yproc()
    t0 = time.time()
    print(f"anim: yproc anim {a.anim} (each frame also re-rendered in full for the check)", flush=True)
    res = subprocess.run([str(yproc), "anim", a.anim, "-o", str(out / "streams")],
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
    seq = anim.frames(out / "streams")
    img = np.zeros((H, W, 3), dtype=np.uint16)
    pics = []
    t1 = time.time()
    for f, chans in enumerate(seq):
        for c in range(3):
            if f == 0:
                changed = list(range(len(chans[c])))
            else:
                changed = [y for y in range(len(chans[c])) if chans[c][y] != seq[f - 1][c][y]]
            if changed:
                img[changed, :, c] = render_lines([chans[c][y] for y in changed], W)
        frame.write_png8(out / f"frame{f:03d}.png", img)
        pics.append(frame.view8(img).copy())
        done = f + 1
        bar = "#" * (30 * done // len(seq))
        if sys.stdout.isatty():
            print(f"\r  golden model, changed lines only [{bar:<30}] {done}/{len(seq)}", end="", flush=True)
        elif done % 6 == 0 or done == len(seq):
            print(f"  golden model, changed lines only: {done}/{len(seq)} frames", flush=True)
    print(f"{'' if not sys.stdout.isatty() else chr(10)}  golden model: {time.time() - t1:.1f} s")
    # the image updated line by line == the last frame's streams rendered from scratch
    full = np.stack([render_lines(seq[-1][c], W) for c in range(3)], axis=-1)
    pixel_ok = bool((full == img).all())
    try:
        from PIL import Image
        ims = [Image.fromarray(p) for p in pics]
        ims[0].save(out / "anim.gif", save_all=True, append_images=ims[1:], duration=80, loop=0)
        gif = f", {out / 'anim.gif'}"
    except ImportError:
        gif = ""
    bad = st["frames_differing_from_full"]
    print(f"frames whose streams differ from yproc's full re-render: {bad}; last frame, "
          f"line-by-line update vs from-scratch render: {'identical' if pixel_ok else 'DIFFERENT'}")
    print(f"wrote {out}/frame000.png .. frame{len(seq) - 1:03d}.png{gif}")
    return 0 if bad == 0 and pixel_ok else 1


if __name__ == "__main__":
    sys.exit(main())
