"""No ISA fact is written by hand where it used to be (issue 17 item 1).

spec/isa.toml, spec/video.toml and spec/regs.toml are the one description;
rtl/xproc/de_pkg.sv, sw/include/de_isa.h and sw/diffengine/isa/_tables.py are generated
from them. This test greps the files that used to hold their own copies (identifier
encodings, field offsets, video timings, the host register map of spec/regs.toml) for
those literals and fails naming file:line, so a copy cannot come back unnoticed. A line
may opt out with the marker `isa-literal-ok` and a reason; synthesised RTL still waiting
for its netlist-proven fix is listed in PENDING with who is fixing it.

What is scanned is code only: comments (`#`, `//`, `/* ... */` over several lines) and
Python docstrings are blanked first, so prose may name any number. The patterns are
scoped: an identifier's value is caught anywhere in the scanned files in any radix
(`0x4B4`, `12'h4B4`, `'h4B4`, `12'd1204`, `1204`), but a decimal that is also an everyday
number (256, 512, 2048) only where it is compared with or assigned to an identifier; a
video total (800, 525, ...) only in the files that used to hold the mode table, where it
has no other meaning. test_the_scanner_catches_every_variant plants each variant.
"""
from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# ---- identifier encodings ------------------------------------------------------------
# The identifiers of the look-up table that are not also small numbers (NOP = 0,
# ACCMODE_ON/OFF = 1/2 cannot be told from any other 0, 1, 2).
_IDS = r"(?:100|200|80[0-3]|4[4-9a-c][048])"
# Their decimal values: those no everyday quantity takes (1092 = 0x444 ... 2051 = 0x803) ...
_IDS_DEC_RARE = r"(?:1092|1096|1104|1120|1124|1156|1160|1204|1220|1224|2049|2050|2051)"
# ... and those that are also sizes (256 = REFRESH, 512 = ACC, 2048 = ADDR_RANGE).
_IDS_DEC_COMMON = r"(?:256|512|2048)"
_ID_NAME = r"\b(?:id|ident|identifier|id_\w+|ident_\w+|\w+_id|\w+_ident)\b"
ID_HEX = re.compile(rf"\b0x{_IDS}\b", re.I)
# SystemVerilog, sized or not, hex or decimal: 12'h4B4, 'h4B4, 12'd1204, 'd256.
ID_SV = re.compile(rf"(?:\b\d+)?'[sS]?(?:[hH]{_IDS}|[dD](?:{_IDS_DEC_RARE}|{_IDS_DEC_COMMON}))\b",
                   re.I)
ID_DEC = re.compile(
    rf"(?<![\w.']){_IDS_DEC_RARE}\b"                                   # 1204 anywhere
    rf"|{_ID_NAME}\s*(?:==|!=|=|<=)\s*{_IDS_DEC_COMMON}\b"             # ident == 256
    rf"|(?<![\w.]){_IDS_DEC_COMMON}\s*(?:==|!=)\s*{_ID_NAME}"          # 256 == ident
    rf"|\bcase\s+{_IDS_DEC_COMMON}\s*:")                               # case 256:
IDS = (ID_HEX, ID_SV, ID_DEC)

# ---- field offsets ---------------------------------------------------------------------
# The word / fraction widths as shifts (w >> 24, (1 << 36) - 1), the identifier's class
# bits as masks or tests (1 << 8, (id >> 11) & 1); a byte's `v << 8 | b` is not one.
SHIFT = re.compile(r"(?:<<|>>)\s*(?:36|24)\b|\b1[uU]?[lL]*\s*<<\s*(?:11|10|9|8)\b"
                   r"|>>\s*(?:11|10|9|8)\s*\)?\s*&\s*1\b")
