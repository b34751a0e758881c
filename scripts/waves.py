#!/usr/bin/env python3
"""make waves TEST=<name> [PE=<p>] [BUG=0|1]: run one cocotb test with an FST dump and
write a GTKWave save file that shows, for PE p, the instruction identifier, the three
skewed data blocks, the block carries, registers A-D (as blocks) and the flags.

Tests are looked up by name in tb/de_pe (a chain of 9 PEs) and tb/de_array (2 chips).
Output: out/waves/<test>_bug<b>.fst and out/waves/<test>_bug<b>_pe<p>.gtkw; open with
    gtkwave out/waves/<test>_bug<b>_pe<p>.gtkw
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "out" / "waves"


def find_test(name: str) -> str:
    for bench in ("de_pe", "de_array"):
        text = (REPO / "tb" / bench / f"test_{bench}.py").read_text()
        if re.search(rf"^async def {re.escape(name)}\(", text, re.M):
            return bench
    sys.exit(f"waves: no cocotb test named {name!r} in tb/de_pe or tb/de_array")


def pe_scope(bench: str, pe: int) -> str:
    """FST scope of PE `pe` as Verilator writes it."""
    if bench == "de_pe":
        return f"de_pe_chain.g_pe[{pe}].u_pe"
    chip, i = divmod(pe, 9)
    return f"de_array.g_chip[{chip}].u_chip.u_core.g_pe[{i}].u_pe"


def vcd_vars(vcd: str):
    """(scope list, $var words) for every variable in a VCD header."""
    scopes = []
    for line in vcd.splitlines():
        w = line.split()
        if not w:
            continue
        if w[0] == "$scope":
            scopes.append(w[2])
        elif w[0] == "$upscope":
            scopes.pop()
        elif w[0] == "$var":
            yield list(scopes), w
        elif w[0] == "$enddefinitions":
            return


def fst_signals(fst: Path) -> list[str]:
    """Every signal in the dump as GTKWave names it: scope.path.name[range]."""
    out = subprocess.run(["fst2vcd", str(fst)], capture_output=True, text=True,
                         check=True).stdout
    names = []
    for scopes, w in vcd_vars(out):
        rng = w[5] if len(w) > 6 and w[5].startswith("[") else ""
        names.append(".".join(scopes + [w[4]]) + rng)
    return names


def gtkw(fst: Path, bench: str, pe: int) -> str:
    s = pe_scope(bench, pe) + "."
    sigs = [n for n in fst_signals(fst) if n.startswith(s)]

    def pick(*patterns: str) -> list[str]:
        got = []
        for pat in patterns:
            rx = re.compile(re.escape(s) + pat + r"(\[\d+:\d+\])?$")
            got += sorted((n for n in sigs if rx.match(n)), reverse=True)
        return got

    groups = {
        f"PE {pe}: instruction identifier and skewed data in": pick("id_i", "data_i"),
        "the three 12-bit blocks in (block j = slot j cycles older)": pick(
            r"in_blk\.in_blk\[\d\]", r"in_blk\[\d\]"),
        "control pipeline: stage-1/2 identifiers, decisions": pick(
            "id_q", "id2_q", "act_q", "act1_q", "act2_q", "prot1_q", "prot2_q"),
        "block carries: data adder c1 (0->1), c2 (1->2); ACC accc2, accc3": pick(
            "c1_q", "c2_q", "accen2_q", "accc2_q", "accen3_q", "accc3_q"),
        "sums passed to the next PE (skewed blocks), pixel": pick(
            r"out_q\.out_q\[\d\]|out_q\[\d\]", "pix_valid_o", "pix_o"),
        "registers A-D, blocks [2]=integer [1] [0]": pick(
            *[rf"{r}_q\.{r}_q\[\d\]|{r}_q\[\d\]" for r in "abcd"]),
        "flags": pick("pa_q", "pb_q", "pc_q", "dis_q", "lock_q", "accm_q"),
    }
    missing = [t for t, v in groups.items() if not v]
    if missing:
        sys.exit(f"waves: no signals found in {fst} for: {missing}")
    lines = [f'[dumpfile] "{fst}"', "[timestart] 0", "[size] 1800 1000",
             "[sst_expanded] 0"]
    for title, names in groups.items():
        lines.append(f"-{title}")
        for n in names:
            lines.append("@22" if n.endswith("]") else "@28")  # hex for vectors
            lines.append(n)
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("test")
    ap.add_argument("--pe", type=int, default=3)
    ap.add_argument("--bug", type=int, default=None,
                    help="carry bug 0/1 (default: 1 for table_7_5*, else 0)")
    a = ap.parse_args(argv)
    bench = find_test(a.test)
    bug = a.bug if a.bug is not None else int(a.test.startswith("table_7_5"))
    sys.path.insert(0, str(REPO / "tb"))
    from cocotb_tools.runner import get_runner
    from filelist import files   # the FuseSoC cores' lists (scripts/filelist.py)

    here = REPO / "tb" / bench
    if bench == "de_pe":
        srcs = files("diffengine:tb:de_pe")
        top, params = "de_pe_chain", {"N": 9, "CarryBug": bug}
        env = {"DE_CARRY_BUG": str(bug), "DE_N_PE": "9"}
    else:
        srcs = files("array", "sim")
        top, params = "de_array", {"NumChips": 2, "CarryBug": bug}
        env = {"DE_CARRY_BUG": str(bug), "DE_FAULTY": "0"}
    build = here / f"sim_build_waves_bug{bug}"
    env["PYTHONPATH"] = os.pathsep.join([str(here), str(REPO / "tb"), str(REPO / "sw")])
    runner = get_runner("verilator")
    runner.build(sources=[str(p) for p in srcs], hdl_toplevel=top, parameters=params,
                 build_dir=build, waves=True,
                 build_args=["-Wno-fatal", "--trace-fst", "--trace-structs",
                             "-MAKEFLAGS", "CFG_CXXFLAGS_PCH_I=-include"])
    OUT.mkdir(parents=True, exist_ok=True)
    fst = OUT / f"{a.test}_bug{bug}.fst"
    runner.test(test_module=f"test_{bench}", hdl_toplevel=top, build_dir=build,
                test_dir=here, testcase=a.test, extra_env=env, waves=True,
                test_args=["--trace-file", str(fst)])
    if not fst.exists():
        for cand in (build / "dump.fst", here / "dump.fst"):
            if cand.exists():
                shutil.move(cand, fst)
    if not fst.exists():
        sys.exit("waves: the simulation wrote no FST")
    save = OUT / f"{a.test}_bug{bug}_pe{a.pe}.gtkw"
    save.write_text(gtkw(fst, bench, a.pe))
    print(f"waves: {fst} ({fst.stat().st_size} bytes)\nwaves: {save}  ->  gtkwave {save}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
