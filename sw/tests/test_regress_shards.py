"""`make sim SHARD=k/N` and `make sim-merge` (sw/diffengine/regress/, docs/regression.md
"Shards and CI matrices"). Fast: the manifest is only expanded (no RTL build); the runs go
through a fake runner that returns made-up results."""
from __future__ import annotations

import json
import random
import shutil
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from diffengine.cli import main as cli_main
from diffengine.regress import cases as regress_cases, main as regress_main, shards as regress_shards

FAKE_MANIFEST = """
[[random]]
seeds = [1, 2, 3, 4, 5, 6, 7]
commands = 100
chips = [1, 2]
tier = "smoke"

[[random]]
seeds = [8, 9]
commands = 400
chips = [8]
tier = "full"

[[carry]]
seeds = [1, 2]
lines = 4
chips = [2]
tier = "full"
bug_check = true
"""


def names(shards):
    return [c.name for s in shards for c in s]


# ---- assignment: every case exactly once, deterministic, balanced -----------------------


@pytest.mark.parametrize("tier", regress_cases.TIERS)
@pytest.mark.parametrize("recorded", ["checked-in", "none"])
def test_shards_cover_every_case_once(tier, recorded):
    cases = regress_cases.load_manifest(regress_cases.MANIFEST, tier)
    durations = regress_shards.load_durations(regress_shards.DURATIONS) if recorded == "checked-in" else {}
    for n in range(1, 6):
        shards = regress_shards.assign_shards(cases, n, durations)
        assert len(shards) == n
        got = names(shards)
        assert len(got) == len(set(got)), f"a case in two shards (N={n})"
        assert sorted(got) == sorted(c.name for c in cases), f"a case in no shard (N={n})"
        order = {c.name: i for i, c in enumerate(cases)}
        for s in shards:   # manifest order inside a shard
            assert [order[c.name] for c in s] == sorted(order[c.name] for c in s)


def test_cli_list_shards_cover_the_tier(capsys):
    cases = regress_cases.load_manifest(regress_cases.MANIFEST, "full")
    seen = []
    for k in (1, 2, 3):
        assert cli_main(["sim", "--tier", "full", "--shard", f"{k}/3", "--list"]) == 0
        seen += [ln.split()[0] for ln in capsys.readouterr().out.splitlines()
                 if not ln.startswith("sim: ")]
    assert sorted(seen) == sorted(c.name for c in cases)


def test_assignment_is_deterministic():
    cases = regress_cases.load_manifest(regress_cases.MANIFEST, "nightly")
    durations = regress_shards.load_durations(regress_shards.DURATIONS)
    for n in (2, 3, 5):
        a = regress_shards.assign_shards(cases, n, durations)
        b = regress_shards.assign_shards(list(cases), n, dict(durations))
        assert [[c.name for c in s] for s in a] == [[c.name for c in s] for s in b]
        shuffled = list(cases)
        random.Random(n).shuffle(shuffled)   # the input order does not matter either
        c = regress_shards.assign_shards(shuffled, n, durations)
        assert [sorted(x.name for x in s) for s in a] == [sorted(x.name for x in s) for s in c]


def test_balance_uses_recorded_durations(tmp_path):
    cases = regress_cases.load_manifest(regress_cases.MANIFEST, "full")
    rng = random.Random(7)
    durations = {c.name: round(rng.uniform(0.5, 300.0), 1) for c in cases}
    longest = max(durations.values())
    total = sum(durations.values())
    for n in range(1, 6):
        sums = [sum(durations[c.name] for c in s)
                for s in regress_shards.assign_shards(cases, n, durations)]
        assert sum(sums) == pytest.approx(total)
        for s in sums:   # every shard within the longest case of the ideal
            assert abs(s - total / n) <= longest + 1e-9, (n, sums)
    # one very long recorded case gets a shard to itself; everything else shares the other
    one = cases[5].name
    skewed = {c.name: 1.0 for c in cases} | {one: 10_000.0}
    a, b = regress_shards.assign_shards(cases, 2, skewed)
    assert [c.name for c in a] == [one] and len(b) == len(cases) - 1
    # and the durations file is what the CLI balances on
    m = tmp_path / "manifest.toml"
    m.write_text(FAKE_MANIFEST)
    fake = regress_cases.load_manifest(m, "full")
    (tmp_path / "durations.json").write_text(json.dumps(
        {"seconds": {c.name: 1.0 for c in fake} | {fake[0].name: 500.0}}))
    assert [c.name for c in regress_shards.assign_shards(
        fake, 3, regress_shards.load_durations(tmp_path / "durations.json"))[0]] == [fake[0].name]


