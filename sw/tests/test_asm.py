"""Command-file parser and printer (docs/isa.md §9)."""
from pathlib import Path

import pytest

from diffengine import isa
from diffengine.formats.asm import AsmError, format_command, parse_file, parse_text
from diffengine.isa import Command

SCENES = Path(__file__).resolve().parents[1] / "scenes"
ONE = 1 << isa.FRAC_BITS  # 1.0 pixel LSB in raw 12.24


def one(text, name="t.cmd"):
    (c,) = parse_text(text, name)
    return c


# every command of Table 7.1 (and EvalN up to Eval8), as written in the source
TABLE_7_1 = [
    ("Eval0 (1, 2, 7);", Command("EVAL0", 1, 2, (7,))),
    ("Eval1 (55, 16, 0.9375);", Command("EVAL", 55, 16, (15 * ONE // 16,))),
    ("Eval2 (1, 17, 0.0625, 0.015625);", Command("EVAL", 1, 17, (ONE // 16, ONE // 64))),
    ("Eval3 (21, 33, 0.0, 0.0, 0.001953125);", Command("EVAL", 21, 33, (0, 0, ONE // 512))),
    ("Eval4 (1, 52, 0.0, 0.5,-0.25, 0.125);",
     Command("EVAL", 1, 52, (0, ONE // 2, -ONE // 4, ONE // 8))),
    ("Eval8 (0, 9, 1, 2, 3, 4, 5, 6, 7, 8);",
     Command("EVAL", 0, 9, tuple(k * ONE for k in range(1, 9)))),
    ("SetI (5, 3.5);", Command("SETI", 5, 1, (7 * ONE // 2,))),
    ("SetdI (5, -1);", Command("SETDI", 5, 1, (-ONE,))),
    ("Setddi (10, 1,-0.00390625);", Command("SETDDI", 10, 1, (-ONE // 256,))),
    ("SetddI (10, 4, 2);", Command("SETDDI", 10, 4, (2 * ONE,))),
    ("Setpi (8, 7, 0.0);", Command("SETPI", 8, 7, (0,))),
    ("SetPdI (8, 7, 1.5);", Command("SETPDI", 8, 7, (3 * ONE // 2,))),
    ("SETPDDI (0, 0, -2047);", Command("SETPDDI", 0, 0, (-2047 * ONE,))),
    ("Dis (3, 4);", Command("DIS", 3, 4)),
    ("Acc_mode ();", Command("ACCMODE", values=(1,))),
    ("Acc_mode;", Command("ACCMODE", values=(1,))),
    ("acc_mode (0);", Command("ACCMODE", values=(0,))),
    ("ACCMODE (1)", Command("ACCMODE", values=(1,))),
    ("Refresh;", Command("REFRESH")),
    ("refresh ()", Command("REFRESH")),
    ("Nop;", Command("NOP")),
]


@pytest.mark.parametrize("text,want", TABLE_7_1, ids=[t for t, _ in TABLE_7_1])
def test_table_7_1_parses(text, want):
    c = one(text)
    assert c == want
    assert c.line == 1
    assert parse_text(format_command(c)) == [c]


def test_isa_md_section_9_example():
    text = """# comment          // comment also
.unit pixel
.unit dac 0
Eval3 (21, 33, 0.0, 0.0, 0.001953125);
Setddi (10, 1,-0.003906);
SetI (5, 0x010.800000);   # hex fixed point: exact 36-bit pattern, unit-independent
Acc_mode ();
Refresh;
"""
    cs = parse_text(text)
    assert [c.op for c in cs] == ["EVAL", "SETDDI", "SETI", "ACCMODE", "REFRESH"]
    assert cs[0].values == (0, 0, round(0.001953125 * 64 * ONE))
    assert cs[1].values == (round(-0.003906 * 64 * ONE),)
    assert cs[2].values == (0x010800000,)
    assert [c.line for c in cs] == [4, 5, 6, 7, 8]


def test_hex_literals_are_raw_and_unit_independent():
    assert one("SetI (0, 0xfff.c00000);").values == (-ONE // 4,)
    assert one(".unit dac 3\nSetI (0, 0xFFF.C00000)").values == (-ONE // 4,)
    assert one("SetI (0, 0x7ff.ffffff);").values == ((1 << 35) - 1,)
    assert one("SetI (0, 0x800.000000);").values == (-(1 << 35),)


def test_decimal_rounding_is_nearest_ties_to_even():
    lsb = 2.0 ** -24
    assert one(f"SetI (0, {lsb / 2!r});").values == (0,)        # 0.5 LSB -> 0
    assert one(f"SetI (0, {3 * lsb / 2!r});").values == (2,)    # 1.5 LSB -> 2
    assert one(f"SetI (0, {5 * lsb / 2!r});").values == (2,)    # 2.5 LSB -> 2
    assert one(f"SetI (0, {-3 * lsb / 2!r});").values == (-2,)
    assert one("SetI (0, 0.0000000596);").values == (1,)         # 0.9999 LSB -> 1
    # exact: 0.1 is not a binary fraction; rounding uses the decimal text, not a float
    assert one("SetI (0, 0.1);").values == (round(0.1 * 2**24),)
    assert one("SetI (0, 1e-3);").values == (16777,)


def test_dac_units():
    assert one(".unit dac 0\nSetI (0, 1.0)").values == (64 * ONE,)
    assert one(".unit dac 4\nSetI (0, 0.5)").values == (512 * ONE,)
    assert one(".unit dac 6\nSetI (0, -0.5)").values == (-2048 * ONE,)
    assert one(".unit dac 2\n.unit pixel\nSetI (0, 3)").values == (3 * ONE,)
    assert one(".unit dac 0\nEval0 (1, 2, 0.5)").values == (32,)
    assert one(".unit dac 6 ;\nEval0 (1, 2, 0.999755859375)").values == (4095,)


def test_syntax_variants():
    cs = parse_text("Refresh; Nop ; // two statements\nNop\n\n  eVaL1(0,1,2)  # no ;\n;;")
    assert [c.op for c in cs] == ["REFRESH", "NOP", "NOP", "EVAL"]
    assert [c.line for c in cs] == [1, 1, 2, 4]
    assert one("Eval0 (1, 1, 0x005.000000)").values == (5,)
    assert one("Eval0 (1, 1, 5.0)").values == (5,)


BAD = [
    ("Foo (1, 2);", "unknown mnemonic"),
    ("Eval9 (1, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1);", "unknown mnemonic"),
    ("Eval2 (1, 2, 3);", "takes 4 operand"),
    ("Eval3 (1, 2, 3, 4, 5, 6);", "takes 5 operand"),
    ("SetI (1);", "takes 2 or 3"),
    ("SetPI (1, 2);", "takes 3"),
    ("Refresh (1);", "takes 0"),
    ("Dis (1, 2, 3);", "takes 2"),
    ("Acc_mode (2);", "0 or 1"),
    ("Eval1 (4096, 1, 0);", "X = 4096"),
    ("Eval1 (-1, 1, 0);", "X = -1"),
    ("Eval1 (0, 4096, 0);", "dX = 4096"),
    ("Eval1 (1.5, 1, 0);", "integer"),
    ("Eval1 (0, 1, 2048);", "outside [-2048, 2048)"),
    ("Eval1 (0, 1, -2048.0001);", "outside [-2048, 2048)"),
    ("Eval1 (0, 1, 2047.99999999999);", "outside [-2048, 2048)"),  # rounds to 2048
    (".unit dac 6\nEval1 (0, 1, 0.5);", "outside [-2048, 2048)"),
    ("Eval0 (0, 1, 4096);", "0..4095"),
    ("Eval0 (0, 1, -1);", "0..4095"),
    ("Eval0 (0, 1, 0.5);", "0..4095"),
    (".unit dac 0\nEval0 (0, 1, 0.3);", "0..4095"),
    ("Eval0 (0, 1, 0x001.800000);", "fraction"),
    ("Eval1 (55, 16, 0.9375.0);", "not a number"),       # the source's own typo
    ("Eval1 (55, 16, abc);", "not a number"),
    ("Eval1 (55, 16, 1e999999999);", "exponent"),
    ("Eval1 (55, 16, 1e-999999999);", "exponent"),
    ("Eval1 (55, 16, 0x01.800000);", "hex literal"),
    ("Eval1 (55, 16, -0x001.800000);", "hex literal"),
    ("Eval1 (55, 16, 0x10);", "hex literal"),
    ("Eval1 (55, , 1);", "empty operand"),
    ("Eval1 (55, 16, 1", "cannot parse"),
    ("Eval1 55, 16, 1", "cannot parse"),
    (".unit dac 7", "bad directive"),
    (".unit furlong", "bad directive"),
    (".include foo", "unknown directive"),
]


@pytest.mark.parametrize("text,msg", BAD, ids=[t for t, _ in BAD])
def test_bad_input_names_file_and_line(text, msg):
    with pytest.raises(AsmError) as e:
        parse_text("# header\n" + text, "bad.cmd")
    line = text.count("\n") + 2
    assert str(e.value).startswith(f"bad.cmd:{line}: ")
    assert msg in str(e.value)
    assert isinstance(e.value, ValueError)


def test_all_errors_are_reported():
    with pytest.raises(AsmError) as e:
        parse_text("Foo;\nRefresh;\nEval1 (0, 1);\nNop\nDis (5000, 1)", "m.cmd")
    lines = str(e.value).splitlines()
    assert [ln.split(":")[1] for ln in lines] == ["1", "3", "5"]
    assert [w for w, _ in e.value.errors] == [1, 3, 5]


def test_format_command_exact_and_unit():
    c = Command("EVAL", 1, 17, (ONE // 2, -ONE // 128))
    assert format_command(c) == "Eval2 (1, 17, 0x000.800000, 0xfff.fe0000);"
    assert "# 0.0078125, -0.00012207" in format_command(c, 0, comment=True)
    e = Command("EVAL0", 1, 2, (32,))
    assert format_command(e) == "Eval0 (1, 2, 32);"
    assert format_command(e, unit=0) == "Eval0 (1, 2, 0.5);"
    assert parse_text(".unit dac 0\n" + format_command(e, unit=0)) == [e]
    assert format_command(Command("SETI", 3, 1, (0,))) == "SetI (3, 0x000.000000);"
    assert format_command(Command("SETI", 3, 2, (0,))) == "SetI (3, 2, 0x000.000000);"


def test_parse_file_and_scenes():
    files = sorted(SCENES.glob("*.cmd"))
    names = {f.name for f in files}
    assert {f"fig7_21{p}.cmd" for p in "abcdef"} <= names
    assert {f"fig7_25{p}.cmd" for p in "abcdef"} | {"fig7_25.cmd"} <= names
    parsed = {f.name: parse_file(f) for f in files}
    for f, cs in parsed.items():
        assert cs and cs[-1].op == "REFRESH", f
        for c in cs:  # exact print/parse round trip of every shipped command
            assert parse_text(format_command(c)) == [c]
    for a, b in ("ab", "cd", "ef"):  # compensated panels hold the same list
        assert parsed[f"fig7_21{a}.cmd"] == parsed[f"fig7_21{b}.cmd"]
    assert parsed["fig7_25.cmd"] == [c for p in "abcdef" for c in parsed[f"fig7_25{p}.cmd"]]
    # the typo fixed: Eval1 (55, 16, 0.9375) at .unit dac 0 = 60 pixel LSBs
    assert Command("EVAL", 55, 16, (60 * ONE,)) in parsed["fig7_21c.cmd"]


def test_parse_file_not_utf8(tmp_path):
    p = tmp_path / "x.cmd"
    p.write_bytes(b"Nop;\n\xff\xfe")
    with pytest.raises(AsmError, match=r"x\.cmd:1: not UTF-8"):
        parse_file(p)
