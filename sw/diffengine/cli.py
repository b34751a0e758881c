"""`diffengine` command line: asm, disasm, model, plot, capacity, compare (see docs/formats.md).

User errors (bad input files, bad options) print `file:where: message` on stderr and exit
non-zero without a traceback; a traceback means a bug in the tools.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from . import binfmt, isa
from .asm import AsmError

EXIT_INPUT = 1   # the input file is wrong
EXIT_USAGE = 2   # the command line is wrong (argparse uses 2 as well)
CHUNK_LINES = 64


class CliError(Exception):
    """A user error that is not tied to a place in an input file."""


def _err(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


def _read(path: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except OSError as e:
        raise CliError(f"{path}: {e.strerror or e}") from None


def _load(path: str, mapped: bool = True):
    return binfmt.load_commands(_read(path), path, mapped)


def _warn_unterminated(commands, filename: str) -> None:
    if not commands or commands[-1].op == "REFRESH":
        return
    k = max((i for i, c in enumerate(commands) if c.op == "REFRESH"), default=-1) + 1
    where = commands[k].line or f"command {k}"
    _err(f"{filename}:{where}: warning: {len(commands) - k} command(s) after the last "
         "Refresh form an unterminated line, which is not shown")


# ---- asm / disasm -----------------------------------------------------------------


def cmd_asm(a) -> int:
    data = _read(a.input)
    fs = a.format == "framestore"
    if not fs and (a.compensate or a.round or a.window is not None):
        raise CliError("--window, --compensate and --round need -f framestore")
    window = 0 if a.window is None else a.window
    if binfmt.detect(data) == "text" and a.round:
        from .asm import parse_text
        try:
            commands = parse_text(data.decode("utf-8"), a.input, round_bits=4 + window)
        except UnicodeDecodeError as e:
            raise AsmError(a.input, [(1, f"not UTF-8 text ({e.reason})")]) from None
    else:
        commands, _ = binfmt.load_commands(data, a.input, mapped=True)
    _warn_unterminated(commands, a.input)
    if fs:
        words = binfmt.framestore_encode(commands, window, a.input)
        out = binfmt.encode_de32(words, window, a.compensate)
        count = len(words)
    else:
        slots = isa.serialise(commands)
        out = binfmt.encode_de48(slots)
        count = len(slots)
    dest = a.output or str(Path(a.input).with_suffix(".de32" if fs else ".de48"))
    Path(dest).write_bytes(out)
    _err(f"{dest}: {len(commands)} commands, {count} instructions")
    return 0


def cmd_disasm(a) -> int:
    data = _read(a.input)
    kind = binfmt.detect(data)
    header = [f"disassembled from {a.input}"]
    unit = a.dac
    if kind == "de32":
        words, window, comp = binfmt.decode_de32(data, a.input)
        header.append(f"frame-store window {window}, compensation "
                      f"{'on' if comp else 'off'}"
                      + (" (applied below)" if comp and a.mapped else
                         " (applied by the mapper, not shown)" if comp else ""))
        slots = binfmt.framestore_slots(words, window, comp and a.mapped)
    elif kind == "de48":
        slots = binfmt.decode_de48(data, a.input)
    else:
        commands, _ = binfmt.load_commands(data, a.input)
        slots = isa.serialise(commands)
    from .disasm import disassemble, list_slots
    if a.slots:
        text = list_slots(slots)
    else:
        commands = binfmt.deserialise(slots, a.input)
        text = disassemble(commands, unit, comment=not a.no_comment, header=header)
    if a.output:
        Path(a.output).write_text(text)
    else:
        sys.stdout.write(text)
    return 0


# ---- model / plot -----------------------------------------------------------------


def _renderer(level: str):
    if level == "functional":
        from . import functional
        return functional.render
    try:
        from . import structural
    except ImportError:
        raise CliError("the structural model (diffengine/structural.py) is not available") from None
    if not hasattr(structural, "render"):
        raise CliError("diffengine.structural has no render(commands, width, carry_bug)")
    return structural.render


def _pixels(a):
    """Load, optionally compensate, render in chunks of lines (progress on stderr)."""
    import numpy as np

    commands, (kind, _, file_comp) = _load(a.input)
    if a.compensate:
        if file_comp:
            raise CliError(f"{a.input}: the .de32 flag already applies compensation")
        commands = binfmt.deserialise(binfmt.compensate_slots(isa.serialise(commands)),
                                      a.input)
    _warn_unterminated(commands, a.input)
    lines = [ln for ln in isa.split_lines(commands) if ln[-1].op == "REFRESH"]
    if not lines:
        raise CliError(f"{a.input}: no complete scanline (no Refresh)")
    if not 1 <= a.width <= isa.ADDR_MAX + 1:
        raise CliError(f"--width {a.width} outside 1..4096")
    render = _renderer(a.level)
    rows = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k in range(0, len(lines), CHUNK_LINES):
            chunk = [c for ln in lines[k:k + CHUNK_LINES] for c in ln]
            rows.append(np.asarray(render(chunk, a.width, carry_bug=a.carry_bug)))
            if len(lines) > CHUNK_LINES:
                _err(f"{a.level}: {min(k + CHUNK_LINES, len(lines))}/{len(lines)} lines")
    for w in caught:
        _err(f"{a.input}: warning: {w.message}")
    return np.concatenate(rows).astype(np.uint16)


def _window(pix, window):
    return pix if window is None else (pix >> window) & 0x3F


def write_image(path: str, pix, bits: int, raw: bool) -> None:
    """uint16 PNG/TIFF (value << (16-bits), or raw numbers); EXR as float value / 2^bits."""
    import numpy as np
    import OpenImageIO as oiio

    h, w = pix.shape
    if path == "-" or path.lower().endswith(".txt"):
        # Pixel numbers as text, one scanline per line: for reading and diffing.
        text = "\n".join(" ".join(str(int(v)) for v in row) for row in pix) + "\n"
        if path == "-":
            sys.stdout.write(text)
        else:
            Path(path).write_text(text)
        return
    if path.lower().endswith(".exr"):
        arr = pix.astype(np.float32) / (1 if raw else (1 << bits))
        spec = oiio.ImageSpec(w, h, 1, "float")
    else:
        arr = pix.astype(np.uint16) << (0 if raw else 16 - bits)
        spec = oiio.ImageSpec(w, h, 1, "uint16")
    spec.attribute("oiio:BitsPerSample", 16)
    spec.attribute("Software", "diffengine model")
    out = oiio.ImageOutput.create(path)
    if out is None:
        raise CliError(f"{path}: cannot write this image type ({oiio.geterror()})")
    ok = out.open(path, spec) and out.write_image(np.ascontiguousarray(arr.reshape(h, w, 1)))
    err = out.geterror()
    out.close()
    if not ok:
        raise CliError(f"{path}: {err or 'write failed'}")


def cmd_model(a) -> int:
    if a.line_height < 1:
        raise CliError("--line-height must be >= 1")
    pix = _window(_pixels(a), a.window).repeat(a.line_height, axis=0)
    write_image(a.output, pix, 12 if a.window is None else 6, a.raw)
    _err(f"{a.output}: {pix.shape[0]} x {pix.shape[1]} "
         f"({'12-bit pixels' if a.window is None else f'DAC window bits {a.window + 5}..{a.window}'})")
    return 0


def _xlim(text, pix, width):
    if text:
        try:
            lo, hi = (int(t) for t in text.split(":"))
        except ValueError:
            raise CliError(f"--xlim {text!r}: want A:B") from None
        return lo, hi
    nz = pix.any(axis=0).nonzero()[0]
    hi = int(nz[-1]) + 9 if len(nz) else width
    return 0, min(width, max(hi, 16))


def cmd_plot(a) -> int:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pix = _window(_pixels(a), a.window)
    index = list(range(pix.shape[0]))
    if a.line is not None:
        if not 0 <= a.line < len(index):
            raise CliError(f"--line {a.line}: the file has lines 0..{len(index) - 1}")
        index = [a.line]
    elif len(index) > a.max_lines:
        _err(f"plot: showing the first {a.max_lines} of {len(index)} lines (use --line N)")
        index = index[:a.max_lines]
    lo, hi = _xlim(a.xlim, pix[index], a.width)
    fig, axes = plt.subplots(len(index), 1, figsize=(8, 1.8 * len(index) + 0.6),
                             squeeze=False, sharex=True)
    for ax, k in zip(axes[:, 0], index):
        ax.plot(range(lo, hi), pix[k, lo:hi], drawstyle="steps-mid", lw=1.2)
        ax.set_title(f"{Path(a.input).name}  scanline {k}", fontsize=9, loc="left")
        ax.set_ylabel("DAC" if a.window is not None else "pixel")
        if a.window is not None:
            ax.set_ylim(-2, 65)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("column")
    label = "12-bit pixel" if a.window is None else f"6-bit DAC window, pixel bits {a.window + 5}..{a.window}"
    fig.suptitle(f"Scanline display ({label}{', carry bug' if a.carry_bug else ''})", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.output, dpi=a.dpi)
    plt.close(fig)
    _err(f"{a.output}: {len(index)} scanline(s), columns {lo}..{hi - 1}")
    return 0


def cmd_capacity(a) -> int:
    try:
        from . import capacity
    except ImportError:
        raise CliError("the capacity model (diffengine/capacity.py) is not available yet") from None
    text = capacity.report()
    if text is not None:
        print(text)
    return 0


# ---- argument parsing --------------------------------------------------------------


def _window_arg(hi):
    def conv(s):
        try:
            v = int(s)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{s!r} is not an integer") from None
        if not 0 <= v <= hi:
            raise argparse.ArgumentTypeError(f"window {v} outside 0..{hi}")
        return v
    return conv


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="diffengine", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("asm", help="command file -> .de48 instruction stream or .de32 frame store")
    s.add_argument("input")
    s.add_argument("-o", "--output", help="default: input with .de48/.de32 suffix")
    s.add_argument("-f", "--format", choices=["de48", "framestore"], default="de48")
    s.add_argument("--window", type=_window_arg(4), help="frame-store DAC window w (0..4, default 0)")
    s.add_argument("--compensate", action="store_true",
                   help="set the .de32 flag: the mapper applies carry-bug compensation")
    s.add_argument("--round", action="store_true",
                   help="round decimal operands to the frame-store precision (bit 4+w)")
    s.set_defaults(func=cmd_asm)

    s = sub.add_parser("disasm", help=".de48/.de32 (or text) -> command-file text")
    s.add_argument("input")
    s.add_argument("-o", "--output", help="default: stdout")
    s.add_argument("--dac", type=_window_arg(6), metavar="W",
                   help="print decimals in .unit dac W (default: .unit pixel)")
    s.add_argument("--slots", action="store_true", help="list instructions, not commands")
    s.add_argument("--mapped", action="store_true",
                   help=".de32: show values after the mapper's compensation")
    s.add_argument("--no-comment", action="store_true", help="no decimal value comments")
    s.set_defaults(func=cmd_disasm)

    def model_opts(s):
        s.add_argument("input", help="command file, .de48 or .de32")
        s.add_argument("-o", "--output", required=True)
        s.add_argument("--width", type=int, default=640, help="columns (PEs), default 640")
        s.add_argument("--level", choices=["functional", "structural"], default="functional")
        s.add_argument("--carry-bug", action="store_true", help="model the §7.7 adder fault")
        s.add_argument("--compensate", action="store_true",
                       help="apply the mapper's carry-bug compensation to intensities")
        s.add_argument("--window", type=_window_arg(6), metavar="W",
                       help="show the 6-bit DAC window, pixel bits [W+5:W] (default: all 12 bits)")

    s = sub.add_parser("model", help="render to an image (PNG/TIFF 16-bit, EXR float)")
    model_opts(s)
    s.add_argument("--raw", action="store_true",
                   help="write the pixel numbers unscaled (default: scaled to 16 bits)")
    s.add_argument("--line-height", type=int, default=1, help="rows per scanline")
    s.set_defaults(func=cmd_model)

    s = sub.add_parser("plot", help="scanline intensity graphs (the source's Scanline Display)")
    model_opts(s)
    s.add_argument("--line", type=int, help="plot only scanline N (0-based)")
    s.add_argument("--xlim", help="column range A:B (default: up to the last lit column)")
    s.add_argument("--max-lines", type=int, default=32)
    s.add_argument("--dpi", type=int, default=110)
    s.set_defaults(func=cmd_plot)

    s = sub.add_parser("compare", help="a frame against a reference: PSNR, maximum error, "
                       "outlier pixels and their map (the quality gate of make demo)")
    s.add_argument("frame", help="16-bit PNG/TIFF of 12-bit pixels (diffengine model, "
                   "make demo's demo.png) or .npy")
    s.add_argument("reference", help="a .scene file (rendered by the 16x16 reference "
                   "renderer), or a 16-bit image / .npy of the reference")
    s.add_argument("--map", help="write the outlier map here (PNG; outliers in red on the "
                   "frame's grey)")
    s.add_argument("--max-outliers", type=int, default=0,
                   help="exit 3 when there are more outlier pixels than this (default 0)")
    s.add_argument("--min-psnr", type=float, default=None,
                   help="exit 3 when the PSNR is below this (dB)")
    s.add_argument("--samples", type=int, default=16,
                   help="reference sub-samples per pixel side for a .scene (default 16)")
    s.set_defaults(func=cmd_compare)

    s = sub.add_parser("capacity", help="print the capacity model report (Table 7.3)")
    s.set_defaults(func=cmd_capacity)
    # Listed for --help only; main() hands `encode` to diffengine.encode.encode_main.
    sub.add_parser("encode", help="image -> multiresolution spline command file "
                   "(diffengine encode -h)")
    # Listed for --help only; main() hands `trace` to diffengine.trace.trace_main.
    sub.add_parser("trace", help="per-PE state per cycle from the RTL harness or the "
                   "structural model, breakpoints, RTL-vs-model compare (diffengine trace -h)")
    # Listed for --help only; main() hands `inspect` to diffengine.inspect_page.inspect_main.
    sub.add_parser("inspect", help="one frame as a self-contained HTML page: image, scanline "
                   "graph, per-pixel commands and register history (diffengine inspect -h)")
    return p


EXIT_GATE = 3   # compare: the frame fails the quality gate


def _image(path: str, samples: int):
    import numpy as np

    from . import frame, reference
    if path.endswith(".npy"):
        return np.load(path).astype(np.float64)
    if path.endswith(".scene"):
        try:
            return reference.render_file(path, samples)
        except reference.SceneError as e:
            raise CliError(str(e)) from None
    if not Path(path).is_file():
        raise CliError(f"{path}: no such file")
    try:
        return frame.read_png16(path).astype(np.float64)
    except OSError as e:
        raise CliError(str(e)) from None


def cmd_compare(a) -> int:
    """PSNR, maximum error and outliers (reference.outliers) of a frame against a
    reference; the same numbers as make demo's report."""
    import numpy as np

    from . import frame, reference
    img = _image(a.frame, a.samples)
    ref = _image(a.reference, a.samples)
    if img.shape != ref.shape:
        raise CliError(f"{a.frame} is {img.shape[1]}x{img.shape[0]} but {a.reference} is "
                       f"{ref.shape[1]}x{ref.shape[0]}")
    err = np.abs(img - ref)
    bad = reference.outliers(img, ref)
    n = int(bad.sum())
    psnr = reference.psnr(img, ref)
    print(f"PSNR {psnr:.2f} dB; |error| max {err.max():.1f}, mean {err.mean():.4f} pixel units")
    print(f"outliers (error > {reference.OUTLIER_ERROR} of full scale where the reference "
          f"varies by < {reference.OUTLIER_SMOOTH}): {n}")
    worst = err.max(axis=-1) if err.ndim == 3 else err
    for y, x in np.argwhere(bad)[:10]:
        print(f"  x={x} y={y}: error {worst[y, x]:.0f}")
    if n > 10:
        print(f"  ... and {n - 10} more")
    if a.map:
        shown = np.clip(np.round(img), 0, 4095).astype(np.uint16)
        frame.write_rgb8(a.map, reference.outlier_map(shown, bad), "diffengine compare")
        print(f"outlier map: {a.map}")
    fail = n > a.max_outliers or (a.min_psnr is not None and psnr < a.min_psnr)
    return EXIT_GATE if fail else 0


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["encode"]:  # its own argument parser (diffengine.encode)
        from .encode import encode_main
        return encode_main(argv[1:])
    if argv[:1] == ["trace"]:  # its own argument parser (diffengine.trace)
        from .trace import trace_main
        return trace_main(argv[1:])
    if argv[:1] == ["inspect"]:  # its own argument parser (diffengine.inspect_page)
        from .inspect_page import inspect_main
        return inspect_main(argv[1:])
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except AsmError as e:
        _err(str(e))
        return EXIT_INPUT
    except CliError as e:
        _err(f"diffengine {args.command}: {e}")
        return EXIT_INPUT
    except OSError as e:
        _err(f"diffengine {args.command}: {e.filename or ''}: {e.strerror or e}")
        return EXIT_INPUT
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
