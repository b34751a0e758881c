"""Structural (cycle-level) golden model of the x-processor array.

This is the model of *how* the hardware computes (docs/xproc.md): every clock, every PE
of the systolic array updates its registers A-D (three 12-bit blocks each), its flags,
its control pipeline, its registered block carries and its registered outputs to the
next PE. The RTL (rtl/xproc/de_pe.sv) has the same registers with the same names and is
compared against this model every cycle (tb/de_pe). `functional.py` is the model of
*what* is computed; both give the same pixels (sw/tests/test_structural.py).

All PEs are updated at once with numpy (a systolic array is one big synchronous state
machine: PE p's inputs this cycle are PE p-1's output registers).

Timing convention (docs/xproc.md §2): a slot whose identifier and block 0 reach a PE in
cycle t has its block j processed there in cycle t+j ("stage j"). `step()` is one clock:
it computes every next-state value from the current registers and the inputs of this
cycle, then commits them all (the clock edge). The pixel output register is loaded in
the Refresh's stage-2 cycle and is visible on the PE's output in the next cycle.
"""
from __future__ import annotations

import numpy as np

from .. import isa

BLK = isa.BLOCK_BITS
M = isa.BLOCK_MASK
N_BLK = isa.BLOCKS

# Register indices in Array.R (index 0 is the "none" operand: always zero, never written).
R_NONE, R_A, R_B, R_C, R_D = 0, 1, 2, 3, 4

# Layout of the RTL's debug vector `dbg_o` (rtl/xproc/de_pe.sv), MSB first. The
# testbench slices the vector with this table and compares it with `Array.state()`.
# Any change here must be mirrored in de_pe.sv (and vice versa).
DBG_FIELDS: list[tuple[str, int]] = isa.DBG_FIELDS  # spec/isa.toml [debug]
DBG_WIDTH = sum(w for _, w in DBG_FIELDS)


def _dec(ident: np.ndarray) -> dict[str, np.ndarray]:
    """Split identifiers into the fields of docs/isa.md §3 (vectorised)."""
    return {
        "addr": (ident & isa.ID_ADDR).astype(bool),
        "data": (ident & isa.ID_DATA).astype(bool),
        "acc": (ident & isa.ID_ACC).astype(bool),
        "ref": (ident & isa.ID_REFRESH).astype(bool),
        "dst": (ident >> isa.DST_SHIFT) & isa.DST_MASK,
        "src": (ident >> isa.SRC_SHIFT) & isa.SRC_MASK,
        "set": (ident & isa.ID_SET).astype(bool),
        "prot": (ident & isa.ID_PROT).astype(bool),
        "sub": ident & isa.SUB_MASK,
    }


def _word(blocks: np.ndarray) -> np.ndarray:
    """(3, n) array of 12-bit blocks -> (n,) uint64 36-bit words."""
    b = blocks.astype(np.uint64)
    return b[0] | (b[1] << np.uint64(BLK)) | (b[2] << np.uint64(2 * BLK))


