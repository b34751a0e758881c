"""Outputs of a run (summary, JUnit, HTML, results.json, run.json, frames) and the
merge of shard folders into one run."""
from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

from .. import REPO
from .cases import Case, MANIFEST, load_manifest
from .report import GOOD, html_report, junit, summary_table, verdict
from .shards import RECORDING_TIERS, record_durations


# ---- outputs of a run (also of a merge) -------------------------------------------------


def write_outputs(out: Path, cases: list[Case], results: dict[str, dict], tier: str,
                  secs: float, meta: dict, case_dirs: dict[str, Path] | None = None,
                  suite_name: str | None = None, note: str = "") -> bool:
    """summary.txt, junit.xml, report.html, results.json and run.json (what was run: tier,
    shard, selection, the cases; what --merge reads back) in `out`. True if all good."""
    out.mkdir(parents=True, exist_ok=True)
    table = summary_table(cases, results)
    print(table)
    (out / "summary.txt").write_text(table + "\n")
    (out / "junit.xml").write_bytes(junit(cases, results, tier, secs, suite_name))
    (out / "report.html").write_text(html_report(cases, results, tier, secs, case_dirs, out,
                                                 note))
    (out / "results.json").write_text(json.dumps(
        {c.name: {k: v for k, v in results[c.name].items() if k not in ("rtl", "ref")}
         | {"verdict": verdict(c, results[c.name])} for c in cases}, indent=1, default=str))
    ok = all(verdict(c, results[c.name]) in GOOD for c in cases)
    (out / "run.json").write_text(json.dumps(
        meta | {"tier": tier, "seconds": round(secs, 3), "ok": ok,
                "cases": [dataclasses.asdict(c) for c in cases]}, indent=1, default=str))
    return ok


def save_frames(out: Path, cases: list[Case], results: dict[str, dict]) -> None:
    """cases/<name>/frames.npz (RTL frame and reference): the merge's report shows them."""
    for c in cases:
        r = results[c.name]
        if r.get("rtl") is not None and r.get("ref") is not None:
            d = out / "cases" / c.name
            d.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(d / "frames.npz", rtl=r["rtl"], ref=r["ref"])


class MergeError(Exception):
    """The shards do not add up to one run: a case missing, run twice, or unknown."""


def load_run_dir(d: Path) -> tuple[dict, list[Case], dict[str, dict]]:
    """run.json, results.json and the frames of one run (shard) folder."""
    d = Path(d)
    if not (d / "run.json").exists() or not (d / "results.json").exists():
        raise MergeError(f"{d}: not a shard folder (no run.json / results.json); "
                         "run `make sim SHARD=k/N` first, or name the folders")
    meta = json.loads((d / "run.json").read_text())
    stored = json.loads((d / "results.json").read_text())
    cases = [Case(**c) for c in meta["cases"]]
    results: dict[str, dict] = {}
    for c in cases:
        if c.name not in stored:
            raise MergeError(f"{d}: case {c.name} is in run.json but not in results.json")
        r = dict(stored[c.name])
        r.pop("verdict", None)
        if r.get("first") is not None:
            r["first"] = tuple(r["first"])
        r["rtl"] = r["ref"] = None
        f = d / "cases" / c.name / "frames.npz"
        if f.exists():
            with np.load(f) as z:
                r["rtl"], r["ref"] = z["rtl"], z["ref"]
        results[c.name] = r
    return meta, cases, results


