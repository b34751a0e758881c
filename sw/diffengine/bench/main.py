"""`diffengine bench NAME`: run one benchmark (out/bench/NAME.json; `--write` also keeps it
in docs/bench/ and renders its docs/performance.md section), or `render` the sections
from the kept records.
"""
from __future__ import annotations

from ..cli.tree import add_module_commands

BENCHES = [
    ("model", ".model", "golden model speed (functional and structural)"),
    ("yproc", ".yproc", "y-processor: commands per line, host time; --scaling: time "
     "against triangle count"),
    ("hsr", ".hsr", "hidden-surface removal: Fig. 5.30, incremental move"),
    ("table52", ".table52", "Grid-List efficiency (Table 5.2) and Figs. 5.13-5.18 on the six scenes"),
    ("hsr-incr", ".hsr_incr", "incremental HSR against a full build: teapot + box, 10-10,000 parts, "
     "the CAD drag, against --baseline-rev"),
    ("array", ".array", "Verilated array speed (1/8/72 chips) against the baseline revision"),
    ("span", ".span", "span-serial array: clocks per line on the teapot and CAD frames, "
     "unpaced and paced at the board's clock ratio (25/8); exit 1 unless the worst line is "
     "at most 90 per cent of the line and no paced line is later than SpanLatency"),
    ("recon", ".recon", "image reconstruction report -> docs/reconstruction.md"),
    ("recon-images", ".recon_images", "the reconstruction test images -> sw/images"),
    ("viewer", ".viewer", "viewer: pointer-to-frame latency of a scripted drag (teapot, CAD)"),
    ("link", ".link", "UART link: host tool + loader model through a pty, teapot budget"),
    ("render", ".render", "docs/performance.md sections from docs/bench/*.json"),
]


def configure(ap) -> None:
    """The benchmarks, one subcommand each."""
    add_module_commands(ap.add_subparsers(dest="bench", required=True, metavar="NAME"),
                        BENCHES, __package__)
