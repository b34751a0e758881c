#!/usr/bin/env python3
"""Load a scene and its animation into the board over the UART loader (docs/board.md §3).

    de32_load.py PORT SCENE [--anim DIR] [--window W --round] [--gain G] [--shift S]
                 [--hold N] [--resume]
    de32_load.py PORT r.de32 g.de32 b.de32 [--shift 0] [--nosat]
    de32_load.py PORT --status | --reg 0x3000

SCENE is what `make demo` writes (a directory with r/g/b .de48 streams, e.g.
out/demo_cmd) or three r g b files (.de32 frame-store images or .de48 streams);
--anim adds every frame of a `make anim` output directory (frame000/ and the
frameNNN.delta files). The frames go into the board's SDRAM as tables of lines
(loader version 2, docs/sdram-frames-spec.md; fpga/ulx3s/frame_pack.py): each colour's
line blocks are stored once however many frames share them ('X'), each frame is a slot
('F': its table, window, compensation), and the sequence ('Q') plays the frames in
order, --hold display frames each, in a loop (--no-loop: stop on the last); --show F
plays frame F alone. The output window ('O') is set last. .de48 streams are turned
into frame-store words at DAC window --window; with --round, operands are rounded to
that window's grid (otherwise a value the frame store cannot hold is an error naming
the file and slot). The 27-bit operand holds intensities below 2^(w+6) pixel units:
`make demo`'s 12-bit scenes need --window 4 --round --gain 1 (intensities halved) and
the output window --shift 3 to show the 8 bits `make demo` shows; an operand clamped
to the range is reported (the frame would not look like the stream).

Link: 3,000,000 baud 8N1 (--baud), the FT231X's maximum, as the bitstream is built.
Every packet is answered: 'K' next packet; 'E' (checksum or field error) or 'T' (the
board abandoned an incomplete command) or no reply within the timeout: wait until the
board has abandoned any partial command, flush, re-send the same packet (writes are
idempotent), up to --retries times. After each acknowledged packet the state file
(--state) records how far the load got; if the link drops or the retries run out, the
tool stops with status 2 and `--resume` (same arguments) restarts from the last
acknowledged packet. On a terminal a progress bar shows bytes, rate and ETA; otherwise
a progress line is printed every 5 s.
Needs only the standard library for .de32 files (termios); .de48 and animations use
diffengine.formats (sw/).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import select
import struct
import sys
import termios
import time
from pathlib import Path

BAUD = 3_000_000
ABANDON_S = 0.3          # > the loader's 2^22 pixel clocks (168 ms) of idle timeout
PACKET_WORDS = 256       # words per 'X' (the loader takes 1..1024)
MAX_PACKET_WORDS = 1024
VERSION = 2              # the loader protocol this tool speaks ('S' byte 1)


class LoadError(Exception):
    """Bad input or a failed load; the message names the file (and line/slot/byte)."""


class LinkDropped(LoadError):
    pass


# ---------------------------------------------------------------------------- packets
def with_chk(body: bytes) -> bytes:
    return body + bytes([(-sum(body)) & 0xFF])


def cmd_x(ch: int, off: int, words: list[int]) -> bytes:
    """Write words into colour ch's SDRAM region from word offset off (loader v2)."""
    return with_chk(b"X" + bytes([ch]) + off.to_bytes(3, "big") + struct.pack(">H", len(words))
                    + b"".join(struct.pack(">I", w) for w in words))


def cmd_f(ch: int, slot: int, table: int, window: int, comp: bool) -> bytes:
    """Frame slot `slot` of colour ch: its table at word offset `table` (loader v2)."""
    return with_chk(b"F" + bytes([ch, slot]) + table.to_bytes(3, "big")
                    + bytes([window, int(comp)]))


def cmd_q(first: int, count: int, hold: int, loop: bool) -> bytes:
    """Play slots first .. first+count-1, hold frames each, from the next frame boundary."""
    return with_chk(b"Q" + bytes([first, count, hold, int(loop)]))


def cmd_o(shift: int, sat: bool) -> bytes:
    return with_chk(b"O" + bytes([shift, int(sat)]))


