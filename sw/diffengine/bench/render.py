"""`diffengine bench render`: the one renderer of docs/performance.md's benchmark sections.

Each section sits between `<!-- bench:NAME:begin -->` and `<!-- bench:NAME:end -->` and
is the benchmark's `render(record)` of docs/bench/NAME.json (bench.record). A section
whose JSON does not exist (measured before the benchmarks kept their figures) is left
exactly as it is, and the renderer says so. `--check` changes nothing and fails if a
section differs from its rendering.
"""
from __future__ import annotations

import importlib
from pathlib import Path

from .. import REPO
from . import record

DOC = REPO / "docs" / "performance.md"

# section -> (module, function) whose function(record) -> the section's markdown: the
# benchmark's module and its `render`, but for the second sections of three modules.
SECTIONS = {name: ("." + name.replace("-", "_"), "render") for name in
            ("model", "hsr", "hsr-incr", "table52", "array", "yproc", "span", "viewer", "link")}
SECTIONS.update({"model-fast": (".model", "render_fast"),
                 "yproc-scaling": (".yproc", "render_scaling"),
                 "viewer-lat": (".viewer", "render_lat")})


def markers(name: str) -> tuple[str, str]:
    return f"<!-- bench:{name}:begin -->", f"<!-- bench:{name}:end -->"


def splice(doc: str, name: str, text: str) -> str:
    """doc with the text between NAME's markers replaced by `text`."""
    begin, end = markers(name)
    if begin not in doc or end not in doc:
        raise ValueError(f"{DOC.name}: no {begin} ... {end} markers")
    i, j = doc.index(begin) + len(begin), doc.index(end)
    return doc[:i] + "\n" + text.strip("\n") + "\n" + doc[j:]


def section(name: str, rec: dict) -> str:
    module, fn = SECTIONS[name]
    return getattr(importlib.import_module(module, __package__), fn)(rec)


def write(names=None, folder: Path = record.KEPT, doc: Path = DOC, check: bool = False) -> int:
    """Render the named sections (default: all) into doc; the number that differ(ed)."""
    text = Path(doc).read_text()
    new = text
    for name in names or SECTIONS:
        rec = record.load(name, folder)
        if rec is None:
            record.log(name, f"no {Path(folder, name + '.json')}: section kept as it is")
            continue
        new = splice(new, name, section(name, rec))
    changed = int(new != text)
    if check:
        if changed:
            record.log("render", f"{doc} differs from its rendering")
        return changed
    if changed:
        Path(doc).write_text(new)
        record.log("render", f"updated {doc}")
    return 0


def configure(ap) -> None:
    """The arguments of `diffengine bench render`."""
    ap.add_argument("names", nargs="*", metavar="NAME",
                    help=f"sections to render (default: all of {', '.join(SECTIONS)})")
    ap.add_argument("--from", dest="folder", type=Path, default=record.KEPT,
                    help="folder of the NAME.json records (default docs/bench; out/bench "
                    "holds every run)")
    ap.add_argument("--check", action="store_true",
                    help="change nothing; exit 1 if a section differs from its rendering")
    ap.set_defaults(func=command)


def command(a) -> int:
    unknown = [n for n in a.names if n not in SECTIONS]
    if unknown:
        record.log("render", f"no section {', '.join(unknown)} (sections: {', '.join(SECTIONS)})")
        return 2
    return 1 if write(a.names, a.folder, check=a.check) and a.check else 0
