"""The verdict of the whole-board full-frame simulations (sim/board/board_sim.py,
`make sim-board`) on the harness's frame list, without the simulation: the frames from
the first one that is not black must follow the sequence and be at least as many as
asked. The harness gives up after `want + 8` decoded frames, so a sequence that starts
late shows fewer frames than asked, with no other error: that must fail the case (it
passed before: an animation whose three frames were never all shown was a PASS).
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "sim" / "board"))

import board_sim  # noqa: E402


def stats(kinds: list[int]) -> dict:
    """A harness stats.json: one entry per decoded frame, -1 black, k golden frame k."""
    first = next((i for i, k in enumerate(kinds) if k != -1), -1)
    return {"errors": [], "first_live_frame": first,
            "frames": [{"index": i, "golden": k} for i, k in enumerate(kinds)]}


def test_the_sequence_in_full_passes():
    # 5 black frames, then frames 0 1 2 twice (hold 1), as make sim-board's animation.
    live, order, expect, errors = board_sim.sequence_check(
        stats([-1] * 5 + [0, 1, 2, 0, 1, 2]), 3, 1, 6)
    assert errors == [] and order == expect == [0, 1, 2, 0, 1, 2] and len(live) == 6


def test_hold_two():
    _, _, expect, errors = board_sim.sequence_check(stats([-1, 0, 0, 1, 1, 0, 0]), 2, 2, 6)
    assert errors == [] and expect == [0, 0, 1, 1, 0, 0]


def test_too_few_frames_fail():
    # The harness stopped at want + 8 = 14 frames: the sequence began at frame 12.
    _, order, expect, errors = board_sim.sequence_check(stats([-1] * 12 + [0, 1]), 3, 1, 6)
    assert order == expect == [0, 1]
    assert errors == ["2 frame(s) of the sequence shown (from decoded frame 12), want 6"]


def test_wrong_order_and_no_live_frame_fail():
    _, _, _, errors = board_sim.sequence_check(stats([-1, 0, 2, 1]), 3, 1, 3)
    assert errors == ["frames shown [0, 2, 1], want the sequence [0, 1, 2]"]
    _, _, _, errors = board_sim.sequence_check(stats([-1] * 9), 1, 1, 2)
    assert errors == ["0 frame(s) of the sequence shown (from decoded frame -1), want 2"]


def test_harness_errors_are_kept():
    res = stats([-1, 0, 0])
    res["errors"] = ["3 late line(s)"]
    _, _, _, errors = board_sim.sequence_check(res, 1, 1, 2)
    assert errors == ["3 late line(s)"]


def test_store_loss_counts_what_the_store_lost():
    """The golden frame (the frame-store words) against the streams' own 8-bit view: a
    frame with 2 % of its pixels 40 levels off is over the 1 % limit; 250 levels off is 6
    levels the other way round (the output window wraps), within the limit."""
    import numpy as np
    views = np.full((2, 10, 100, 3), 100, dtype=np.uint8)
    gold = views.copy()
    gold[0, 0, :20, 1] += 40                 # 20 of 1,000 pixels, one colour each
    gold[1, :, :, 2] = (gold[1, :, :, 2].astype(int) + 250) % 256
    loss = board_sim.store_loss(gold, views)
    key = f"over_{board_sim.LOSS_LEVELS}_levels"
    assert loss[0]["pixels_differing"] == 20 and loss[0][key] == 0.02 > board_sim.LOSS_MAX
    assert loss[0]["over_32_levels"] == 0.02 and loss[0]["max_levels"] == 40
    assert loss[1]["pixels_differing"] == 1000 and loss[1][key] == 0.0
    assert loss[1]["max_levels"] == 6
    assert board_sim.store_loss(views, views)[0] == {
        "pixels_differing": 0, key: 0.0, "over_32_levels": 0.0, "max_levels": 0}
