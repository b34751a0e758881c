#!/usr/bin/env python3
"""Host side of the board top's UART loader (docs/board.md §3).

    de32_load.py /dev/ttyUSB0 red.de32 green.de32 blue.de32 [--base 0] [--shift 0] [--nosat]
    de32_load.py /dev/ttyUSB0 --status
    de32_load.py /dev/ttyUSB0 --reg 0x3000

Writes each colour's .de32 words into its frame store at --base (24 words per 'W'
command, each acknowledged; a command answered 'E' or 'T' is sent again, up to 3 times),
then the three descriptors ('P': base, length, window and compensation flag from the
.de32 header), then the 8-bit output window ('O'). The descriptors take effect at the
next frame each, so load a new image at another base to switch without tearing.
Needs only the standard library (termios); 115200 baud 8N1, as the bitstream is built.
"""
from __future__ import annotations

import argparse
import os
import struct
import sys
import termios
import time


def with_chk(body: bytes) -> bytes:
    return body + bytes([(-sum(body)) & 0xFF])


def cmd_w(ch: int, addr: int, words: list[int]) -> bytes:
    return with_chk(b"W" + bytes([ch]) + struct.pack(">HH", addr, len(words))
                    + b"".join(struct.pack(">I", w) for w in words))


def cmd_p(ch: int, base: int, n: int, window: int, comp: bool) -> bytes:
    return with_chk(b"P" + bytes([ch]) + struct.pack(">HHBB", base, n, window, int(comp)))


def read_de32(path: str) -> tuple[list[int], int, bool]:
    data = open(path, "rb").read()
    if data[:4] != b"DE32" or len(data) < 8 or (len(data) - 8) % 4:
        sys.exit(f"{path}: not a .de32 file (docs/formats.md §3)")
    n = (len(data) - 8) // 4
    return list(struct.unpack(f">{n}I", data[8:])), data[6], bool(data[7] & 1)


class Port:
    def __init__(self, dev: str, baud: int = 115200):
        self.fd = os.open(dev, os.O_RDWR | os.O_NOCTTY)
        attr = termios.tcgetattr(self.fd)
        speed = getattr(termios, f"B{baud}")
        attr[0] = 0                                   # iflag: raw
        attr[1] = 0                                   # oflag
        attr[2] = termios.CS8 | termios.CREAD | termios.CLOCAL
        attr[3] = 0                                   # lflag: no echo, non-canonical
        attr[4] = attr[5] = speed
        attr[6][termios.VMIN] = 0
        attr[6][termios.VTIME] = 5                    # 0.5 s read timeout
        termios.tcsetattr(self.fd, termios.TCSANOW, attr)
        termios.tcflush(self.fd, termios.TCIOFLUSH)

    def command(self, data: bytes, n_reply: int = 1, tries: int = 3) -> bytes:
        for _ in range(tries):
            os.write(self.fd, data)
            got = b""
            deadline = time.time() + 1.0 + len(data) * 10 / 115200
            while len(got) < n_reply and time.time() < deadline:
                got += os.read(self.fd, n_reply - len(got))
            if got[:1] in (b"K", b"R", b"S") and len(got) == n_reply:
                return got
            time.sleep(0.3)                           # let an abandoned command time out
            termios.tcflush(self.fd, termios.TCIFLUSH)
        sys.exit(f"command {data[:1]!r} failed after {tries} tries (last reply {got!r})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("port")
    ap.add_argument("images", nargs="*", help="red, green, blue .de32 files")
    ap.add_argument("--base", type=lambda s: int(s, 0), default=0)
    ap.add_argument("--shift", type=int, default=0, help="8-bit output window [shift+7:shift]")
    ap.add_argument("--nosat", action="store_true", help="wrap instead of clamping")
    ap.add_argument("--status", action="store_true")
    ap.add_argument("--reg", type=lambda s: int(s, 0))
    a = ap.parse_args()
    port = Port(a.port)
    if a.images:
        if len(a.images) != 3:
            sys.exit("give three .de32 files: red green blue")
        imgs = [read_de32(p) for p in a.images]
        for ch, (words, _, _) in enumerate(imgs):
            for k in range(0, len(words), 24):
                port.command(cmd_w(ch, a.base + k, words[k:k + 24]))
        for ch, (words, window, comp) in enumerate(imgs):
            port.command(cmd_p(ch, a.base, len(words), window, comp))
        port.command(with_chk(b"O" + bytes([a.shift, 0 if a.nosat else 1])))
        print(f"loaded {[len(w) for w, _, _ in imgs]} words at base {a.base}")
    if a.status:
        s = port.command(with_chk(b"S"), 16)
        f = struct.unpack(">HHHH", s[4:12])
        print(f"version {s[1]} chips/colour {s[2]} frame store 2^{s[3]} words; errors: "
              f"framing {f[0]} checksum {f[1]} command {f[2]}; frames {f[3]}; "
              f"flags {s[12]:#04x} (bit0 align_err, 1-3 collision, 4-6 pending); "
              f"output shift {s[13] & 7} sat {s[13] >> 3 & 1}")
    if a.reg is not None:
        r = port.command(with_chk(b"R" + struct.pack(">H", a.reg)), 5)
        print(f"reg {a.reg:#06x} = {struct.unpack('>I', r[1:])[0]:#010x}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