# ---------------------------------------------------------------------------- inputs
Image = tuple  # (words, window, compensate)


def read_de32(path: str) -> Image:
    data = Path(path).read_bytes()
    if data[:4] != b"DE32":
        raise LoadError(f"{path}:byte 0: not a .de32 file (docs/formats.md §3)")
    if len(data) < 8 or (len(data) - 8) % 4:
        raise LoadError(f"{path}:byte {len(data)}: truncated .de32 (header 8 bytes, then "
                        "4-byte words)")
    if data[6] > 4:
        raise LoadError(f"{path}:byte 6: window {data[6]} outside 0..4")
    n = (len(data) - 8) // 4
    return list(struct.unpack(f">{n}I", data[8:])), data[6], bool(data[7] & 1)


def round_slot(ident: int, data: int, window: int, gain: int = 0) -> tuple[int, bool]:
    """The 36-bit data of a slot, its intensity divided by 2^gain, rounded to the nearest
    value the frame store holds at `window`; and whether it had to be clamped to the
    store's range (Eval0 fields: 7 bits at pixel bits [w+6:w]; intensity operands:
    |v| < 2^(w+6) pixel units, docs/formats.md §3)."""
    from diffengine import isa
    typ = isa.ID_TYPE[ident]
    if typ == isa.TYPE_ADDR:
        b2 = data >> 24
        v = b2 - (1 << 12) if b2 & 0x800 else b2
        sh = window + gain
        q = (v + (1 << sh >> 1)) >> sh
        c = max(-64, min(63, q))
        return (data & 0xFFFFFF) | ((c << window) & 0xFFF) << 24, c != q
    if typ != isa.TYPE_NONE:
        low = 4 + window
        q = (isa.to_signed(data) + (1 << (low + gain - 1))) >> (low + gain)
        c = max(-(1 << 26), min((1 << 26) - 1, q))
        return isa.to_word(c << low), c != q
    return data, False


def de48_image(data: bytes, name: str, window: int, rnd: bool, gain: int = 0) -> Image:
    """A .de48 stream -> frame-store words at `window` (docs/formats.md §3). With `gain`
    G > 0 every intensity is divided by 2^G first (and rounded, as with `rnd`): the
    scenes' 12-bit intensities need G = 1 at window 4, shown with output shift 4 - G.
    Operands clamped to the store's range are counted and reported on stderr: such a
    frame does not look like its stream."""
    from diffengine import isa
    from diffengine.formats import binfmt
    from diffengine.formats.asm import AsmError
    try:
        slots = binfmt.decode_de48(data, name)
    except AsmError as e:
        raise LoadError(str(e)) from None
    if not 0 <= gain <= 3:
        raise LoadError(f"{name}: --gain {gain} outside 0..3")
    words, clamped = [], 0
    for k, (ident, d) in enumerate(slots):
        if rnd or gain:
            d, cl = round_slot(ident, d, window, gain)
            clamped += cl
        try:
            words.append(isa.LUT_INDEX[ident] << binfmt.OPERAND_BITS
                         | binfmt._fs_operand(ident, d, window))
        except (ValueError, KeyError) as e:
            raise LoadError(f"{name}:slot {k}: {e} (give --round, or another --window)") \
                from None
    if clamped:
        hint = (f"give --gain {gain + 1}, shown with --shift {max(0, 3 - gain)}" if gain < 3
                else "no gain avoids it at this window: give a higher --window")
        print(f"de32_load: {name}: {clamped:,} of {len(slots):,} operands clamped to the "
              f"frame store's range at window {window}, gain {gain}: the frame will not look "
              f"like the stream ({hint})", file=sys.stderr)
    return words, window, False


def read_image(path: str, window: int | None, rnd: bool, gain: int = 0) -> Image:
    head = Path(path).read_bytes()[:4]
    if head == b"DE32":
        return read_de32(path)
    if head == b"DE48":
        if window is None:
            raise LoadError(f"{path}:byte 0: a .de48 stream needs --window (0..4)")
        return de48_image(Path(path).read_bytes(), path, window, rnd, gain)
    raise LoadError(f"{path}:byte 0: neither .de32 nor .de48 (docs/formats.md)")


