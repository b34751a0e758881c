"""`make waves` and the walk-through of docs/debugging.md, as written.

Runs scripts/waves.py exactly as `make waves TEST=table_7_5 PE=1 [BUG=0]` does, then
reads the FST back (fst2vcd) and asserts what docs/debugging.md §3 reads off it: in PE 1
the registered block-1 carry c2_q goes high, and block 2 of the sum passed on, out_q[2],
is 002 with the carry bug and 001 with the correct adder. Also checks that the GTKWave
save file holds the identifier, the three skewed blocks, the carries and A-D of PE 1.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _vcd_values(fst: Path, scope: str) -> dict[str, set[int]]:
    """Every value each signal directly in `scope` (dotted) takes, from fst2vcd."""
    vcd = subprocess.run(["fst2vcd", str(fst)], capture_output=True, text=True, check=True).stdout
    sys.path.insert(0, str(REPO / "scripts"))
    from waves import vcd_vars

    ids, vals = {}, {}
    for scopes, w in vcd_vars(vcd):
        if ".".join(scopes).endswith(scope):
            name = w[4] + (w[5] if len(w) > 6 and w[5].startswith("[") and ":" not in w[5] else "")
            ids.setdefault(w[3], []).append(name)
        elif ".".join(scopes[:-1]).endswith(scope):
            # unpacked arrays / structs: one sub-scope per element (out_q -> out_q[2])
            ids.setdefault(w[3], []).append(f"{scopes[-1]}.{w[4]}")
    lines = iter(vcd.split("$enddefinitions", 1)[1].splitlines())
    for line in lines:
        if not line or line[0] in "#$":
            continue
        if line[0] == "b":
            v, code = line[1:].split()
        else:
            v, code = line[0], line[1:]
        if code in ids and set(v) <= {"0", "1"}:
            for n in ids[code]:
                vals.setdefault(n, set()).add(int(v, 2))
    return vals


def _waves(bug: int) -> tuple[Path, Path]:
    env = dict(os.environ)
    res = subprocess.run([sys.executable, str(REPO / "scripts" / "waves.py"), "table_7_5",
                          "--pe", "1", "--bug", str(bug)], cwd=REPO, env=env,
                         capture_output=True, text=True)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    out = REPO / "out" / "waves"
    return out / f"table_7_5_bug{bug}.fst", out / f"table_7_5_bug{bug}_pe1.gtkw"


@pytest.fixture(scope="module", autouse=True)
def fst_tools():
    subprocess.run(["bash", str(REPO / "scripts" / "ensure_fst.sh")], check=False)


@pytest.mark.parametrize("bug,block2", [(1, 0x002), (0, 0x001)])
def test_make_waves_shows_the_carry_fault(bug, block2):
    fst, gtkw = _waves(bug)
    assert fst.stat().st_size > 0
    save = gtkw.read_text()
    assert f'[dumpfile] "{fst}"' in save
    for sig in ("id_i", "in_blk", "c1_q", "c2_q", "a_q", "b_q", "c_q", "d_q", "out_q"):
        assert f"g_pe[1].u_pe.{sig}" in save, sig
    vals = _vcd_values(fst, "g_pe[1].u_pe")
    c2 = [v for n, v in vals.items() if n.split(".")[-1].startswith("c2_q")]
    assert c2 and any(1 in v for v in c2), "c2_q never high in PE 1"
    blk2 = [v for n, v in vals.items() if n.replace("out_q.out_q", "out_q").endswith("out_q[2]")]
    assert blk2, f"no out_q[2] in PE 1: {sorted(vals)}"
    seen = set().union(*blk2)
    # the word PE 1 passes on after the dI slot: 002.000000 with the fault, else 001.000000
    assert block2 in seen and (0x002 in seen) == bool(bug), sorted(seen)
