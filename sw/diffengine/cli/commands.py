"""Handlers of the small `diffengine` subcommands: asm, disasm, model, plot, capacity,
compare (docs/formats.md). Each takes the parsed arguments and returns the exit status;
user errors raise CliError or AsmError, which cli.tree prints as `file:where: message`."""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

from .. import isa
from ..formats import binfmt
from ..formats.asm import AsmError

EXIT_INPUT = 1   # the input file is wrong
EXIT_USAGE = 2   # the command line is wrong (argparse uses 2 as well)
CHUNK_LINES = 64


class CliError(Exception):
    """A user error that is not tied to a place in an input file."""


def err(msg: str) -> None:
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
    err(f"{filename}:{where}: warning: {len(commands) - k} command(s) after the last "
         "Refresh form an unterminated line, which is not shown")


# ---- asm / disasm -----------------------------------------------------------------


def cmd_asm(a) -> int:
    data = _read(a.input)
    fs = a.format == "framestore"
    if not fs and (a.compensate or a.round or a.window is not None):
        raise CliError("--window, --compensate and --round need -f framestore")
    window = 0 if a.window is None else a.window
    if binfmt.detect(data) == "text" and a.round:
        from ..formats.asm import parse_text
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
    err(f"{dest}: {len(commands)} commands, {count} instructions")
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
    from ..formats.disasm import disassemble, list_slots
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
        from ..model import functional
        return functional.render
    if level == "fast":
        from ..model import fast
        return fast.render
    try:
        from ..model import structural
    except ImportError:
        raise CliError("the structural model (diffengine/model/structural.py) is not available") from None
    if not hasattr(structural, "render"):
        raise CliError("diffengine.model.structural has no render(commands, width, carry_bug)")
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
                err(f"{a.level}: {min(k + CHUNK_LINES, len(lines))}/{len(lines)} lines")
    for w in caught:
        err(f"{a.input}: warning: {w.message}")
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
    err(f"{a.output}: {pix.shape[0]} x {pix.shape[1]} "
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
        err(f"plot: showing the first {a.max_lines} of {len(index)} lines (use --line N)")
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
    err(f"{a.output}: {len(index)} scanline(s), columns {lo}..{hi - 1}")
    return 0


def cmd_capacity(a) -> int:
    try:
        from ..model import capacity
    except ImportError:
        raise CliError("the capacity model (diffengine/model/capacity.py) is not available yet") from None
    text = capacity.report()
    if text is not None:
        print(text)
    return 0


EXIT_GATE = 3   # compare: the frame fails the quality gate


def _image(path: str, samples: int):
    import numpy as np

    from ..formats import frame
    from ..model import reference
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

    from ..formats import frame
    from ..model import reference
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
