"""The C sources of a baseline revision, for the benches that build its yproc/libhsr
(--baseline-rev of `bench yproc` and `bench hsr-incr`): `git archive` of the folders the
C build reads, each taken only if the revision has it (sw/include, sw/yproc and sw/lib.mk
exist from issue 17 on, sw/fmodel is linked into yproc from stop 31 on), unpacked into a
temporary directory. The repository's working tree is not touched."""
from __future__ import annotations

import subprocess
import tarfile
from pathlib import Path

from .. import REPO as ROOT

# What the C libraries and yproc build from, at any revision (missing ones are skipped).
C_SOURCES = ("sw/hsr", "sw/include", "sw/yproc", "sw/fmodel", "sw/lib.mk")


def present(rev: str, paths=C_SOURCES) -> list[str]:
    """The paths of `paths` that revision rev has (git cat-file -e)."""
    return [p for p in paths
            if subprocess.run(["git", "-C", str(ROOT), "cat-file", "-e", f"{rev}:{p}"],
                              capture_output=True).returncode == 0]


def extract(rev: str, dest: Path, paths=C_SOURCES) -> Path:
    """Unpack rev's copy of `paths` (those it has) into dest (created); returns dest."""
    have = present(rev, paths)
    if not have:
        raise SystemExit(f"baseline {rev}: none of {', '.join(paths)} in that revision")
    dest.mkdir(parents=True, exist_ok=False)
    arch = dest.with_suffix(".tar")
    with open(arch, "wb") as f:
        subprocess.run(["git", "-C", str(ROOT), "archive", rev, *have], stdout=f, check=True)
    with tarfile.open(arch) as t:
        t.extractall(dest)
    arch.unlink()
    return dest
