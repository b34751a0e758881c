"""The C++ display_controller harness (sim/dc) against the golden model.

One small build (4 chips = 36 PEs per colour, test mode 32x16 with a 640x480-length
line of 800 slots, 1 y-processor), shared with test_pipeline.py. Random command streams
(diffengine.regress.randgen, seed printed, SEED=n replays) per colour, two frames: every frame
equals functional.render bit for bit, sync/blank are exact, and the Load Monitor's
registers (read over reg_addr_i by the harness) equal what the streams asked for; an
overloaded line is late, discarded and counted.
"""
from __future__ import annotations

import os
import random

import numpy as np
import pytest

from diffengine.rtl import dc_harness as dh
from diffengine.formats import frame
from diffengine.model import functional
from diffengine import isa
from diffengine.regress import randgen

W, H = 32, 16
CFG = dh.Config(chips=4, num_buf=1, test=(W, 16, 96, 800 - W - 112, H, 1, 2, 2))


def _seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 30)))
    print(f"SEED={s}")
    return s


def _lines(seed: int, n: int, per_line=(1, 25)) -> list[list[isa.Command]]:
    cmds = randgen.stream(seed, n * 30, W, per_line=per_line)
    lines = isa.split_lines(cmds)
    assert len(lines) >= n
    return [ln for ln in lines[:n]]


def _slots(line) -> int:
    return len(isa.serialise(line)) - 1  # without the Refresh (the marker uses no slot)


@pytest.fixture(scope="module")
def exe():
    return dh.build(CFG)[0]


def test_two_frames_vs_golden(exe):
    seed = _seed()
    per_ch = [_lines(seed + c, 2 * H) for c in range(3)]
    for lines in per_ch:
        for ln in lines:
            assert _slots(ln) <= 799
    frames, st = dh.run([[c for ln in lines for c in ln] for lines in per_ch], CFG, mode=3)
    assert frames.shape == (2, H, W, 3)
    for f in range(2):
        for c in range(3):
            cmds = [x for ln in per_ch[c][f * H:(f + 1) * H] for x in ln]
            want = functional.render(cmds, W)
            np.testing.assert_array_equal(frames[f, :, :, c], want,
                                          err_msg=f"frame {f} colour {'RGB'[c]} SEED={seed}")
    assert st["ok"] and not st["errors"]
    assert st["sync"] == {"hsync_pulses": 2 * 21 - 1, "hsync_width": 96, "hsync_period": 800,
                          "vsync_pulses": 2, "vsync_width": 2 * 800, "vsync_period": 21 * 800}
    assert st["align_err"] == 0 and st["pix_collision"] == [0, 0, 0]
    for c, name in enumerate("RGB"):
        m = st["load_monitor"][name]
        want = [_slots(ln) for ln in per_ch[c][H:]]      # the line table keeps frame 2
        assert m["frame_count"] == 2
        assert m["line_issued"] == want
        assert m["issued"] == sum(want) and m["max_issued"] == max(want)
        assert m["free"] == H * 799 - sum(want)
        assert m["late_lines"] == 0 and m["total_dropped"] == 0
        assert sum(m["hist"]) == H
    assert st["words_written"] == [sum(len(isa.serialise(ln)) for ln in lines)
                                   for lines in per_ch]


def test_overload_is_late_and_counted(exe):
    seed = _seed()
    lines = _lines(seed, H, per_line=(1, 6))
    k = 5
    big = [isa.Command("EVAL", 1, 20, (1 << 24, 0, 0))] * 210 + [isa.Command("REFRESH")]
    assert _slots(big) > 799
    lines[k] = big
    stream = [c for ln in lines for c in ln]
    frames, st = dh.run([stream, stream, stream], CFG, mode=3)
    want = functional.render(stream, W)
    rows_ok = [r for r in range(H) if r != k]
    for c in range(3):
        np.testing.assert_array_equal(frames[0][rows_ok, :, c], want[rows_ok])
        m = st["load_monitor"]["RGB"[c]]
        assert m["late_lines"] == 1 and m["late_line_numbers"] == [k]
        assert m["total_dropped"] == _slots(big) - 799  # markers are not counted as drops
        assert m["line_issued"][k] == 799
    assert not (frames[0][k] == want[k][:, None]).all()  # the late line lost commands
    assert any("late line" in s for s in st["stderr"])


def test_png_roundtrip(tmp_path):
    rng = np.random.default_rng(1)
    img = rng.integers(0, 4096, (5, 7, 3), dtype=np.uint16)
    frame.write_png16(tmp_path / "a.png", img)
    np.testing.assert_array_equal(frame.read_png16(tmp_path / "a.png"), img)
    with pytest.raises(ValueError):
        frame.write_png16(tmp_path / "b.png", img + 4095)
