"""`make sim`: the RTL regression (docs/regression.md).

Every case of sim/regress/manifest.toml (command files, the seed's figures, random
streams from recorded seeds, long spans across the 12-bit carry boundaries, spans across
chip boundaries, scenes from `yproc`) is played through the Verilated array by the plain
C++ harness (sim/harness: no Python in the clock loop), and the frame must equal the
golden model (functional.py) bit for bit. Cases marked `bug_check` run a second time on
the carry-bug build, where they must FAIL: that proves the regression can fail, and the
report shows why it failed.

    diffengine sim [--tier smoke|full|nightly] [-j N] [-k TEXT] [--out DIR] [--shard K/N]
    diffengine sim --merge DIR... [--out DIR]

Builds: one per (chip count, carry bug), made before the runs start, reused by all runs.
Outputs in --out (default sim/out/): report.html (self-contained), junit.xml, and per case
cases/<name>/ (stream.cmd, stream.de48, rtl.txt, and on a failure the windowed FST of the
first bad line with its .gtkw save file). Exit status 0 when every case did what it was
expected to do, 1 otherwise.

--shard K/N runs the K-th of N shards, balanced on the durations recorded in
sim/regress/durations.json (greedy longest first), into OUT/shard-K-of-N/; --merge joins
the shard folders into one report.html and junit.xml, and exits 2 if a case is missing or
ran twice (docs/regression.md, "Shards and CI matrices").
"""
from __future__ import annotations

import argparse
import fnmatch
import sys
from pathlib import Path

from .. import REPO
from .cases import MANIFEST, OUT, TIERS, ManifestError, load_manifest
from .merge import is_complete, record_run, merge_main, save_frames, write_outputs
from .run import run
from .shards import RECORDING_TIERS, assign_shards, estimates, load_durations, parse_shard, shard_dir


def _shard_arg(text: str) -> tuple[int, int] | None:
    """--shard K/N; an empty value (make sim SHARD=) means no shard."""
    if not text.strip():
        return None
    try:
        return parse_shard(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def configure(ap) -> None:
    """The arguments of this subcommand (the `diffengine` tree calls this)."""
    ap.add_argument("--tier", choices=TIERS, default="full")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("-k", dest="pattern", help="only cases whose name matches this glob/text")
    ap.add_argument("--manifest", type=Path, default=MANIFEST)
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--no-waves", action="store_true", help="no FST on failures")
    ap.add_argument("--no-bug-checks", action="store_true",
                    help="skip the expected-failure runs on the carry-bug build")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--shard", metavar="K/N", type=_shard_arg,
                    help="run only the K-th of N duration-balanced shards (K = 1..N); "
                    "outputs go to OUT/shard-K-of-N/")
    ap.add_argument("--merge", nargs="+", type=Path, metavar="DIR",
                    help="join the shard folders DIR... into one report in OUT (nothing "
                    "runs); exit 2 if a case is missing or ran twice")
    ap.add_argument("--durations", type=Path, default=None,
                    help="recorded case durations (default: durations.json next to the "
                    "manifest)")
    ap.add_argument("--record-durations", action=argparse.BooleanOptionalAction,
                    default=None, help="write the measured durations into the durations "
                    "file (default: only for complete full/nightly runs and their merge)")
    ap.set_defaults(func=command)


def command(a) -> int:
    durations = a.durations or Path(a.manifest).parent / "durations.json"
    if a.merge:
        return merge_main(a.merge, a.out, a.durations, a.record_durations)
    shard = a.shard
    try:
        cases = load_manifest(a.manifest, a.tier)
    except ManifestError as e:
        print(f"sim: {e}", file=sys.stderr)
        return 1
    if a.pattern:
        cases = [c for c in cases if a.pattern in c.name or fnmatch.fnmatch(c.name, a.pattern)]
    if a.no_bug_checks:
        cases = [c for c in cases if not c.bug]
    selected = [c.name for c in cases]
    out = a.out
    if shard:
        k, n = shard
        try:
            recorded = load_durations(durations)
        except ValueError as e:
            print(f"sim: {e}", file=sys.stderr)
            return 1
        cases = assign_shards(cases, n, recorded)[k - 1]
        out = shard_dir(a.out, k, n)
        est = estimates(cases, recorded)
        print(f"sim: shard {k}/{n}: {len(cases)} of {len(selected)} cases, estimated "
              f"{sum(est.values()):.1f} s ({sum(c.name in recorded for c in cases)} with a "
              f"recorded duration, {durations.name}); outputs in {out}", flush=True)
    if a.list:
        for c in cases:
            print(f"{c.name:32s} {c.chips:3d} chips  expect {c.expect}  {c.source}")
        return 0
    if not cases and not shard:
        print("sim: no cases selected", file=sys.stderr)
        return 1
    mpath = Path(a.manifest).resolve()
    meta = {"manifest": mpath.relative_to(REPO).as_posix() if mpath.is_relative_to(REPO)
            else str(mpath), "pattern": a.pattern,
            "no_bug_checks": a.no_bug_checks, "selected": selected,
            "shard": list(shard) if shard else [1, 1]}
    if cases:
        results, secs = run(cases, out, a.jobs, not a.no_waves, a.tier,
                            log=lambda m: print(m, flush=True))
    else:   # more shards than cases: an empty shard is a success with empty reports
        results, secs = {}, 0.0
    save_frames(out, cases, results)
    ok = write_outputs(out, cases, results, a.tier, secs, meta,
                       suite_name=f"sim-regress-{a.tier}-shard-{shard[0]}-of-{shard[1]}"
                       if shard else None)
    if a.record_durations or (a.record_durations is None and not shard and
                              is_complete(meta) and a.tier in RECORDING_TIERS):
        record_run(durations, a.manifest, cases, results)
    what = f"{a.tier} tier" + (f", shard {shard[0]}/{shard[1]}" if shard else "")
    print(f"sim: {what}, {len(cases)} cases in {secs:.1f} s: "
          f"{'OK' if ok else 'FAILED'}; report {out / 'report.html'}, junit {out / 'junit.xml'}")
    return 0 if ok else 1