class Array:
    """A linear array of `n_pe` x-processors, cycle by cycle.

    `step(ident, data)` presents one instruction (12-bit identifier, 36-bit data, in
    unskewed form) at the array input and advances one clock. The input skew
    (block j enters PE 0 j cycles after the identifier) is applied here by three
    registers in front of PE 0, as the array top's input skew does in hardware.
    """

    def __init__(self, n_pe: int, carry_bug: bool = False):
        if n_pe < 1:
            raise ValueError("n_pe must be >= 1")
        self.n = int(n_pe)
        self.bug = bool(carry_bug)
        # The carry fault as spec/isa.toml [adder] gives it (de_pkg::blk_carry_in): the
        # registered carry into the block that holds bit ADD_CARRY_FROM enters it at bit
        # ADD_CARRY_TO - ADD_CARRY_FROM instead of bit 0. Only into the top block: below
        # it the weighted carry could carry 2 out, which a one-bit block carry cannot hold
        # (de_pe refuses the same, g_bad_carry_blk).
        fault_blk, off = divmod(isa.ADD_CARRY_FROM, BLK)
        if off or fault_blk != N_BLK - 1:
            raise ValueError(f"structural: the carry fault must enter the top block at a block "
                             f"boundary, got ADD_CARRY_FROM = {isa.ADD_CARRY_FROM}")
        self.cin2_weight = 1 << (isa.ADD_CARRY_TO - isa.ADD_CARRY_FROM) if self.bug else 1
        self.reset()

    # ---- state -----------------------------------------------------------------
    def reset(self) -> None:
        """Synchronous reset: every register of every PE (and the input skew) to 0."""
        n = self.n
        zi = lambda: np.zeros(n, dtype=np.int64)  # noqa: E731
        zb = lambda: np.zeros(n, dtype=bool)  # noqa: E731
        self.cycle = 0
        # Architectural registers: R[r, j, p] = block j of register r of PE p.
        self.R = np.zeros((5, N_BLK, n), dtype=np.int64)
        self.P = np.zeros((4, n), dtype=bool)  # protect flags, index = register code
        self.dis, self.lock, self.acc_mode, self.act = zb(), zb(), zb(), zb()
        # Registered outputs to the next PE (= stage-1 identifier, skewed data blocks).
        self.id1 = zi()
        self.out = np.zeros((N_BLK, n), dtype=np.int64)
        # Control pipeline.
        self.id2 = zi()
        self.xz1, self.act1, self.prot1, self.c1 = zb(), zb(), zb(), zb()
        self.act2, self.prot2, self.c2 = zb(), zb(), zb()
        self.e0wr2 = zb()
        self.accen2, self.accc2, self.accen3, self.accc3 = zb(), zb(), zb(), zb()
        # Pixel output register.
        self.pix_valid = zb()
        self.pix = zi()
        # Input skew in front of PE 0: block 1 one cycle late, block 2 two cycles late.
        self.sk1 = 0
        self.sk2a = 0
        self.sk2b = 0
        self.events: list[tuple[int, int, int]] = []

    def state(self) -> dict[str, np.ndarray]:
        """Snapshot of every register of every PE, keyed as DBG_FIELDS (copies)."""
        s = {
            "A": _word(self.R[R_A]), "B": _word(self.R[R_B]), "C": _word(self.R[R_C]),
            "D": _word(self.R[R_D]),
            "pA": self.P[1].copy(), "pB": self.P[2].copy(), "pC": self.P[3].copy(),
            "dis": self.dis.copy(), "lock": self.lock.copy(),
            "acc_mode": self.acc_mode.copy(), "act": self.act.copy(),
            "id1": self.id1.copy(), "id2": self.id2.copy(), "out": _word(self.out),
            "xz1": self.xz1.copy(), "act1": self.act1.copy(), "prot1": self.prot1.copy(),
            "c1": self.c1.copy(), "act2": self.act2.copy(), "prot2": self.prot2.copy(),
            "c2": self.c2.copy(), "e0wr2": self.e0wr2.copy(),
            "accen2": self.accen2.copy(), "accc2": self.accc2.copy(),
            "accen3": self.accen3.copy(), "accc3": self.accc3.copy(),
            "pix_valid": self.pix_valid.copy(), "pix": self.pix.copy(),
        }
        return s

    def packed_state(self) -> list[int]:
        """Per PE, the state packed exactly like the RTL's dbg_o (DBG_FIELDS, MSB first)."""
        s = self.state()
        cols = [(s[name].astype(np.uint64).tolist(), w) for name, w in DBG_FIELDS]
        out = []
        for p in range(self.n):
            v = 0
            for vals, w in cols:
                v = (v << w) | (int(vals[p]) & ((1 << w) - 1))
            out.append(v)
        return out

    # ---- one clock ---------------------------------------------------------------
    def step(self, ident: int, data: int) -> None:
        n = self.n
        idx = np.arange(n)
        R, P = self.R, self.P
        cin2_weight = self.cin2_weight  # the §7.7 fault (spec/isa.toml; __init__)

        # PE inputs: PE 0 from the array input (+ skew), PE p from PE p-1's registers.
        in_id = np.empty(n, dtype=np.int64)
        in_id[0] = ident & isa.ID_MASK
        in_id[1:] = self.id1[:-1]
        inb = np.empty((N_BLK, n), dtype=np.int64)
        inb[0, 0] = data & M
        inb[1, 0] = self.sk1
        inb[2, 0] = self.sk2b
        inb[:, 1:] = self.out[:, :-1]

        d0, d1, d2 = _dec(in_id), _dec(self.id1), _dec(self.id2)

        # ---- stage 1, address slot: the "fire" decision (needs block 1 = dX / count)
        a1 = d1["addr"]
        per1 = a1 & (d1["sub"] == isa.SUB_PERIODIC)
        x1 = inb[1]
        fire_per = x1 == 0
        fire_rng = self.xz1 & (x1 != 0)
        fire1 = a1 & np.where(per1, fire_per, fire_rng)
        # act as seen by the slot at stage 0: an address slot one cycle ahead decides it.
        act_eff = np.where(a1, fire1, self.act)

        # ---- stage 0: identifier + block 0 --------------------------------------
        ev0 = d0["data"] & ~d0["set"]
        st0 = d0["data"] & d0["set"]
        dst0, src0 = d0["dst"], d0["src"]
        rng0 = d0["addr"] & (d0["sub"] != isa.SUB_PERIODIC)
        x0 = inb[0]
        xz0 = x0 == 0
        prot0 = ev0 & act_eff & d0["prot"] & P[dst0, idx]
        active0 = ev0 & act_eff
        v0 = np.where(prot0, R[dst0, 0, idx], inb[0])
        s0 = v0 + R[src0, 0, idx]
        out0 = np.where(rng0, np.where(xz0, 0, (x0 - 1) & M), inb[0])
        out0 = np.where(active0, s0 & M, out0)
        c1_d = active0 & ((s0 >> BLK) != 0)
        wr0 = (ev0 | st0) & act_eff & (dst0 != R_NONE)

        # ---- stage 1: block 1 ---------------------------------------------------
        ev1 = d1["data"] & ~d1["set"]
        st1 = d1["data"] & d1["set"]
        dst1, src1 = d1["dst"], d1["src"]
        active1 = ev1 & self.act1
        v1 = np.where(self.prot1, R[dst1, 1, idx], x1)
        s1 = v1 + R[src1, 1, idx] + self.c1
        # out_q block 0 still holds the period P of a periodic slot (passed unchanged).
        out1 = np.where(per1, np.where(fire_per, (self.out[0] - 1) & M, (x1 - 1) & M),
                        np.where(a1 & fire_rng, (x1 - 1) & M, x1))
        out1 = np.where(active1, s1 & M, out1)
        c2_d = active1 & ((s1 >> BLK) != 0)
        wr1 = (ev1 | st1) & self.act1 & (dst1 != R_NONE)
        dis1 = a1 & (d1["sub"] == isa.SUB_DIS) & fire1
        e0_1 = a1 & (d1["sub"] == isa.SUB_EVAL0) & fire1
        e0en = e0_1 & ~self.lock & ~self.dis

        # ---- stage 2: block 2 ---------------------------------------------------
        ev2 = d2["data"] & ~d2["set"]
        st2 = d2["data"] & d2["set"]
        dst2, src2 = d2["dst"], d2["src"]
        active2 = ev2 & self.act2
        v2 = np.where(self.prot2, R[dst2, 2, idx], inb[2])
        s2 = v2 + R[src2, 2, idx] + cin2_weight * self.c2
        out2 = np.where(active2, s2 & M, inb[2])
        wr2 = (ev2 | st2) & self.act2 & (dst2 != R_NONE)
        ref0, ref1, ref2 = d0["ref"], d1["ref"], d2["ref"]

        # Next value of A block 2 (sign of the intensity the ACC at stage 1 adds).
        a2_next = np.where(ref2, 0, np.where(wr2 & (dst2 == R_A), v2, R[R_A, 2]))
        a_neg = (a2_next >> (BLK - 1)) & 1 != 0

        # ---- accumulator: ACC decided at stage 1, D block j written at stage j+1 -
        acc_act1 = d1["acc"] & self.act1
        accen1 = acc_act1 & ~self.lock & ~self.dis & ~(self.acc_mode & a_neg)
        sa0 = R[R_D, 0] + R[R_A, 0]
        sa1 = R[R_D, 1] + R[R_A, 1] + self.accc2
        sa2 = R[R_D, 2] + R[R_A, 2] + cin2_weight * self.accc3
        accc2_d = accen1 & ((sa0 >> BLK) != 0)
        accc3_d = self.accen2 & ((sa1 >> BLK) != 0)
        # D next value before a Refresh clear; priority Eval0 > ACC (stream order).
        dn0 = np.where(self.e0wr2, 0, np.where(accen1, sa0 & M, R[R_D, 0]))
        dn1 = np.where(self.e0wr2, 0, np.where(self.accen2, sa1 & M, R[R_D, 1]))
        dn2 = np.where(self.e0wr2, inb[2], np.where(self.accen3, sa2 & M, R[R_D, 2]))

        # ---- register next state --------------------------------------------------
        Rn = R.copy()
        Rn[dst0[wr0], 0, idx[wr0]] = v0[wr0]
        Rn[dst1[wr1], 1, idx[wr1]] = v1[wr1]
        Rn[dst2[wr2], 2, idx[wr2]] = v2[wr2]
        Rn[R_D, 0], Rn[R_D, 1], Rn[R_D, 2] = dn0, dn1, dn2
        # A Refresh clears block j of A-D in its stage j; a clear wins over any write.
        Rn[1:, 0, ref0] = 0
        Rn[1:, 1, ref1] = 0
        Rn[1:, 2, ref2] = 0

        # ---- flags: stage-1 writes first, stage-0 writes (later in stream) win ----
        Pn = P.copy()
        dis_n = self.dis | dis1
        lock_n = self.lock | e0en
        clr1 = e0_1 | acc_act1
        Pn[:, clr1] = False
        dis_n = dis_n & ~clr1
        setp = st0 & act_eff & (dst0 != R_NONE)
        Pn[dst0[setp], idx[setp]] = True
        no_class0 = ~(d0["addr"] | d0["data"] | d0["acc"] | d0["ref"])
        am_on = no_class0 & (d0["sub"] == isa.SUB_ACCMODE_ON)
        am_off = no_class0 & (d0["sub"] == isa.SUB_ACCMODE_OFF)
        accm_n = (self.acc_mode | am_on) & ~am_off
        Pn[:, ref0] = False
        dis_n = dis_n & ~ref0
        lock_n = lock_n & ~ref0
        accm_n = accm_n & ~ref0
        act_n = (d0["data"] | d0["acc"]) & act_eff

        # ---- commit (the clock edge) -----------------------------------------------
        self.R, self.P = Rn, Pn
        self.dis, self.lock, self.acc_mode, self.act = dis_n, lock_n, accm_n, act_n
        self.id2 = self.id1
        self.id1 = in_id
        self.out = np.stack([out0, out1, out2])
        self.xz1 = rng0 & xz0
        self.act2, self.prot2, self.c2 = self.act1, self.prot1, c2_d
        self.act1, self.prot1, self.c1 = act_eff.copy(), prot0, c1_d
        self.e0wr2 = e0en
        self.accen3, self.accc3 = self.accen2, accc3_d
        self.accen2, self.accc2 = accen1, accc2_d
        # Pixel register: D block 2 as it is at the end of this cycle without the
        # Refresh's own clear (forwards an ACC/Eval0 write of the same cycle); 0 when
        # not valid so that a chip may OR its PEs' pixel outputs.
        self.pix_valid = ref2.copy()
        self.pix = np.where(ref2, dn2, 0)
        self.sk2b, self.sk2a, self.sk1 = self.sk2a, (data >> 2 * BLK) & M, (data >> BLK) & M
        if ref2.any():
            for p in np.flatnonzero(ref2).tolist():
                self.events.append((self.cycle, p, int(self.pix[p])))
        self.cycle += 1

    def run(self, slots) -> None:
        for ident, data in slots:
            self.step(ident, data)

    def flush(self) -> None:
        """Nops until every slot already fed has left the last PE's pixel stage."""
        for _ in range(self.n + N_BLK):
            self.step(isa.NOP, 0)


