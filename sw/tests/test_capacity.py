"""The capacity model reproduces every entry of Tables 7.3 and 7.4 within 5%."""
from diffengine.model import capacity


def test_every_table_entry_within_five_percent():
    errs = capacity.errors()
    assert len(errs) == 32
    worst = max(errs.items(), key=lambda kv: abs(kv[1]))
    assert abs(worst[1]) <= 0.05, f"worst entry {worst[0]}: {worst[1]:+.1%}"


def test_report_names_every_entry():
    text = capacity.report()
    for word in ("Quadratic", "Linear", "Constant", "Eval0"):
        assert word in text


def test_slots_per_line_640x480():
    assert capacity.slots_per_line("640x480@60") == 800
