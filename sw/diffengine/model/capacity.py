"""Rasterisation capacity of the Difference Engine: a model of Tables 7.3 and 7.4 (§7.4.5).

The source gives the tables' numbers but only some of their assumptions. The set below
reproduces all 16 + 16 entries within 5 % (most within 1 %; `report()` prints every
error). Every assumption is explicit and named, so it can be argued with:

A1  Instruction slots. The array takes one instruction per clock. Every clock of a
    *displayed* scanline is a slot, horizontal retrace included ("the processors
    continue to operate usefully during horizontal retrace time"). Clocks of
    vertically blanked lines are not: their instructions would produce no pixels.
    One slot per displayed line is the Refresh (Table 7.2).
A2  Video timing, derived from the tables, not assumed. Table 7.4 / Table 7.3 for Eval0
    gives instruction slots per displayed pixel = clocks per line / active pixels per
    line = 1.28 (640 columns) and 1.34 (1280), hence 820 and 1720 clocks per line;
    the pixel counts of Table 7.4 give 50 Hz (1280*1024*50 = 65.5 M pixels/s) for
    both modes. 640x485: 820 x 525 lines x 50 Hz = 21.525 MHz -- the text's 21.5 MHz.
    1280x1024: 1720 clocks x 1024 lines x 50 Hz = 88.1 M slots/s already exceeds the
    text's 85 MHz, so the tables cannot have used 85 MHz (even with every clock a slot,
    85 MHz gives at most 850 K Eval0 100x100 patterns/s, not 880 K); the mode below
    takes the VESA vertical total 1066, i.e. a 91.7 MHz clock.
A3  A pattern of size s x s covers s scanlines with one span of s pixels on each
    (footnote 10: convex patterns); it costs its per-scanline instructions s times.
A4  Instructions per pattern-scanline, from the slot counts of Table 7.2:
      Eval0 = 1 (rasterised images), constant = Eval1 = 3, linear (Gouraud) = Eval2 = 4,
      quadratic (Phong) = Eval3 (5) + 10 % x Eval3 (5) + 10 % x Eval3 (5) = 6.0:
      one light source; the 10 % of patterns in range of the specular term accumulate a
      specular Eval3 on top of the diffuse one (footnote 11); the 10 % that fall into two
      sections of the piecewise quadratic need a second Eval3 span on each scanline.
    A SetddI (2 slots) instead of the second Eval3 gives 5.7 and misses six Quadratic
    entries by 5.2-7.1 %: the source counted a whole command for the second section.
A5  Table 7.4 = patterns/s x s^2 / displayed pixels per second.
"""
from __future__ import annotations

from dataclasses import dataclass

from .. import isa


@dataclass(frozen=True)
class VideoMode:
    hactive: int
    vactive: int
    htotal: int
    vtotal: int
    fps: float

    @property
    def clock(self) -> float:
        return self.htotal * self.vtotal * self.fps

    @property
    def pixels_per_second(self) -> float:
        return self.hactive * self.vactive * self.fps

    @property
    def slots_per_second(self) -> float:
        """A1: all clocks of displayed lines, less one Refresh per line."""
        return (self.htotal - 1) * self.vactive * self.fps


def _controller_mode(index: int, fps: int) -> VideoMode:
    _, h, v, _, _ = isa.VIDEO_MODES[index]
    return VideoMode(h[0], v[0], sum(h), sum(v), fps)


MODES = {
    # The source's 50 Hz modes (its own figures, not spec/video.toml's): isa-literal-ok.
    "640x485@50": VideoMode(640, 485, 820, 525, 50),        # the source's low-res mode
    "1280x1024@50": VideoMode(1280, 1024, 1720, 1066, 50),  # high-res, isa-literal-ok
    # The controller's modes 0 and 2 (spec/video.toml).
    "640x480@60": _controller_mode(0, 60),                  # VGA, 25.2 MHz
    "1280x1024@60": _controller_mode(2, 60),                # VESA, 108 MHz
}
TABLE_MODES = ("640x485@50", "1280x1024@50")
SIZES = (10, 100)
INTERPOLATIONS = ("Quadratic", "Linear", "Constant", "Eval0")


def slots_per_line(mode) -> int:
    """Instruction slots in one scanline: every clock of the line, retrace included.

    One of them must be the line's Refresh. `mode` is a VideoMode or a MODES key.
    """
    m = MODES[mode] if isinstance(mode, str) else mode
    return m.htotal


def _slots(op: str, order: int = -1) -> int:
    values = (0,) * (order + 1) if op == "EVAL" else (0,)
    return len(isa.slots(isa.Command(op, 0, 1, values)))


SPECULAR_FRACTION = 0.10
TWO_SECTION_FRACTION = 0.10


def instructions_per_pattern_line(interp: str, two_section_cost: int | None = None) -> float:
    """A4. `two_section_cost` overrides the cost of a second section (default: an Eval3)."""
    eval3 = _slots("EVAL", 2)
    second = eval3 if two_section_cost is None else two_section_cost
    return {
        "Quadratic": eval3 + SPECULAR_FRACTION * eval3 + TWO_SECTION_FRACTION * second,
        "Linear": _slots("EVAL", 1),
        "Constant": _slots("EVAL", 0),
        "Eval0": _slots("EVAL0"),
    }[interp]