# A constant bit or range of an identifier signal (id_i[8], ident_q[7:6]): the fields.
ID_BIT = re.compile(r"\b(?:id|ident)(?:_[iodq]\d*)?\s*\[\s*\d+\s*(?::\s*\d+\s*)?\]")
# The data word's blocks and fraction ([35:24], [23:12], data_i[11:0], w[23:0]), a
# record's identifier and data (rec[47:36], rec[35:0]).
DATA_SLICE = re.compile(r"\[\s*(?:35|23)\s*:\s*(?:24|12)\s*\]"
                        r"|\b\w*(?:data|word|blk)\w*\s*\[\s*11\s*:\s*0\s*\]"
                        r"|\b\w+\[\s*(?:35|23)\s*:\s*0\s*\]"
                        r"|\[\s*47\s*:\s*36\s*\]", re.I)
FIELDS = (SHIFT, ID_BIT, DATA_SLICE)
# The modules that cut a word into its 12-bit blocks now call isa.word_blocks; a cut by
# hand (w >> 12, & 0xFFF) in them is a copy. Elsewhere 12 and 0xFFF are pixels and bytes.
BLOCK_CUT = re.compile(r"(?:<<|>>)\s*12\b|\b0xfff\b", re.I)

# ---- video timings ---------------------------------------------------------------------
# The totals and porch/sync runs of the fixed modes, an active size as a pair.
VIDEO = re.compile(r"\b(?:683|1688|1066)\b|\b16,\s*96\b|\b8,\s*24,\s*11\b|\b48,\s*112\b"
                   r"|(?:\b\d+)?'d(?:96|112|248|485|480|640|1024|1280|800|525|683|1688|1066)\b"
                   r"|\(\s*(?:640|1280)\s*,\s*(?:480|485|1024)\s*\)")
# 800 and 525 (640x480's totals) mean nothing else in the files that held the mode table
# (elsewhere 800 is a picture size or a timeout, 525 a line count in prose).
VIDEO_TOTAL = re.compile(r"(?<![\w.'])(?:800|525)\b")

# ---- the host register map (spec/regs.toml): register numbers, window bases, ID magics.
REGS = re.compile(r"\b0x300[01]\b|\brd\(base \+ (?:0x[0-9a-f]+|\d+)|\b0xD[CE]\b", re.I)
# A testbench's register read: the channel shifted by hand, a window base or register number.
REGS_PY = re.compile(r"\bread_reg\(dut,\s*[^)]*<<\s*12\b|\bread_reg\(dut,\s*[^)]*\|\s*0x[0-9a-f]+",
                     re.I)
REGS_SV = re.compile(r"\b12'h0[0-9A-F]{2}:|\b8'hD[CE]\b|\[47:36\]", re.I)

