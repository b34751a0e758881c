"""The generated ISA files are what spec/isa.toml and spec/video.toml say (issue 17).

rtl/xproc/de_pkg.sv, sw/include/de_isa.h and sw/diffengine/isa/_tables.py are generated
by `python -m diffengine.isa.gen`; a hand edit of any of them, or a change of the spec
without regenerating, fails here with the diff.
"""
from __future__ import annotations

import difflib
from pathlib import Path

import pytest

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


def test_video_mode_param_is_de_pkg_layout():
    """isa.video_mode_param packs spec/video.toml's test geometry into the same value as
    de_pkg::VideoTestDefault (the struct's field order and widths), and reads it back."""
    import re
    import tomllib
    from diffengine import isa
    spec = tomllib.loads((gen.ROOT / "spec" / "video.toml").read_text())["test"]
    pkg = (gen.ROOT / gen.SV_OUT).read_text()
    concat = re.search(r"video_mode_t VideoTestDefault = \{([^}]*)\}", pkg).group(1)
    word, bits = 0, 0
    for w, base, digits in re.findall(r"(\d+)'([db])(\d+)", concat):
        word = word << int(w) | int(digits, 10 if base == "d" else 2)
        bits += int(w)
    assert bits == isa.VIDEO_MODE_BITS
    lit = isa.video_mode_param(spec["h"], spec["v"], spec["hpol"], spec["vpol"])
    assert lit == f"{bits}'h{word:x}"
    g = isa.video_mode_fields(word)
    assert [g[k] for k in ("TestHActive", "TestHFp", "TestHSync", "TestHBp")] == spec["h"]
    assert [g[k] for k in ("TestVActive", "TestVFp", "TestVSync", "TestVBp")] == spec["v"]
    assert g["HTotal"] == sum(spec["h"]) and g["VTotal"] == sum(spec["v"])
    g = isa.video_mode_fields(int(isa.video_mode_param((9, 16, 96, 679), (16, 1, 2, 2))
                                  .split("'h")[1], 16))
    assert (g["TestHBp"], g["TestVActive"], g["HTotal"]) == (679, 16, 800)
    with pytest.raises(ValueError):
        isa.video_mode_param((4096, 1, 1, 1), (1, 1, 1, 1))
    with pytest.raises(ValueError):
        isa.video_mode_param((1, 1, 1), (1, 1, 1, 1))


# A spoiled spec file through `python -m diffengine.isa.gen`: (name, file, spoil, where).
# `where` is the FILE:LINE:COL the message must start with (tomllib's position).
BAD_SPECS = [
    ("bad_value", "spec/isa.toml", ("id_bits = 12", "id_bits = twelve"), "spec/isa.toml:7:11: "),
    ("unclosed_table", "spec/regs.toml", ("[address]", "[address"), "spec/regs.toml:6:9: "),
    ("unclosed_array", "spec/video.toml", ("vpol = false\n\n[[mode]]", "vpol = false\n\n[[mo"),
     "spec/video.toml:16:5: "),
    ("cut_short", "spec/regs.toml", ("", ""), "spec/regs.toml:14:12: "),
]
CUT = "hist_base = 0x040"   # spec/regs.toml cut short after "hist_base =": at the end of it


@pytest.mark.parametrize("name,rel,spoil,where", BAD_SPECS, ids=[b[0] for b in BAD_SPECS])
def test_bad_spec_names_file_and_line(tmp_path: Path, name, rel, spoil, where):
    import subprocess
    import sys
    for r in gen.SPEC:
        (tmp_path / r).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / r).write_text((gen.ROOT / r).read_text())
    text = (tmp_path / rel).read_text()
    assert spoil[0] in text
    text = text.replace(spoil[0], spoil[1], 1)
    if name == "cut_short":
        text = text[:text.index(CUT) + len("hist_base =")]
    (tmp_path / rel).write_text(text)
    res = subprocess.run([sys.executable, "-m", "diffengine.isa.gen", "--spec-root", str(tmp_path),
                          "--out", str(tmp_path / "out")], capture_output=True, text=True)
    assert res.returncode == 1, res.stderr
    assert "Traceback" not in res.stderr, res.stderr
    assert res.stderr.startswith(f"{tmp_path}/{where}"), res.stderr
    assert not (tmp_path / "out").exists()


def test_missing_spec_is_named(tmp_path: Path):
    for r in gen.SPEC[:2]:
        (tmp_path / r).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / r).write_text((gen.ROOT / r).read_text())
    with pytest.raises(SystemExit) as e:
        gen.load(tmp_path)
    assert str(e.value) == f"{tmp_path}/spec/regs.toml: cannot read (No such file or directory)"
