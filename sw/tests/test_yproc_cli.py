"""The yproc and hsr_bench command lines: every subcommand their usage lists answers --help
on stdout with exit 0, and a bad command line names what is wrong (exit 2), not 'cannot
read'."""
from __future__ import annotations

import re
import subprocess

import pytest

import yproc_common as yc


@pytest.fixture(scope="module")
def yproc():
    return yc.build_yproc()


@pytest.mark.parametrize("args", [["--help"], ["-h"], ["scan", "x.scene", "-o", "d", "-h"]])
def test_help_exits_zero_on_stdout(yproc, args):
    r = yc.run(*args)
    assert r.stdout.startswith("usage: yproc hsr SCENE") and "--shading" in r.stdout
    assert r.stderr == ""


def _subcommands() -> list[str]:
    """The subcommands yproc's usage lists (`yproc NAME ...` lines), so a new one is
    covered without editing this file."""
    r = yc.run("--help")
    return sorted({m.group(1) for m in re.finditer(r"^\s*(?:usage: )?yproc ([a-z]+) ",
                                                     r.stdout, re.M)})


def test_usage_lists_every_subcommand(yproc):
    assert _subcommands() == ["anim", "hsr", "read", "scan", "serve"]


def test_every_subcommand_answers_help(yproc):
    for sub in _subcommands():
        for flag in ("--help", "-h"):
            r = yc.run(sub, flag)
            assert r.returncode == 0 and r.stderr == "", (sub, flag, r.stderr)
            assert r.stdout.startswith("usage: yproc hsr SCENE"), (sub, flag)
            assert f"yproc {sub} " in r.stdout, (sub, flag)


@pytest.mark.parametrize("args, msg", [
    ([], "missing subcommand"),
    (["render", "a.scene"], "unknown subcommand 'render'"),
    (["hsr"], "missing scene file after 'hsr'"),
    (["hsr", "a.scene", "--svg"], "missing value after '--svg'"),
    (["hsr", "a.scene", "--bogus"], "unknown option '--bogus'"),
    (["scan", "a.scene"], "missing -o OUTDIR"),
    (["scan", "a.scene", "-o"], "missing value after '-o'"),
    (["scan", "a.scene", "-o", "d", "--shading", "toon"], "--shading takes flat, gouraud or phong, not 'toon'"),
    (["scan", "a.scene", "-o", "d", "--frames", "0"], "--frames takes a count >= 1, not '0'"),
    (["anim", "a.anim", "-o", "d", "--capacity", "2"], "--capacity takes a slot count >= 4, not '2'"),
])
def test_bad_command_line_names_the_problem(yproc, args, msg):
    r = yc.run(*args, ok=False)
    assert r.returncode == 2
    assert r.stderr.startswith("yproc: " + msg), r.stderr
    assert "usage: yproc" in r.stderr


def test_hsr_bench_help_exits_zero():
    r = subprocess.run(["make", "-C", str(yc.HSR), "-s", "build/hsr_bench"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    exe = str(yc.HSR / "build" / "hsr_bench")
    usage = subprocess.run([exe, "--help"], capture_output=True, text=True)
    assert usage.returncode == 0 and usage.stdout.startswith("usage: hsr_bench")
    subs = sorted({m.group(1) for m in re.finditer(r"^\s*(?:usage: )?hsr_bench ([a-z]+) ",
                                                     usage.stdout, re.M)})
    assert subs == ["grid", "hsr", "move", "stack"]
    for sub in subs:
        r = subprocess.run([exe, sub, "--help"], capture_output=True, text=True)
        assert r.returncode == 0 and r.stdout.startswith("usage: hsr_bench"), sub