def test_fallback_estimate_for_unrecorded_cases(tmp_path):
    m = tmp_path / "manifest.toml"
    m.write_text(FAKE_MANIFEST)
    cases = {c.name: c for c in regress_cases.load_manifest(m, "full")}
    model = {n: regress_shards.model_seconds(c) for n, c in cases.items()}
    # nothing recorded: the cost model, so bigger streams and arrays cost more
    est = regress_shards.estimates(list(cases.values()), {})
    assert est == model
    assert est["random_s8_c8"] > est["random_s1_c2"] > est["random_s1_c1"] > 0
    # one 1-chip random case recorded: the others of its kind and size scale from it;
    # other sizes keep the model (no extrapolation across array sizes)
    est = regress_shards.estimates(list(cases.values()), {"random_s1_c1": 2.0})
    assert est["random_s1_c1"] == 2.0
    assert est["random_s2_c1"] == pytest.approx(2.0)
    assert est["random_s1_c2"] == pytest.approx(model["random_s1_c2"])
    assert est["carry_s1_c2"] == pytest.approx(model["carry_s1_c2"])
    # a recorded 2-chip carry case: 2-chip random cases take its ratio (same size)
    rec = {"carry_s1_c2": 3 * model["carry_s1_c2"]}
    est = regress_shards.estimates(list(cases.values()), rec)
    assert est["random_s1_c2"] == pytest.approx(3 * model["random_s1_c2"])
    assert est["random_s8_c8"] == pytest.approx(model["random_s8_c8"])
    # the real manifest: the model is in the range of the measured figures (§7)
    real = regress_cases.load_manifest(regress_cases.MANIFEST, "full")
    est = regress_shards.estimates(real, {})
    assert 120 < est["scene_cube_r_c72"] < 160 and 150 < est["scene_teapot_g_c72"] < 300


@pytest.mark.parametrize("bad", ["0/3", "4/3", "x", "1/0", "3", "a/b", "1/2/3", "-1/3", ""])
def test_bad_shard_values(bad):
    with pytest.raises(ValueError, match="SHARD"):
        regress_shards.parse_shard(bad)


@pytest.mark.parametrize("bad, why", [("0/3", "k must be in 1..3"),
                                      ("4/3", "k must be in 1..3"), ("x", "want k/N")])
