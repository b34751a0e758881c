"""bench.baseline: the C sources of a baseline revision. yproc links sw/fmodel since stop
31, so a baseline build that archived only sw/hsr, sw/yproc and sw/include (as the two
benches did) fails for any newer revision; and an old revision lacks folders a new list
names. Both cases, and a real build of HEAD's yproc from the extracted sources."""
from __future__ import annotations

import subprocess

import pytest

from diffengine import REPO
from diffengine.bench import baseline


def _rev_without(path: str) -> str:
    """The newest commit whose tree has no `path` (the commit before the one adding it)."""
    first = subprocess.run(["git", "-C", str(REPO), "log", "--diff-filter=A", "--format=%H",
                            "--reverse", "--", path], capture_output=True, text=True,
                           check=True).stdout.split()
    rev = first[0] + "^" if first else ""
    if not first or subprocess.run(["git", "-C", str(REPO), "cat-file", "-e", rev],
                                   capture_output=True).returncode != 0:
        pytest.skip(f"the commit before {path} was added is not in this clone (shallow)")
    return rev


def test_head_has_every_c_source():
    assert baseline.present("HEAD") == list(baseline.C_SOURCES)


def test_an_old_revision_skips_what_it_lacks():
    rev = _rev_without("sw/fmodel/Makefile")
    have = baseline.present(rev)
    assert "sw/fmodel" not in have and "sw/hsr" in have


def test_extract_refuses_a_revision_with_none_of_them(tmp_path):
    with pytest.raises(SystemExit, match="none of"):
        baseline.extract("HEAD", tmp_path / "x", paths=("no/such/folder",))


def test_heads_yproc_builds_from_the_extracted_sources(tmp_path):
    src = baseline.extract("HEAD", tmp_path / "base")
    r = subprocess.run(["make", "-s", "-C", str(src / "sw/yproc"), "build/yproc"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    assert (src / "sw/yproc/build/yproc").exists()
