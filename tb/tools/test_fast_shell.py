"""The fast array's shell sim/fast/de_array.sv stands in for rtl/array/de_array.sv in the
fast harness builds (docs/simulation.md 7.3), so its header is a copy of de_array's: the
same parameters, types and defaults, the same ports in the same order. sim/fast/equiv.cpp
checks the behaviour (it drives the flat de_array and the C++ composition, not the shell);
this test checks the copy, so that a port or parameter added to de_array cannot be
forgotten in the shell.

One difference is the shell's by design: TimingCopies defaults to 0 there, because the
pieces are built without the timing-only copies (de_chip TimingCopies = 0)."""
from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
RTL = REPO / "rtl/array/de_array.sv"
SHELL = REPO / "sim/fast/de_array.sv"
# Parameters whose default the shell sets its own way: name -> (rtl, shell).
OWN_DEFAULTS = {"TimingCopies": ("1", "0")}


def _bracketed(text: str, start: int) -> tuple[str, int]:
    """The text inside the parenthesis that opens at text[start], and the index after it."""
    depth = 0
    for i in range(start, len(text)):
        depth += {"(": 1, ")": -1}.get(text[i], 0)
        if depth == 0:
            return text[start + 1:i], i + 1
    raise ValueError(f"unbalanced parenthesis at offset {start}")


def _decls(body: str) -> list[str]:
    """The comma-separated declarations of a parameter or port list, white space folded."""
    return [" ".join(d.split()) for d in body.split(",") if d.strip()]


def header(path: Path, module: str = "de_array") -> tuple[list[str], list[str]]:
    """(parameters, ports) of `module` in path, comments left out."""
    text = re.sub(r"/\*.*?\*/", "", path.read_text(), flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    m = re.search(rf"\bmodule\s+{module}\b[^#(]*#\s*(?=\()", text)
    assert m, f"{path}: no `module {module} ... #(` header"
    params, after = _bracketed(text, m.end())
    ports, _ = _bracketed(text, text.index("(", after))
    return _decls(params), _decls(ports)


def _without_own_defaults(params: list[str], side: int) -> list[str]:
    out = []
    for p in params:
        name, _, default = p.partition(" = ")
        own = OWN_DEFAULTS.get(name.split()[-1])
        if own:
            assert default == own[side], f"{p}: expected the default {own[side]}"
            default = "(own)"
        out.append(f"{name} = {default}")
    return out


def test_shell_has_de_arrays_parameters_and_ports():
    rtl_params, rtl_ports = header(RTL)
    shell_params, shell_ports = header(SHELL)
    assert rtl_ports, f"{RTL}: no ports read"
    assert shell_ports == rtl_ports, (
        f"{SHELL.relative_to(REPO)}'s ports differ from {RTL.relative_to(REPO)}'s")
    assert _without_own_defaults(shell_params, 1) == _without_own_defaults(rtl_params, 0), (
        f"{SHELL.relative_to(REPO)}'s parameters differ from {RTL.relative_to(REPO)}'s")


def test_a_changed_port_is_seen(tmp_path):
    """The check can fail: a shell with one port renamed does not pass."""
    changed = tmp_path / "de_array.sv"
    changed.write_text(SHELL.read_text().replace("obs_bit_o", "obs_out_o"))
    assert header(changed)[1] != header(RTL)[1]
