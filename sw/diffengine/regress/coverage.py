"""Functional coverage of command streams played through an array of chips.

Bins: every command kind x {inside one chip, crossing a chip boundary, at PE 0, at the
last PE, dX 0, dX 1, protected, unprotected, disabled}. "protected" means the command
covered a column whose protect flag (for an Eval: one its order honours) was set;
"disabled" a column with a pending Dis. Flags are tracked per column with the rules of
docs/isa.md §6, so the bins say what the hardware actually saw.
"""
from __future__ import annotations

from collections import Counter

import numpy as np

from .. import isa


KINDS = ("Eval0", "Eval1", "Eval2", "Eval3", "EvalN", "SetI", "SetdI", "SetddI",
         "SetPI", "SetPdI", "SetPddI", "Dis")
WHERE = ("in_chip", "cross_chip", "pe0", "last_pe", "dx0", "dx1", "protected",
         "unprotected", "disabled")
_KIND_OF = {"SETI": "SetI", "SETDI": "SetdI", "SETDDI": "SetddI", "SETPI": "SetPI",
            "SETPDI": "SetPdI", "SETPDDI": "SetPddI", "DIS": "Dis", "EVAL0": "Eval0"}


def kind(c: isa.Command) -> str | None:
    if c.op == "EVAL":
        return f"Eval{c.order + 1}" if c.order <= 2 else "EvalN"
    return _KIND_OF.get(c.op)


class Coverage:
    def __init__(self, n_pe: int, pe_per_chip: int = 9):
        self.n = n_pe
        self.chip = pe_per_chip
        self.hits: Counter = Counter()
        self._reset_line()

    def _reset_line(self) -> None:
        n = self.n
        self.prot = np.zeros((4, n), dtype=bool)  # index = register code (1 A, 2 B, 3 C)
        self.dis = np.zeros(n, dtype=bool)

    def _cols(self, c: isa.Command) -> np.ndarray:
        if c.op.startswith("SETP"):
            if c.x >= self.n:
                return np.arange(0)
            step = c.dx if c.dx else 4096
            return np.arange(c.x, self.n, step)
        return np.arange(c.x, min(self.n, c.x + c.dx))

    def add(self, c: isa.Command) -> None:
        if c.op == "REFRESH":
            self._reset_line()
            return
        k = kind(c)
        if k is None:
            return
        cols = self._cols(c)
        h = self.hits
        if c.dx == 0:
            h[(k, "dx0")] += 1
        if c.dx == 1:
            h[(k, "dx1")] += 1
        if len(cols):
            chips = set((cols // self.chip).tolist())
            h[(k, "cross_chip" if len(chips) > 1 else "in_chip")] += 1
            if cols[0] == 0:
                h[(k, "pe0")] += 1
            if cols[-1] == self.n - 1:
                h[(k, "last_pe")] += 1
            if c.op == "EVAL":
                regs = {0: [1], 1: [2, 1], 2: [3, 2, 1]}.get(c.order, [3, 2])
            else:
                regs = [1, 2, 3]
            prot = self.prot[regs][:, cols].any()
            h[(k, "protected" if prot else "unprotected")] += 1
            if self.dis[cols].any():
                h[(k, "disabled")] += 1
        # Update the per-column state (docs/isa.md §6).
        if c.op in isa.SET_REG:
            self.prot[isa.SET_REG[c.op], cols] = True
        elif c.op == "DIS":
            self.dis[cols] = True
        elif c.op in ("EVAL", "EVAL0"):
            self.prot[:, cols] = False
            self.dis[cols] = False

    def add_stream(self, commands) -> "Coverage":
        for c in commands:
            self.add(c)
        return self

    def missing(self) -> list[tuple[str, str]]:
        return [(k, w) for k in KINDS for w in WHERE
                if self.hits[(k, w)] == 0 and not self.impossible(k, w)]

    def report(self) -> str:
        width = max(len(w) for w in WHERE)
        lines = ["command    " + " ".join(f"{w:>{width}}" for w in WHERE)]
        for k in KINDS:
            cells = []
            for w in WHERE:
                n = self.hits[(k, w)]
                cells.append(f"{'n/a' if self.impossible(k, w) else n:>{width}}")
            lines.append(f"{k:<10} " + " ".join(cells))
        miss = self.missing()
        lines.append("all bins hit" if not miss else
                     "NOT HIT: " + ", ".join(f"{k}x{w}" for k, w in miss))
        return "\n".join(lines)

    def impossible(self, k: str, w: str) -> bool:
        """Bins no stream can hit on this array: crossing a chip boundary needs two chips.
        (For SetP*, dX 0 and 1 are real edge cases: 'X only' and 'every column'.)"""
        del k
        return w == "cross_chip" and self.n <= self.chip