def render(commands, n_pe: int, carry_bug: bool = False) -> np.ndarray:
    """Run a command list through the array; one row of n_pe pixels per Refresh.

    Rows come from the pixel events of each PE in order (PE p's k-th pixel belongs to
    the k-th Refresh), so back-to-back Refreshes are fine here even though a shared
    pixel bus would need them n_pe slots apart (docs/xproc.md §7).
    """
    cmds = list(commands)
    arr = Array(n_pe, carry_bug)
    arr.run(isa.serialise(cmds))
    arr.flush()
    n_lines = sum(1 for c in cmds if c.op == "REFRESH")
    out = np.zeros((n_lines, n_pe), dtype=np.uint16)
    seen = np.zeros(n_pe, dtype=np.int64)
    for _, p, v in arr.events:
        out[seen[p], p] = v
        seen[p] += 1
    assert (seen == n_lines).all(), "every PE outputs one pixel per Refresh"
    return out


# ---- random well-formed command streams (shared by sw/tests and tb/de_pe) ------------

def random_value(rng: np.random.Generator) -> int:
    """A signed 12.24 intensity: mostly small, sometimes full-range or near a carry."""
    k = rng.integers(0, 6)
    if k == 0:
        return int(rng.integers(-(1 << (isa.WORD_BITS - 1)), 1 << (isa.WORD_BITS - 1)))
    if k == 1:  # fraction near the block-1 -> block-2 carry boundary
        return (int(rng.integers(-(1 << isa.FRAC_BITS), 1 << isa.FRAC_BITS))
                | int(rng.integers(0, 2)) * (M << BLK))
    if k == 2:  # block-0 -> block-1 carry boundary
        return int(rng.integers(-(1 << (BLK + 1)), 1 << (BLK + 1))) + M * int(rng.integers(0, 2))
    if k == 3:
        return 0
    return int(rng.integers(-(1 << 30), 1 << 30))


