"""The cases of `make sim` (sim/regress/manifest.toml) and the streams they play:
command files, figures, random streams from recorded seeds, carry-boundary and
chip-crossing spans, scenes from `yproc scan`. Pure functions of the manifest and seeds."""
from __future__ import annotations

import random
import subprocess
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .. import REPO, isa
from ..formats import binfmt
from ..rtl.harness import PE_PER_CHIP
from . import randgen


MANIFEST = REPO / "sim" / "regress" / "manifest.toml"
OUT = REPO / "sim" / "out"
YPROC = REPO / "sw" / "yproc" / "build" / "yproc"
TIERS = ("smoke", "full", "nightly")   # cumulative: full runs smoke's cases too
ONE = 1 << isa.FRAC_BITS


# ---- cases --------------------------------------------------------------------------


@dataclass
class Case:
    name: str
    kind: str            # file | random | carry | chipcross | scene
    chips: int
    source: str          # where the stream comes from, for people (path or generator+seed)
    bug: bool = False    # run on the carry-bug build (expected to fail)
    params: dict = field(default_factory=dict)
    reference: str | None = None   # stored frame (pixel text) instead of the golden model

    @property
    def width(self) -> int:
        return PE_PER_CHIP * self.chips

    @property
    def expect(self) -> str:
        return "fail" if self.bug else "pass"


def _safe(text: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in text)


class ManifestError(ValueError):
    """A manifest that cannot be read or expanded; the message starts `FILE:LINE: `."""


def _entry_lines(text: str) -> dict[str, list[int]]:
    """Line of each `[[kind]]` table header, per kind, in order (tomllib keeps no
    positions; an entry's errors are reported at its header)."""
    lines: dict[str, list[int]] = {}
    for n, ln in enumerate(text.splitlines(), 1):
        head = ln.split("#", 1)[0].strip()
        if head.startswith("[[") and head.endswith("]]"):
            lines.setdefault(head[2:-2].strip(), []).append(n)
    return lines


def load_manifest(path: Path = MANIFEST, tier: str = "full") -> list[Case]:
    """Expand the manifest into cases for `tier` (tiers are cumulative). ManifestError
    (naming the file and the line of the entry) for a manifest that does not parse, an
    entry without a field it needs, an unknown tier, a path pattern that matches nothing."""
    if tier not in TIERS:
        raise ValueError(f"tier {tier!r}: want one of {', '.join(TIERS)}")
    rank = TIERS.index(tier)
    text = Path(path).read_text()
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:   # "... (at line L, column C)"
        msg, _, at = str(e).rpartition(" (at line ")
        line = at.split(",")[0] if at else "?"
        raise ManifestError(f"{path}:{line}: {msg or e}") from None
    heads = _entry_lines(text)
    base = Path(path).resolve().parent
    cases: list[Case] = []
    where = {id(e): (kind, i) for kind in ("file", "random", "carry", "chipcross", "scene")
             for i, e in enumerate(doc.get(kind, []))}

    def fail(entry, msg):
        kind, i = where[id(entry)]
        line = heads.get(kind, [])[i] if i < len(heads.get(kind, [])) else "?"
        raise ManifestError(f"{path}:{line}: [[{kind}]] {msg}")

    def need(entry, key):
        if key not in entry:
            fail(entry, f"has no {key!r}")
        return entry[key]

    def wanted(entry) -> bool:
        t = entry.get("tier", "full")
        if t not in TIERS:
            fail(entry, f"tier {t!r} not in {TIERS}")
        return TIERS.index(t) <= rank

    def add(case: Case, entry) -> None:
        if not entry.get("bug_only"):
            cases.append(case)
        if entry.get("bug_check") or entry.get("bug_only"):
            cases.append(Case(case.name + "+bug", case.kind, case.chips, case.source, True,
                              case.params, None))

    for e in doc.get("file", []):
        if not wanted(e):
            continue
        files = []
        for pat in need(e, "paths"):
            root = REPO if not pat.startswith(".") else base
            hits = sorted(root.glob(pat))
            if not hits:
                fail(e, f"{pat!r} matches no file")
            files += hits
        for f in files:
            for chips in need(e, "chips"):
                ref = e.get("reference")
                add(Case(_safe(f"{f.stem}_c{chips}"), "file", chips,
                         str(f.relative_to(REPO)) if f.is_relative_to(REPO) else str(f),
                         params={"path": str(f)},
                         reference=str((base / ref).resolve()) if ref else None), e)
    for kind in ("random", "carry", "chipcross"):
        for e in doc.get(kind, []):
            if not wanted(e):
                continue
            for seed in need(e, "seeds"):
                for chips in need(e, "chips"):
                    p = {k: v for k, v in e.items() if k not in ("seeds", "chips", "tier",
                                                                 "bug_check", "bug_only")}
                    p["seed"] = seed
                    add(Case(f"{kind}_s{seed}_c{chips}", kind, chips,
                             f"{kind}(seed={seed}, " + ", ".join(
                                 f"{k}={v}" for k, v in p.items() if k != "seed") + ")",
                             params=p), e)
    for e in doc.get("scene", []):
        if not wanted(e):
            continue
        scene = REPO / need(e, "scene")
        for chips in need(e, "chips"):
            for ch in e.get("channels", ["r", "g", "b"]):
                add(Case(_safe(f"scene_{scene.stem}_{ch}_c{chips}"), "scene", chips,
                         f"yproc scan {e['scene']} ({ch})",
                         params={"scene": str(scene), "channel": ch,
                                 "yproc_args": e.get("yproc_args",
                                                     ["scan", "{scene}", "-o", "{outdir}"])}), e)
    names = [c.name for c in cases]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise ManifestError(f"{path}: duplicate case names {sorted(dup)}")
    return cases


