#!/usr/bin/env python3
"""The RTL file lists of every tool, from the FuseSoC cores (docs/simulation.md, "File lists").

Each block's `.core` file (CAPI2: rtl/*/*.core, sim/*/*.core (sim/fast, sim/models), fpga/de_fpga.core,
tb/*/*.core) names its files and the cores it depends on; FuseSoC resolves a core and a
target into one ordered list, dependencies first. This module asks FuseSoC's API for that
list (the EDAM file's `files`, as `fusesoc run --setup` would write it) and caches it under
build/cores/, so a tool that runs often does not start FuseSoC: the cache is reused while
it is newer than every .core file.

    filelist.py CORE [TARGET]            the files, one a line (absolute paths)
    filelist.py CORE [TARGET] --make VAR -o F   a make fragment `VAR := files` (cores.mk)
    filelist.py --cores                  every core file found (for make dependencies)

CORE is a VLNV (diffengine:de:array) or its last part (array); TARGET defaults to
`default`. From Python: `files("array", "sim")` -> [Path, ...].
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "build" / "cores"
# Where the project's cores live (`fusesoc --cores-root .` finds the same ones; these
# folders only keep the scan away from .venv and the build trees).
CORE_DIRS = ("rtl", "sim/fast", "sim/models", "fpga", "tb")
HDL_TYPES = ("systemVerilogSource", "verilogSource")


# The same patterns as scripts/cores.mk's CORE_DEFS (make's dependencies).
CORE_GLOBS = ("rtl/*/*.core", "sim/*/*.core", "fpga/*.core", "tb/*/*.core")


def core_files() -> list[Path]:
    """Every .core file of the project, sorted."""
    return sorted(p for g in CORE_GLOBS for p in ROOT.glob(g))


def vlnv(core: str) -> str:
    """diffengine:de:<core> for a short name; a full VLNV unchanged."""
    return core if ":" in core else f"diffengine:de:{core}"


def _resolve(core: str, target: str) -> dict:
    """Ask FuseSoC: the EDAM description (files, toplevel, parameters) of core/target."""
    import logging
    from fusesoc.config import Config
    from fusesoc.coremanager import CoreManager
    from fusesoc.edalizer import Edalizer
    from fusesoc.librarymanager import Library
    from fusesoc.vlnv import Vlnv

    logging.getLogger("fusesoc").setLevel(logging.ERROR)
    CACHE.mkdir(parents=True, exist_ok=True)
    # An empty configuration of our own: no user or system libraries leak in.
    config = Config(path=str(CACHE / "fusesoc.conf"))
    cm = CoreManager(config)
    for d in CORE_DIRS:
        cm.add_library(Library(f"diffengine-{d}", str(ROOT / d)), [])
    flags = {"target": target, "is_toplevel": True}
    try:
        top = cm.get_core(Vlnv(vlnv(core))).name   # with its version: the toplevel test
        edam = Edalizer(toplevel=top, flags=flags, work_root=str(ROOT),   # compares names
                        core_manager=cm).run()                            # whole
    except Exception as e:  # noqa: BLE001  DependencyError, SyntaxError: a message will do
        raise SystemExit(f"filelist: {vlnv(core)} target {target}: {e}") from None
    if not any(f.get("file_type") in HDL_TYPES for f in edam["files"]):
        raise SystemExit(f"filelist: {vlnv(core)} target {target!r} has no HDL files "
                         "(no such target?)")
    return edam


def _cache_path(core: str, target: str) -> Path:
    return CACHE / f"{vlnv(core).replace(':', '_')}-{target}.json"


def describe(core: str, target: str = "default") -> dict:
    """{'files': [repo-relative paths], 'toplevel': ..., 'parameters': {...}}, cached."""
    cache = _cache_path(core, target)
    newest = max(p.stat().st_mtime for p in core_files() + [Path(__file__)])
    if cache.exists() and cache.stat().st_mtime > newest:
        return json.loads(cache.read_text())
    edam = _resolve(core, target)
    desc = {"core": vlnv(core), "target": target,
            "files": [os.path.normpath(f["name"]) for f in edam["files"]
                      if f.get("file_type") in HDL_TYPES],
            "toplevel": edam.get("toplevel"),
            "parameters": {k: v.get("default") for k, v in edam.get("parameters", {}).items()}}
    # Written whole and renamed: parallel builds may ask for the same list at once.
    CACHE.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=CACHE, delete=False, suffix=".tmp") as f:
        json.dump(desc, f, indent=1)
    os.replace(f.name, cache)
    return desc


def files(core: str, target: str = "default") -> list[Path]:
    """The ordered HDL files of core/target, absolute."""
    return [ROOT / f for f in describe(core, target)["files"]]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("core", nargs="?", help="VLNV or short name (array, pe, ...)")
    ap.add_argument("target", nargs="?", default="default")
    ap.add_argument("--make", metavar="VAR", help="write `VAR := files` (a make fragment)")
    ap.add_argument("-o", "--out", type=Path, help="output file (default: stdout)")
    ap.add_argument("--cores", action="store_true", help="list the .core files")
    ap.add_argument("--relative", action="store_true", help="paths relative to the checkout")
    args = ap.parse_args()
    if args.cores:
        text = "".join(f"{p}\n" for p in core_files())
    elif not args.core:
        ap.error("a CORE (or --cores) is needed")
    else:
        rel = describe(args.core, args.target)["files"]
        names = rel if args.relative else [str(ROOT / f) for f in rel]
        text = (f"# {vlnv(args.core)} target {args.target} (scripts/filelist.py)\n"
                f"{args.make} := {' '.join(names)}\n" if args.make
                else "".join(f"{n}\n" for n in names))
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        tmp = args.out.with_name(args.out.name + f".{os.getpid()}.tmp")
        tmp.write_text(text)
        os.replace(tmp, args.out)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
