"""System packages install once, under one lock, whoever asks (scripts/ensure_system.sh).

`make test` runs pytest with several workers, and several tests (and sim/Makefile trace
builds) call scripts/ensure_fst.sh; with a bare `apt-get install` each, all but one lost
the dpkg lock. Now every caller goes through scripts/ensure_system.sh, which checks with
dpkg-query, then takes one flock before apt-get. Here:
(a) N callers of the ensure scripts at once (the set-up step, ensure_fst.sh with and
    without --headers, ensure_clang.sh) all exit 0;
(b) as root with a working apt: liblz4-dev (a leaf package the step installs; checked
    with `apt-get -s remove`) is removed, then the set-up step and ensure_fst.sh --headers
    run concurrently: every caller exits 0, exactly one of them installs, no apt lock
    error, and the package (and /usr/include/lz4.h) is back.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCRIPTS = REPO / "scripts"
PKG = "liblz4-dev"
ENV = dict(os.environ, DEBIAN_FRONTEND="noninteractive")


def run_at_once(cmds: list[list[str]], timeout: float = 600) -> list[subprocess.CompletedProcess]:
    """Start every command before waiting for any; return their results in order."""
    procs = [subprocess.Popen(c, cwd=REPO, env=ENV, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for c in cmds]
    out = []
    for c, p in zip(cmds, procs):
        so, se = p.communicate(timeout=timeout)
        out.append(subprocess.CompletedProcess(c, p.returncode, so, se))
    return out


def report(results) -> str:
    return "\n".join(f"$ {' '.join(r.args)} -> {r.returncode}\n{r.stdout}{r.stderr}"
                     for r in results)


def installed(pkg: str) -> bool:
    r = subprocess.run(["dpkg-query", "-W", "-f=${db:Status-Status}", pkg],
                       capture_output=True, text=True)
    return r.returncode == 0 and r.stdout.strip() == "installed"


def test_help_names_the_lock_and_the_list():
    r = subprocess.run([str(SCRIPTS / "ensure_system.sh"), "--help"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert "DPkg::Lock::Timeout=300" in r.stdout and "--no-install-recommends" in r.stdout
    lst = subprocess.run([str(SCRIPTS / "ensure_system.sh"), "--list"], capture_output=True,
                         text=True, check=True).stdout.split()
    assert {PKG, "gtkwave", "chromium", "build-essential", "ccache?"} <= set(lst), lst


def test_parallel_callers_all_succeed():
    """(a) N callers of the ensure scripts at once all exit 0."""
    cmds = [[str(SCRIPTS / "ensure_system.sh")]] * 3
    cmds += [[str(SCRIPTS / "ensure_fst.sh")]] * 2 + [[str(SCRIPTS / "ensure_fst.sh"),
                                                        "--headers"]] * 2
    if os.geteuid() == 0 or shutil.which("clang"):
        cmds += [[str(SCRIPTS / "ensure_clang.sh")]] * 2
    t0 = time.monotonic()
    res = run_at_once(cmds)
    assert all(r.returncode == 0 for r in res), report(res)
    assert not any("Could not get lock" in r.stderr for r in res), report(res)
    # and afterwards nothing is missing: a second call is a silent no-op
    again = subprocess.run([str(SCRIPTS / "ensure_system.sh"), "--check"],
                           capture_output=True, text=True)
    assert again.returncode == 0 and again.stderr == "", again.stderr
    print(f"{len(cmds)} parallel callers: {time.monotonic() - t0:.1f} s")


def test_removed_package_comes_back_once_under_concurrent_callers():
    """(b) remove liblz4-dev, then the set-up step x3 and ensure_fst.sh --headers x3 at once."""
    if os.environ.get("DE_TEST_REINSTALL") != "1":
        # Inside `make test` other workers compile against the lz4 headers at the same
        # time; removing them under their feet would fail those builds, not this step.
        pytest.skip("removes a package other tests use while they run: run alone with "
                    "`make test-first-run` (DE_TEST_REINSTALL=1)")
    if os.geteuid() != 0:
        pytest.skip("not root: cannot remove and reinstall a Debian package here")
    sim = subprocess.run(["apt-get", "-s", "remove", PKG], capture_output=True, text=True)
    removed = [ln.split()[1] for ln in sim.stdout.splitlines() if ln.startswith("Remv ")]
    assert sim.returncode == 0 and removed == [PKG], \
        f"removing {PKG} would remove {removed}: pick another package\n{sim.stderr}"
    lock = os.environ.get("DE_SYSTEM_LOCK") or (
        "/run/lock/diffengine-apt.lock" if os.access("/run/lock", os.W_OK)
        else "/tmp/diffengine-apt.lock")
    cmds = [[str(SCRIPTS / "ensure_system.sh")]] * 3 + \
        [[str(SCRIPTS / "ensure_fst.sh"), "--headers"]] * 3
    t0 = time.monotonic()
    try:
        # Remove under the project's lock, so that no other caller (another pytest worker,
        # a trace build) sees a half-removed package; it waits and then reinstalls.
        rm = subprocess.run(["flock", "-w", "900", lock, "apt-get",
                             "-o", "DPkg::Lock::Timeout=300", "remove", "-y", "-qq", PKG],
                            capture_output=True, text=True, env=ENV)
        assert rm.returncode == 0, rm.stdout + rm.stderr
        assert not installed(PKG) and not Path("/usr/include/lz4.h").exists()
        res = run_at_once(cmds)
    finally:
        if not installed(PKG):  # leave the machine as it was, whatever happened above
            subprocess.run([str(SCRIPTS / "ensure_system.sh"), PKG], env=ENV)
    assert all(r.returncode == 0 for r in res), report(res)
    assert not any("Could not get lock" in r.stderr for r in res), report(res)
    installers = [r for r in res if "ensure_system: installing" in r.stderr]
    assert len(installers) == 1, report(res)
    assert PKG in installers[0].stderr
    assert installed(PKG) and Path("/usr/include/lz4.h").exists()
    print(f"remove + {len(cmds)} concurrent callers: {time.monotonic() - t0:.1f} s")