def scene_files(paths: list[str]) -> list[str]:
    """The r, g, b files of a scene: a directory's r/g/b .de32 or .de48, or three files."""
    for p in paths:
        if not Path(p).exists():
            raise LoadError(f"{p}: no such file or directory")
    if len(paths) == 1 and Path(paths[0]).is_dir():
        d = Path(paths[0])
        files = []
        for c in "rgb":
            f = next((d / f"{c}{s}" for s in (".de32", ".de48") if (d / f"{c}{s}").exists()),
                     None)
            if f is None:
                raise LoadError(f"{d}: no {c}.de32 or {c}.de48 (make demo writes out/demo_cmd)")
            files.append(str(f))
        paths = files
    if len(paths) != 3:
        raise LoadError("give a scene directory or three files: red green blue")
    return list(paths)


def read_scene(paths: list[str], window, rnd, gain: int = 0) -> list[Image]:
    return [read_image(p, window, rnd, gain) for p in scene_files(paths)]


def anim_dir(d: str) -> Path:
    """The directory holding frame000/ and the deltas: `make anim`'s out/anim keeps them
    in streams/ (diffengine anim), `yproc anim -o DIR` in DIR itself."""
    p = Path(d)
    if not (p / "frame000").is_dir() and (p / "streams" / "frame000").is_dir():
        p = p / "streams"
    if not (p / "frame000").is_dir():
        raise LoadError(f"{d}: no frame000/ nor streams/frame000/ (make anim writes "
                        "out/anim/streams)")
    return p


def anim_files(d: str, n: int) -> list[list[str]]:
    """[f][c]: the file each frame's colour comes from (frame 0's .de48, then the delta)."""
    p = anim_dir(d)
    return [[str(p / "frame000" / f"{c}.de48") if f == 0 else str(p / f"frame{f:03d}.delta")
             for c in "rgb"] for f in range(n)]


def read_anim(d: str, window, rnd, gain: int = 0) -> list[list[Image]]:
    from diffengine.pipeline import anim
    if window is None:
        raise LoadError(f"{d}: an animation's .de48 streams need --window (0..4)")
    p = anim_dir(d)
    try:
        seq = anim.frames(p)
    except ValueError as e:
        raise LoadError(f"{p}: {e}") from None
    return [[de48_image(anim.to_de48(ch), f"{p}/frame{f:03d} {'rgb'[c]}", window, rnd, gain)
             for c, ch in enumerate(fr)] for f, fr in enumerate(seq)]


# ---------------------------------------------------------------------------- the plan
def plan_packets(frames: list[list[Image]], words: int, shift: int, sat: bool,
                 region_bits: int = 21, hold: int = 1, show: int | None = None,
                 loop: bool = True, names: list[list[str]] | None = None):
    """Every packet in order ('X' runs of at most `words` words, 'F' per frame and
    colour, 'Q', 'O'), and the frame_pack.Plan they come from. names[f][c]: the file
    frame f's colour c came from, named first in a packer error."""
    import frame_pack
    lines = sum(1 for w in frames[0][0][0] if frame_pack.is_marker(w))
    try:
        plan = frame_pack.pack(frames, lines, hold=hold, loop=loop and len(frames) > 1,
                               region_words=1 << region_bits)
    except frame_pack.PackError as e:
        f, c = getattr(e, "frame", None), getattr(e, "colour", None)
        if names is not None and f is not None and c is not None:
            raise LoadError(f"{names[f][c]}: {e}") from None
        raise LoadError(str(e)) from None
    pkts = []
    for ch, off, ws in plan.writes:
        for k in range(0, len(ws), words):
            pkts.append(cmd_x(ch, off + k, ws[k:k + words]))
    for ch, slot, toff, window, comp in plan.slots:
        pkts.append(cmd_f(ch, slot, toff, window, comp))
    first, count, hold, lp = plan.sequence
    if show is not None:
        if not 0 <= show < count:
            raise LoadError(f"--show {show}: there are {count} frames")
        first, count, hold, lp = first + show, 1, 1, 0
    pkts.append(cmd_q(first, count, hold, bool(lp)))
    pkts.append(cmd_o(shift, sat))
    return pkts, plan