def test_bad_shard_on_the_command_line(bad, why, capsys):
    with pytest.raises(SystemExit) as e:
        cli_main(["sim", "--shard", bad, "--list"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "--shard" in err and why in err


def test_good_shard_values():
    assert regress_shards.parse_shard("1/1") == (1, 1)
    assert regress_shards.parse_shard(" 3/5 ") == (3, 5)


# ---- runs and the merge, with a fake runner ----------------------------------------------


def fake_run(cases, out, jobs=2, waves=True, tier="", log=print):
    """Made-up results in the runner's format: pass, and the carry-bug cases an XFAIL with
    a first differing pixel (so the report needs the frames)."""
    results = {}
    for c in cases:
        ref = np.arange(6 * c.width, dtype=np.uint16).reshape(6, c.width)
        rtl = ref.copy()
        r = {"name": c.name, "status": "pass", "message": "bit-exact", "n_diff": 0,
             "first": None, "rtl": rtl, "ref": ref, "harness": "fake", "n_commands": 10,
             "n_lines": 6, "reasons": [], "seconds": 1.0 + len(c.name) / 10}
        if c.bug:
            rtl[2, 3] += 1
            r.update(status="fail", n_diff=1, first=(2, 3), bug_model_matches=True,
                     message="1 pixel(s) differ; first at line 2 column 3: RTL x reference y",
                     touching=[(7, "EVAL 0 18 ...")])
        results[c.name] = r
        (out / "cases" / c.name).mkdir(parents=True, exist_ok=True)
        (out / "cases" / c.name / "stream.cmd").write_text("REFRESH\n")
    return results, 0.5 * len(cases)


@pytest.fixture
def fake(tmp_path, monkeypatch):
    m = tmp_path / "manifest.toml"
    m.write_text(FAKE_MANIFEST)
    monkeypatch.setattr(regress_main, "run", fake_run)
    return m


def run_shards(manifest, out, n, tier="full"):
    for k in range(1, n + 1):
        assert cli_main(["sim", "--manifest", str(manifest), "--tier", tier, "--shard", f"{k}/{n}",
                             "--out", str(out)]) == 0
    return [regress_shards.shard_dir(out, k, n) for k in range(1, n + 1)]


def junit_names(path):
    return sorted(tc.get("name") for tc in ET.parse(path).getroot().iter("testcase"))


def test_shards_write_their_own_outputs_and_merge(fake, tmp_path):
    out = tmp_path / "out"
    dirs = run_shards(fake, out, 3)
    cases = regress_cases.load_manifest(fake, "full")
    per_shard = [junit_names(d / "junit.xml") for d in dirs]
    assert sorted(n for s in per_shard for n in s) == sorted(c.name for c in cases)
    for d in dirs:
        assert {"junit.xml", "results.json", "run.json", "report.html"} <= {
            p.name for p in d.iterdir()}
    assert not (out / "junit.xml").exists()     # nothing outside the shard folders
    assert not (tmp_path / "durations.json").exists(), "a shard must not record durations"

    merged = tmp_path / "merged"
    assert cli_main(["sim", "--merge", *map(str, dirs), "--out", str(merged)]) == 0
    assert junit_names(merged / "junit.xml") == sorted(c.name for c in cases)
    page = (merged / "report.html").read_text()
    assert "Merged from 3 shard(s)" in page
    for c in cases:
        assert f'<section id="{c.name}">' in page
    bug = next(c for c in cases if c.bug)
    # the frames came back from the shard: the first-pixel analysis is in the report,
    # and the case's files are linked in its shard folder
    assert "First differing pixel: line 2, column 3" in page
    k = next(i for i, d in enumerate(dirs) if (d / "cases" / bug.name).exists()) + 1
    assert f'href="../out/shard-{k}-of-3/cases/{bug.name}/stream.cmd"' in page
    # the merged summary is the one an unsharded run gives
    whole = tmp_path / "whole"
    assert cli_main(["sim", "--manifest", str(fake), "--tier", "full", "--out", str(whole),
                         "--no-record-durations"]) == 0
    assert (merged / "summary.txt").read_text() == (whole / "summary.txt").read_text()
    # a complete full-tier merge records the durations next to the manifest
    rec = regress_shards.load_durations(tmp_path / "durations.json")
    assert set(rec) == {c.name for c in cases}


def test_merge_detects_a_missing_case(fake, tmp_path, capsys):
    out = tmp_path / "out"
    dirs = run_shards(fake, out, 3)
    shard2 = [c["name"] for c in json.loads((dirs[1] / "run.json").read_text())["cases"]]
    capsys.readouterr()
    assert cli_main(["sim", "--merge", str(dirs[0]), str(dirs[2]), "--out",
                         str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert "missing" in err and "shard(s) not given: 2/3" in err
    for name in shard2:
        assert name in err
    assert not (tmp_path / "m" / "junit.xml").exists()
    # a case dropped from a shard's run (e.g. a hand-edited or truncated artifact)
    meta = json.loads((dirs[0] / "run.json").read_text())
    gone = meta["cases"].pop()["name"]
    (dirs[0] / "run.json").write_text(json.dumps(meta))
    assert cli_main(["sim", "--merge", *map(str, dirs), "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert "1 case(s) missing" in err and gone in err


def test_merge_detects_a_case_run_twice(fake, tmp_path, capsys):
    out = tmp_path / "out"
    dirs = run_shards(fake, out, 2)
    capsys.readouterr()
    assert cli_main(["sim", "--merge", str(dirs[0]), str(dirs[0]), str(dirs[1]), "--out",
                         str(tmp_path / "m")]) == 2
    assert "ran more than once" in capsys.readouterr().err
    # one case of shard 2 also in shard 1
    m2 = json.loads((dirs[1] / "run.json").read_text())
    r2 = json.loads((dirs[1] / "results.json").read_text())
    dup = m2["cases"][0]
    m1 = json.loads((dirs[0] / "run.json").read_text())
    r1 = json.loads((dirs[0] / "results.json").read_text())
    m1["cases"].append(dup)
    r1[dup["name"]] = r2[dup["name"]]
    (dirs[0] / "run.json").write_text(json.dumps(m1))
    (dirs[0] / "results.json").write_text(json.dumps(r1))
    assert cli_main(["sim", "--merge", *map(str, dirs), "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert "1 case(s) ran more than once" in err and dup["name"] in err


def test_merge_refuses_shards_of_different_runs(fake, tmp_path, capsys):
    a = run_shards(fake, tmp_path / "a", 2)
    b = run_shards(fake, tmp_path / "b", 3)
    capsys.readouterr()
    assert cli_main(["sim", "--merge", str(a[0]), str(b[1]), "--out", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err
    assert "different runs" in err and "shard 2/3 vs 1/2" in err
    c = run_shards(fake, tmp_path / "c", 2, tier="smoke")
    capsys.readouterr()
    assert cli_main(["sim", "--merge", str(a[0]), str(c[1]), "--out", str(tmp_path / "m")]) == 2
    assert "different runs (tier differs)" in capsys.readouterr().err
    assert cli_main(["sim", "--merge", str(tmp_path / "nowhere")]) == 2
    assert "not a shard folder" in capsys.readouterr().err


def test_more_shards_than_cases(fake, tmp_path):
    out = tmp_path / "out"
    dirs = []
    for k in range(1, 4):
        assert cli_main(["sim", "--manifest", str(fake), "--tier", "smoke", "-k", "random_s1_*",
                             "--shard", f"{k}/3", "--out", str(out)]) == 0
        dirs.append(regress_shards.shard_dir(out, k, 3))
    assert [len(junit_names(d / "junit.xml")) for d in dirs] == [1, 1, 0]
    assert cli_main(["sim", "--merge", *map(str, dirs), "--out", str(tmp_path / "m")]) == 0
    assert junit_names(tmp_path / "m" / "junit.xml") == ["random_s1_c1", "random_s1_c2"]


def test_record_durations_file(tmp_path, fake):
    cases = regress_cases.load_manifest(fake, "full")
    results, _ = fake_run(cases, tmp_path / "o")
    results[cases[0].name]["status"] = "unavailable"   # N/A: not a real duration
    path = tmp_path / "d.json"
    path.write_text(json.dumps({"seconds": {"gone_case": 3.0, cases[1].name: 99.0}}))
    n = regress_shards.record_durations(path, cases, results, keep={c.name for c in cases})
    assert n == len(cases) - 1
    rec = regress_shards.load_durations(path)
    assert cases[0].name not in rec and "gone_case" not in rec
    assert rec[cases[1].name] == round(results[cases[1].name]["seconds"], 1)
    shutil.copy(path, tmp_path / "again.json")
    regress_shards.record_durations(tmp_path / "again.json", cases, results,
                             keep={c.name for c in cases})
    assert (tmp_path / "again.json").read_text() == path.read_text()   # stable file