ISA = IDS + FIELDS
PLACES: list[tuple[str, tuple[re.Pattern, ...]]] = [
    # synthesised RTL
    ("rtl/proto/de_instr_lut.sv", ISA),
    ("rtl/proto/de_skew.sv", ISA),
    ("rtl/proto/de_deskew.sv", ISA),
    ("rtl/proto/de_data_mapper.sv", ISA),
    ("rtl/ctrl/de_instr_buffer.sv", ISA + (REGS_SV,)),
    ("rtl/ctrl/de_access_ctrl.sv", ISA + (REGS_SV,)),
    ("rtl/ctrl/de_video_timing.sv", ISA + (VIDEO, VIDEO_TOTAL)),
    ("rtl/ctrl/de_load_monitor.sv", ISA + (REGS_SV,)),
    ("rtl/ctrl/de_display_core.sv", ISA + (REGS_SV,)),
    ("rtl/ctrl/display_controller.sv", ISA + (REGS_SV,)),
    ("rtl/board/de_board_core.sv", ISA + (VIDEO, VIDEO_TOTAL)),
    ("rtl/xproc/de_pe.sv", ISA),
    ("rtl/varray/de_span_array.sv", ISA),
    ("rtl/array/de_chip.sv", ISA),
    ("rtl/array/de_array.sv", ISA),
    ("rtl/varray/de_span_video.sv", ISA),
    ("sim/fast/de_array.sv", ISA),
    ("sim/fast/de_fast_unit.sv", ISA),
    ("sim/fast/de_fast_head.sv", ISA),
    ("sim/fast/de_fast_tail.sv", ISA),
    ("fpga/span_top.sv", ISA),
    # C, C++: the y-processor, its tests, the simulation harnesses
    ("sw/yproc/src/yp_emit.c", ISA + (VIDEO, VIDEO_TOTAL)),
    ("sw/yproc/src/yp_scan.c", IDS),
    ("sw/yproc/tests/test_yp_scan.c", ISA),
    ("sw/yproc/tests/test_yp_coh.c", ISA),
    ("sw/yproc/tests/test_main.c", ISA),
    ("sw/yproc/tests/test_obj_shading.c", ISA),
    ("sw/yproc/tests/test_yp_tess.c", ISA),
    ("sw/yproc/tests/test_yp_tex_lod.c", ISA),
    ("sw/yproc/tests/yp_fixture.c", ISA),
    ("sim/harness/array_harness.cpp", ISA),
    ("sim/dc/dc_harness.cpp", ISA + (VIDEO, VIDEO_TOTAL, REGS)),
    ("sim/fast/equiv.cpp", ISA),
    ("sim/fast/de_fast.cpp", ISA),
    # Python: the ISA, the models, the formats that cut words into blocks, the pipeline
    ("sw/diffengine/isa/__init__.py", ISA),
    ("sw/diffengine/model/structural.py", ISA),
    ("sw/diffengine/model/functional.py", ISA),
    ("sw/diffengine/model/capacity.py", IDS + (VIDEO,)),
    ("sw/diffengine/formats/binfmt.py", ISA + (BLOCK_CUT,)),
    ("sw/diffengine/formats/disasm.py", ISA + (BLOCK_CUT,)),
    ("sw/diffengine/formats/asm.py", ISA),
    ("sw/diffengine/rtl/trace.py", ISA + (BLOCK_CUT,)),
    ("sw/diffengine/rtl/inspect_page.py", ISA + (BLOCK_CUT,)),
    ("sw/diffengine/rtl/dc_harness.py", ISA + (VIDEO, VIDEO_TOTAL, REGS)),
    ("sw/diffengine/regress/randgen.py", ISA + (BLOCK_CUT,)),
    ("sw/diffengine/rtl/harness.py", ISA),
    ("sw/diffengine/model/fast.py", ISA),
    ("sw/diffengine/model/lines.py", ISA),
    ("sw/diffengine/formats/frame.py", ISA),
    ("sw/diffengine/pipeline/anim.py", IDS + (VIDEO, VIDEO_TOTAL)),
    ("sw/diffengine/pipeline/demo.py", IDS + (VIDEO, VIDEO_TOTAL)),
    # testbenches
    ("tb/de_pe/test_de_pe.py", ISA),
    ("tb/de_pe/de_pe_chain.sv", ISA),
    ("tb/de_access_ctrl/test_de_access_ctrl.py", ISA + (VIDEO, VIDEO_TOTAL, REGS)),
    ("tb/de_instr_buffer/test_de_instr_buffer.py", ISA + (REGS,)),
    ("tb/display_controller/test_display_controller.py", ISA + (REGS, REGS_PY)),
    ("tb/de_span_array/test_de_span_array.py", ISA),
    ("tb/sim_harness/test_sim_harness.py", ISA),
    ("tb/sim_regress/test_inspect.py", ISA),
    ("tb/de_array/test_de_array.py", ISA),
    ("tb/de_input_circuit/test_de_input_circuit.py", ISA),
    ("tb/de_input_circuit/de_input_circuit_tb.sv", ISA),
    ("tb/de_load_monitor/test_de_load_monitor.py", ISA + (REGS, REGS_PY)),
    ("tb/board_top/test_board_top.py", ISA + (REGS, REGS_PY, VIDEO)),
    ("tb/board_top/test_link_host.py", ISA),
    ("tb/tools/test_sdram_budget.py", ISA),
]
# Not scanned, and why: tb/board_top/tmds.py and sim/board/board_harness.cpp (TMDS bits 8
# and 9, not identifier bits), tb/sdram_model (the SDRAM's A10), tb/board_top/
# test_sdram_frames.py (its 36-bit prefetch word is {comp, window, word[31:0]}, not a data
# word).

