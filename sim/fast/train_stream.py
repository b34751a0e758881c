#!/usr/bin/env python3
"""The training stream for the fast array's profile-guided build (sim/fast/pieces.mk,
docs/simulation.md 7.3): constrained-random lines (diffengine.regress.randgen) at 641 columns
written as a .de48 instruction stream.

Its seed differs from the one `make bench-array` measures with, so the benchmark does not
run the very stream the compiler was trained on."""
import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sw"))
from diffengine.formats import binfmt  # noqa: E402
from diffengine import isa  # noqa: E402
from diffengine.regress import randgen  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", type=Path, help="the .de48 file to write")
    ap.add_argument("--seed", type=int, default=7, help="randgen seed (default 7)")
    ap.add_argument("--commands", type=int, default=7000,
                    help="commands, Refreshes included (default 7000: about 37K cycles)")
    ap.add_argument("--width", type=int, default=641, help="columns addressed (default 641)")
    a = ap.parse_args(argv)
    slots = isa.serialise(randgen.stream(a.seed, a.commands, a.width, (60, 200)))
    a.out.write_bytes(binfmt.encode_de48(slots))
    print(f"train_stream: {len(slots)} instructions (seed {a.seed}) -> {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
