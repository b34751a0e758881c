"""The generated ISA files are what spec/isa.toml and spec/video.toml say (issue 17).

rtl/xproc/de_pkg.sv, sw/include/de_isa.h and sw/diffengine/isa/_tables.py are generated
by `python -m diffengine.isa.gen`; a hand edit of any of them, or a change of the spec
without regenerating, fails here with the diff.
"""
from __future__ import annotations

import difflib
from pathlib import Path

from diffengine.isa import gen


def test_generated_files_match_the_spec(tmp_path: Path):
    assert gen.main(["--out", str(tmp_path)]) == 0
    diffs = []
    for rel in (gen.SV_OUT, gen.C_OUT, gen.PY_OUT):
        want = (tmp_path / rel).read_text()
        have = (gen.ROOT / rel).read_text()
        if have != want:
            diffs += difflib.unified_diff(have.splitlines(True), want.splitlines(True),
                                          f"checked in: {rel}", f"generated: {rel}")
    assert not diffs, "run `make gen`:\n" + "".join(diffs)


def test_generated_files_say_do_not_edit():
    for rel in (gen.SV_OUT, gen.C_OUT, gen.PY_OUT):
        head = (gen.ROOT / rel).read_text().splitlines()[0]
        assert "GENERATED FILE, DO NOT EDIT" in head and "spec/isa.toml" in head, rel


def test_lut_identifiers_compose_from_their_fields():
    """The encodings the RTL has always had (docs/isa.md section 3), from the fields."""
    from diffengine import isa
    assert [v for _, v, _ in isa.LUT] == [
        0x000, 0x100, 0x001, 0x002, 0x800, 0x801, 0x802, 0x803, 0x200, 0x444, 0x484, 0x4C4,
        0x4B4, 0x464, 0x460, 0x450, 0x448, 0x488, 0x4C8]
    assert isa.D_B_C == isa.data_id(isa.REG_B, isa.REG_C, True)
    assert isa.SET_C == isa.set_id(isa.REG_C)


def test_adder_carry_bug_model():
    """The fault adds 2 where the fraction's carry should add 1 (docs/isa.md section 7)."""
    from diffengine import isa
    one_frac = (1 << isa.FRAC_BITS) - 1
    assert isa.add_word(one_frac, 1) == 1 << isa.FRAC_BITS
    assert isa.add_word(one_frac, 1, carry_bug=True) == 2 << isa.FRAC_BITS
    assert isa.add_word(isa.WORD_MASK, 1) == 0
