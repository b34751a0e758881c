"""The coverage classifier: bins follow docs/isa.md's flag rules, and the report names
every bin that was not hit."""
from diffengine.regress import coverage, randgen
from diffengine import isa

ONE = 1 << 24


def test_random_stream_hits_every_bin_on_two_chips():
    cov = coverage.Coverage(18).add_stream(randgen.stream(7, 20000, 18))
    assert cov.missing() == [], cov.report()


def test_cross_chip_is_not_a_bin_on_one_chip():
    cov = coverage.Coverage(9).add_stream(randgen.stream(7, 20000, 9))
    assert ("Eval1", "cross_chip") not in cov.missing()
    assert "n/a" in cov.report()


def test_report_names_missing_bins():
    cov = coverage.Coverage(18).add_stream([isa.Command("EVAL", 2, 3, (ONE,))])
    assert ("Eval1", "in_chip") not in cov.missing()
    assert ("Dis", "pe0") in cov.missing()
    assert "NOT HIT" in cov.report() and "DisxPe0".lower() in cov.report().lower()


def test_protect_and_disable_follow_the_isa_rules():
    cmds = [isa.Command("SETI", 4, 1, (ONE,)), isa.Command("EVAL", 8, 2, (ONE,)),
            isa.Command("EVAL", 3, 3, (ONE,)),     # covers 4: protected; clears it
            isa.Command("EVAL", 3, 3, (ONE,)),     # now unprotected
            isa.Command("DIS", 10, 1), isa.Command("EVAL", 7, 4, (0, ONE))]
    cov = coverage.Coverage(18).add_stream(cmds)
    assert cov.hits[("Eval1", "protected")] == 1
    assert cov.hits[("Eval1", "unprotected")] == 2
    assert cov.hits[("Eval2", "disabled")] == 1
    assert cov.hits[("Eval2", "cross_chip")] == 1
