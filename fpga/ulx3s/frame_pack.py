#!/usr/bin/env python3
"""Pack frames into the SDRAM frame store as tables of lines (docs/sdram-frames-spec.md §1-2, §6).

    frame_pack.py SCENE_OR_ANIM [...] [--vactive 480] [--window 2] [--no-round] [--gain G]
                  [--stats] [--json FILE] [--image FILE]

Each colour's word stream is cut into line blocks at the end-of-line markers (the
REFRESH word, docs/formats.md §3; the block keeps its marker); identical blocks of one
colour are stored once, shared within a frame and between frames (the seed's incremental
frame, §7.7.1, in storage). Every block and every frame table starts on a multiple of 4
words (one BL8 burst); a line that is only the canonical marker word gets a table entry
with len 0 and no block (the player plays its own marker). Identical frame tables are
stored once too (a frame that repeats an earlier one costs only its slot).

Inputs, in order, become frames 0, 1, ...: a `make demo` scene directory (r/g/b .de48 or
.de32, e.g. out/demo_cmd), three r g b files given as one argument each is not supported
here (give a directory), or a `make anim` output directory (its frame000/ and
frameNNN.delta files: out/anim/streams, or out/anim which holds streams/). .de48 streams
become frame-store words at --window (default 2), rounded to that window's grid unless
--no-round (de32_load.py's conversion).

--stats prints per colour the words used of the region, the words all frames reference,
the lines referenced and the line blocks stored, the frame tables stored, and whether
everything fits the 2^21-word region. --image FILE writes the SDRAM model's preload file
(spec §5: `<addr> <word>` in hex per line). --json FILE writes the stats as JSON.
Errors (a stream with the wrong number of lines, words after the last marker, a block
over 4095 words, a region overflow, more than 64 frames) name the frame, colour and line.
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

try:
    from diffengine import isa
    from diffengine.formats import binfmt
except ImportError:                                   # run from the repository root
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "sw"))
    from diffengine import isa
    from diffengine.formats import binfmt

REGION_BITS = 21                       # log2 words per colour region (spec §1, loader 'S')
REGION_WORDS = 1 << REGION_BITS
ALIGN = 4                              # words: one BL8 burst of 16-bit columns
MAX_LEN = 4095                         # len[11:0] of a table entry
BLK_BITS = 20
SLOTS = 64
COLOURS = "rgb"
MARKER_INDEX = isa.LUT_INDEX[isa.REFRESH]          # the LUT code of the end-of-line marker
MARKER_WORD = MARKER_INDEX << binfmt.OPERAND_BITS   # the canonical marker (operand 0)


class PackError(ValueError):
    """A frame that cannot be packed; the message names frame, colour and line, and
    `frame` / `colour` (indices, None if none) say which input it was."""
    frame: int | None = None
    colour: int | None = None


def is_marker(word: int) -> bool:
    """True for an end-of-line marker (any word whose LUT code is REFRESH's)."""
    return word >> binfmt.OPERAND_BITS == MARKER_INDEX


def entry(blk: int, length: int) -> int:
    """A frame-table entry {len[11:0], blk[19:0]} (spec §1)."""
    if not 0 <= length <= MAX_LEN or not 0 <= blk < 1 << BLK_BITS:
        raise ValueError(f"table entry len {length} blk {blk} out of range")
    return length << BLK_BITS | blk


def split_entry(e: int) -> tuple[int, int]:
    """(word offset of the block, len) of a table entry."""
    return (e & ((1 << BLK_BITS) - 1)) * ALIGN, e >> BLK_BITS


def addr(ch: int, off: int) -> int:
    """The controller's 23-bit word address of offset `off` in colour ch's region."""
    return ch << REGION_BITS | off


def _align(n: int) -> int:
    return -(-n // ALIGN) * ALIGN


def _fields(img: Any) -> tuple[Sequence[int], int, bool]:
    """(words, window, comp) of an object with those attributes or a (words, window,
    comp) tuple (de32_load.py's Image)."""
    if hasattr(img, "words"):
        return img.words, img.window, bool(img.comp)
    words, window, comp = img
    return words, window, bool(comp)


def split_lines(words: Sequence[int], vactive: int, where: str = "") -> list[tuple[int, ...]]:
    """A colour's word stream -> its vactive lines, each ending with its marker."""
    lines, start = [], 0
    for k, w in enumerate(words):
        if not 0 <= w <= 0xFFFFFFFF:
            raise PackError(f"{where}line {len(lines)}: word {k} ({w:#x}) is not 32 bits")
        if is_marker(w):
            if len(lines) == vactive:
                raise PackError(f"{where}line {vactive}: more than {vactive} lines "
                                f"(marker at word {k}); the frame has vactive = {vactive}")
            lines.append(tuple(words[start:k + 1]))
            start = k + 1
    if start != len(words):
        raise PackError(f"{where}line {len(lines)}: {len(words) - start} word(s) after the "
                        "last end-of-line marker")
    if len(lines) != vactive:
        raise PackError(f"{where}line {len(lines)}: the stream has {len(lines)} lines, "
                        f"vactive is {vactive}")
    return lines


@dataclass
class ColourStats:
    words_used: int = 0          # region words written (blocks, padding, tables)
    words_referenced: int = 0    # sum over frames of the frame's stream length
    lines_referenced: int = 0    # frames x vactive
    blocks_stored: int = 0       # distinct line blocks
    block_words: int = 0         # words in the stored blocks (no padding)
    empty_lines: int = 0         # entries with len 0
    tables_stored: int = 0       # distinct frame tables

    def as_dict(self) -> dict:
        d = dict(self.__dict__)
        d["region_words"] = REGION_WORDS
        d["fits"] = self.words_used <= REGION_WORDS
        return d


@dataclass
class Plan:
    """Where every frame went (spec §6). `writes`: (ch, off, words) contiguous runs;
    `slots`: (ch, slot, table_off, window, comp); `sequence`: (first, count, hold, loop);
    `tables[f][c]`: the table offset of frame f, colour c."""
    vactive: int
    writes: list = field(default_factory=list)
    slots: list = field(default_factory=list)
    sequence: tuple = (0, 1, 1, 0)
    tables: list = field(default_factory=list)
    colour_stats: list = field(default_factory=lambda: [ColourStats() for _ in COLOURS])

    def image(self) -> dict[int, int]:
        """Controller word address -> word, everything `writes` puts in the SDRAM."""
        img = {}
        for ch, off, words in self.writes:
            base = addr(ch, off)
            for k, w in enumerate(words):
                img[base + k] = w
        return img

    def stats(self) -> list[dict]:
        """Per colour: words_used, words_referenced, lines_referenced, blocks_stored,
        block_words, empty_lines, tables_stored, region_words, fits."""
        return [s.as_dict() for s in self.colour_stats]

    def fits(self) -> bool:
        return all(s.words_used <= REGION_WORDS for s in self.colour_stats)

    def write_image(self, path) -> int:
        """The SDRAM model's preload file (spec §5); returns the number of words."""
        img = self.image()
        with open(path, "w") as f:
            f.write(f"# frame_pack: {len(self.tables)} frame(s), vactive {self.vactive}; "
                    "<controller word address> <32-bit word>, hex\n")
            for ch, slot, toff, window, comp in self.slots:
                f.write(f"# slot {slot} colour {COLOURS[ch]} table {toff:#x} window {window} "
                        f"comp {int(comp)}\n")
            f.write("# sequence first {} count {} hold {} loop {}\n".format(*self.sequence))
            for a in sorted(img):
                f.write(f"{a:06x} {img[a]:08x}\n")
        return len(img)


def pack(frames, vactive: int, *, first_slot: int = 0, hold: int = 1,
         loop: bool | None = None, region_words: int = REGION_WORDS) -> Plan:
    """frames[f][c] (colour c of frame f: .words/.window/.comp, or a (words, window, comp)
    tuple) -> a Plan. Blocks are laid out per colour in order of first use, each frame's
    new blocks followed by its table (if the table is new); `loop` defaults to True for
    more than one frame. `region_words` is for tests (a small region to overflow)."""
    if not 1 <= vactive <= MAX_LEN:
        raise PackError(f"vactive {vactive} outside 1..{MAX_LEN}")
    if not frames:
        raise PackError("no frames to pack")
    if not 0 <= first_slot or first_slot + len(frames) > SLOTS:
        raise PackError(f"{len(frames)} frame(s) from slot {first_slot}: the board has "
                        f"{SLOTS} slots per colour")
    if not 1 <= hold <= 255:
        raise PackError(f"hold {hold} outside 1..255")
    plan = Plan(vactive=vactive)
    blocks: list[dict[tuple, int]] = [{} for _ in COLOURS]     # block words -> offset
    tables: list[dict[tuple, int]] = [{} for _ in COLOURS]     # table entries -> offset
    nxt = [0] * len(COLOURS)
    run: list[int] = []               # the words of the current (frame, colour) write

    def append(c, words, at, what):
        """Lay `words` out at the next 4-word boundary of colour c's region."""
        off, size = nxt[c], _align(len(words))
        if off + size > region_words:
            raise PackError(f"{at}: region overflow: the {what} needs words "
                            f"{off}..{off + size - 1}, colour {COLOURS[c]}'s region "
                            f"holds {region_words}")
        run.extend(words)
        run.extend([0] * (size - len(words)))
        nxt[c] += size
        return off

    for f, fr in enumerate(frames):
        if len(fr) != len(COLOURS):
            raise PackError(f"frame {f}: {len(fr)} colours, want 3 (r, g, b)")
        row = []
        for c, img in enumerate(fr):
            try:
                words, window, comp = _fields(img)
                where = f"frame {f} colour {COLOURS[c]} "
                if not 0 <= window <= 4:
                    raise PackError(f"{where.rstrip()}: window {window} outside 0..4")
                st = plan.colour_stats[c]
                st.words_referenced += len(words)
                st.lines_referenced += vactive
                run_off, run = nxt[c], []
                ents = []
                for y, line in enumerate(split_lines(words, vactive, where)):
                    if line == (MARKER_WORD,):
                        ents.append(entry(0, 0))
                        st.empty_lines += 1
                        continue
                    if len(line) > MAX_LEN:
                        raise PackError(f"{where}line {y}: {len(line)} words, a block holds at "
                                        f"most {MAX_LEN} (marker included)")
                    off = blocks[c].get(line)
                    if off is None:
                        off = blocks[c][line] = append(c, line, f"{where}line {y}", "block")
                        st.blocks_stored += 1
                        st.block_words += len(line)
                    ents.append(entry(off // ALIGN, len(line)))
                key = tuple(ents)
                toff = tables[c].get(key)
                if toff is None:
                    toff = tables[c][key] = append(c, ents, f"{where}line {vactive - 1}",
                                                   "frame table")
                    st.tables_stored += 1
                if run:
                    plan.writes.append((c, run_off, run))
                st.words_used = nxt[c]
                plan.slots.append((c, first_slot + f, toff, window, comp))
                row.append(toff)
            except PackError as e:
                if e.frame is None:
                    e.frame, e.colour = f, c
                raise
        plan.tables.append(row)
    if loop is None:
        loop = len(frames) > 1
    plan.sequence = (first_slot, len(frames), hold, int(bool(loop)))
    return plan


def read_back(image: dict[int, int], ch: int, table_off: int, vactive: int) -> list[int]:
    """The word stream the player plays for the frame whose table is at `table_off` in
    colour ch's region, rebuilt from an SDRAM image through its table (len 0: the
    canonical marker)."""
    out = []
    for v in range(vactive):
        off, n = split_entry(image[addr(ch, table_off + v)])
        if n == 0:
            out.append(MARKER_WORD)
        else:
            out += [image[addr(ch, off + k)] for k in range(n)]
    return out


def read_image_file(path) -> dict[int, int]:
    """A preload file (spec §5) -> {address: word}; errors name the file and line."""
    img = {}
    for n, text in enumerate(Path(path).read_text().splitlines(), 1):
        text = text.split("#", 1)[0].strip()
        if not text:
            continue
        try:
            a, w = (int(x, 16) for x in text.split())
        except ValueError:
            raise PackError(f"{path}:{n}: want '<addr> <word>' in hex, got {text!r}") from None
        if not 0 <= a < 1 << (REGION_BITS + 2) or not 0 <= w <= 0xFFFFFFFF:
            raise PackError(f"{path}:{n}: address {a:#x} or word {w:#x} out of range")
        img[a] = w
    return img


# ---------------------------------------------------------------------------- CLI
def load_inputs(paths: list[str], window: int, rnd: bool, gain: int = 0) -> list:
    """Frames from scene directories and `make anim` directories, in order."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import de32_load                                  # its readers; lazy: it imports us
    frames = []
    for p in paths:
        d = Path(p)
        if (d / "frame000").is_dir() or (d / "streams" / "frame000").is_dir():
            frames += de32_load.read_anim(str(d), window, rnd, gain)   # finds streams/ itself
        else:
            frames.append(de32_load.read_scene([str(d)], window, rnd, gain))
    return frames


def format_stats(plan: Plan) -> str:
    rows = [f"{len(plan.tables)} frame(s), vactive {plan.vactive}, sequence first {plan.sequence[0]} "
            f"count {plan.sequence[1]} hold {plan.sequence[2]} loop {plan.sequence[3]}",
            f"{'colour':6} {'words used':>11} {'of region':>9} {'referenced':>11} {'saved':>6} "
            f"{'lines ref':>9} {'blocks':>7} {'empty':>6} {'tables':>6} fits"]
    for c, s in enumerate(plan.stats()):
        saved = 1 - s["words_used"] / s["words_referenced"] if s["words_referenced"] else 0
        rows.append(f"{COLOURS[c]:6} {s['words_used']:>11,} {s['words_used'] / s['region_words']:>8.1%} "
                    f"{s['words_referenced']:>11,} {saved:>6.1%} {s['lines_referenced']:>9,} "
                    f"{s['blocks_stored']:>7,} {s['empty_lines']:>6,} {s['tables_stored']:>6} "
                    f"{'yes' if s['fits'] else 'NO'}")
    rows.append(f"all colours fit: {'yes' if plan.fits() else 'NO'}")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 2)[2],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("inputs", nargs="+", help="scene directory (out/demo_cmd) or make anim "
                    "directory (out/anim), in frame order")
    ap.add_argument("--vactive", type=int, default=480, help="lines per frame (480)")
    ap.add_argument("--window", type=int, default=2, choices=range(5),
                    help="DAC window for .de48 streams (2)")
    ap.add_argument("--no-round", action="store_true",
                    help="do not round .de48 operands to the window (an unfit one is an error)")
    ap.add_argument("--gain", type=int, default=0, choices=range(4),
                    help="divide .de48 intensities by 2^GAIN first (de32_load.py --gain) (0)")
    ap.add_argument("--first-slot", type=int, default=0, help="slot of frame 0 (0)")
    ap.add_argument("--hold", type=int, default=1, help="display frames per slot (1)")
    ap.add_argument("--no-loop", action="store_true", help="stop at the last frame")
    ap.add_argument("--stats", action="store_true", help="print the per-colour table")
    ap.add_argument("--json", help="write the stats as JSON")
    ap.add_argument("--image", help="write the SDRAM model preload file (spec §5)")
    a = ap.parse_args(argv)
    try:
        frames = load_inputs(a.inputs, a.window, not a.no_round, a.gain)
        # Pack past the region (up to what a table entry can address) so that --stats can
        # say by how much it does not fit; the API's default is an error at the overflow.
        plan = pack(frames, a.vactive, first_slot=a.first_slot, hold=a.hold,
                    loop=False if a.no_loop else None, region_words=ALIGN << BLK_BITS)
    except (PackError, ValueError) as e:
        print(f"frame_pack: {e}", file=sys.stderr)
        return 1
    except Exception as e:                            # de32_load.LoadError
        if type(e).__name__ != "LoadError":
            raise
        print(f"frame_pack: {e}", file=sys.stderr)
        return 1
    if a.stats or not (a.json or a.image):
        print(format_stats(plan))
    if a.json:
        Path(a.json).write_text(json.dumps({"frames": len(frames), "vactive": a.vactive,
                                            "sequence": plan.sequence,
                                            "colours": plan.stats(), "fits": plan.fits()},
                                           indent=1) + "\n")
    if not plan.fits():
        print("frame_pack: the frames do not fit the 2^21-word colour regions",
              file=sys.stderr)
    elif a.image:
        n = plan.write_image(a.image)
        print(f"wrote {a.image}: {n:,} words")
    return 0 if plan.fits() else 3


if __name__ == "__main__":
    sys.exit(main())
