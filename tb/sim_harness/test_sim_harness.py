"""The C++ array harness's inspection tools (docs/simulation.md) on 1-2 chip arrays:
windowed FST + GTKWave save file, per-PE trace CSV against the structural model,
breakpoints, `diffengine trace --compare` on the Table 7.5 carry bug, the build cache,
threaded builds and .cmd input.

Builds used (cached in sim/build): 2 chips trace (bug 0 and 1), 2 chips fast (1 and 2
threads). Random streams print their seed; SEED=<n> replays.
"""
from __future__ import annotations

import os
import random
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "sw"))
sys.path.insert(0, str(REPO / "scripts"))

from diffengine.formats import binfmt  # noqa: E402
from diffengine.model import functional, structural
from diffengine.rtl import harness, trace
from diffengine import isa

CHIPS = 2
N_PE = 9 * CHIPS
T75 = "Eval3 (0, 9, 0x000.000000, 0x000.000000, 0x000.800000);\nRefresh;\n"


@pytest.fixture(scope="module")
def seed():
    s = int(os.environ.get("SEED", random.randrange(1 << 31)))
    print(f"SEED={s} (replay: SEED={s})", file=sys.stderr)
    return s


@pytest.fixture(scope="module")
def stream(seed):
    """At least four random lines for an 18-PE array (spans cross the chip boundary):
    four chunks, each ending with a Refresh."""
    rng = np.random.default_rng(seed)
    cmds = [c for _ in range(4)
            for c in structural.random_commands(rng, N_PE, 18, refresh_every=15)]
    return cmds, isa.serialise(cmds)


def harness_exe(bug=0, trace_build=True, threads=1) -> Path:
    return harness.build(CHIPS, bool(bug), threads, trace=trace_build)


def stream_on_disk(stream, tmp_path):
    """The trace build, the random stream as tmp_path/in.de48 and its timing."""
    _, slots = stream
    src = tmp_path / "in.de48"
    src.write_bytes(binfmt.encode_de48(slots))
    return harness_exe(), src, trace.Timing.of(slots, CHIPS)


# A harness run here takes seconds; one that has not ended after this long hangs (an
# error path once printed its message and then hung in a destructor for 36 minutes).
RUN_TIMEOUT_S = 600


