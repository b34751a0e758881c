"""Shards: duration-balanced, deterministic partitions of the cases (docs/regression.md
§9), and the per-case durations they are balanced on."""
from __future__ import annotations

import json
from pathlib import Path

from .cases import Case, MANIFEST
from .report import verdict


# ---- shards: duration-balanced, deterministic (docs/regression.md §9) --------------------

# Per-case seconds recorded by earlier runs. Checked in next to the manifest (an input of
# the scheduling, like the manifest; sim/out/ is git-ignored and wiped by make clean).
DURATIONS = MANIFEST.parent / "durations.json"
# The fallback estimate of a case with no recorded duration (seconds): a cost model fitted
# to the figures of docs/regression.md §7 at 72 chips (the cube, 240 lines: 136 s; the
# teapot channels, 480 lines: 170-280 s) and the smoke tier (1500 random commands on one
# chip: 0.1 s); over the full tier it gives 1710 s, the measured cases added up to 1705 s.
# The 72-chip scene times follow their line counts, not their command counts: per line the
# cycles grow with the columns and each cycle's cost with the chips (chips^2 per line).
LINE_COST = 1e-4     # s per line per chip^2
CMD_COST = 1e-5      # s per command per chip
CASE_COST = 0.05     # s per case (process, files, golden model set-up)
SCENE_CMDS_PER_LINE = 100   # unknown before yproc runs: the teapot's ~50k / 480 lines
RECORDING_TIERS = ("full", "nightly")   # complete runs of these tiers update DURATIONS


def parse_shard(text: str) -> tuple[int, int]:
    """'k/N' -> (k, N), 1 <= k <= N; ValueError with the reason otherwise."""
    parts = str(text).strip().split("/")
    try:
        if len(parts) != 2:
            raise ValueError
        k, n = int(parts[0]), int(parts[1])
    except ValueError:
        raise ValueError(f"SHARD {text!r}: want k/N with whole numbers, e.g. 2/4") from None
    if n < 1:
        raise ValueError(f"SHARD {text!r}: N must be at least 1")
    if not 1 <= k <= n:
        raise ValueError(f"SHARD {text!r}: k must be in 1..{n} (shards count from 1)")
    return k, n


def shard_dir(out: Path, k: int, n: int) -> Path:
    return Path(out) / f"shard-{k}-of-{n}"


def load_durations(path: Path = DURATIONS) -> dict[str, float]:
    """{case name: seconds} from the durations file; {} if it does not exist."""
    path = Path(path)
    if not path.exists():
        return {}
    try:
        doc = json.loads(path.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}:{e.lineno}: {e.msg}") from None
    secs = doc.get("seconds", {}) if isinstance(doc, dict) else None
    if not isinstance(secs, dict):
        raise ValueError(f"{path}: want {{\"seconds\": {{case: seconds, ...}}}}")
    return {str(k): float(v) for k, v in secs.items()}


def case_size(case: Case) -> tuple[float, float]:
    """(lines, commands) of a case as far as the manifest tells, without making the
    stream: generated kinds from their parameters, files from their size, scenes from
    their `screen W H` line."""
    p = case.params
    if case.kind == "random":
        n = p.get("commands", 2000)
        return n / (sum(p.get("per_line", (1, 40))) / 2), n
    if case.kind == "carry":
        return p.get("lines", 8), 6 * p.get("lines", 8)     # 2-5 spans, Refresh, Acc_mode
    if case.kind == "chipcross":
        return p.get("lines", 8), 13 * p.get("lines", 8)    # 12 commands + Refresh
    if case.kind == "file":
        try:
            n = Path(p["path"]).stat().st_size / 16
        except OSError:
            n = 100
        return max(1.0, n / 4), n
    lines = 480
    try:
        for ln in Path(p["scene"]).read_text().splitlines():
            if ln.split()[:1] == ["screen"]:
                lines = int(ln.split()[2])
                break
    except (OSError, ValueError, IndexError):
        pass
    return lines, lines * SCENE_CMDS_PER_LINE


def model_seconds(case: Case) -> float:
    """The fallback cost model (LINE_COST, CMD_COST, CASE_COST)."""
    lines, cmds = case_size(case)
    return LINE_COST * lines * case.chips ** 2 + CMD_COST * cmds * case.chips + CASE_COST


def estimates(cases: list[Case], durations: dict[str, float]) -> dict[str, float]:
    """Seconds per case: the recorded duration, else model_seconds() times the median of
    recorded / modelled seconds over the recorded cases of the selection with the same
    kind and array size, else the same array size, else 1 (not across array sizes: a
    1-chip case's seconds are mostly fixed costs and say little about 72 chips).
    A pure function of its inputs."""
    def median(v: list[float]) -> float:
        v = sorted(v)
        return v[len(v) // 2] if len(v) % 2 else (v[len(v) // 2 - 1] + v[len(v) // 2]) / 2

    by_kind: dict[tuple[str, int], list[float]] = {}
    by_chips: dict[int, list[float]] = {}
    for c in cases:
        if c.name in durations:
            ratio = durations[c.name] / model_seconds(c)
            by_kind.setdefault((c.kind, c.chips), []).append(ratio)
            by_chips.setdefault(c.chips, []).append(ratio)

    def factor(c: Case) -> float:
        if (c.kind, c.chips) in by_kind:
            return median(by_kind[(c.kind, c.chips)])
        return median(by_chips[c.chips]) if c.chips in by_chips else 1.0

    return {c.name: durations[c.name] if c.name in durations else model_seconds(c) * factor(c)
            for c in cases}


def assign_shards(cases: list[Case], n: int, durations: dict[str, float]
                  ) -> list[list[Case]]:
    """Greedy longest-processing-time first: cases by decreasing estimate (ties by name)
    each go to the shard with the least estimated time so far (ties: the lowest index).
    Every case lands in exactly one shard; each shard's total stays within the longest
    case of the ideal (total / n). Shards keep the manifest order of their cases."""
    if n < 1:
        raise ValueError("n must be at least 1")
    est = estimates(cases, durations)
    load = [0.0] * n
    where: dict[str, int] = {}
    for c in sorted(cases, key=lambda c: (-est[c.name], c.name)):
        i = min(range(n), key=lambda j: (load[j], j))
        where[c.name] = i
        load[i] += est[c.name]
    return [[c for c in cases if where[c.name] == i] for i in range(n)]


def record_durations(path: Path, cases: list[Case], results: dict[str, dict],
                     keep: set[str] | None = None) -> int:
    """Write the measured seconds of `cases` into the durations file (other entries stay,
    except names not in `keep`, the manifest's cases, when given). Cases that did not
    really run (N/A, ERROR) are not recorded. Returns how many were recorded."""
    path = Path(path)
    old = load_durations(path) if path.exists() else {}
    n = 0
    for c in cases:
        r = results[c.name]
        if verdict(c, r) in ("N/A", "ERROR"):
            continue
        old[c.name] = max(0.01, round(float(r["seconds"]), 2))
        n += 1
    if keep is not None:
        old = {k: v for k, v in old.items() if k in keep}
    doc = {"about": "Seconds per case recorded by complete `make sim` runs of the full or "
                    "nightly tier (and their `make sim-merge`); `--shard k/N` balances on "
                    "them. docs/regression.md, section 'Shards and CI matrices'.",
           "seconds": dict(sorted(old.items()))}
    path.write_text(json.dumps(doc, indent=1) + "\n")
    return n
