"""The `diffengine` command line: outputs, and user errors without tracebacks."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from diffengine.formats import binfmt
from diffengine.cli import commands, tree as cli
from diffengine.model import functional
from diffengine import isa
from diffengine.formats.asm import parse_file, parse_text

SCENES = Path(__file__).resolve().parents[1] / "scenes"
FIG25 = SCENES / "fig7_25.cmd"


def run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def read_image(path):
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(str(path))
    assert not buf.has_error, buf.geterror()
    fmt = "float" if str(path).endswith(".exr") else "uint16"
    return buf.get_pixels(fmt)[:, :, 0]


def test_asm_disasm_round_trip(tmp_path, capsys):
    de48 = tmp_path / "a.de48"
    rc, _, err = run(capsys, "asm", FIG25, "-o", de48)
    assert rc == 0 and "23 commands" in err
    assert de48.read_bytes()[:4] == b"DE48"
    txt = tmp_path / "a.cmd"
    assert run(capsys, "disasm", de48, "-o", txt)[0] == 0
    assert parse_file(txt) == parse_file(FIG25)
    rc, out, _ = run(capsys, "disasm", de48, "--slots")
    assert rc == 0 and out.count("\n") == len(isa.serialise(parse_file(FIG25)))


def test_asm_framestore(tmp_path, capsys):
    src = SCENES / "fig7_21c.cmd"
    de32 = tmp_path / "c.de32"
    assert run(capsys, "asm", src, "-f", "framestore", "--window", "0", "--compensate",
               "-o", de32)[0] == 0
    words, w, comp = binfmt.decode_de32(de32.read_bytes())
    assert (w, comp) == (0, True)
    assert words == binfmt.framestore_encode(parse_file(src), 0)
    rc, out, _ = run(capsys, "disasm", de32)
    assert rc == 0 and "compensation on" in out
    assert parse_text(out) == parse_file(src)             # stored values, not compensated
    rc, out, _ = run(capsys, "disasm", de32, "--mapped")
    assert parse_text(out)[0].values[0] == isa.compensate(parse_file(src)[0].values[0])


def test_asm_framestore_round_option(tmp_path, capsys):
    rc, _, err = run(capsys, "asm", FIG25, "-f", "framestore", "--window", "3",
                     "-o", tmp_path / "x.de32")
    assert rc == 1 and "fig7_25.cmd:17: Eval4:" in err and "precision below bit 7" in err
    rc, _, _ = run(capsys, "asm", FIG25, "-f", "framestore", "--window", "3", "--round",
                   "-o", tmp_path / "x.de32")
    assert rc == 0


def test_model_png_keeps_12_bits(tmp_path, capsys):
    png = tmp_path / "d.png"
    rc, _, err = run(capsys, "model", FIG25, "-o", png)
    assert rc == 0 and "6 x 640" in err
    want = functional.render(parse_file(FIG25), 640)
    got = read_image(png)
    assert got.shape == (6, 640)
    np.testing.assert_array_equal(got, want.astype(np.uint16) << 4)
    raw = tmp_path / "r.tif"
    assert run(capsys, "model", FIG25, "-o", raw, "--raw", "--window", "3",
               "--line-height", "2")[0] == 0
    np.testing.assert_array_equal(read_image(raw), ((want >> 3) & 63).repeat(2, axis=0))
    exr = tmp_path / "e.exr"
    assert run(capsys, "model", FIG25, "-o", exr, "--width", "200")[0] == 0
    np.testing.assert_array_equal(read_image(exr), want[:, :200] / 4096.0)


def test_model_carry_bug_and_compensate(tmp_path, capsys):
    src = SCENES / "fig7_21a.cmd"
    cmds = parse_file(src)
    a = tmp_path / "a.png"
    assert run(capsys, "model", src, "-o", a, "--raw", "--carry-bug", "--width", "64")[0] == 0
    np.testing.assert_array_equal(read_image(a), functional.render(cmds, 64, carry_bug=True))
    b = tmp_path / "b.png"
    assert run(capsys, "model", src, "-o", b, "--raw", "--carry-bug", "--compensate",
               "--width", "64")[0] == 0
    comp = binfmt.deserialise(binfmt.compensate_slots(isa.serialise(cmds)))
    np.testing.assert_array_equal(read_image(b), functional.render(comp, 64, carry_bug=True))
    # a .de32 with the flag set is compensated by the mapper; --compensate again is an error
    de32 = tmp_path / "a.de32"
    assert run(capsys, "asm", src, "-f", "framestore", "--compensate", "-o", de32)[0] == 0
    c = tmp_path / "c.png"
    assert run(capsys, "model", de32, "-o", c, "--raw", "--carry-bug", "--width", "64")[0] == 0
    np.testing.assert_array_equal(read_image(c), read_image(b))
    rc, _, err = run(capsys, "model", de32, "-o", c, "--compensate")
    assert rc == 1 and "already" in err


def test_plot(tmp_path, capsys):
    out = tmp_path / "p.png"
    rc, _, err = run(capsys, "plot", FIG25, "-o", out, "--window", "3")
    assert rc == 0 and out.stat().st_size > 5000 and "6 scanline(s)" in err
    rc, _, err = run(capsys, "plot", FIG25, "-o", out, "--line", "4", "--xlim", "0:64")
    assert rc == 0 and "1 scanline(s), columns 0..63" in err
    rc, _, err = run(capsys, "plot", FIG25, "-o", out, "--line", "6")
    assert rc == 1 and "lines 0..5" in err


def test_capacity(capsys):
    rc, out, err = run(capsys, "capacity")
    try:
        import diffengine.model.capacity  # noqa: F401
    except ImportError:
        assert rc == 1 and "not available" in err
    else:
        assert rc == 0 and out.strip()


def test_structural_level_is_clean(tmp_path, capsys):
    rc, _, err = run(capsys, "model", SCENES / "fig7_21a.cmd", "-o", tmp_path / "s.png",
                     "--level", "structural", "--width", "64")
    assert rc == 0 or "structural" in err


def test_progress_and_unterminated_warning(tmp_path, capsys):
    src = tmp_path / "many.cmd"
    src.write_text("Eval2 (0, 8, 1, 1);\nRefresh;\n" * 70 + "Eval1 (0, 1, 5)\n")
    rc, _, err = run(capsys, "model", src, "-o", tmp_path / "m.png", "--width", "16")
    assert rc == 0
    assert f"{src}:141: warning: 1 command(s) after the last Refresh" in err
    assert "64/70 lines" in err and "70/70 lines" in err
    assert read_image(tmp_path / "m.png").shape == (70, 16)


BAD_TEXT = [
    ("Eval1 (55, 16, 0.9375.0);\nRefresh;\n", ":1: "),
    ("Refresh;\nFoo (1);\n", ":2: "),
    ("Refresh;\nRefresh;\nEval2 (1, 2, 3);\n", ":3: "),
    ("Eval1 (5000, 1, 0);\n", ":1: "),
    ("Eval1 (0, 1, 4000);\n", ":1: "),
    ("Eval0 (0, 1, 1.5);\n", ":1: "),
    (".unit dac 9\n", ":1: "),
]


@pytest.mark.parametrize("sub", ["asm", "model", "plot", "disasm"])
@pytest.mark.parametrize("text,where", BAD_TEXT)
def test_bad_input_exit_status_and_location(tmp_path, capsys, sub, text, where):
    src = tmp_path / "bad.cmd"
    src.write_text(text)
    argv = [sub, src] + (["-o", tmp_path / "o.png"] if sub in ("model", "plot") else [])
    rc, _, err = run(capsys, *argv)
    assert rc != 0
    assert err.startswith(f"{src}{where}")


@pytest.mark.parametrize("blob,where", [
    (b"DE48\0\x01\0\0" + bytes(5), "byte 8"),
    (b"DE48\0\x01\0\0" + bytes.fromhex("444000000000"), "slot 0"),
    (b"DE32\0\x01\x07\0", "byte 6"),
    (b"\xff\xfe\x00garbage", "1"),
])
def test_bad_binary_inputs(tmp_path, capsys, blob, where):
    src = tmp_path / "bad.bin"
    src.write_bytes(blob)
    for argv in (["disasm", src], ["model", src, "-o", tmp_path / "o.png"]):
        rc, _, err = run(capsys, *argv)
        assert rc == 1 and err.startswith(f"{src}:{where}: "), err


def test_usage_errors(tmp_path, capsys):
    rc, _, err = run(capsys, "asm", tmp_path / "missing.cmd")
    assert rc == 1 and "missing.cmd" in err
    rc, _, err = run(capsys, "asm", FIG25, "--window", "2", "-o", tmp_path / "x")
    assert rc == 1 and "framestore" in err
    rc, _, err = run(capsys, "model", FIG25, "-o", tmp_path / "x.nosuchformat")
    assert rc == 1 and "x.nosuchformat" in err
    empty = tmp_path / "e.cmd"
    empty.write_text("# nothing\n")
    rc, _, err = run(capsys, "model", empty, "-o", tmp_path / "x.png")
    assert rc == 1 and "no complete scanline" in err
    with pytest.raises(SystemExit) as e:  # argparse: bad window value
        cli.main(["asm", str(FIG25), "-f", "framestore", "--window", "5"])
    assert e.value.code == 2


def test_console_script_no_traceback(tmp_path):
    bad = tmp_path / "bad.cmd"
    bad.write_text("Nop;\nEval1 (55, 16, 0.9375.0);\n")
    p = subprocess.run([sys.executable, "-m", "diffengine", "asm", str(bad)],
                       capture_output=True, text=True)
    assert p.returncode == 1
    assert p.stderr == f"{bad}:2: Eval1 I: not a number: '0.9375.0'\n"


def test_model_text_output_table_7_5(tmp_path, capsys):
    """`-o -` prints pixel rows: the Table 7.5 rows of docs/debugging.md."""
    from diffengine.cli import tree as cli
    src = tmp_path / "t75.cmd"
    src.write_text("Eval3 (0, 9, 0x000.000000, 0x000.000000, 0x000.800000);\nRefresh;\n")
    rows = {}
    for name, extra in (("good", []), ("bad", ["--carry-bug"]),
                        ("comp", ["--carry-bug", "--compensate"])):
        assert cli.main(["model", str(src), "--width", "9", "-o", "-", *extra]) == 0
        rows[name] = capsys.readouterr().out.split()
    assert rows["good"] == "0 0 0 1 3 5 7 10 14".split()
    assert rows["bad"] == "0 0 0 2 6 10 14 20 28".split()
    assert rows["comp"] == "0 0 0 0 2 4 6 10 14".split()


def test_encode_subcommand_is_wired(tmp_path):
    from diffengine.cli import tree as cli
    out = tmp_path / "r.cmd"
    assert cli.main(["encode", "/no/such/image.png", "-o", str(out)]) != 0


def test_compare_reports_outliers_and_fails_the_gate(tmp_path, capsys):
    """diffengine compare: a smooth ramp against itself passes; one pixel 0.25 of full
    scale off on the flat part is an outlier (exit 3, map written); a step edge that is
    off by as much is not (the reference is not smooth there)."""
    from diffengine.formats import frame
    ref = np.zeros((12, 16, 3), dtype=np.uint16)
    ref[:] = (np.arange(16) * 8 + 1000)[None, :, None]
    ref[:, 12:] = 3000                                   # an edge at column 12
    frame.write_png16(tmp_path / "ref.png", ref)
    frame.write_png16(tmp_path / "same.png", ref)
    rc, out, _ = run(capsys, "compare", tmp_path / "same.png", tmp_path / "ref.png")
    assert rc == 0 and "outliers" in out and ": 0" in out
    bad = ref.copy()
    bad[5, 4] += 1024                                    # flat neighbourhood
    bad[5, 12] -= 1024                                   # on the edge: not counted
    frame.write_png16(tmp_path / "bad.png", bad)
    m = tmp_path / "map.png"
    rc, out, _ = run(capsys, "compare", tmp_path / "bad.png", tmp_path / "ref.png", "--map", m)
    assert rc == commands.EXIT_GATE
    assert "x=4 y=5" in out and "x=12" not in out and m.is_file()
    assert "max 1024.0" in out
    rc, _, _ = run(capsys, "compare", tmp_path / "bad.png", tmp_path / "ref.png",
                   "--max-outliers", "1")
    assert rc == 0
    rc, _, err = run(capsys, "compare", tmp_path / "bad.png", tmp_path / "nope.png")
    assert rc == commands.EXIT_INPUT and "nope.png" in err


def test_reference_and_frame_bad_input_name_the_file_without_traceback(tmp_path, capsys):
    """The subcommands that were module mains (`python -m diffengine.reference/.frame`)
    report a bad file as `file[:line]: message` with exit 1, as the others do."""
    scene = tmp_path / "bad.scene"
    scene.write_text("camera 0 0 0\n")
    rc, _, err = run(capsys, "reference", scene, "-o", tmp_path / "x.png")
    assert rc == 1 and f"{scene}:1:" in err and "Traceback" not in err
    dcf = tmp_path / "bad.dcf"
    dcf.write_bytes(b"nope")
    rc, _, err = run(capsys, "frame", dcf, tmp_path / "x.png")
    assert rc == 1 and f"{dcf}: not a DCF1 frame file" in err
    rc, _, err = run(capsys, "frame", tmp_path / "missing.dcf", tmp_path / "x.png")
    assert rc == 1 and "missing.dcf: No such file" in err
