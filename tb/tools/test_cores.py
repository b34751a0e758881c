"""The FuseSoC cores are the one file list (docs/simulation.md, "File lists"): every RTL
file belongs to a core, FuseSoC itself lists the cores, the lists the Makefiles hand to
Verilator and yosys are the cores' lists, and no tool keeps a list of its own."""
from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "scripts"))
import filelist  # noqa: E402


def _cores() -> dict[Path, dict]:
    return {p: yaml.safe_load(p.read_text()) for p in filelist.core_files()}


def test_every_rtl_file_belongs_to_a_core_and_every_core_file_exists():
    named = set()
    for path, core in _cores().items():
        assert path.read_text().startswith("CAPI=2:"), path
        for fs_name, fs in core.get("filesets", {}).items():
            for f in fs.get("files", []):
                f = f if isinstance(f, str) else next(iter(f))
                full = (path.parent / f).resolve()
                assert full.exists(), f"{path.relative_to(REPO)}: {fs_name}: {f} is missing"
                named.add(full)
    stray = [p.relative_to(REPO) for p in sorted((REPO / "rtl").rglob("*.sv"))
             if p.resolve() not in named]
    assert not stray, f"RTL files in no core (add each to its block's .core): {stray}"


@pytest.mark.skipif(shutil.which("fusesoc") is None, reason="fusesoc not on PATH (.venv)")
def test_fusesoc_lists_the_cores():
    out = subprocess.run(["fusesoc", "--cores-root", str(REPO), "core", "list"],
                         capture_output=True, text=True, check=True).stdout
    for core in _cores().values():
        assert core["name"] in out, f"fusesoc core list does not show {core['name']}"


def _make_var(directory: str, var: str, *args: str, makefile: str | None = None) -> list[str]:
    cmd = ["make", "-s", "--no-print-directory", "-C", str(REPO / directory)]
    if makefile:
        cmd += ["-f", makefile]
    cmd += ["--eval", f"print-var: ; @echo $({var})", "print-var", *args]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return out.split()


def _abs(core: str, target: str = "default") -> list[str]:
    return [str(p) for p in filelist.files(core, target)]


@pytest.mark.parametrize("directory,var,args,makefile,expect", [
    ("sim", "RTL", ["FLAT=1"], None, lambda: _abs("array", "sim")),
    ("sim", "RTL", ["TRACE=1"], None, lambda: _abs("array", "sim")),
    ("sim", "RTL", [], None, lambda: _abs("fast", "shell")),
    ("sim/dc", "RTL", ["FLAT=1"], None, lambda: _abs("display_controller", "sim")),
    ("sim/dc", "RTL", [], None, lambda: [str(REPO / "sim/fast/de_array.sv")] + [
        f for f in _abs("display_controller", "sim") if not f.endswith("rtl/array/de_array.sv")]),
    ("sim/fast", "CORE_fast.unit", [], "pieces.mk", lambda: _abs("fast", "unit")),
    ("fpga/ulx3s", "SRCS", [], None, lambda: _abs("board")),
    ("fpga/ulx3s", "SHELL_SV", [], None, lambda: _abs("sdram_ctrl", "pkg") + [
        f for f in _abs("fpga", "ulx3s") if f not in _abs("board")]),
], ids=["harness-flat", "harness-trace", "harness-fast", "dc-flat", "dc-fast", "fast-unit",
        "ulx3s", "ulx3s-shell"])
def test_make_lists_are_the_cores(directory, var, args, makefile, expect):
    assert _make_var(directory, var, *args, makefile=makefile) == expect()


# Single RTL files a tool may still name (a one-module unit test, a substitution); a file
# that names two or more RTL sources outside comments and docstrings keeps a list by hand.
# A shell `case` pattern (`*/de_uart_pkg.sv) ;;`, scripts/lint.sh's loop over
# rtl/board/*.sv) selects a file, it lists none; a brace expansion
# (`de_uart_{rx,tx}.sv`) names every file it expands to.
ALLOWED: dict[str, str] = {}
TOOL_GLOBS = ["Makefile", "sim/**/Makefile", "sim/**/*.mk", "fpga/**/Makefile",
              "fpga/**/*.sh", "fpga/**/*.ys", "fpga/**/*.py", "scripts/*.sh", "scripts/*.py",
              "tb/**/*.py", "tb/**/*.sby"]
CASE_PATTERN = re.compile(r"^\s*[\w.*/|]+\)")
BRACES = re.compile(r"(\w*)\{([\w,]+)\}(\w*)\.sv\b")


def _rtl_names_in(path: Path, rtl: set[str]) -> set[str]:
    text = path.read_text()
    if path.suffix == ".py":
        tree = ast.parse(text)
        docs = {id(n.body[0].value) for n in ast.walk(tree)
                if isinstance(n, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef,
                                  ast.ClassDef))
                and n.body and isinstance(n.body[0], ast.Expr)
                and isinstance(n.body[0].value, ast.Constant)}
        strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
                   and isinstance(n.value, str) and id(n) not in docs]
    else:
        strings = [line.split("#", 1)[0] for line in text.splitlines()]
        if path.suffix == ".sh":
            strings = [CASE_PATTERN.sub("", s) for s in strings]
        strings = [BRACES.sub(lambda m: " ".join(f"{m[1]}{x}{m[3]}.sv" for x in m[2].split(",")), s)
                   for s in strings]
    return {m for s in strings for m in re.findall(r"(\w+\.sv)\b", s) if m in rtl}


def _source_files() -> set[str] | None:
    """The files git knows as sources here: tracked, or new and not ignored. Ignored
    leftovers (an old SymbiYosys work folder's config.sby, a build product) are not tools.
    None outside a git checkout (then only the build-folder filter below applies)."""
    r = subprocess.run(["git", "-C", str(REPO), "ls-files", "--cached", "--others",
                        "--exclude-standard"], capture_output=True, text=True)
    return set(r.stdout.splitlines()) if r.returncode == 0 else None


def test_no_tool_keeps_its_own_list():
    sources = _source_files()
    rtl = {p.name for p in (REPO / "rtl").rglob("*.sv")}
    # The fpga tops count too in Makefiles and scripts (Python names them in its report
    # texts, which are not lists).
    tops = {p.name for p in (REPO / "fpga").rglob("*.sv") if "build" not in p.parts}
    bad = {}
    for pattern in TOOL_GLOBS:
        for path in sorted(REPO.glob(pattern)):
            rel = str(path.relative_to(REPO))
            parts = path.relative_to(REPO).parts   # build products are not tools
            if (rel in ALLOWED or not path.is_file()
                    or (sources is not None and rel not in sources)
                    or any(q in ("build", "out") or q.startswith("sim_build") for q in parts)):
                continue
            names = _rtl_names_in(path, rtl if path.suffix == ".py" else rtl | tops)
            if len(names) > 1:
                bad[rel] = sorted(names)
    assert not bad, f"hand-kept RTL lists (read them from the cores instead): {bad}"
