"""Pure-Python model of the board's UART loader, version 2 (rtl/board/de_loader.sv,
docs/board.md §3, docs/sdram-frames-spec.md §3), for testing the host tool without a
board. Imports nothing from cocotb.

LoaderModel.feed(data) consumes host bytes and returns the reply bytes, byte for byte
what the RTL would send: commands 'X' 'F' 'Q' 'O' 'R' 'S', checksum (all bytes of a
command sum to 0 mod 256), replies 'K' / 'E' / 'T', X words written as they arrive into
the colour's SDRAM region (`mem[ch]`, offset -> word), F into `slots[ch]`, Q into
`sequence` (the RTL applies it at the next frame boundary), bytes that are not a command
byte (the retired 'W' and 'P' among them) skipped and counted, status counters
saturating at 0xFFFF. The RTL's command FIFO to the SDRAM side is taken never to be full
(it drains far faster than the UART fills it).
LoaderModel.idle() is the RTL's idle timer: a command that stopped arriving is abandoned
with 'T'.

Device(fd, model, faults) serves the model on one end of a pty or socket pair in a
thread, with injected faults (a corrupted received byte, a swallowed reply, a dropped
link after so many bytes), so the host tool sees a board.
"""
from __future__ import annotations

import os
import select
import threading
import time
from dataclasses import dataclass, field

HEADER = {ord("X"): 6, ord("F"): 7, ord("Q"): 4, ord("O"): 2, ord("R"): 2, ord("S"): 0}
VERSION = 2
REGION_BITS = 21                                # log2 words per colour region
REGION = 1 << REGION_BITS
MAX_X_WORDS = 1024
SLOTS = 64


class LoaderModel:
    def __init__(self, num_chips: int = 1, regs: dict[int, int] | None = None):
        self.num_chips = num_chips
        self.mem: list[dict[int, int]] = [{}, {}, {}]     # per colour: offset -> word
        self.slots: list[dict[int, tuple]] = [{}, {}, {}]  # slot -> (table, window, comp)
        self.sequence: tuple | None = None      # (first, count, hold, loop), last Q
        self.out8 = (0, 1)                      # shift, sat
        self.malformed = self.late = 0          # the SDRAM side's counters (status)
        self.regs = regs or {}
        self.ferr = self.cerr = self.kerr = self.frames = 0
        self.writes = 0                         # words written, for the tests
        self._reset_cmd()

    def _reset_cmd(self):
        self.cmd = None        # None: waiting for a command byte
        self.buf = bytearray()
        self.bad = False

    @staticmethod
    def _inc(v: int) -> int:
        return min(v + 1, 0xFFFF)

    def busy(self) -> bool:
        """A command is incomplete (the RTL's idle timer runs)."""
        return self.cmd is not None

    def idle(self) -> bytes:
        """The command stopped arriving: abandon it, reply 'T'."""
        if self.cmd is None:
            return b""
        self.kerr = self._inc(self.kerr)
        self._reset_cmd()
        return b"T"

    def framing_error(self) -> None:
        """A UART framing error: counted; it spoils the command in progress."""
        self.ferr = self._inc(self.ferr)
        if self.cmd is not None:
            self.bad = True

    def feed(self, data: bytes) -> bytes:
        out = bytearray()
        for b in data:
            out += self._byte(b)
        return bytes(out)

    def _byte(self, b: int) -> bytes:
        if self.cmd is None:
            if b in HEADER:
                self.cmd, self.buf, self.bad = b, bytearray([b]), False
            else:
                self.kerr = self._inc(self.kerr)     # not a command byte: skipped
            return b""
        self.buf.append(b)
        n = len(self.buf) - 1                       # bytes after the command byte
        hdr = HEADER[self.cmd]
        if self.cmd == ord("X") and n >= hdr:
            ch, off, nw = self.buf[1], int.from_bytes(self.buf[2:5], "big"), \
                int.from_bytes(self.buf[5:7], "big")
            if n == hdr and (ch > 2 or off >= REGION or nw == 0 or nw > MAX_X_WORDS):
                self.bad = True
            data_n = n - hdr
            if 0 < data_n <= 4 * nw and data_n % 4 == 0:
                a = off + data_n // 4 - 1
                if not self.bad and a < REGION:
                    self.mem[ch][a] = int.from_bytes(self.buf[-4:], "big")
                    self.writes += 1
                else:
                    self.bad = True
            if data_n < 4 * nw + 1:
                return b""
        elif n < hdr + 1:
            return b""
        return self._complete()

    def _complete(self) -> bytes:
        buf, cmd, bad = bytes(self.buf), self.cmd, self.bad
        self._reset_cmd()
        if sum(buf) & 0xFF:
            self.cerr = self._inc(self.cerr)
            return b"E"
        if bad or self._bad_fields(cmd, buf):
            self.kerr = self._inc(self.kerr)
            return b"E"
        h = buf[1:-1]
        if cmd == ord("F"):
            self.slots[h[0]][h[1]] = (int.from_bytes(h[2:5], "big"), h[5], bool(h[6] & 1))
        elif cmd == ord("Q"):
            self.sequence = (h[0], h[1], h[2], h[3])
        elif cmd == ord("O"):
            self.out8 = (h[0], h[1] & 1)
        elif cmd == ord("R"):
            v = self.regs.get(int.from_bytes(h, "big") & 0x3FFF, 0)
            return b"R" + v.to_bytes(4, "big")
        elif cmd == ord("S"):
            return (b"S" + bytes([VERSION, self.num_chips & 0xFF, REGION_BITS])
                    + b"".join(v.to_bytes(2, "big") for v in
                               (self.ferr, self.cerr, self.kerr, self.frames))
                    + bytes([0, self.out8[1] << 3 | self.out8[0],
                             min(self.malformed, 255), min(self.late, 255)]))
        return b"K"

    @staticmethod
    def _bad_fields(cmd: int, buf: bytes) -> bool:
        h = buf[1:-1]
        if cmd == ord("F"):
            table = int.from_bytes(h[2:5], "big")
            return (h[0] > 2 or h[1] >= SLOTS or table >= REGION or table % 4 != 0
                    or h[5] > 4 or bool(h[6] & 0xFE))
        if cmd == ord("Q"):
            return (h[0] >= SLOTS or not 1 <= h[1] <= SLOTS or h[0] + h[1] > SLOTS
                    or h[2] == 0 or h[3] > 1)
        if cmd == ord("O"):
            return h[0] > 4 or bool(h[1] & 0xFE)
        return False


