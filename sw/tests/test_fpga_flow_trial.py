"""fpga/scripts/flow.py: a chip seed run with other options than the committed ones is a
trial and never overwrites fpga/reports/seeds_chip.* (docs/fpga-timing-log.md section 6,
sixth look). Only the option handling is tested here; no tool runs."""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FLOW = ROOT / "fpga" / "scripts" / "flow.py"


@pytest.fixture(scope="module")
def flow():
    spec = importlib.util.spec_from_file_location("de_fpga_flow", FLOW)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def chip_args(**kw):
    # No timing_weight: the flow's own default (CHIP_TIMING_WEIGHT), as argparse gives it.
    base = dict(design="chip", seeds="1,2,3,4,5", freq=200.0, pnr_arg=None)
    base.update(kw)
    return argparse.Namespace(**base)


def test_the_committed_configuration_is_not_a_trial(flow):
    assert flow.chip_trial_tag(chip_args()) is None
    assert flow.chip_trial_tag(chip_args(timing_weight=flow.CHIP_TIMING_WEIGHT)) is None
    assert flow.chip_pnr_args(chip_args()) == ["--placer-heap-timingweight",
                                               str(flow.CHIP_TIMING_WEIGHT)]


def test_nextpnrs_own_default_weight_is_a_trial_now(flow):
    # 10 adds no nextpnr option, but it is not the committed weight (80): a trial.
    assert flow.CHIP_TIMING_WEIGHT != 10
    assert flow.chip_pnr_args(chip_args(timing_weight=10)) == []
    assert flow.chip_trial_tag(chip_args(timing_weight=10)) == "trial_placer-heap-timingweight_10"


@pytest.mark.parametrize("kw, tag", [
    (dict(seeds="1"), "trial_s1"),
    (dict(freq=155.0), "trial_f155"),
    (dict(timing_weight=60), "trial_placer-heap-timingweight_60"),
    (dict(pnr_arg=["--placer static"]), "trial_placer_static"),
    (dict(seeds="1,2", pnr_arg=["--placer-heap-beta 0.7"]),
     "trial_s1-2_placer-heap-beta_0.7"),
])
def test_any_other_option_makes_a_trial(flow, kw, tag):
    assert flow.chip_trial_tag(chip_args(**kw)) == tag


def test_pnr_args_are_split_on_blanks_after_the_timing_weight(flow):
    args = chip_args(timing_weight=30, pnr_arg=["--placer static", "--tmg-ripup"])
    assert flow.chip_pnr_args(args) == ["--placer-heap-timingweight", "30",
                                        "--placer", "static", "--tmg-ripup"]


def test_a_trial_report_repeats_its_options(flow):
    args = chip_args(seeds="1", freq=155.0, timing_weight=30, pnr_arg=["--placer static"])
    assert flow.trial_options(args) == " --freq 155 --timing-weight 30 --pnr-arg='--placer static'"
    assert flow.trial_options(chip_args()) == ""
    assert flow.trial_options(chip_args(design="board")) == ""


@pytest.mark.parametrize("sub", [[], ["seeds"], ["pe"], ["chip"], ["array-fit"], ["frames"]])
def test_every_subcommand_answers_help(sub):
    r = subprocess.run([sys.executable, str(FLOW), *sub, "--help"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert "usage:" in r.stdout
