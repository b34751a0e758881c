"""Bad input files through the command lines name the file and the line (issue 17 item 5).

Each case writes a small scene (and its OBJ, animation or command file), spoils one thing
in it - a malformed OBJ, a camera whose eye is its look-at point, an unknown statement, a
file cut short, a file that is not there - and runs it through every command that reads
it: `yproc hsr/scan/read/anim`, and `diffengine reference/compare` (which read scenes
through `yproc read`), `diffengine asm/disasm/model` for command files. The message must
start with `FILE:LINE: ` (or `FILE: ` where no line exists: a file that cannot be opened
is named by the line that refers to it when there is one) and the status must be 1.
`diffengine sim --manifest` (make sim's TOML manifest) is held to the same rule.
test_obj_features.py holds the OBJ/MTL readers' individual messages; this file holds the
paths from the command line to them.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import yproc_common as yc

GOOD = ("screen 32 24\n"
        "camera eye 3 2 4 at 0 0 0 up 0 1 0 fov 50\n"
        "light 1 2 3 0.8\n"
        "material red 1 0.2 0.1\n"
        "obj m.obj material red\n")
OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def _spoil(text: str, old: str, new: str) -> str:
    assert old in text
    return text.replace(old, new)


# (name, files written into tmp_path, the scene to run, expected "file:line: message")
SCENE_CASES = [
    ("eye_is_at", {"s.scene": _spoil(GOOD, "eye 3 2 4", "eye 0 0 0"), "m.obj": OBJ},
     "s.scene:2: camera eye and at are the same point"),
    ("unknown_statement", {"s.scene": _spoil(GOOD, "light", "lihgt"), "m.obj": OBJ},
     "s.scene:3: unknown statement 'lihgt'"),
    ("scene_cut_short", {"s.scene": GOOD[:GOOD.index("0.8")], "m.obj": OBJ},
     "s.scene:3: 'light DX DY DZ I' or 'light DX DY DZ R G B' needs finite numbers"),
    ("malformed_obj", {"s.scene": GOOD, "m.obj": _spoil(OBJ, "v 0 1 0", "v 0 1 x")},
     "m.obj:3: bad or non-finite number 'x'"),
    ("obj_cut_short", {"s.scene": GOOD, "m.obj": OBJ[:-4]},
     "m.obj:4: face needs at least 3 vertices"),
    ("obj_missing", {"s.scene": GOOD},
     "s.scene:5: cannot read OBJ file"),
    ("scene_missing", {},
     "s.scene: cannot read"),
]


@pytest.fixture(scope="module")
def yproc():
    return yc.build_yproc()


def _write(tmp_path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return tmp_path / "s.scene"


def _first_line(stderr: str) -> str:
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    assert lines, "no message on stderr"
    return lines[-1]


@pytest.mark.parametrize("sub", ["hsr", "scan", "read"])
@pytest.mark.parametrize("name,files,msg", SCENE_CASES, ids=[c[0] for c in SCENE_CASES])
def test_yproc_names_file_and_line(yproc, tmp_path, sub, name, files, msg):
    scene = _write(tmp_path, files)
    args = {"hsr": ["hsr", scene], "scan": ["scan", scene, "-o", tmp_path / "out"],
            "read": ["read", scene, "-o", tmp_path / "s.json"]}[sub]
    r = yc.run(*args, ok=False)
    assert r.returncode == 1, r.stdout + r.stderr
    assert _first_line(r.stderr).startswith(f"{tmp_path}/{msg}"), r.stderr


@pytest.mark.parametrize("sub", ["reference", "compare"])
@pytest.mark.parametrize("name,files,msg", SCENE_CASES, ids=[c[0] for c in SCENE_CASES])
def test_diffengine_scene_readers_name_file_and_line(yproc, tmp_path, sub, name, files, msg):
    scene = _write(tmp_path, files)
    png = tmp_path / "x.png"
    args = (["reference", scene, "-o", png] if sub == "reference" else ["compare", png, scene])
    if sub == "compare":   # a picture to compare: any 16-bit PNG of the scene's size
        from diffengine.formats import frame
        import numpy as np
        frame.write_png16(png, np.zeros((24, 32, 3), dtype=np.uint16))
    r = subprocess.run([sys.executable, "-m", "diffengine", *map(str, args)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stdout + r.stderr
    assert f"{tmp_path}/{msg}" in _first_line(r.stderr), r.stderr


ANIM_CASES = [
    ("scene_missing", "scene nothere.scene\nframes 2\n",
     "a.anim:1: cannot read scene file"),
    ("scene_eye_is_at", "scene bad.scene\nframes 2\n",
     "bad.scene:2: camera eye and at are the same point"),
    ("unknown_statement", "scene s.scene\nframez 2\n", "a.anim:2: unknown statement 'framez'"),
    ("cut_short", "scene s.scene\nframes 4\nmove 1 1 0", "a.anim:3: expected 'move OBJ DX DY DZ"),
    ("no_such_object", "scene s.scene\nframes 4\nmove 7 1 0 0 from 0 to 3\n",
     "a.anim:3: object 7 does not exist"),
]


@pytest.mark.parametrize("name,anim,msg", ANIM_CASES, ids=[c[0] for c in ANIM_CASES])
def test_yproc_anim_names_file_and_line(yproc, tmp_path, name, anim, msg):
    _write(tmp_path, {"s.scene": GOOD, "m.obj": OBJ,
                      "bad.scene": _spoil(GOOD, "eye 3 2 4", "eye 0 0 0")})
    (tmp_path / "a.anim").write_text(anim)
    r = yc.run("anim", tmp_path / "a.anim", "-o", tmp_path / "out", ok=False)
    assert r.returncode == 1, r.stdout + r.stderr
    assert _first_line(r.stderr).startswith(f"{tmp_path}/{msg}"), r.stderr


def test_diffengine_command_files_name_file_and_line(tmp_path):
    """A malformed command file, a stream cut short, a missing file (asm, disasm, model)."""
    (tmp_path / "bad.cmd").write_text("SetI (0, 1.0);\nBogus (1, 2);\n")
    (tmp_path / "cut.cmd").write_text("SetI (0, 0x800.000000")
    good = tmp_path / "good.de48"
    (tmp_path / "good.cmd").write_text("SetI (0, 1.0);\nRefresh;\n")

    def de(*args):
        return subprocess.run([sys.executable, "-m", "diffengine", *map(str, args)],
                              capture_output=True, text=True, timeout=300)

    assert de("asm", tmp_path / "good.cmd", "-o", good).returncode == 0
    (tmp_path / "cut.de48").write_bytes(good.read_bytes()[:-1])
    for args, msg in [(("asm", tmp_path / "bad.cmd", "-o", tmp_path / "x.de48"),
                       f"{tmp_path}/bad.cmd:2: unknown mnemonic 'Bogus'"),
                      (("model", tmp_path / "bad.cmd", "-o", tmp_path / "x.png"),
                       f"{tmp_path}/bad.cmd:2: unknown mnemonic 'Bogus'"),
                      (("asm", tmp_path / "cut.cmd", "-o", tmp_path / "x.de48"),
                       f"{tmp_path}/cut.cmd:1: cannot parse statement"),
                      (("disasm", tmp_path / "cut.de48"), f"{tmp_path}/cut.de48:byte "),
                      (("model", tmp_path / "cut.de48", "-o", tmp_path / "x.png"),
                       f"{tmp_path}/cut.de48:byte "),
                      (("disasm", tmp_path / "none.de48"), f"{tmp_path}/none.de48: No such file")]:
        r = de(*args)
        assert r.returncode == 1, (args, r.stderr)
        assert msg in _first_line(r.stderr), (args, r.stderr)


MANIFESTS = [
    ("toml_syntax", '[[file]]\npaths = ["sw/scenes/fig7_25.cmd"]\nchips [2]\n',
     "m.toml:3: Expected '=' after a key"),
    ("missing_field", '# c\n[[file]]\npaths = ["sw/scenes/fig7_25.cmd"]\nchips = [2]\n\n[[random]]\n'
     'seeds = [1]\n',
     "m.toml:6: [[random]] has no 'chips'"),
    ("no_match", '[[file]]\npaths = ["sw/scenes/fig7_25.cmd"]\nchips = [2]\n[[file]]\n'
     'paths = ["sw/scenes/nothere_*.cmd"]\nchips = [2]\n',
     "m.toml:4: [[file]] 'sw/scenes/nothere_*.cmd' matches no file"),
    ("bad_tier", '[[carry]]\nseeds = [1]\nchips = [2]\ntier = "weekly"\n',
     "m.toml:1: [[carry]] tier 'weekly' not in"),
]


@pytest.mark.parametrize("name,text,msg", MANIFESTS, ids=[m[0] for m in MANIFESTS])
def test_sim_manifest_names_file_and_line(tmp_path, name, text, msg):
    """`diffengine sim --manifest` (make sim's TOML): an error names the file and line."""
    (tmp_path / "m.toml").write_text(text)
    r = subprocess.run([sys.executable, "-m", "diffengine", "sim", "--manifest",
                        str(tmp_path / "m.toml"), "--list", "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stdout + r.stderr
    assert _first_line(r.stderr).startswith(f"sim: {tmp_path}/{msg}"), r.stderr


def test_sim_durations_file_names_file_and_line(tmp_path):
    """A corrupt durations file (--shard's recorded case times) names file and line."""
    (tmp_path / "d.json").write_text('{"seconds": {\n  "a": 1.0,\n  "b": \n}}\n')
    r = subprocess.run([sys.executable, "-m", "diffengine", "sim", "--tier", "smoke",
                        "--shard", "1/2", "--durations", str(tmp_path / "d.json"), "--list",
                        "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 1, r.stdout + r.stderr
    assert _first_line(r.stderr).startswith(f"sim: {tmp_path}/d.json:4: Expecting value"), r.stderr