def merge_runs(dirs: list[Path]) -> tuple[dict, list[Case], dict[str, dict], dict[str, Path]]:
    """Check that the shard folders are the N shards of one selection, with every case
    exactly once, and join them: (meta, cases in selection order, results, case dirs)."""
    if not dirs:
        raise MergeError("no shard folders given")
    runs = [(Path(d), *load_run_dir(d)) for d in dirs]
    meta0 = runs[0][1]
    for d, meta, _, _ in runs[1:]:
        for key in ("tier", "selected", "pattern", "no_bug_checks"):
            if meta.get(key) != meta0.get(key):
                raise MergeError(f"{d} and {runs[0][0]} come from different runs ({key} "
                                 f"differs): merge the shards of one run only")
        if meta["shard"][1] != meta0["shard"][1]:
            raise MergeError(f"{d} and {runs[0][0]} come from different runs (shard "
                             f"{meta['shard'][0]}/{meta['shard'][1]} vs "
                             f"{meta0['shard'][0]}/{meta0['shard'][1]}): merge the shards of "
                             "one run only")
    n = meta0["shard"][1]
    selected = list(meta0["selected"])
    problems = []
    seen_k: dict[int, list[str]] = {}
    for d, meta, _, _ in runs:
        seen_k.setdefault(meta["shard"][0], []).append(str(d))
    missing_k = [k for k in range(1, n + 1) if k not in seen_k]
    where: dict[str, list[Path]] = {}
    for d, _, cases, _ in runs:
        for c in cases:
            where.setdefault(c.name, []).append(d)
    missing = [name for name in selected if name not in where]
    if missing:
        problems.append(f"{len(missing)} case(s) missing (in no shard): "
                        + ", ".join(missing[:20]) + (" ..." if len(missing) > 20 else "")
                        + (f" [shard(s) not given: {', '.join(f'{k}/{n}' for k in missing_k)}]"
                           if missing_k else ""))
    twice = {name: ds for name, ds in where.items() if len(ds) > 1}
    if twice:
        problems.append(f"{len(twice)} case(s) ran more than once: " + "; ".join(
            f"{name} in {', '.join(map(str, ds))}" for name, ds in list(twice.items())[:20]))
    extra = [name for name in where if name not in set(selected)]
    if extra:
        problems.append(f"{len(extra)} case(s) not in the run's selection: "
                        + ", ".join(extra[:20]))
    if problems:
        raise MergeError("; ".join(problems))
    cases_by: dict[str, Case] = {}
    results: dict[str, dict] = {}
    dirs_by: dict[str, Path] = {}
    for d, _, cases, res in runs:
        for c in cases:
            cases_by[c.name], results[c.name] = c, res[c.name]
            dirs_by[c.name] = d / "cases" / c.name
    secs = [float(m["seconds"]) for _, m, _, _ in runs]
    meta = {k: meta0.get(k) for k in ("manifest", "pattern", "no_bug_checks", "selected")}
    meta |= {"shard": [1, 1], "merged_from": [str(d) for d, *_ in runs],
             "shard_seconds": secs, "tier": meta0["tier"]}
    return meta, [cases_by[name] for name in selected], results, dirs_by


def is_complete(meta: dict) -> bool:
    return not meta.get("pattern") and not meta.get("no_bug_checks")


def record_run(path: Path, manifest: Path, cases, results, log=print) -> None:
    try:
        keep = {c.name for c in load_manifest(manifest, "nightly")}
    except (OSError, ValueError):
        keep = None
    n = record_durations(path, cases, results, keep)
    log(f"sim: recorded {n} case durations in {path}")


def merge_main(dirs: list[Path], out: Path, durations: Path | None,
               record: bool | None) -> int:
    try:
        meta, cases, results, case_dirs = merge_runs(dirs)
    except MergeError as e:
        print(f"sim-merge: ERROR: {e}", file=sys.stderr)
        return 2
    secs = max(meta["shard_seconds"], default=0.0)
    n = len(meta["merged_from"])
    note = (f"Merged from {n} shard(s) (longest {secs:.1f} s, together "
            f"{sum(meta['shard_seconds']):.1f} s).")
    ok = write_outputs(out, cases, results, meta["tier"], secs, meta, case_dirs, note=note)
    manifest = REPO / meta.get("manifest", MANIFEST)   # repository-relative, or absolute
    if not manifest.exists():
        manifest = MANIFEST
    if record or (record is None and is_complete(meta) and meta["tier"] in RECORDING_TIERS):
        record_run(durations or manifest.parent / "durations.json", manifest, cases, results)
    print(f"sim-merge: {meta['tier']} tier, {len(cases)} cases from {n} shard(s): "
          f"{'OK' if ok else 'FAILED'}; report {out / 'report.html'}, junit {out / 'junit.xml'}")
    return 0 if ok else 1
