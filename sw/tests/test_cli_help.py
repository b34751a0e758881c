"""Every `diffengine` subcommand, nested ones included, answers --help with exit status 0
(issue 17 item 5). The tree is walked, not listed, so a new subcommand is covered."""
from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from diffengine.cli import tree


def _paths(parser: argparse.ArgumentParser, prefix=()):
    yield prefix
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _paths(sub, prefix + (name,))


PATHS = list(_paths(tree.build_parser()))


def test_the_tree_has_every_stage():
    names = {p[0] for p in PATHS if p}
    assert {"asm", "disasm", "model", "plot", "compare", "capacity", "encode", "reference",
            "frame", "trace", "inspect", "sim", "demo", "anim", "bench"} <= names
    assert {p[1] for p in PATHS if len(p) == 2 and p[0] == "bench"} >= {
        "model", "yproc", "hsr", "array", "span", "recon", "recon-images", "render"}


@pytest.mark.parametrize("path", PATHS, ids=lambda p: " ".join(p) or "diffengine")
def test_help_exits_0(path, capsys):
    with pytest.raises(SystemExit) as e:
        tree.main([*path, "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: ") and "--help" in out


def test_help_as_a_process():
    """python -m diffengine (what the console script runs) with a nested subcommand."""
    r = subprocess.run([sys.executable, "-m", "diffengine", "bench", "render", "--help"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "docs/performance.md" in r.stdout