def plan_hash(pkts: list[bytes]) -> str:
    h = hashlib.sha256()
    for p in pkts:
        h.update(p)
    return h.hexdigest()


class State:
    """The small state file: which load (plan hash) and how many packets are acknowledged."""

    def __init__(self, path: str, digest: str, n: int):
        self.path, self.digest, self.n = path, digest, n
        self.acked = 0
        self._saved = 0.0

    def load(self) -> int:
        try:
            text = Path(self.path).read_text()
        except FileNotFoundError:
            raise LoadError(f"{self.path}: no state file to resume from") from None
        try:
            st = json.loads(text)
        except json.JSONDecodeError as e:
            raise LoadError(f"{self.path}:{e.lineno}: {e.msg}") from None
        if st.get("plan") != self.digest or st.get("packets") != self.n:
            raise LoadError(f"{self.path}:1: written for another load (other files or "
                            "options); run without --resume")
        a = st.get("acked")
        if not isinstance(a, int) or not 0 <= a <= self.n:
            raise LoadError(f"{self.path}:1: bad 'acked' {a!r}")
        self.acked = a
        return a

    def save(self, force: bool = False) -> None:
        now = time.monotonic()
        if not force and now - self._saved < 0.5:
            return
        tmp = self.path + ".tmp"
        Path(tmp).write_text(json.dumps({"version": 1, "plan": self.digest,
                                         "packets": self.n, "acked": self.acked}) + "\n")
        os.replace(tmp, self.path)
        self._saved = now


# ---------------------------------------------------------------------------- the link
class Port:
    """A serial port (or pty / socket: any file descriptor) in raw 8N1."""

    def __init__(self, dev: str | int, baud: int = BAUD):
        self.fd = dev if isinstance(dev, int) else os.open(dev, os.O_RDWR | os.O_NOCTTY)
        self.baud = baud
        if os.isatty(self.fd):
            attr = termios.tcgetattr(self.fd)
            speed = getattr(termios, f"B{baud}", None)
            if speed is None:
                raise LoadError(f"--baud {baud}: not a termios speed on this system")
            attr[0] = 0                                   # iflag: raw
            attr[1] = 0                                   # oflag
            attr[2] = termios.CS8 | termios.CREAD | termios.CLOCAL
            attr[3] = 0                                   # lflag: no echo, non-canonical
            attr[4] = attr[5] = speed
            attr[6][termios.VMIN] = 0
            attr[6][termios.VTIME] = 0
            termios.tcsetattr(self.fd, termios.TCSANOW, attr)
            termios.tcflush(self.fd, termios.TCIOFLUSH)

    def write(self, data: bytes) -> None:
        try:
            while data:
                n = os.write(self.fd, data)
                data = data[n:]
        except OSError as e:
            raise LinkDropped(f"link dropped while sending ({e.strerror})") from None

    def read(self, n: int, timeout: float) -> bytes:
        got, end = b"", time.monotonic() + timeout
        while len(got) < n:
            left = end - time.monotonic()
            if left <= 0:
                break
            r, _, _ = select.select([self.fd], [], [], left)
            if not r:
                break
            try:
                b = os.read(self.fd, n - len(got))
            except OSError as e:
                raise LinkDropped(f"link dropped while waiting for a reply ({e.strerror})") \
                    from None
            if not b:
                raise LinkDropped("link dropped while waiting for a reply (end of file)")
            got += b
        return got

    def drain(self) -> None:
        while self.read(4096, 0.0):
            pass


