"""`diffengine trace`: the state of chosen PEs per cycle, from the Verilated RTL (the C++
harness's trace build) or from the structural golden model, with identical columns and
cycle numbering; breakpoints; and `--compare`, which runs both and names the first
cycle, PE, register and 12-bit block where they part. docs/simulation.md is the manual.

Cycle numbering is the RTL's (the harness's): cycle c is the cycle in which instruction
c of the padded stream (Nops inserted so that Refreshes are at least n_pe apart, then
2*n_pe+64 drain Nops) is on the array input, and a row holds the registers as they are
during that cycle. The structural model has no chip-boundary registers, so PE p of chip
k = p // 9 lags it by k cycles in the RTL: the model row of (cycle c, PE p) is the
model's state after c - k steps (reset state before that).
"""
from __future__ import annotations

import argparse
import bisect
import csv
import io
import sys
from dataclasses import dataclass
from pathlib import Path

from .. import isa
from ..formats import binfmt
from .harness import PE_PER_CHIP

PIX_LATENCY = 3  # docs/array.md: column q of a Refresh on id_i in cycle R leaves at R+NumChips+3+q

COLUMNS = ["cycle", "pe", "ident", "data", "A", "B", "C", "D", "flags", "id1", "id2", "out",
           "c1", "c2", "accc2", "accc3", "xz1", "act1", "prot1", "act2", "prot2", "e0wr2",
           "accen2", "accen3", "pix_valid", "pix", "line"]
WORD_COLUMNS = ("data", "A", "B", "C", "D", "out")  # 36-bit words: three 12-bit blocks
FLAG_LETTERS = "ABCdlma"  # pA pB pC dis lock acc_mode act
EXIT_DIFFER = 1
EXIT_BREAK = 3


class TraceError(Exception):
    """A user error (bad option, bad input)."""


# ---- the stream as the harness plays it -----------------------------------------------

def pad_stream(slots, n_pe: int) -> list[tuple[int, int]]:
    """The harness's clock-loop stream: Nops before a Refresh closer than n_pe cycles to
    the previous one, then 2*n_pe+64 drain Nops (sim/harness/array_harness.cpp)."""
    seq: list[tuple[int, int]] = []
    since = n_pe
    for ident, data in slots:
        if ident == isa.REFRESH:
            while since < n_pe:
                seq.append((isa.NOP, 0))
                since += 1
        seq.append((ident, data))
        since = 1 if ident == isa.REFRESH else since + 1
    seq += [(isa.NOP, 0)] * (2 * n_pe + 64)
    return seq


@dataclass
class Timing:
    n_pe: int
    chips: int
    seq: list
    refresh_at: list  # cycle of each Refresh on id_i, line by line

    @classmethod
    def of(cls, slots, chips: int) -> "Timing":
        n_pe = chips * PE_PER_CHIP
        seq = pad_stream(slots, n_pe)
        return cls(n_pe, chips, seq, [c for c, (i, _) in enumerate(seq) if i == isa.REFRESH])

    def line_of_slot(self, slot: int) -> int:
        """The scanline instruction `slot` belongs to (a Refresh ends its line)."""
        return 0 if slot < 0 else bisect.bisect_left(self.refresh_at, slot)

    def check_line(self, line: int, opt: str) -> None:
        if not 0 <= line < len(self.refresh_at):
            raise TraceError(f"{opt} {line}: the stream has lines 0..{len(self.refresh_at) - 1}")

    def line_window(self, line: int) -> tuple[int, int]:
        """Cycles of scanline L: from Refresh L-1 on id_i (cycle 0 for L = 0) to the
        cycle its last pixel is on pix_o."""
        self.check_line(line, "--line")
        lo = self.refresh_at[line - 1] if line else 0
        return lo, min(self.refresh_at[line] + self.chips + PIX_LATENCY + self.n_pe - 1,
                       len(self.seq) - 1)

    def line_start(self, line: int) -> int:
        """Breakpoint cycle of scanline L: its first instruction is on id_i."""
        self.check_line(line, "--break-line")
        return self.refresh_at[line - 1] + 1 if line else 0


