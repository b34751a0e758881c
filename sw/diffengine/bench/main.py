"""`diffengine bench NAME`: run one benchmark (out/bench/NAME.json; `--write` also keeps it
in docs/bench/ and renders its docs/performance.md section), or `render` the sections
from the kept records.
"""
from __future__ import annotations

import argparse
import importlib

BENCHES = [
    ("model", ".model", "golden model speed (functional and structural)"),
    ("yproc", ".yproc", "y-processor: commands per line, host time; --scaling: time "
     "against triangle count"),
    ("hsr", ".hsr", "hidden-surface removal: Table 5.2, Fig. 5.30, incremental move"),
    ("array", ".array", "Verilated array speed (1/8/72 chips) against the baseline revision"),
    ("span", ".span", "span-serial array: clocks per line on the teapot and CAD frames, "
     "and the levers against the line budget"),
    ("recon", ".recon", "image reconstruction report -> docs/reconstruction.md"),
    ("recon-images", ".recon_images", "the reconstruction test images -> sw/images"),
    ("render", ".render", "docs/performance.md sections from docs/bench/*.json"),
]


def configure(ap) -> None:
    """The benchmarks, one subcommand each."""
    sub = ap.add_subparsers(dest="bench", required=True, metavar="NAME")
    for name, module, help_ in BENCHES:
        mod = importlib.import_module(module, __package__)
        mod.configure(sub.add_parser(name, help=help_,
                                     description=(mod.__doc__ or "").strip().split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter))