class Loader:
    def __init__(self, port: Port, retries: int = 5, abandon: float = ABANDON_S,
                 log=None):
        self.port, self.retries, self.abandon = port, retries, abandon
        self.resent = 0
        self.log = log or (lambda msg: None)

    def command(self, pkt: bytes, n_reply: int = 1) -> bytes:
        want = {ord("R"): b"R", ord("S"): b"S"}.get(pkt[0], b"K")
        timeout = 0.2 + len(pkt) * 10 / self.port.baud
        last = b""
        for t in range(self.retries + 1):
            if t:
                self.resent += 1
                self.log(f"packet {chr(pkt[0])} re-sent (try {t + 1}): "
                         f"{'no reply' if not last else 'reply ' + repr(last)}")
                time.sleep(self.abandon)              # a partial command is abandoned
                self.port.drain()
            self.port.write(pkt)
            last = self.port.read(n_reply, timeout)
            if last[:1] == want and len(last) == n_reply:
                return last
        raise LoadError(f"packet {chr(pkt[0])} failed after {self.retries + 1} tries "
                        f"(last reply {last!r})")


class Progress:
    def __init__(self, total: int, stream=sys.stderr, start: int = 0):
        self.total, self.stream, self.done = total, stream, start
        self.t0, self.d0 = time.monotonic(), start
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self._last = 0.0

    def line(self) -> str:
        dt = max(time.monotonic() - self.t0, 1e-9)
        rate = (self.done - self.d0) / dt
        eta = (self.total - self.done) / rate if rate > 0 else float("inf")
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(frac * 30)
        eta_s = "--:--" if eta == float("inf") else f"{int(eta) // 60}:{int(eta) % 60:02d}"
        return (f"[{bar:<30}] {frac * 100:5.1f}% {self.done / 1e3:,.1f}/{self.total / 1e3:,.1f} kB "
                f"{rate / 1e3:,.1f} kB/s ETA {eta_s}")

    def update(self, n: int) -> None:
        self.done += n
        now = time.monotonic()
        if now - self._last < (0.1 if self.tty else 5.0):
            return
        self._last = now
        self.stream.write(("\r" + self.line()) if self.tty else self.line() + "\n")
        self.stream.flush()

    def finish(self) -> None:
        self.stream.write(("\r" + self.line() + "\n") if self.tty else self.line() + "\n")
        self.stream.flush()


def run_plan(loader: Loader, pkts: list[bytes], state: State, start: int,
             stream=sys.stderr) -> None:
    total = sum(len(p) for p in pkts)
    prog = Progress(total, stream, start=sum(len(p) for p in pkts[:start]))
    state.acked = start
    try:
        for k in range(start, len(pkts)):
            loader.command(pkts[k])
            state.acked = k + 1
            state.save()
            prog.update(len(pkts[k]))
    finally:
        state.save(force=True)
    prog.finish()


# ---------------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 2)[2],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("port", help="serial device (/dev/ttyUSB0) of the board's FT231X")
    ap.add_argument("scene", nargs="*", help="scene directory, or r g b files (.de32/.de48)")
    ap.add_argument("--anim", help="make anim output directory: load all its frames too")
    ap.add_argument("--window", type=int, choices=range(5), help="DAC window for .de48")
    ap.add_argument("--round", action="store_true", help="round .de48 operands to the window")
    ap.add_argument("--gain", type=int, default=0, choices=range(4),
                    help="divide .de48 intensities by 2^GAIN first, rounded: make demo's "
                         "12-bit scenes need 1 at window 4, shown with --shift 3 (0)")
    ap.add_argument("--show", type=int, help="play this frame alone (default: all, in order)")
    ap.add_argument("--hold", type=int, default=1,
                    help="display frames per animation frame, 1..255 (1)")
    ap.add_argument("--no-loop", action="store_true",
                    help="stop on the last frame instead of looping")
    ap.add_argument("--shift", type=int, default=0, help="8-bit output window [shift+7:shift]")
    ap.add_argument("--nosat", action="store_true", help="wrap instead of clamping")
    ap.add_argument("--words", type=int, default=PACKET_WORDS,
                    help=f"words per 'X' packet, 1..{MAX_PACKET_WORDS} ({PACKET_WORDS})")
    ap.add_argument("--baud", type=int, default=BAUD, help=f"({BAUD})")
    ap.add_argument("--retries", type=int, default=5, help="re-sends per packet (5)")
    ap.add_argument("--abandon", type=float, default=ABANDON_S,
                    help=f"seconds the board needs to abandon a partial command ({ABANDON_S})")
    ap.add_argument("--state", default="de32_load.state.json", help="state file for --resume")
    ap.add_argument("--resume", action="store_true", help="continue an interrupted load")
    ap.add_argument("--no-size-check", action="store_true",
                    help="do not ask the board ('S') for its version and region size first")
    ap.add_argument("--status", action="store_true", help="print the board's status")
    ap.add_argument("--reg", type=lambda s: int(s, 0), help="read a controller register")
    return ap