# Hits in synthesised RTL that is changed only with a netlist comparison proving the
# change a refactor: file:line -> who is fixing it. An entry that no longer hits fails
# test_pending_hits_are_still_there, so the list shrinks as the fixes land.
PENDING: dict[str, str] = {}


def _blank_c_comments(text: str) -> str:
    """C, C++, SystemVerilog: comments replaced by spaces, newlines kept (line numbers
    stay); string literals are kept as they are."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"' and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _blank_py_comments(text: str) -> list[str]:
    """Python: comments and docstrings (and other bare string statements) blanked."""
    lines = text.splitlines()
    for node in ast.walk(ast.parse(text)):
        if (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
                and isinstance(node.value.value, str)):
            for k in range(node.lineno - 1, node.end_lineno):
                lines[k] = ""
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT:
            row, col = tok.start
            lines[row - 1] = lines[row - 1][:col]
    return lines


def code_lines(path: Path) -> list[str]:
    """The code of each line of a file (comments and docstrings blanked)."""
    text = path.read_text()
    if path.suffix == ".py":
        return _blank_py_comments(text)
    return _blank_c_comments(text).splitlines()


def stray(root: Path = ROOT, places=PLACES) -> list[str]:
    found = []
    for rel, patterns in places:
        raw = (root / rel).read_text().splitlines()
        for n, code in enumerate(code_lines(root / rel), 1):
            if "isa-literal-ok" in raw[n - 1]:
                continue
            for pat in patterns:
                m = pat.search(code)
                if m:
                    found.append(f"{rel}:{n}: {m.group(0)!r} is written by hand; use the "
                                 "generated name (spec/*.toml)")
                    break
    return found


def test_no_isa_literals_outside_the_spec():
    found = [f for f in stray() if f.split(": ", 1)[0] not in PENDING]
    assert not found, "\n".join(found)


def test_pending_hits_are_still_there():
    """A pending entry that no longer hits is stale: remove it."""
    hits = {f.split(": ", 1)[0] for f in stray()}
    stale = sorted(set(PENDING) - hits)
    assert not stale, f"fixed, remove from PENDING: {stale}"


def test_every_place_exists():
    missing = [rel for rel, _ in PLACES if not (ROOT / rel).is_file()]
    assert not missing, missing


# The audit's fifteen variants (issue 17, 11-26; reconstructed): (file, planted line).
# The old patterns caught the first nine; the last six slipped through ('h4B4, id_i[8],
# [23:12] and [35:24] in rtl/proto, a decimal 256, a total of 800).
PLANTS = [
    ("sw/yproc/src/yp_emit.c", "static const unsigned planted = 0x4B4;"),
    ("rtl/ctrl/de_instr_buffer.sv", "localparam logic [11:0] Planted = 12'h4B4;"),
    ("sim/harness/array_harness.cpp", "static uint64_t planted(uint64_t w) { return w >> 24; }"),
    ("rtl/xproc/de_pe.sv", "assign planted = d_q[35:24];"),
    ("rtl/ctrl/de_load_monitor.sv", "localparam logic [7:0] Planted = 8'hDE;"),
    ("sw/yproc/src/yp_emit.c", "static const int planted_htotal = 683;"),
    ("sim/dc/dc_harness.cpp", "static const unsigned planted_reg = 0x3001;"),
    ("rtl/ctrl/de_video_timing.sv", "localparam logic [11:0] Planted = 12'd96;"),
    ("sim/dc/dc_harness.cpp", "static const int planted_h[] = {640, 16, 96, 48};"),
    ("rtl/ctrl/de_access_ctrl.sv", "localparam logic [11:0] Planted = 'h4B4;"),
    ("rtl/xproc/de_pe.sv", "assign planted = id_i[8];"),
    ("rtl/proto/de_skew.sv", "assign planted = data_i[23:12];"),
    ("rtl/proto/de_deskew.sv", "assign planted = data_i[35:24];"),
    ("sw/diffengine/model/functional.py", "planted = ident == 256"),
    ("sim/dc/dc_harness.cpp", "static const int planted_htotal = 800;"),
]
# More variants, in the places this test scans since (11-26).
PLANTS_MORE = [
    ("sw/diffengine/pipeline/demo.py", "planted = 525"),
    ("sw/diffengine/rtl/dc_harness.py", "planted = (640, 480)"),
    ("rtl/board/de_board_core.sv", "localparam logic [11:0] Planted = 12'd480;"),
    ("rtl/ctrl/de_video_timing.sv", "localparam logic [11:0] Planted = 12'd1688;"),
    ("rtl/ctrl/de_video_timing.sv", "localparam logic [11:0] Planted = 'd485;"),
    ("sw/diffengine/formats/binfmt.py", "planted = (word >> 12) & 0xFFF"),
    ("sw/diffengine/regress/randgen.py", "planted = word & 0xfff"),
    ("tb/de_pe/test_de_pe.py", "planted = 1 << 36"),
    ("sw/yproc/tests/test_yp_scan.c", "static const unsigned planted = 1u << 8;"),
    ("tb/display_controller/test_display_controller.py", "planted = read_reg(dut, 3 << 12)"),
    ("tb/de_access_ctrl/test_de_access_ctrl.py", "planted = 1204"),
]


@pytest.mark.parametrize("rel,line", PLANTS + PLANTS_MORE,
                         ids=[f"{r.split('/')[-1]}:{ln}" for r, ln in PLANTS + PLANTS_MORE])
def test_the_scanner_catches_every_variant(tmp_path: Path, rel: str, line: str):
    """The test can fail: each variant planted alone in a copy of its file (at the end, or
    before an SV file's endmodule) is reported with that file and line, and nothing else is."""
    place = [p for p in PLACES if p[0] == rel]
    target = tmp_path / rel
    target.parent.mkdir(parents=True, exist_ok=True)
    text = (ROOT / rel).read_text()
    target.write_text(text)
    before = stray(tmp_path, place)
    if rel.endswith(".sv"):
        k = text.rindex("endmodule")
        text = text[:k] + line + "\n" + text[k:]
    else:
        text = text + line + "\n"
    target.write_text(text)
    n = text[:text.index(line)].count("\n") + 1
    new = set(stray(tmp_path, place)) - set(before)
    assert len(new) == 1, new
    assert new.pop().startswith(f"{rel}:{n}: "), (rel, n)


def test_comments_and_docstrings_are_not_scanned(tmp_path: Path):
    (tmp_path / "a.c").write_text("/* 0x4B4\n   id_i[8] 800 */ int x; // 0x100\n")
    (tmp_path / "b.py").write_text('"""0x4B4\n800"""\nx = "#"  # 0x100\n'
                                   'y = ("it\'s",  # 0x100\n     """a\nb\'s""")  # 0x100\n')
    places = [("a.c", ISA + (VIDEO_TOTAL,)), ("b.py", ISA + (VIDEO_TOTAL,))]
    assert stray(tmp_path, places) == []
    (tmp_path / "a.c").write_text("/* 0x4B4 */ int x = 0x100;\n")
    (tmp_path / "b.py").write_text('"""doc"""\nx = 1  # 0x100\ny = 0x100  # code\n')
    assert [f.split(" ", 1)[0] for f in stray(tmp_path, places)] == ["a.c:1:", "b.py:3:"]