def parse_pes(spec: str, n_pe: int) -> list[int]:
    """"0,5,17-19" or "all" -> sorted PE numbers (the harness's --trace-pes syntax)."""
    if spec == "all":
        return list(range(n_pe))
    out = set()
    for item in spec.split(","):
        lo, _, hi = item.partition("-") if not item.startswith("-") else (item, "", "")
        try:
            a, b = int(lo, 0), int(hi or lo, 0)
        except ValueError:
            raise TraceError(f"PE list item {item!r} is not a PE or range") from None
        if not 0 <= a <= b < n_pe:
            raise TraceError(f"PE list item {item!r} outside 0..{n_pe - 1}")
        out.update(range(a, b + 1))
    return sorted(out)


def parse_op(text: str) -> int:
    """A mnemonic of isa.LUT (case-insensitive) or an identifier number -> identifier."""
    names = {name.upper(): ident for name, ident, _ in isa.LUT}
    if text.upper() in names:
        return names[text.upper()]
    try:
        v = int(text, 0)
    except ValueError:
        raise TraceError(f"--break-op {text!r}: not a mnemonic ({', '.join(names)}) "
                         "nor an identifier") from None
    if not 0 <= v <= isa.ID_MASK:
        raise TraceError(f"--break-op {text!r}: identifiers are 0..{isa.ID_MASK:#x}")
    return v


# ---- the structural model, producing the harness's rows ----------------------------------

def _fmt_row(cycle: int, pe: int, line: int, ident: int, data: int, st: dict, p: int) -> str:
    b = lambda k: int(bool(st[k][p]))  # noqa: E731
    flags = "".join(ch if st[k][p] else "." for ch, k in
                    zip(FLAG_LETTERS, ("pA", "pB", "pC", "dis", "lock", "acc_mode", "act")))
    return (f"{cycle},{pe},{ident:03x},{data:09x},{int(st['A'][p]):09x},{int(st['B'][p]):09x},"
            f"{int(st['C'][p]):09x},{int(st['D'][p]):09x},{flags},{int(st['id1'][p]):03x},"
            f"{int(st['id2'][p]):03x},{int(st['out'][p]):09x},{b('c1')},{b('c2')},"
            f"{b('accc2')},{b('accc3')},{b('xz1')},{b('act1')},{b('prot1')},{b('act2')},"
            f"{b('prot2')},{b('e0wr2')},{b('accen2')},{b('accen3')},{b('pix_valid')},"
            f"{int(st['pix'][p]):03x},{line}")


@dataclass
class Result:
    rows: list          # CSV rows (strings, no header) inside the window
    stop: str | None    # breakpoint print-out (header line + rows), None if no break