def run(exe, src, dst, *args, rc=0) -> subprocess.CompletedProcess:
    res = subprocess.run([str(exe), str(src), str(dst), *map(str, args)],
                         capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
    assert res.returncode == rc, res.stderr + res.stdout
    return res


def fst_names_and_times(fst: Path) -> tuple[list[str], list[int]]:
    """Signal names as GTKWave shows them (scripts/waves.py's reader) and the time stamps."""
    from waves import fst_signals

    out = subprocess.run(["fst2vcd", str(fst)], capture_output=True, text=True,
                         check=True).stdout
    body = out[out.index("$enddefinitions"):]
    times = [int(ln[1:]) for ln in body.splitlines() if ln.startswith("#")]
    return fst_signals(fst), times


def have_fst2vcd() -> bool:
    if shutil.which("fst2vcd") is None:
        subprocess.run(["bash", str(REPO / "scripts" / "ensure_fst.sh")], check=False)
    return shutil.which("fst2vcd") is not None


def test_fst_window_is_small_and_exact(stream, tmp_path):
    exe, src, t = stream_on_disk(stream, tmp_path)
    assert len(t.refresh_at) >= 4, "the stream should have a few lines"
    lo, hi = t.line_window(1)
    res = run(exe, src, tmp_path / "a.depx", "--fst", tmp_path / "line.fst", "--line", 1,
              "--col", 10)
    m = re.search(r"fst \S+ cycles (\d+)\.\.(\d+) \(time (\d+)\.\.(\d+) ns\), PEs (\d+)\.\.(\d+)",
                  res.stderr)
    assert m, res.stderr
    assert (int(m[1]), int(m[2])) == (lo, hi) == (t.refresh_at[0],
                                                  t.refresh_at[1] + CHIPS + 3 + N_PE - 1)
    assert (int(m[5]), int(m[6])) == (9, 11)
    run(exe, src, tmp_path / "b.depx", "--fst", tmp_path / "full.fst", "--col", 10)
    one, full = (tmp_path / "line.fst").stat().st_size, (tmp_path / "full.fst").stat().st_size
    assert one < full, (one, full)
    # The frame is unchanged by dumping.
    assert np.array_equal(harness.read_depx(tmp_path / "a.depx"),
                          harness.read_depx(tmp_path / "b.depx"))
    gtkw = (tmp_path / "line.gtkw").read_text()
    assert f'[dumpfile] "{tmp_path / "line.fst"}"' in gtkw
    wanted = [ln for ln in gtkw.splitlines() if ln.startswith("TOP.")]
    for pe in (9, 10, 11):
        assert any(f"g_chip[1].u_chip.u_core.g_pe[{pe - 9}].u_pe.c2_q" == w[-len(
            f"g_chip[1].u_chip.u_core.g_pe[{pe - 9}].u_pe.c2_q"):] for w in wanted), pe
    assert have_fst2vcd(), "fst2vcd (gtkwave) is needed: scripts/ensure_fst.sh"
    names, times = fst_names_and_times(tmp_path / "line.fst")
    missing = [w for w in wanted if w not in names]
    assert not missing, f"the save file names signals the dump lacks: {missing[:5]}"
    assert min(times) == 10 * lo and max(times) == 10 * hi + 10, (min(times), max(times))
    # Only the chip of the shown PEs is dumped (plus the top and array levels).
    assert not any(".g_chip[0]." in n for n in names)
    assert any(".g_chip[1].u_chip.u_core.g_pe[0].u_pe.a_q" in n for n in names)


def test_trace_csv_equals_structural_model(stream, tmp_path):
    _, slots = stream
    pes = [0, 1, 8, 9, 17]
    got = trace.rtl_trace(slots, CHIPS, False, pes, 0, 10**9)
    want = trace.model_trace(slots, CHIPS, False, pes, 0, 10**9)
    assert len(got.rows) == len(trace.Timing.of(slots, CHIPS).seq) * len(pes)
    assert trace.first_difference(got.rows, want.rows) is None
    assert got.rows == want.rows
    # Something happened in the traced PEs (not a trace of zeros).
    assert any(r.split(",")[7] != "000000000" for r in got.rows)


def test_breakpoints_stop_at_the_right_cycle(stream, tmp_path):
    _, slots = stream
    exe, src, t = stream_on_disk(stream, tmp_path)

    def stopped(res) -> tuple[int, list[str]]:
        lines = res.stdout.splitlines()
        m = re.match(r"break: cycle (\d+), line (\d+)", lines[0])
        assert m, res.stdout
        assert lines[1] == ",".join(trace.COLUMNS)
        return int(m[1]), lines[2:]

    model = trace.model_trace(slots, CHIPS, False, list(range(N_PE)), 0, 10**9).rows
    by_key = {tuple(r.split(",")[:2]): r for r in model}
    # At a cycle.
    c, rows = stopped(run(exe, src, tmp_path / "o", "--break-cycle", 57, "--trace-pes",
                          "8-10", rc=3))
    assert c == 57 and rows == [by_key[("57", str(p))] for p in (8, 9, 10)]
    # At a scanline: its first instruction is on id_i. A dump stops there too, with
    # its save file.
    c, _ = stopped(run(exe, src, tmp_path / "o", "--break-line", 2, "--fst",
                       tmp_path / "b.fst", rc=3))
    assert c == t.refresh_at[1] + 1
    assert (tmp_path / "b.fst").stat().st_size > 0 and (tmp_path / "b.gtkw").exists()
    # When PE 10 (chip 1) receives the first ACC: slot k reaches PE p in cycle k + p + chip.
    k = next(i for i, (ident, _) in enumerate(t.seq) if ident == isa.ACC)
    res = run(exe, src, tmp_path / "o", "--break-pe", 10, "--break-op", "acc", rc=3)
    c, rows = stopped(res)
    assert c == k + 10 + 1
    assert f"PE 10 (column 10) receives identifier {isa.ACC:#05x}" in res.stdout
    assert [r.split(",")[1] for r in rows] == ["9", "10", "11"]
    assert rows[1].split(",")[2] == "200"
    # The same breakpoint from the model engine prints the same.
    m = trace.model_trace(slots, CHIPS, False, [], 0, -1, show=[9, 10, 11], break_pe=10,
                          break_op=isa.ACC)
    assert m.stop.splitlines() == res.stdout.splitlines()[:5]
    # Numeric identifiers work too, and the op table is isa.LUT.
    assert stopped(run(exe, src, tmp_path / "o", "--break-pe", 10, "--break-op", f"{isa.ACC:#05x}",
                       rc=3))[0] == c
    listed = run(exe, src, tmp_path / "o", "--list-ops").stdout.split()
    assert dict(zip(listed[::2], (int(v, 16) for v in listed[1::2]))) == {
        name: ident for name, ident, _ in isa.LUT}


def test_compare_finds_the_table_7_5_carry_fault(tmp_path):
    cmd = tmp_path / "t75.cmd"
    cmd.write_text(T75)
    env = dict(os.environ, PYTHONPATH=str(REPO / "sw"))
    base = [sys.executable, "-c", "import sys; from diffengine.cli.tree import main; "
            "sys.exit(main(sys.argv[1:]))", "trace", str(cmd), "--chips", str(CHIPS),
            "--compare"]
    bad = subprocess.run(base + ["--bug", "1", "--model-bug", "0"], capture_output=True,
                         text=True, env=env)
    assert bad.returncode == trace.EXIT_DIFFER, bad.stderr
    # Table 7.5: PE 1's dI slot (slot 2 of the command, identifier 4b4) adds
    # 000.800000 + 000.800000; block 1 carries out (c2_q in its stage 2, cycle 2+1+2 = 5)
    # and the sum it passes on is wrong from the next cycle: out block 2 = 002, not 001.
    assert "first difference: cycle 6, PE 1 (chip 0), out block 2 (bits 35:24): " \
           "RTL 002, model 001" in bad.stdout, bad.stdout
    for bug in ("0", "1"):
        same = subprocess.run(base + ["--bug", bug], capture_output=True, text=True, env=env)
        assert same.returncode == 0 and same.stdout.rstrip().endswith(": identical"), \
            same.stdout + same.stderr
    # The text trace shows the carry and the wrong block in PE 1.
    txt = subprocess.run(base[:-1] + ["--bug", "1", "--pes", "1", "--from", "5", "--to", "6"],
                         capture_output=True, text=True, env=env)
    lines = txt.stdout.splitlines()
    assert len(lines) == 2 and "carry c2" in lines[0] and "out 002.800000" in lines[1], txt.stdout


def test_second_make_is_a_noop():
    harness_exe()  # built (or already there)
    exe = harness_exe()
    before = exe.stat().st_mtime_ns
    out = subprocess.run(["make", "-C", str(REPO / "sim"), "harness", f"CHIPS={CHIPS}",
                          "TRACE=1"], capture_output=True, text=True, check=True).stdout
    assert "sim: built" not in out and exe.stat().st_mtime_ns == before, out


def test_threads_build_gives_identical_output(stream, tmp_path):
    cmds, slots = stream
    f1, _ = harness.run(None, CHIPS, slots=slots, threads=1)
    f2, rep = harness.run(None, CHIPS, slots=slots, threads=2)
    assert (REPO / "sim" / "build" / harness.tag(CHIPS, False, 2, False) / "Vde_array").exists()
    assert np.array_equal(f1, f2)
    assert np.array_equal(f1, functional.render(cmds, N_PE))


def test_cmd_input_is_assembled(tmp_path):
    cmd = tmp_path / "t75.cmd"
    cmd.write_text(T75)
    exe = harness.build(CHIPS, False, 1, trace=False)
    run(exe, cmd, tmp_path / "a.depx")
    assert harness.read_depx(tmp_path / "a.depx")[0, :9].tolist() == [0, 0, 0, 1, 3, 5, 7, 10, 14]
    bad = tmp_path / "bad.cmd"
    bad.write_text("Frobnicate (1);\n")
    res = run(exe, bad, tmp_path / "b.depx", rc=1)
    assert "diffengine asm" in res.stderr and "bad.cmd" in res.stderr


def _vcd_body(fst: Path) -> str:
    out = subprocess.run(["fst2vcd", str(fst)], capture_output=True, text=True,
                         check=True, stdin=subprocess.DEVNULL).stdout
    return out[out.index("$enddefinitions"):]  # without the header's date


@pytest.mark.parametrize("bug", [0, 1])
def test_fast_forward_hands_over_exactly(seed, tmp_path, bug):
    """The trace build runs the cycles before its window in the fast array and hands the
    state to the traced flat model (docs/simulation.md 7.5): the window's FST, the trace
    CSV, the frame and a line breakpoint are identical to a run that simulates every cycle
    in the traced model (--no-fast-forward). Many lines, so the hand-over is deep in the
    stream and spans cross the chip boundary."""
    from diffengine.regress import randgen

    assert have_fst2vcd(), "fst2vcd (gtkwave) is needed: scripts/ensure_fst.sh"
    cmds = randgen.stream(seed, 500, N_PE, (1, 40))
    src = tmp_path / "s.de48"
    src.write_bytes(binfmt.encode_de48(isa.serialise(cmds)))
    lines = len(isa.split_lines(cmds))
    line = max(2, lines * 2 // 3)
    exe = harness_exe(bug)
    out = {}
    for mode, extra in (("ff", []), ("full", ["--no-fast-forward"])):
        fst, csv, frame = (tmp_path / f"{mode}.fst", tmp_path / f"{mode}.csv",
                           tmp_path / f"{mode}.depx")
        res = run(exe, src, frame, "--line", line, "--fst", fst, "--col", 9,
                  "--trace-pes", "7-10", "--trace-csv", csv, *extra)
        brk = run(exe, src, tmp_path / f"{mode}_b.depx", "--break-line", line - 1, *extra,
                  rc=3)
        out[mode] = (res.stderr, _vcd_body(fst), csv.read_text(), frame.read_bytes(),
                     brk.stdout, brk.stderr)
    assert "fast-forward" in out["ff"][0] and "fast-forward" not in out["full"][0]
    assert "after the window" in out["ff"][0]  # and back to the fast array for the rest
    assert "fast-forward" in out["ff"][5]
    assert out["ff"][1] == out["full"][1], f"seed {seed}: window FST differs"
    assert out["ff"][2] == out["full"][2], f"seed {seed}: trace CSV differs"
    assert out["ff"][3] == out["full"][3], f"seed {seed}: frame differs"
    assert out["ff"][4] == out["full"][4], f"seed {seed}: breakpoint print-out differs"
    assert len(out["ff"][2].splitlines()) > 4 * 10