@dataclass
class Faults:
    """Injected errors, counted in bytes received / replies produced since the start."""
    corrupt_rx: set[int] = field(default_factory=set)    # flip bit 4 of these bytes
    drop_reply: set[int] = field(default_factory=set)    # swallow these replies (0-based)
    drop_link_after: int | None = None                   # close the link after N bytes
    reply_delay: float = 0.0                             # seconds before each reply


class Device:
    """The model behind a file descriptor (pty master or socket), in a thread."""

    def __init__(self, fd: int, model: LoaderModel, faults: Faults | None = None,
                 timeout: float = 0.05):
        self.fd, self.model = fd, model
        self.faults = faults or Faults()
        self.timeout = timeout        # the RTL's 2^TimeoutBits clocks, in seconds
        self.rx_count = self.reply_count = 0
        self.replies: list[bytes] = []
        self.dropped = False
        self._stop = False
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def stop(self) -> None:
        self._stop = True
        self.thread.join(2)

    def _send(self, rep: bytes) -> None:
        if not rep:
            return
        k = self.reply_count
        self.reply_count += 1
        self.replies.append(rep)
        if k in self.faults.drop_reply:
            return
        if self.faults.reply_delay:
            time.sleep(self.faults.reply_delay)
        os.write(self.fd, rep)

    def _run(self) -> None:
        last = time.monotonic()
        while not self._stop:
            r, _, _ = select.select([self.fd], [], [], 0.01)
            if not r:
                if self.model.busy() and time.monotonic() - last > self.timeout:
                    self._send(self.model.idle())
                continue
            try:
                data = os.read(self.fd, 4096)
            except OSError:
                return
            if not data:
                return
            last = time.monotonic()
            f = self.faults
            if not (f.corrupt_rx or f.drop_reply or f.drop_link_after is not None):
                self.rx_count += len(data)      # no fault to place: the whole chunk at once
                self._send(self.model.feed(data))
                continue
            for b in data:
                if self.rx_count in self.faults.corrupt_rx:
                    b ^= 0x10
                self.rx_count += 1
                self._send(self.model.feed(bytes([b])))
                if self.faults.drop_link_after is not None and \
                        self.rx_count >= self.faults.drop_link_after:
                    self.dropped = True
                    os.close(self.fd)
                    return
