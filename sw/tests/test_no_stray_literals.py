"""No ISA fact is written by hand where it used to be (issue 17 item 1).

spec/isa.toml, spec/video.toml and spec/regs.toml are the one description; rtl/xproc/de_pkg.sv,
sw/include/de_isa.h and sw/diffengine/isa/_tables.py are generated from them. This test
greps the files that used to hold their own copies (identifier encodings, field offsets,
video timings, the host register map of spec/regs.toml) for those literals and fails naming file:line, so a copy cannot come back
unnoticed. A line may opt out with the marker `isa-literal-ok` and a reason.
"""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# The identifiers of the look-up table that are not also small numbers (NOP = 0,
# ACCMODE_ON/OFF = 1/2 cannot be told from any other 0, 1, 2).
_IDS = r"(?:100|200|80[0-3]|4[4-9a-c][048])"
ID_HEX = re.compile(rf"\b0x{_IDS}\b", re.I)
ID_SV = re.compile(rf"\b12'h{_IDS}\b", re.I)
# Field offsets: the word / fraction widths and the identifier's class bits as shifts.
SHIFT = re.compile(r"(?:<<|>>)\s*(?:36|24|11|10|9|8)\b(?!\s*\))")
SV_FIELD = re.compile(r"\[(?:35|23):(?:24|0)\]")
# Video timings: the totals and porch/sync runs of the fixed modes.
VIDEO = re.compile(r"\b(?:683|1688)\b|\b16,\s*96\b|\b8,\s*24,\s*11\b|\b48,\s*112\b"
                   r"|12'd(?:96|112|248|485)\b")

# The host register map (spec/regs.toml): register numbers, window bases, ID magics.
REGS = re.compile(r"\b0x300[01]\b|\brd\(base \+ (?:0x[0-9a-f]+|\d+)|\b0xD[CE]\b", re.I)
REGS_SV = re.compile(r"\b12'h0[0-9A-F]{2}:|\b8'hD[CE]\b|\[47:36\]", re.I)

PLACES: list[tuple[str, tuple[re.Pattern, ...]]] = [
    ("rtl/proto/de_instr_lut.sv", (ID_SV,)),
    ("rtl/ctrl/de_instr_buffer.sv", (ID_SV, REGS_SV)),
    ("rtl/ctrl/de_access_ctrl.sv", (ID_SV, REGS_SV)),
    ("rtl/ctrl/de_video_timing.sv", (VIDEO,)),
    ("rtl/ctrl/de_load_monitor.sv", (REGS_SV,)),
    ("rtl/ctrl/de_display_core.sv", (REGS_SV,)),
    ("rtl/ctrl/display_controller.sv", (REGS_SV,)),
    ("sw/yproc/src/yp_emit.c", (ID_HEX, SHIFT, VIDEO)),
    ("sim/harness/array_harness.cpp", (ID_HEX, SHIFT)),
    ("sim/dc/dc_harness.cpp", (ID_HEX, VIDEO, REGS, SHIFT)),
    ("sim/fast/equiv.cpp", (ID_HEX,)),
    ("rtl/xproc/de_pe.sv", (ID_SV, SV_FIELD)),
    ("rtl/varray/de_span_array.sv", (ID_SV, SV_FIELD)),
    ("rtl/array/de_chip.sv", (ID_SV,)),
    ("sw/diffengine/isa/__init__.py", (ID_HEX, SHIFT)),
    ("sw/diffengine/model/structural.py", (ID_HEX,)),
    ("sw/diffengine/model/functional.py", (ID_HEX,)),
    ("sw/diffengine/pipeline/anim.py", (ID_HEX,)),
    ("sw/diffengine/pipeline/demo.py", (ID_HEX, VIDEO)),
    ("sw/diffengine/model/capacity.py", (ID_HEX, VIDEO)),
    ("tb/de_access_ctrl/test_de_access_ctrl.py", (ID_HEX, VIDEO)),
    ("tb/de_instr_buffer/test_de_instr_buffer.py", (ID_HEX,)),
    ("tb/display_controller/test_display_controller.py", (ID_HEX,)),
    ("tb/de_span_array/test_de_span_array.py", (ID_HEX,)),
    ("tb/sim_harness/test_sim_harness.py", (ID_HEX,)),
]


def _comment_free(line: str, path: str) -> str:
    """The code of a line: comments name numbers freely (docs, the source's tables)."""
    if path.endswith(".py"):
        return line.split("#", 1)[0]
    return line.split("//", 1)[0].split("/*", 1)[0]


def stray(root: Path = ROOT) -> list[str]:
    found = []
    for rel, patterns in PLACES:
        for n, line in enumerate((root / rel).read_text().splitlines(), 1):
            if "isa-literal-ok" in line:
                continue
            code = _comment_free(line, rel)
            for pat in patterns:
                m = pat.search(code)
                if m:
                    found.append(f"{rel}:{n}: {m.group(0)!r} is written by hand; use the "
                                 "generated name (spec/*.toml)")
    return found


def test_no_isa_literals_outside_the_spec():
    found = stray()
    assert not found, "\n".join(found)


def test_the_grep_finds_a_planted_literal(tmp_path: Path):
    """The test can fail: a copy of the places with one raw identifier planted."""
    for rel, _ in PLACES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text((ROOT / rel).read_text())
    target = tmp_path / "sw/yproc/src/yp_emit.c"
    target.write_text(target.read_text() + "static const unsigned planted = 0x4B4;\n")
    found = stray(tmp_path)
    assert len(found) == 1 and found[0].startswith("sw/yproc/src/yp_emit.c:")