# ---- stream generators (pure functions of their seed) ------------------------------------


def _fits(v: int) -> int:
    return max(-(1 << 35), min((1 << 35) - 1, v))


def carry_stream(seed: int, width: int, lines: int = 8, spans: tuple[int, int] = (2, 5)
                 ) -> list[isa.Command]:
    """Long spans whose accumulation crosses the 12-bit block boundaries again and again.

    Start intensities sit just below a block boundary (fractions 0xFFFFFF, 0xFFF000,
    0x000FFF: the block-1 -> block-2 carry of the §7.7 fault, and the block-0 -> block-1
    carry), increments are chosen so that the running value crosses an integer (block 2)
    every few columns, or crosses 0xFFF in block 0 every column, over spans that cover
    most of the array; several spans overlap so that D's own adder carries as well.
    """
    rng = random.Random(seed)
    out: list[isa.Command] = []
    for _ in range(lines):
        for _ in range(rng.randint(*spans)):
            x = rng.choice([0, 0, 1, rng.randrange(min(width, 9))])
            dx = rng.choice([width - x, width - x + rng.randrange(1, 9), 4095 - x])
            base = rng.randrange(0, 16) << isa.FRAC_BITS
            i0 = base | rng.choice([0xFFFFFF, 0xFFF000, 0x000FFF, 0xFFEFFF, 0x7FFFFF,
                                    0xFFFFFF - rng.randrange(1 << 12)])
            kind = rng.random()
            if kind < 0.35:   # crosses an integer every 1..40 columns
                di = (ONE // rng.randint(1, 40)) * rng.choice([1, -1])
            elif kind < 0.6:  # block 0 runs over 0xFFF every column
                di = rng.choice([0xFFF, 0x1001, 0xFFFF, 0x1FFF]) * rng.choice([1, -1])
            elif kind < 0.85:  # block-1 scale steps
                di = (rng.randint(1, 0xFFF) << isa.BLOCK_BITS) * rng.choice([1, -1])
            else:
                di = 0
            if rng.random() < 0.4:
                ddi = rng.randint(-0x400, 0x400) * rng.choice([1, 1 << 8])
                out.append(isa.Command("EVAL", x, dx, (_fits(i0), _fits(di), ddi)))
            else:
                out.append(isa.Command("EVAL", x, dx, (_fits(i0), _fits(di))))
        if rng.random() < 0.3:
            out.append(isa.Command("ACCMODE", values=(1,)))
            out.append(isa.Command("EVAL", 0, width, (-(1 << 20), ONE // 64)))
        out.append(isa.Command("REFRESH"))
    return out


def chipcross_stream(seed: int, width: int, lines: int = 8, per_line: int = 12
                     ) -> list[isa.Command]:
    """Short spans that start a few columns before a chip boundary (every 9 PEs) and end
    a few after it, with Set/Dis/Eval0 on the boundary columns themselves."""
    rng = random.Random(seed)
    bounds = list(range(PE_PER_CHIP, width + 1, PE_PER_CHIP)) or [PE_PER_CHIP]
    out: list[isa.Command] = []
    for _ in range(lines):
        for _ in range(per_line):
            b = rng.choice(bounds)
            x = max(0, b - rng.randint(1, 8))
            dx = b - x + rng.randint(0, 10)
            r = rng.random()
            if r < 0.55:
                p = rng.choice([0, 1, 1, 2, 2, 3])
                vals = [rng.randint(-64, 64) * ONE + rng.randrange(ONE)]
                vals += [rng.randint(-ONE * 4, ONE * 4) >> (4 * k) for k in range(1, p + 1)]
                out.append(isa.Command("EVAL", x, dx, tuple(_fits(v) for v in vals)))
            elif r < 0.7:
                out.append(isa.Command(rng.choice(["SETI", "SETDI", "SETDDI"]), b - 1 + rng.randint(0, 1),
                                       1, (rng.randint(-ONE * 8, ONE * 8),)))
            elif r < 0.8:
                out.append(isa.Command("DIS", b - 1, rng.randint(1, 3)))
            elif r < 0.9:
                out.append(isa.Command("EVAL0", x, dx, (rng.randrange(4096),)))
            else:
                out.append(isa.Command("SETPI", rng.randrange(PE_PER_CHIP), PE_PER_CHIP,
                                       (rng.randint(-ONE, ONE),)))
        out.append(isa.Command("REFRESH"))
    return out


class Unavailable(Exception):
    """A case whose input cannot be produced here (e.g. yproc has no `scan` yet)."""


def scene_stream(case: Case, workdir: Path) -> list[isa.Command]:
    """Run the y-processor (`yproc scan SCENE -o DIR`, sw/hsr) and take one colour's
    instruction stream, DIR/<channel>.de48."""
    if not YPROC.exists():
        raise Unavailable(f"{YPROC.relative_to(REPO)} not built (make -C sw/hsr)")
    outdir = workdir / "yproc"
    outdir.mkdir(exist_ok=True)
    args = [a.format(scene=case.params["scene"], outdir=outdir, width=case.width)
            for a in case.params["yproc_args"]]
    res = subprocess.run([str(YPROC), *args], capture_output=True, text=True, timeout=600)
    out = outdir / f"{case.params['channel']}.de48"
    if res.returncode or not out.exists():
        msg = (res.stderr.strip().splitlines() or ["no output"])[0]
        raise Unavailable(f"yproc {args[0]} failed ({res.returncode}): {msg}")
    return binfmt.load_commands(out.read_bytes(), str(out))[0]


def commands_for(case: Case, workdir: Path) -> list[isa.Command]:
    p = case.params
    if case.kind == "file":
        return binfmt.load_commands(Path(p["path"]).read_bytes(), p["path"])[0]
    if case.kind == "random":
        per = tuple(p.get("per_line", (1, 40)))
        return randgen.stream(p["seed"], p.get("commands", 2000), case.width, per)
    if case.kind == "carry":
        return carry_stream(p["seed"], case.width, p.get("lines", 8))
    if case.kind == "chipcross":
        return chipcross_stream(p["seed"], case.width, p.get("lines", 8))
    if case.kind == "scene":
        return scene_stream(case, workdir)
    raise ValueError(f"unknown case kind {case.kind!r}")