def model_trace(slots, chips: int, carry_bug: bool, pes: list[int], lo: int, hi: int,
                show: list[int] | None = None, break_cycle: int | None = None,
                break_pe: int | None = None, break_op: int | None = None) -> Result:
    """The harness's trace (same rows, same breakpoints) from structural.Array."""
    from ..model import structural

    t = Timing.of(slots, chips)
    n_pe = t.n_pe
    arr = structural.Array(n_pe, carry_bug)
    show = show or []
    want = sorted(set(pes) | set(show) | ({break_pe} if break_pe is not None else set()))
    lag = {p: p // PE_PER_CHIP for p in want}
    max_lag = max(lag.values(), default=0)
    up = sorted({p - 1 for p in want if p > 0} | set(want))
    hist: dict[int, tuple] = {}  # model step -> (state of `up` PEs, skew regs)
    M = isa.BLOCK_MASK

    def snapshot():
        st = arr.state()
        return {k: v[up] for k, v in st.items()}, arr.sk1, arr.sk2b

    pos = {p: i for i, p in enumerate(up)}

    zero = {k: [0] * len(up) for k in arr.state()}  # every register before cycle 0

    def row(c: int, p: int) -> str:
        s = c - lag[p]
        slot = c - p - lag[p]
        if s < 0:
            return _fmt_row(c, p, t.line_of_slot(slot), 0, 0, zero, pos[p])
        st, sk1, sk2b = hist[s]
        if p == 0:
            ident, d = t.seq[s]
            ident, data = ident, isa.blocks_word((d & M, sk1, sk2b))
        else:
            ident, data = int(st["id1"][pos[p - 1]]), int(st["out"][pos[p - 1]])
        return _fmt_row(c, p, t.line_of_slot(slot), ident, data, st, pos[p])

    rows = []
    for c in range(len(t.seq)):
        hist[c] = snapshot()
        hist.pop(c - max_lag - 1, None)  # rows of cycle c need steps c-max_lag..c
        if lo <= c <= hi:
            rows += [row(c, p) for p in pes]
        stop = break_cycle is not None and c == break_cycle
        if break_pe is not None and not stop:
            r = row(c, break_pe).split(",")
            stop = int(r[2], 16) == break_op
        if stop:
            head = (f"break: cycle {c}, line {t.line_of_slot(c)} (of the instruction on id_i)"
                    + (f", PE {break_pe} (column {break_pe}) receives identifier "
                       f"0x{break_op:03x}" if break_pe is not None else ""))
            return Result(rows, "\n".join([head, ",".join(COLUMNS)] + [row(c, p) for p in show]))
        arr.step(*t.seq[c])
    return Result(rows, None)


def rtl_trace(slots, chips: int, carry_bug: bool, pes: list[int], lo: int, hi: int,
              show: list[int] | None = None, break_cycle: int | None = None,
              break_pe: int | None = None, break_op: int | None = None,
              threads: int = 1) -> Result:
    """The same from the Verilated RTL (the harness's trace build)."""
    from . import harness

    spec = ",".join(str(p) for p in pes) if pes else None
    run = harness.run_traced(slots, chips, carry_bug, pes=spec, window=(lo, hi),
                             break_cycle=break_cycle, break_pe=break_pe, break_op=break_op,
                             threads=threads)
    rows = run.csv.splitlines()[1:] if run.csv else []
    stop = None
    if run.returncode == harness.EXIT_BREAK:
        lines = run.stdout.splitlines()
        i = next(k for k, ln in enumerate(lines) if ln.startswith("break:"))
        stop = "\n".join(lines[i:])
        if show is not None:  # the harness shows --trace-pes; keep only `show`
            head, hdr, *body = stop.splitlines()
            keep = {str(p) for p in show}
            stop = "\n".join([head, hdr] + [r for r in body if r.split(",")[1] in keep])
    return Result(rows, stop)


# ---- formatting and comparing ------------------------------------------------------------

def _word(h: str) -> str:
    b0, b1, b2 = isa.word_blocks(int(h, 16))
    return f"{b2:03x}.{b1:03x}{b0:03x}"


def text_row(r: str) -> str:
    d = dict(zip(COLUMNS, r.split(",")))
    carries = " ".join(k for k in ("c1", "c2", "accc2", "accc3") if d[k] == "1") or "-"
    pix = d["pix"] if d["pix_valid"] == "1" else "-"
    name = isa.ID_NAME.get(int(d["ident"], 16), d["ident"])
    return (f"{d['cycle']:>7} PE{d['pe']:<4} line {d['line']:<4} in {name:<13} "
            f"{_word(d['data'])}  A {_word(d['A'])} B {_word(d['B'])} C {_word(d['C'])} "
            f"D {_word(d['D'])}  {d['flags']}  out {_word(d['out'])}  carry {carries:<7} "
            f"pix {pix}")


def first_difference(a: list[str], b: list[str]) -> dict | None:
    """First (cycle, PE) row where two traces part, with the column and, for a 36-bit
    word, the lowest 12-bit block that differs. None when identical."""
    for ra, rb in zip(a, b):
        if ra == rb:
            continue
        fa, fb = ra.split(","), rb.split(",")
        for name, x, y in zip(COLUMNS, fa, fb):
            if x == y:
                continue
            out = {"cycle": int(fa[0]), "pe": int(fa[1]), "column": name, "a": x, "b": y,
                   "block": None}
            if name in WORD_COLUMNS:
                va, vb = int(x, 16), int(y, 16)
                out["block"] = next(j for j, (p, q) in enumerate(
                    zip(isa.word_blocks(va), isa.word_blocks(vb))) if p != q)
            return out
    if len(a) != len(b):
        return {"cycle": None, "pe": None, "column": "rows", "a": str(len(a)),
                "b": str(len(b)), "block": None}
    return None


def describe(d: dict | None, what_a: str = "RTL", what_b: str = "model") -> str:
    if d is None:
        return "identical"
    if d["column"] == "rows":
        return f"{what_a} has {d['a']} rows, {what_b} {d['b']} (one stopped early)"
    s = f"first difference: cycle {d['cycle']}, PE {d['pe']} (chip {d['pe'] // PE_PER_CHIP}), "
    if d["block"] is not None:
        j = d["block"]
        va, vb = int(d["a"], 16), int(d["b"], 16)
        (msb, lsb), a_j, b_j = isa.block_bits(j), isa.word_blocks(va)[j], isa.word_blocks(vb)[j]
        s += (f"{d['column']} block {j} (bits {msb}:{lsb}): {what_a} "
              f"{a_j:03x}, {what_b} {b_j:03x} "
              f"(words {_word(d['a'])} / {_word(d['b'])})")
    else:
        s += f"{d['column']}: {what_a} {d['a']}, {what_b} {d['b']}"
    return s


# ---- command line -------------------------------------------------------------------------

def load_slots(path: str) -> list[tuple[int, int]]:
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise TraceError(f"{path}: {e.strerror or e}") from None
    if binfmt.detect(data) == "de48":
        return binfmt.decode_de48(data, path)
    commands, _ = binfmt.load_commands(data, path, True)
    return isa.serialise(commands)


def configure(p: argparse.ArgumentParser) -> None:
    """The arguments of `diffengine trace`."""
    p.add_argument("stream", help=".cmd text, .de48 or .de32")
    p.add_argument("--chips", type=int, required=True, help="array size in 9-PE chips")
    p.add_argument("--bug", type=int, choices=(0, 1), default=0,
                   help="carry bug in the RTL build and (unless --model-bug) the model")
    p.add_argument("--model-bug", type=int, choices=(0, 1), default=None,
                   help="carry bug of the model when it differs from --bug (--compare)")
    p.add_argument("--pes", help="PEs to trace: 0,5,17-19 or all (default: all with "
                   "--compare, else required)")
    p.add_argument("--from", dest="lo", type=int, help="first cycle of the window")
    p.add_argument("--to", dest="hi", type=int, help="last cycle of the window")
    p.add_argument("--line", type=int, help="window = the cycles of scanline L")
    p.add_argument("--format", choices=("text", "csv"), default="text")
    p.add_argument("--engine", choices=("rtl", "model"), default="rtl")
    p.add_argument("--compare", action="store_true",
                   help="run RTL and model, report where they first part")
    p.add_argument("--break-cycle", type=int)
    p.add_argument("--break-line", type=int)
    p.add_argument("--break-pe", type=int)
    p.add_argument("--break-op", help="mnemonic (isa.LUT name) or identifier")
    p.add_argument("--threads", type=int, default=1, help="Verilator threads of the RTL build")
    p.add_argument("-o", "--output", help="write here instead of stdout")
    p.set_defaults(func=command)


def command(a) -> int:
    try:
        return _run(a)
    except (TraceError, RuntimeError) as e:   # a bad window or a failed harness run
        print(f"diffengine trace: {e}", file=sys.stderr)
        return 2


def _run(a) -> int:
    if a.chips < 1:
        raise TraceError("--chips must be >= 1")
    if (a.break_pe is None) != (a.break_op is None):
        raise TraceError("--break-pe and --break-op go together")
    if a.line is not None and (a.lo is not None or a.hi is not None):
        raise TraceError("--line and --from/--to exclude each other")
    slots = load_slots(a.stream)
    t = Timing.of(slots, a.chips)
    if a.pes is None and not a.compare and a.break_pe is None and a.break_cycle is None \
            and a.break_line is None:
        raise TraceError("--pes is required (e.g. --pes 0-2)")
    pes = parse_pes(a.pes or "all", t.n_pe) if (a.pes or a.compare) else []
    if a.line is not None:
        lo, hi = t.line_window(a.line)
    else:
        lo, hi = a.lo or 0, len(t.seq) - 1 if a.hi is None else min(a.hi, len(t.seq) - 1)
    op = parse_op(a.break_op) if a.break_op is not None else None
    if a.break_pe is not None and not 0 <= a.break_pe < t.n_pe:
        raise TraceError(f"--break-pe {a.break_pe}: the array has PEs 0..{t.n_pe - 1}")
    brk = [c for c in (a.break_cycle,
                       t.line_start(a.break_line) if a.break_line is not None else None)
           if c is not None]
    break_cycle = min(brk) if brk else None
    # PEs shown at a breakpoint: --pes, else the break PE and its neighbours, else 0..2.
    centre = a.break_pe if a.break_pe is not None else 1
    show = pes or list(range(max(0, centre - 1), min(t.n_pe - 1, centre + 1) + 1))
    kw = dict(show=show, break_cycle=break_cycle, break_pe=a.break_pe, break_op=op)
    model_bug = bool(a.bug if a.model_bug is None else a.model_bug)
    out = open(a.output, "w") if a.output else sys.stdout
    try:
        if a.compare:
            r = rtl_trace(slots, a.chips, bool(a.bug), pes, lo, hi, threads=a.threads, **kw)
            m = model_trace(slots, a.chips, model_bug, pes, lo, hi, **kw)
            d = first_difference(r.rows, m.rows)
            out.write(f"RTL (bug {a.bug}) vs structural model (bug {int(model_bug)}), "
                      f"{a.chips} chip(s), PEs {a.pes or 'all'}, cycles {lo}..{hi}: "
                      f"{describe(d)}\n")
            return 0 if d is None else EXIT_DIFFER
        fn = rtl_trace if a.engine == "rtl" else model_trace
        extra = {"threads": a.threads} if a.engine == "rtl" else {}
        res = fn(slots, a.chips, model_bug if a.engine == "model" else bool(a.bug), pes,
                 lo, hi, **kw, **extra)
        if a.format == "csv":
            out.write(",".join(COLUMNS) + "\n" + "".join(r + "\n" for r in res.rows))
        else:
            out.writelines(text_row(r) + "\n" for r in res.rows)
        if res.stop is not None:
            head, _, *body = res.stop.splitlines()
            if a.format == "csv":
                sys.stderr.write(head + "\n")
                if not res.rows:  # nothing traced: the stop rows are the output
                    out.write(",".join(COLUMNS) + "\n" + "".join(r + "\n" for r in body))
            else:
                out.write(head + "\n" + "".join(text_row(r) + "\n" for r in body))
            return EXIT_BREAK
        return 0
    finally:
        if a.output:
            out.close()


def read_csv(text: str) -> list[dict]:
    """Trace CSV -> list of dicts (for tools built on top of the trace)."""
    return list(csv.DictReader(io.StringIO(text)))

