"""The FPGA flow synthesises the RTL as it is written (issue 17, item 4: no source is
rewritten by a script). A what-if design is a parameter of the RTL (de_chip TieBypass
for the chip whose bypass is tied off), never a copy of an .sv file edited by
str.replace or re.sub and written out. This test reads the flow's Python (fpga/**/*.py)
with `ast` and fails on a script that reads an HDL file's text and substitutes in it,
or that writes an HDL file; it is shown to catch the old flow.py's nobypass_chip.
No synthesis runs; verilator --lint-only checks TieBypass's elaboration check."""
from __future__ import annotations

import ast
import importlib.util
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HDL = re.compile(r"(\.(sv|svh|v|vh)$)|(^rtl/)")
SUBST = {"replace", "sub", "subn"}


def _mentions_hdl(node: ast.AST) -> bool:
    """The expression names an HDL file: a string constant that ends in .sv/.v or
    starts with rtl/ (a path built with / or f-strings included)."""
    return any(isinstance(n, ast.Constant) and isinstance(n.value, str)
               and HDL.search(n.value) for n in ast.walk(node))


def _names(node: ast.AST) -> set[str]:
    return {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}


FUNCS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)


def _scope_nodes(scope: ast.AST) -> list[ast.AST]:
    """The nodes of one function (or the module's top level), not of functions in it."""
    out, todo = [], list(ast.iter_child_nodes(scope))
    while todo:
        n = todo.pop()
        out.append(n)
        if not isinstance(n, FUNCS):
            todo.extend(ast.iter_child_nodes(n))
    return sorted(out, key=lambda n: (getattr(n, "lineno", 0), getattr(n, "col_offset", 0)))


def _is_write_open(call: ast.Call) -> bool:
    mode = call.args[1] if len(call.args) > 1 else next(
        (k.value for k in call.keywords if k.arg == "mode"), None)
    return (isinstance(mode, ast.Constant) and isinstance(mode.value, str)
            and any(c in mode.value for c in "wax+"))


def rewrites(source: str, filename: str = "<flow>") -> list[str]:
    """Lines of `source` that read an HDL file's text and substitute in it, or write an
    HDL file. Within a function (or the module body): a name assigned from an HDL read
    is tainted, and so is a name assigned from an expression with a tainted name."""
    tree = ast.parse(source, filename)
    found = []
    scopes = [tree] + [n for n in ast.walk(tree) if isinstance(n, FUNCS)]
    for scope in scopes:
        tainted: set[str] = set()
        body = _scope_nodes(scope)
        # A path bound to an HDL name: `p = out / "x.sv"; p.write_text(..)` writes one.
        hdl_paths = {t.id for n in body if isinstance(n, ast.Assign)
                     and _mentions_hdl(n.value) for t in n.targets if isinstance(t, ast.Name)}
        for _ in range(3):   # assignments in any order: propagate to a fixed point
            for n in body:
                if isinstance(n, (ast.Assign, ast.AnnAssign, ast.AugAssign)) and n.value:
                    reads_hdl = any(
                        isinstance(c, ast.Call) and (
                            (isinstance(c.func, ast.Attribute)
                             and c.func.attr in ("read_text", "read_bytes")
                             and _mentions_hdl(c.func.value))
                            or (isinstance(c.func, ast.Name) and c.func.id == "open"
                                and c.args and _mentions_hdl(c.args[0])
                                and not _is_write_open(c)))
                        for c in ast.walk(n.value))
                    if reads_hdl or _names(n.value) & tainted:
                        targets = n.targets if isinstance(n, ast.Assign) else [n.target]
                        for t in targets:
                            tainted |= _names(t)
        for n in body:
            if not isinstance(n, ast.Call):
                continue
            f = n.func
            where = f"{filename}:{n.lineno}"
            if isinstance(f, ast.Attribute) and f.attr in SUBST:
                operands = [f.value, *n.args]
                if any(_names(o) & tainted for o in operands):
                    found.append(f"{where}: {f.attr}() on an HDL file's text")
            if isinstance(f, ast.Attribute) and f.attr in ("write_text", "write_bytes"):
                if _mentions_hdl(f.value) or _names(f.value) & (tainted | hdl_paths):
                    found.append(f"{where}: writes an HDL file")
                elif any(_names(a) & tainted for a in n.args):
                    found.append(f"{where}: writes an HDL file's rewritten text")
            if isinstance(f, ast.Name) and f.id == "open" and n.args \
                    and _is_write_open(n) and _mentions_hdl(n.args[0]):
                found.append(f"{where}: opens an HDL file for writing")
    return found


