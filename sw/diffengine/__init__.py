"""diffengine: golden model and tools for the Difference Engine x-processor array.

The package is split by stage; `ls` reads as the pipeline (each folder's `__init__.py`
says what belongs there):

    isa        the instruction set: identifiers, commands, serialisation (docs/isa.md)
    formats    command text (asm, disasm), binary streams (.de48/.de32), frames on disk
    model      the golden models (functional, structural), the numpy reference renderer,
               the capacity model of Tables 7.3/7.4
    encode     images -> command files (spline, raster and RLE codecs)
    host       the C host tools (sw/hsr) from Python: building yproc, reading scenes
    rtl        drivers of the Verilated RTL (array and display-controller harnesses),
               per-PE traces and the HTML frame inspector
    regress    checking the RTL against the model: random streams, coverage, `make sim`
    pipeline   `make demo` and `make anim`: scene -> yproc -> RTL and model -> images
    bench      benchmarks (JSON in out/bench/) and the docs/performance.md renderer
    cli        the `diffengine` command and its subcommand tree

The package imports nothing from cocotb, so the model can be used and tested alone.
"""
import sys
from pathlib import Path

__version__ = "0.1.0"

REPO = Path(__file__).resolve().parents[2]   # the checkout: sw/diffengine/__init__.py


def fail(prog: str, msg, status: int = 1) -> int:
    """Every command's error line, `PROG: error: MSG` on stderr; returns the exit status."""
    print(f"{prog}: error: {msg}", file=sys.stderr)
    return status
