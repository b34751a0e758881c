#!/usr/bin/env python3
"""`make demo`: render a scene through the whole Difference Engine pipeline.

OBJ -> HSR -> scan conversion + shading (yproc scan) -> r/g/b.de48 command streams ->
the Verilated full-colour display_controller (3 x CHIPS chips) -> out/demo.png (16-bit)
and out/demo_8bit.png; the same streams through the golden model (must be bit-identical
to the RTL frame); the numpy reference renderer (16x16 supersampled Phong) -> PSNR
(target >= 38 dB). Prints the time of each stage and the Load Monitor summary, writes
out/demo_report.json. Exit status 0 only if the RTL frame equals the golden model, the
PSNR reaches --min-psnr and there are no more than --max-outliers outlier pixels (an
error above 0.15 of full scale where the reference is smooth: isolated wrong pixels and
streaks that an average hides; out/demo_outliers.png marks them in red).

A smaller array (--chips) only makes sense with a smaller screen: the array needs at
least ceil(width / 9) chips per colour; screens other than 640x480 run the controller's
test mode with a 640x480-length line (798 usable command slots per line).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "sw"))

from diffengine import pipeline  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--scene", default=str(REPO / "sw/scenes/teapot/teapot.scene"),
                    help="scene file (default: the Utah teapot at 640x480)")
    ap.add_argument("--out", default=str(REPO / "out"), help="output folder (default out/)")
    ap.add_argument("--chips", type=int, default=72,
                    help="chips (9 PEs each) per colour array; default 72 = 648 PEs for "
                         "640 columns. Fewer chips need a screen at most 9*CHIPS wide")
    ap.add_argument("--threads", type=int, default=1,
                    help="Verilator threads for the RTL model (separate cached build)")
    ap.add_argument("--no-rtl", action="store_true",
                    help="model only: skip the Verilated controller, demo.png from the golden model")
    ap.add_argument("--no-aa", action="store_true", help="yproc scan --no-aa (point sampling)")
    ap.add_argument("--shading", choices=["flat", "gouraud", "phong"],
                    help="yproc scan --shading (default: the scene's)")
    ap.add_argument("--num-buf", type=int, default=1,
                    help="y-processors (buffers per colour); lines are dealt round-robin")
    ap.add_argument("--min-psnr", type=float, default=pipeline.MIN_PSNR)
    ap.add_argument("--max-outliers", type=int, default=0,
                    help="fail above this many outlier pixels (error > 0.15 of full scale "
                         "where the reference is smooth; default 0)")
    a = ap.parse_args(argv)
    try:
        rep = pipeline.run(a.scene, a.out, chips=a.chips, threads=a.threads,
                           rtl=not a.no_rtl, aa=not a.no_aa, shading=a.shading,
                           num_buf=a.num_buf)
    except (pipeline.PipelineError, RuntimeError, OSError, ValueError) as e:
        print(f"demo: error: {e}", file=sys.stderr)
        return 1
    ok = True
    out = Path(a.out)
    print(f"  {'total':<28} {rep['total_seconds']:8.2f} s")
    if rep["bit_identical"] is not None:
        if rep["bit_identical"]:
            print("RTL frame == golden model frame, bit for bit")
        else:
            print(f"FAIL: RTL frame differs from the golden model: {rep['first_difference']}")
            ok = False
    good = rep["psnr_db"] >= a.min_psnr
    print(f"PSNR against the reference renderer: {rep['psnr_db']:.2f} dB "
          f"({'>=' if good else 'BELOW'} {a.min_psnr:g} dB target); |error| max "
          f"{rep['error']['max']}, mean {rep['error']['mean']} pixel units")
    ok &= good
    o = rep["outliers"]
    clean = o["count"] <= a.max_outliers
    print(f"outliers (error > {o['error_above']:g} of full scale where the reference is "
          f"smooth): {o['count']} ({'<=' if clean else 'ABOVE'} {a.max_outliers}); map: "
          f"{out / o['map']}")
    if not clean:
        print("  first: " + ", ".join(f"({p['x']},{p['y']}) {p['error']}" for p in o["first"][:8]))
    ok &= clean
    print(f"wrote {out / 'demo.png'} (16-bit), {out / 'demo_8bit.png'}, "
          f"{out / 'demo_reference.png'}, {out / 'demo_report.json'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
