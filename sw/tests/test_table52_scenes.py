"""The source's observations on Figs. 5.13-5.18 (section 5.3.3), checked on the six test
scenes as `diffengine bench table52` generates them (seed 1995, the benchmark's).

H = the largest number of domains in one slice (cell) x the number of slices (cells) /
the number of domains: 1 for a perfectly even spread; "the maximum of the number of
domains per slice is inversely proportional to the number of slices" = H about the same
at every subdivision.

    pytest -q sw/tests/test_table52_scenes.py
"""
from __future__ import annotations

import numpy as np
import pytest

from diffengine.bench import table52 as T

SEED = 1995


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    return T.scenes(SEED, tmp_path_factory.mktemp("teapot"), teapot_n=25)


@pytest.fixture(scope="module")
def H(scenes):
    """H per scene: slices 10 / 100 / 1000, cells 40x40 / 100x100 / 1000x1000."""
    out = {}
    for name, e in scenes.items():
        n = len(e)
        h = {m: T.homogeneity(T.slice_counts(e, m), n) for m in T.SLICES}
        for m in (40, 100, 1000):
            h[f"{m}x{m}"] = T.homogeneity(T.cell_counts(e, m), n)
        out[name] = h
        print(name, {k: round(v, 2) for k, v in h.items()})
    return out


def test_scenes_as_described(scenes):
    """100K domains (Teapot ~40K), coverage ~10 (Teapot: over its own part of the image)."""
    for name, e in scenes.items():
        info = T.scene_info(name, e)
        assert ((e[:, 0] >= 0) & (e[:, 1] >= 0) & (e[:, 2] <= T.WIN) & (e[:, 3] <= T.WIN)).all(), name
        if name == "Teapot":
            assert 38_000 <= info["n"] <= 42_000
        else:
            assert info["n"] == T.N_DOM, name
            assert 9.0 <= info["coverage"] <= 10.5, (name, info)
    r = T.scene_info("Random", scenes["Random"])
    assert r["wmax"] <= 125 and r["hmax"] <= 125


@pytest.mark.parametrize("name", ["Random", "Two-size"])
def test_homogeneous_at_every_resolution(H, name):
    """Figs. 5.13-5.15, 5.17: Random and Two-size spread evenly over 10, 100, 1000 slices
    and 100 x 100 cells."""
    for m in T.SLICES:
        assert H[name][m] <= 1.5, (name, m, H[name][m])
    assert H[name]["100x100"] <= 3.0, H[name]


def test_vlsi_grid_alignment(H, scenes):
    """Figs. 5.13-5.15, 5.17, 5.18: Vlsi is homogeneous over 10 and 100 slices and 100 x 100
    cells, but at 1000 slices (and 1000 x 1000 cells) the alignment of its domains on the
    100 x 100 grid shows: more slices no longer lower the maximum in proportion."""
    v = H["Vlsi"]
    assert v[10] <= 1.5 and v[100] <= 1.5 and v["100x100"] <= 3.0, v
    assert v[1000] >= 3.0 and v[1000] >= 2.5 * v[100], v
    assert v["1000x1000"] >= 2 * H["Random"]["1000x1000"], (v, H["Random"])


@pytest.mark.parametrize("name", ["Landscape", "Cluster"])
def test_inhomogeneous_but_inversely_proportional(H, name):
    """Landscape and Cluster are unevenly spread, yet their maximum per slice (per cell) is
    'practically inversely proportional' to the number of slices (cells)."""
    h = H[name]
    assert h[10] >= 2.0, h                       # inhomogeneous
    assert h[1000] / h[10] <= 2.0, h             # practically inversely proportional
    assert h["100x100"] / h["40x40"] <= 2.0, h


def test_teapot_hot_spots(H, scenes):
    """Teapot's hot spots: the maximum per slice does not fall in proportion, and from 1K
    slices to 1M cells the longest list shrinks 'with just a factor of 15'."""
    h = H["Teapot"]
    assert h[1000] / h[10] >= 2.5, h
    e = scenes["Teapot"]
    factor = T.slice_counts(e, 1000).max() / T.cell_counts(e, 1000).max()
    print("Teapot longest list, 1K slices / 1M cells:", factor)
    assert 15 * 0.75 <= factor <= 15 * 1.25, factor


