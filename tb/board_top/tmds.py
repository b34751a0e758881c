"""DVI 1.0 TMDS (§3.2.2, Figure 3-5) reference model: encoder, decoder, control tokens.

Written from the specification's flow chart, independently of rtl/board/de_tmds_enc.sv.
Symbols are 10-bit integers whose bit 0 is sent first.
"""
from __future__ import annotations

# Control tokens by (C1, C0) = c, written q_out[9:0].
CTRL = {0b00: 0b1101010100, 0b01: 0b0010101011, 0b10: 0b0101010100, 0b11: 0b1010101011}
CTRL_OF = {v: k for k, v in CTRL.items()}


def n1(v: int) -> int:
    return bin(v & 0xFF).count("1")


class Encoder:
    """One channel; cnt is the running disparity (ones minus zeros sent since blanking)."""

    def __init__(self) -> None:
        self.cnt = 0

    def step(self, de: bool, d: int = 0, c: int = 0) -> int:
        if not de:
            self.cnt = 0
            return CTRL[c]
        bits = [(d >> i) & 1 for i in range(8)]
        q = [bits[0]]
        xnor = n1(d) > 4 or (n1(d) == 4 and bits[0] == 0)
        for i in range(1, 8):
            x = q[i - 1] ^ bits[i]
            q.append(1 - x if xnor else x)
        qm8 = 0 if xnor else 1
        qm = sum(b << i for i, b in enumerate(q))
        ones = n1(qm)
        zeros = 8 - ones
        if self.cnt == 0 or ones == zeros:
            out = ((1 - qm8) << 9) | (qm8 << 8) | (qm if qm8 else (~qm & 0xFF))
            self.cnt += (ones - zeros) if qm8 else (zeros - ones)
        elif (self.cnt > 0 and ones > zeros) or (self.cnt < 0 and zeros > ones):
            out = (1 << 9) | (qm8 << 8) | (~qm & 0xFF)
            self.cnt += 2 * qm8 + (zeros - ones)
        else:
            out = (qm8 << 8) | qm
            self.cnt += -2 * (1 - qm8) + (ones - zeros)
        return out


def decode(sym: int) -> tuple[str, int]:
    """('ctrl', c) for a control token, else ('data', 8-bit value)."""
    if sym in CTRL_OF:
        return "ctrl", CTRL_OF[sym]
    d = sym & 0xFF
    if (sym >> 9) & 1:
        d = ~d & 0xFF
    out = d & 1
    for i in range(1, 8):
        b = ((d >> i) ^ (d >> (i - 1))) & 1
        if not (sym >> 8) & 1:
            b ^= 1
        out |= b << i
    return "data", out


def disparity(sym: int) -> int:
    ones = bin(sym & 0x3FF).count("1")
    return ones - (10 - ones)


def reachable_disparity() -> set[int]:
    """Every running disparity the encoder can reach from blanking (cnt = 0)."""
    seen, todo = {0}, [0]
    while todo:
        c0 = todo.pop()
        for d in range(256):
            e = Encoder()
            e.cnt = c0
            e.step(True, d)
            if e.cnt not in seen:
                seen.add(e.cnt)
                todo.append(e.cnt)
    return seen
