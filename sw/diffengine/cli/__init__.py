"""The `diffengine` command: one argparse subcommand tree (`tree`), and the handlers of the
small subcommands (`commands`: asm, disasm, model, plot, capacity, compare). Larger
subcommands keep their arguments next to their code (`configure(parser)` in
diffengine.encode.image, rtl.trace, rtl.inspect_page, regress.main, pipeline.demo,
pipeline.anim and the bench modules); `tree` only lists them. docs/formats.md.
"""
from .tree import main

__all__ = ["main"]