def main(argv=None, port_fd: int | None = None) -> int:
    a = build_parser().parse_args(argv)
    if not 1 <= a.words <= MAX_PACKET_WORDS:
        print(f"de32_load: --words {a.words} outside 1..{MAX_PACKET_WORDS}", file=sys.stderr)
        return 1
    if not 1 <= a.hold <= 255:
        print(f"de32_load: --hold {a.hold} outside 1..255", file=sys.stderr)
        return 1
    try:
        frames, names = [], []
        if a.scene:
            frames.append(read_scene(a.scene, a.window, a.round, a.gain))
            names.append(scene_files(a.scene))
        if a.anim:
            seq = read_anim(a.anim, a.window, a.round, a.gain)
            frames += seq
            names += anim_files(a.anim, len(seq))
        port = Port(port_fd if port_fd is not None else a.port, a.baud)
        loader = Loader(port, a.retries, a.abandon,
                        log=lambda m: print(f"\nde32_load: {m}", file=sys.stderr))
        if frames:
            region_bits = 21
            if not a.no_size_check:
                st = loader.command(with_chk(b"S"), 16)
                if st[1] != VERSION:
                    raise LoadError(f"the board speaks loader version {st[1]}; this tool "
                                    f"speaks version {VERSION} (SDRAM frames): rebuild the "
                                    "bitstream (make fpga-board)")
                region_bits = st[3]
            pkts, plan = plan_packets(frames, a.words, a.shift, not a.nosat, region_bits,
                                      a.hold, a.show, not a.no_loop, names)
            state = State(a.state, plan_hash(pkts), len(pkts))
            start = state.load() if a.resume else 0
            if start == len(pkts):
                print(f"de32_load: {a.state}: this load is already complete", file=sys.stderr)
            else:
                if start:
                    print(f"de32_load: resuming at packet {start} of {len(pkts)}",
                          file=sys.stderr)
                run_plan(loader, pkts, state, start)
            st = plan.stats()
            q = plan.sequence if a.show is None else (a.show, 1, 1, 0)
            print(f"loaded {len(frames)} frame(s), {len(pkts)} packets, "
                  f"{loader.resent} re-sent; SDRAM words per colour "
                  f"{[c['words_used'] for c in st]} (line blocks "
                  f"{[c['blocks_stored'] for c in st]} for "
                  f"{[c['lines_referenced'] for c in st]} lines); sequence first {q[0]} "
                  f"count {q[1]} hold {q[2]} loop {q[3]}")
        if a.status:
            s = loader.command(with_chk(b"S"), 16)
            f = struct.unpack(">HHHH", s[4:12])
            print(f"version {s[1]} chips/colour {s[2]} SDRAM region 2^{s[3]} words per colour; "
                  f"errors: framing {f[0]} checksum {f[1]} command {f[2]}; frames {f[3]}; "
                  f"flags {s[12]:#04x} (bit0 align_err, 1-3 collision, 4 sequence pending); "
                  f"output shift {s[13] & 7} sat {s[13] >> 3 & 1}; malformed lines {s[14]}, "
                  f"late lines for want of SDRAM data {s[15]}")
        if a.reg is not None:
            r = loader.command(with_chk(b"R" + struct.pack(">H", a.reg)), 5)
            print(f"reg {a.reg:#06x} = {struct.unpack('>I', r[1:])[0]:#010x}")
    except LinkDropped as e:
        print(f"\nde32_load: {e}; run again with --resume (state in {a.state})",
              file=sys.stderr)
        return 2
    except LoadError as e:
        print(f"\nde32_load: {e}", file=sys.stderr)
        return 2 if "failed after" in str(e) else 1
    except OSError as e:
        print(f"de32_load: {e.filename or a.port}: {e.strerror}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