# main's flow.py before issue 17 item 4 (commit 537fcd8), verbatim: the what-if chip was
# made by editing de_chip.sv's text.
OLD_NOBYPASS = '''
def nobypass_chip(out: Path) -> Path:
    """What-if copy of de_chip.sv with the bypass tied off (every PE always used)."""
    src = (ROOT / "rtl/array/de_chip.sv").read_text()
    new = src.replace(".bypass_i   (pe_byp[i]),", ".bypass_i   (1'b0),")
    new2 = new.replace(".live_i     (pe_live[i]),", ".live_i     (1'b1),")
    if new == src or new2 == new:
        sys.exit("nobypass what-if: de_chip.sv bypass lines changed; update flow.py")
    out.mkdir(parents=True, exist_ok=True)
    path = out / "de_chip_nobypass.sv"
    path.write_text(new2)
    return path
'''


def test_the_check_catches_the_old_what_if_chip():
    found = rewrites(OLD_NOBYPASS, "old flow.py")
    assert any("replace() on an HDL file's text" in f for f in found), found
    assert any("writes an HDL file" in f for f in found), found


@pytest.mark.parametrize("snippet", [
    'import re\ntext = open("rtl/xproc/de_pe.sv").read()\nx = re.sub("a", "b", text)\n',
    'from pathlib import Path\nPath("gen/de_vpe.sv").write_text("module m; endmodule")\n',
    'with open(out + "/top.v", "w") as f:\n    f.write("")\n',
])
def test_the_check_catches_other_rewrites(snippet):
    assert rewrites(snippet), snippet


def test_the_check_passes_a_template_fill():
    # flow.py's yosys(): a .ys template filled with str.replace is not an HDL source.
    ok = ('text = (FPGA / "synth" / template).read_text()\n'
          'text = text.replace("{top}", top)\n(out / template).write_text(text)\n')
    assert rewrites(ok) == []


@pytest.mark.parametrize("script", sorted(
    p.relative_to(ROOT).as_posix() for p in (ROOT / "fpga").rglob("*.py")
    if "build" not in p.parts))
def test_no_fpga_script_rewrites_a_source(script):
    found = rewrites((ROOT / script).read_text(), script)
    assert not found, "a script rewrites RTL source text:\n" + "\n".join(found)


def test_the_what_if_chip_is_a_de_chip_parameter():
    """flow.py's what-if chip sets de_chip's TieBypass (through chip_top's), and both
    tops declare it with the default 0 (the product chip)."""
    flow = (ROOT / "fpga/scripts/flow.py").read_text()
    assert re.search(r'params\["TieBypass"\]\s*=\s*1', flow)
    for top in ("rtl/array/de_chip.sv", "fpga/chip_top.sv"):
        assert re.search(r"parameter int unsigned TieBypass\s*=\s*0\b",
                         (ROOT / top).read_text()), top


@pytest.mark.parametrize("value,ok", [(0, True), (1, True), (2, False)])
def test_tie_bypass_is_checked_at_elaboration(value, ok, tmp_path):
    """de_chip lints clean (-Wall) with TieBypass 0 and 1 and refuses any other value
    (docs/style.md's g_bad_ idiom), on the files flow.py synthesises."""
    vl = shutil.which("verilator")
    assert vl, "verilator not on PATH"
    spec = importlib.util.spec_from_file_location("de_fpga_flow_src", ROOT / "fpga/scripts/flow.py")
    flow = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(flow)
    r = subprocess.run([vl, "--lint-only", "-Wall", f"-GTieBypass={value}", "--top-module",
                        "de_chip", *flow.core_srcs("chip"), "--Mdir", str(tmp_path)],
                       capture_output=True, text=True, cwd=ROOT)
    if ok:
        assert r.returncode == 0, r.stderr
    else:
        assert r.returncode != 0, f"TieBypass={value} elaborated"
        assert "TieBypass must be 0 or 1, got 2" in r.stderr, r.stderr
