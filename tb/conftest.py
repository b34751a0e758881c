"""Settings shared by every RTL test process (pytest and its xdist workers load this
before any test module).

ccache, when installed, compiles the Verilated C++ of every cocotb bench, as sim/Makefile
does for the harnesses: cocotb's runner calls `make -f Vtop.mk` itself, and Verilator's
verilated.mk takes OBJCACHE from the environment (the runner copies os.environ when it is
created, so this must come first). CCACHE_BASEDIR makes ccache's hashes independent of
where the checkout is, so a second clone on the same machine recompiles nothing.
"""
import os
import shutil
from pathlib import Path

_CCACHE = shutil.which("ccache")
if _CCACHE:
    os.environ.setdefault("OBJCACHE", _CCACHE)
    os.environ.setdefault("CCACHE_BASEDIR", str(Path(__file__).resolve().parents[1]))