def patterns_per_second(mode: str, interp: str, size: int, **kw) -> float:
    return MODES[mode].slots_per_second / (size * instructions_per_pattern_line(interp, **kw))


def values_per_pixel(mode: str, interp: str, size: int, **kw) -> float:
    return patterns_per_second(mode, interp, size, **kw) * size * size / MODES[mode].pixels_per_second


# The source's tables: (interpolation, mode, size) -> value.
_K, _M = 1e3, 1e6
SOURCE_7_3 = {
    ("Quadratic", "640x485@50", 10): 331 * _K, ("Quadratic", "640x485@50", 100): 33 * _K,
    ("Linear", "640x485@50", 10): 497 * _K, ("Linear", "640x485@50", 100): 50 * _K,
    ("Constant", "640x485@50", 10): 663 * _K, ("Constant", "640x485@50", 100): 66 * _K,
    ("Eval0", "640x485@50", 10): 2.0 * _M, ("Eval0", "640x485@50", 100): 199 * _K,
    ("Quadratic", "1280x1024@50", 10): 1.5 * _M, ("Quadratic", "1280x1024@50", 100): 146 * _K,
    ("Linear", "1280x1024@50", 10): 2.2 * _M, ("Linear", "1280x1024@50", 100): 220 * _K,
    ("Constant", "1280x1024@50", 10): 2.9 * _M, ("Constant", "1280x1024@50", 100): 292 * _K,
    ("Eval0", "1280x1024@50", 10): 8.8 * _M, ("Eval0", "1280x1024@50", 100): 880 * _K,
}
SOURCE_7_4 = {
    ("Quadratic", "640x485@50", 10): 2.1, ("Quadratic", "640x485@50", 100): 21.4,
    ("Linear", "640x485@50", 10): 3.2, ("Linear", "640x485@50", 100): 32.0,
    ("Constant", "640x485@50", 10): 4.3, ("Constant", "640x485@50", 100): 42.9,
    ("Eval0", "640x485@50", 10): 12.8, ("Eval0", "640x485@50", 100): 128.0,
    ("Quadratic", "1280x1024@50", 10): 2.2, ("Quadratic", "1280x1024@50", 100): 22.4,
    ("Linear", "1280x1024@50", 10): 3.3, ("Linear", "1280x1024@50", 100): 33.6,
    ("Constant", "1280x1024@50", 10): 4.5, ("Constant", "1280x1024@50", 100): 44.9,
    ("Eval0", "1280x1024@50", 10): 13.4, ("Eval0", "1280x1024@50", 100): 134.0,
}


def table_7_3(**kw) -> dict:
    """Model patterns/second for every entry of Table 7.3 (keys as in SOURCE_7_3)."""
    return {k: patterns_per_second(k[1], k[0], k[2], **kw) for k in SOURCE_7_3}


def table_7_4(**kw) -> dict:
    """Model intensity values per pixel for every entry of Table 7.4."""
    return {k: values_per_pixel(k[1], k[0], k[2], **kw) for k in SOURCE_7_4}


def errors(**kw) -> dict:
    """Relative error model/source - 1 of all 32 entries, keyed (table, interp, mode, size)."""
    out = {}
    for name, model, src in (("7.3", table_7_3(**kw), SOURCE_7_3), ("7.4", table_7_4(**kw), SOURCE_7_4)):
        for k, v in model.items():
            out[(name,) + k] = v / src[k] - 1
    return out


def _fmt(v: float) -> str:
    if v >= 1e6:
        return f"{v / 1e6:.2f}M"
    if v >= 1e3:
        return f"{v / 1e3:.1f}K"
    return f"{v:.2f}"


def report() -> str:
    """Every entry of Tables 7.3 and 7.4: model, source, error."""
    lines = []
    for m in TABLE_MODES:
        vm = MODES[m]
        lines.append(f"{m}: {vm.htotal}x{vm.vtotal} clocks, clock {vm.clock / 1e6:.3f} MHz, "
                     f"{vm.slots_per_second / 1e6:.2f} M instruction slots/s, "
                     f"{vm.pixels_per_second / 1e6:.2f} M pixels/s")
    lines.append("instructions per pattern-scanline: " + ", ".join(
        f"{i} {instructions_per_pattern_line(i):g}" for i in INTERPOLATIONS))
    err = errors()
    for name, model, src, head in (("7.3", table_7_3(), SOURCE_7_3, "patterns/second"),
                                   ("7.4", table_7_4(), SOURCE_7_4, "intensity values/pixel")):
        lines += ["", f"Table {name} ({head})",
                  f"{'interpolation':<10} {'mode':<13} {'size':>7} {'model':>9} {'source':>9} {'error':>7}"]
        for k in src:
            interp, mode, size = k
            lines.append(f"{interp:<10} {mode:<13} {size:>3}x{size:<3} {_fmt(model[k]):>9} "
                         f"{_fmt(src[k]):>9} {100 * err[(name,) + k]:>+6.1f}%")
    worst = max(err, key=lambda k: abs(err[k]))
    lines += ["", f"largest error {100 * err[worst]:+.1f}% (Table {worst[0]}, {' '.join(map(str, worst[1:]))})"]
    return "\n".join(lines)
