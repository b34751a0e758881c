"""The `diffengine` command: one argparse subcommand tree (docs/formats.md).

    diffengine asm | disasm | model | plot | compare | capacity | encode | reference |
               frame | trace | inspect | sim | demo | anim | view | bench NAME   [-h]

The small subcommands' handlers are in cli.commands; a larger subcommand keeps its
arguments next to its code (`configure(parser)` sets `func`, the handler). User errors
(bad input files, bad options) print `file:where: message` on stderr and exit non-zero
without a traceback; a traceback means a bug in the tools.
"""
from __future__ import annotations

import argparse

from ..formats.asm import AsmError
from .commands import (EXIT_INPUT, CliError, err, cmd_asm, cmd_capacity, cmd_compare,
                       cmd_disasm, cmd_model, cmd_plot)

# Subcommands configured by their own module: (name, module, one-line help).
MODULES = [
    ("encode", "..encode.image", "image -> multiresolution spline command file"),
    ("reference", "..model.reference", "a .scene through the numpy reference renderer "
     "(16x16 supersampled Phong) -> 16-bit PNG or .npy"),
    ("frame", "..formats.frame", "display_controller raw frame (.dcf) -> 16-bit PNG"),
    ("trace", "..rtl.trace", "per-PE state per cycle from the RTL harness or the "
     "structural model, breakpoints, RTL-vs-model compare"),
    ("inspect", "..rtl.inspect_page", "one frame as a self-contained HTML page: image, "
     "scanline graph, per-pixel commands and register history"),
    ("sim", "..regress.main", "make sim: the RTL regression against the golden model "
     "(tiers, shards, merge; docs/regression.md)"),
    ("demo", "..pipeline.demo", "make demo: scene -> yproc -> Verilated display controller "
     "and golden model -> PNGs, PSNR"),
    ("anim", "..pipeline.anim", "make anim: incremental frame deltas -> PNGs and a GIF, "
     "every frame checked against its full re-render"),
    ("view", "..viewer.server", "make view: the interactive viewer on 127.0.0.1 (pick, drag, "
     "opacity, light, undo; per-frame statistics; docs/viewer.md)"),
    ("bench", "..bench.main", "benchmarks -> out/bench/NAME.json, and the "
     "docs/performance.md tables rendered from them"),
]

# ---- argument parsing --------------------------------------------------------------


def _window_arg(hi):
    def conv(s):
        try:
            v = int(s)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{s!r} is not an integer") from None
        if not 0 <= v <= hi:
            raise argparse.ArgumentTypeError(f"window {v} outside 0..{hi}")
        return v
    return conv


def _description(module) -> str:
    """The first paragraph of a module's docstring: the subcommand's --help text."""
    return (module.__doc__ or "").strip().split("\n\n")[0]