def test_large_landscape_extents_break_proportionality():
    """Why Landscape's largest side is 200, not 750: with 750 the near-horizon cut-off
    u_min is ~200 units, most domains crowd into a thin band and the maximum per slice no
    longer falls in proportion (the check above then fails)."""
    e = T.scene_landscape(np.random.default_rng(SEED), smax=750.0)
    h = {m: T.homogeneity(T.slice_counts(e, m), len(e)) for m in T.SLICES}
    assert h[1000] / h[10] > 3.0, h
    with pytest.raises(ValueError):
        T.scene_landscape(np.random.default_rng(SEED), smax=100.0)   # coverage 10 impossible


def test_grid_scan_counts(tmp_path):
    """hsr_bench grid on a small scene against a numpy recount: overlaps by brute force;
    entries = per cell in the visited range, the entries with right+top >= Q.left+Q.bot
    plus the one that stops the list; empty cells; the source's wider loop range."""
    import subprocess
    rng = np.random.default_rng(7)
    W, Q, NQ, n = 1000, 40, 12, 300
    lb = rng.integers(0, W - 60, (n, 2))
    e = np.concatenate([lb, lb + rng.integers(0, 60, (n, 2))], 1)
    f = tmp_path / "ext.txt"
    np.savetxt(f, e, fmt="%d")
    r = subprocess.run(["make", "-C", str(T.HSR), "-s", "build/hsr_bench"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    wmax, hmax = int((e[:, 2] - e[:, 0]).max()), int((e[:, 3] - e[:, 1]).max())
    for m in (1, 7, 50):
        out = subprocess.run([str(T.BENCH), "grid", f, str(W), str(Q), str(NQ), str(m)],
                             capture_output=True, text=True, check=True).stdout
        d = T.kv(out)
        cw = -(-W // m)
        col = lambda x: int(np.clip(x // cw, 0, m - 1))
        cell = np.clip(e[:, 1] // cw, 0, m - 1) * m + np.clip(e[:, 0] // cw, 0, m - 1)
        key = e[:, 2] + e[:, 3]
        tot = dict(entries=0, empty=0, over=0, passed=0, s_entries=0, s_empty=0)
        dc, dr = -(-(Q + wmax) * m // W), -(-(Q + hmax) * m // W)
        for qy in range(NQ):
            for qx in range(NQ):
                cx, cy = int((qx + 0.5) * W / NQ), int((qy + 0.5) * W / NQ)
                q = (cx - Q // 2, cy - Q // 2, cx - Q // 2 + Q, cy - Q // 2 + Q)
                tot["over"] += int((~((e[:, 2] < q[0]) | (e[:, 0] > q[2]) | (e[:, 3] < q[1]) | (e[:, 1] > q[3]))).sum())
                c0, c1, r0, r1 = col(q[0] - wmax), col(q[2]), col(q[1] - hmax), col(q[3])
                for rr in range(max(0, r1 - dr), r1 + 1):
                    for cc in range(max(0, c1 - dc), c1 + 1):
                        k = key[cell == rr * m + cc]
                        ge = int((k >= q[0] + q[1]).sum())
                        v, emp = ge + (ge < len(k)), len(k) == 0
                        tot["s_entries"] += v
                        tot["s_empty"] += emp
                        if rr >= r0 and cc >= c0:
                            tot["entries"] += v
                            tot["empty"] += emp
                            tot["passed"] += ge
        assert int(d["overlaps"]) == tot["over"] > 0
        assert int(d["entries"]) == tot["entries"] and int(d["passed"]) == tot["passed"], (m, d, tot)
        assert int(d["empty_cells"]) == tot["empty"], (m, d, tot)
        assert int(d["seed_entries"]) == tot["s_entries"] and int(d["seed_empty"]) == tot["s_empty"], (m, d, tot)
        assert int(d["seed_entries"]) >= int(d["entries"]) >= int(d["passed"])
