"""README.md's layout table is the tree (issue 17: "a package a newcomer can read from ls").

Every folder git tracks at the top level and one level below sw/, rtl/, sim/, tb/, fpga/,
docs/ and scripts/, and every subpackage of sw/diffengine, is named in the layout table
(the first table of README.md); every folder the table names exists; and the `make clean`
row names every path the Makefile's clean recipe removes.
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEPTH2 = ("sw", "rtl", "sim", "tb", "fpga", "docs", "scripts")


def _table() -> str:
    """The layout table: the rows from the first `| folder |` header to the first blank."""
    text = (ROOT / "README.md").read_text()
    start = text.index("| folder | what |")
    return text[start:text.index("\n\n", start)]


def _tracked_dirs() -> set[str]:
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                           check=True).stdout.split()
    dirs = set()
    for f in files:
        parts = Path(f).parts[:-1]
        for k in range(1, len(parts) + 1):
            dirs.add("/".join(parts[:k]))
    return {d for d in dirs if not d.startswith(".")}


def _named(table: str, folder: str) -> bool:
    """`folder` written out (`sw/tests/`, `tb/formal`); a testbench folder named after its
    RTL module by the tb row's "one folder per module"; a subpackage of sw/diffengine by
    its name in that row (`isa`, `formats/`)."""
    if re.search(rf"`{re.escape(folder)}/?[`/]|`{re.escape(folder)}/?\*", table) or \
            re.search(rf"(?<![\w/]){re.escape(folder)}/?(?=[\s,;:)`])", table):
        return True
    parent, _, name = folder.rpartition("/")
    if parent == "tb" and list(ROOT.glob(f"rtl/*/{name}.sv")):   # "one folder per module"
        return "one folder per module" in table
    if parent == "sw/diffengine":
        row = next(r for r in table.splitlines() if r.startswith("| `sw/diffengine/`"))
        return re.search(rf"`{re.escape(name)}/?`", row) is not None
    return False


def test_every_folder_is_in_the_layout_table():
    table = _table()
    dirs = _tracked_dirs()
    want = sorted(d for d in dirs if d.count("/") == 0
                  or (d.count("/") == 1 and d.split("/")[0] in DEPTH2)
                  or (d.count("/") == 2 and d.startswith("sw/diffengine/")))
    missing = [d for d in want if not _named(table, d)]
    assert not missing, f"folders the README's layout table does not describe: {missing}"


def test_every_folder_the_table_names_exists():
    table = _table()
    named = set()
    for cell in re.findall(r"`([^`]+)`", table):
        for m in re.finditer(r"(?<![\w.])((?:sw|rtl|sim|tb|fpga|docs|scripts|spec)(?:/[\w.*-]+)*)/?",
                             cell):
            named.add(m.group(1))
    gone = sorted(n for n in named if not list(ROOT.glob(n)))
    assert not gone, f"the layout table names paths that do not exist: {gone}"


def test_make_clean_row_names_what_clean_removes():
    mk = (ROOT / "Makefile").read_text()
    recipe = mk[mk.index("\nclean:"):].split("\n\n", 1)[0]
    recipe = recipe.replace("$(OUT)", "out/")
    removed = set()
    for line in recipe.splitlines()[1:]:
        words = line.split()
        if words[:2] == ["rm", "-rf"] or words[:2] == ["rm", "-f"]:
            removed |= {w.rstrip("/") for w in words[2:]}
        elif words[:1] == ["find"]:
            removed |= ({"tb/*/sim_build*"} if "sim_build" in line
                        else {"tb/*/*.result.xml"} if "result.xml" in line else {line})
    row = next(r for r in (ROOT / "README.md").read_text().splitlines()
               if r.startswith("| `make clean` |"))
    said = {re.sub(r"/$", "", w) for w in re.findall(r"[\w.*/_-]+", row)}
    # tb/de_array/coverage_*.txt and seed_*.txt are said as "tb/de_array's coverage_*/seed_*"
    unsaid = sorted(p for p in removed
                    if p not in said and not (p.startswith("tb/de_array/")
                                              and "tb/de_array" in row
                                              and p.split("/")[-1].split("_")[0] in row))
    assert not unsaid, f"make clean removes what README's row does not say: {unsaid}"
    assert ("worktree" in recipe) == ("worktree" in row)