def random_commands(rng: np.random.Generator, n_pe: int, count: int,
                    max_order: int = isa.MAX_EVAL_ORDER, refresh_every: int = 12):
    """`count` random well-formed commands for an n_pe array, ending with a Refresh."""
    cmds: list[isa.Command] = []
    span = n_pe + 3

    def xdx():
        x = int(rng.integers(0, span))
        dx = int(rng.integers(0, span)) if rng.random() < 0.9 else int(rng.integers(0, 4096))
        return x, dx

    for _ in range(count):
        r = rng.random()
        if r < 0.30:
            x, dx = xdx()
            order = int(rng.integers(0, max_order + 1))
            vals = tuple(random_value(rng) for _ in range(order + 1))
            cmds.append(isa.Command("EVAL", x, dx, vals))
        elif r < 0.40:
            x, dx = xdx()
            cmds.append(isa.Command("EVAL0", x, dx, (int(rng.integers(0, 4096)),)))
        elif r < 0.55:
            x, dx = xdx()
            op = ("SETI", "SETDI", "SETDDI")[int(rng.integers(0, 3))]
            cmds.append(isa.Command(op, x, dx, (random_value(rng),)))
        elif r < 0.62:
            x = int(rng.integers(0, span))
            dx = int(rng.integers(0, 5))
            op = ("SETPI", "SETPDI", "SETPDDI")[int(rng.integers(0, 3))]
            cmds.append(isa.Command(op, x, dx, (random_value(rng),)))
        elif r < 0.72:
            x, dx = xdx()
            cmds.append(isa.Command("DIS", x, dx))
        elif r < 0.80:
            cmds.append(isa.Command("ACCMODE", values=(int(rng.integers(0, 2)),)))
        elif r < 0.85:
            cmds.append(isa.Command("NOP"))
        elif r < 0.85 + 1.0 / refresh_every:
            cmds.append(isa.Command("REFRESH"))
        else:
            x, dx = xdx()
            order = int(rng.integers(0, min(2, max_order) + 1))
            vals = tuple(random_value(rng) for _ in range(order + 1))
            cmds.append(isa.Command("EVAL", x, dx, vals))
    cmds.append(isa.Command("REFRESH"))
    return cmds
