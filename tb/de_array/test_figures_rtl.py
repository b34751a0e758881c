"""The seed's command lists (Figs. 7.21 and 7.25, sw/scenes/fig7_*.cmd) through the
Verilated array (16 chips = 144 columns, wide enough for every list), with and without
the carry fault; (b), (d), (f) of Fig. 7.21 also compensated. Frames must equal the
golden model bit for bit."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from diffengine.formats import asm
from diffengine.model import functional
from diffengine.rtl import harness
from diffengine import isa

SCENES = Path(__file__).resolve().parents[2] / "sw" / "scenes"
FILES = sorted(p.name for p in SCENES.glob("fig7_*.cmd"))
CHIPS = 16


def compensated(cmds):
    return [isa.Command(c.op, c.x, c.dx, tuple(isa.compensate(v) for v in c.values))
            if c.op in ("EVAL", "SETI", "SETDI", "SETDDI", "SETPI", "SETPDI", "SETPDDI")
            else c for c in cmds]


@pytest.mark.parametrize("bug", [0, 1])
@pytest.mark.parametrize("name", FILES)
def test_figure_list_in_rtl(name, bug):
    cmds = asm.parse_file(SCENES / name)
    if bug and name[:7] == "fig7_21" and name[7:8] in "bdf":
        cmds = compensated(cmds)
    got, _ = harness.run(cmds, CHIPS, bool(bug))
    want = functional.render(cmds, 9 * CHIPS, carry_bug=bool(bug))
    np.testing.assert_array_equal(got, want, err_msg=f"{name} carry_bug={bug}")