def add_module_commands(sub, table, package: str) -> None:
    """One subcommand per (name, module, help) row of table (module relative to package):
    the module's `configure(parser)` adds its options, its docstring describes it. The
    command tree (MODULES) and `diffengine bench` (bench.main.BENCHES) are both built so."""
    import importlib

    for name, module, help_ in table:
        mod = importlib.import_module(module, package)
        mod.configure(sub.add_parser(name, help=help_, description=_description(mod),
                                     formatter_class=argparse.RawDescriptionHelpFormatter))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="diffengine", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser("asm", help="command file -> .de48 instruction stream or .de32 frame store")
    s.add_argument("input")
    s.add_argument("-o", "--output", help="default: input with .de48/.de32 suffix")
    s.add_argument("-f", "--format", choices=["de48", "framestore"], default="de48")
    s.add_argument("--window", type=_window_arg(4), help="frame-store DAC window w (0..4, default 0)")
    s.add_argument("--compensate", action="store_true",
                   help="set the .de32 flag: the mapper applies carry-bug compensation")
    s.add_argument("--round", action="store_true",
                   help="round decimal operands to the frame-store precision (bit 4+w)")
    s.set_defaults(func=cmd_asm)

    s = sub.add_parser("disasm", help=".de48/.de32 (or text) -> command-file text")
    s.add_argument("input")
    s.add_argument("-o", "--output", help="default: stdout")
    s.add_argument("--dac", type=_window_arg(6), metavar="W",
                   help="print decimals in .unit dac W (default: .unit pixel)")
    s.add_argument("--slots", action="store_true", help="list instructions, not commands")
    s.add_argument("--mapped", action="store_true",
                   help=".de32: show values after the mapper's compensation")
    s.add_argument("--no-comment", action="store_true", help="no decimal value comments")
    s.set_defaults(func=cmd_disasm)

    def model_opts(s):
        s.add_argument("input", help="command file, .de48 or .de32")
        s.add_argument("-o", "--output", required=True)
        s.add_argument("--width", type=int, default=640, help="columns (PEs), default 640")
        s.add_argument("--level", choices=["functional", "structural", "fast"], default="functional",
                       help="functional (numpy, the reference; default), structural (cycle "
                            "level) or fast (the C functional model, sw/fmodel)")
        s.add_argument("--carry-bug", action="store_true", help="model the §7.7 adder fault")
        s.add_argument("--compensate", action="store_true",
                       help="apply the mapper's carry-bug compensation to intensities")
        s.add_argument("--window", type=_window_arg(6), metavar="W",
                       help="show the 6-bit DAC window, pixel bits [W+5:W] (default: all 12 bits)")

    s = sub.add_parser("model", help="render to an image (PNG/TIFF 16-bit, EXR float)")
    model_opts(s)
    s.add_argument("--raw", action="store_true",
                   help="write the pixel numbers unscaled (default: scaled to 16 bits)")
    s.add_argument("--line-height", type=int, default=1, help="rows per scanline")
    s.set_defaults(func=cmd_model)

    s = sub.add_parser("plot", help="scanline intensity graphs (the source's Scanline Display)")
    model_opts(s)
    s.add_argument("--line", type=int, help="plot only scanline N (0-based)")
    s.add_argument("--xlim", help="column range A:B (default: up to the last lit column)")
    s.add_argument("--max-lines", type=int, default=32)
    s.add_argument("--dpi", type=int, default=110)
    s.set_defaults(func=cmd_plot)

    s = sub.add_parser("compare", help="a frame against a reference: PSNR, maximum error, "
                       "outlier pixels and their map (the quality gate of make demo)")
    s.add_argument("frame", help="16-bit PNG/TIFF of 12-bit pixels (diffengine model, "
                   "make demo's demo.png) or .npy")
    s.add_argument("reference", help="a .scene file (rendered by the 16x16 reference "
                   "renderer), or a 16-bit image / .npy of the reference")
    s.add_argument("--map", help="write the outlier map here (PNG; outliers in red on the "
                   "frame's grey)")
    s.add_argument("--max-outliers", type=int, default=0,
                   help="exit 3 when there are more outlier pixels than this (default 0)")
    s.add_argument("--min-psnr", type=float, default=None,
                   help="exit 3 when the PSNR is below this (dB)")
    s.add_argument("--samples", type=int, default=16,
                   help="reference sub-samples per pixel side for a .scene (default 16)")
    s.set_defaults(func=cmd_compare)

    s = sub.add_parser("capacity", help="print the capacity model report (Table 7.3)")
    s.set_defaults(func=cmd_capacity)
    add_module_commands(sub, MODULES, __package__)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except AsmError as e:
        err(str(e))
        return EXIT_INPUT
    except CliError as e:
        err(f"diffengine {args.command}: {e}")
        return EXIT_INPUT
    except OSError as e:
        err(f"diffengine {args.command}: {e.filename or ''}: {e.strerror or e}")
        return EXIT_INPUT
    except KeyboardInterrupt:
        return 130


