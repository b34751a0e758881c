"""2-D spline-wavelet coding (encode/wavelet.py) and its entropy coder (encode/entropy.py).

Random tests print their seed (SEED=n replays). The decode path under test is the
receiver's: file -> entropy decoder -> vertical synthesis -> per-line commands -> the
golden model (functional.render), whose pixels must equal the floating-point decoder's.
"""
from __future__ import annotations

import os
import random

import numpy as np
import pytest

from diffengine import REPO, isa
from diffengine.encode import entropy as EC
from diffengine.encode import image as EN
from diffengine.encode import spline as ES
from diffengine.encode import wavelet as WV
from diffengine.model import functional


def _seed() -> int:
    s = int(os.environ.get("SEED", random.randrange(1 << 30)))
    print(f"SEED={s}")
    return s


def _golden(streams, width):
    g = [functional.render(s, width).astype(np.int64) for s in streams]
    return g[0] if len(g) == 1 else np.stack(g, -1)


# ---- transform ----------------------------------------------------------------------------


@pytest.mark.parametrize("trial", range(4))
def test_transform_perfect_reconstruction(trial):
    seed = _seed() + trial
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(1, 90, 2))
    Jx, Jy = WV.levels_for(w), WV.levels_for(h)
    x = rng.normal(0, 1000, (h, w))
    c = WV.fwd2(x, Jx, Jy)
    assert c.shape == x.shape
    np.testing.assert_allclose(WV.inv2(c, Jx, Jy), x, atol=1e-8, err_msg=f"SEED={seed}")


def test_synthesis_is_piecewise_linear_with_few_knots():
    # one coarse coefficient: its line is a hat (3 knots), what Eval2 + 2-3 SetdI draws
    lay = WV.Layout(256, 1, WV.levels_for(256), 0)
    hc = np.zeros(256)
    hc[3] = 100.0
    r = WV.synth_line(hc, lay)
    knots = np.flatnonzero(np.abs(np.diff(r, 2)) > WV.KNOT_TOL)
    assert 1 <= len(knots) <= 3
    lc = WV.line_commands(r)
    assert lc.kind in ("spline", "mixed") and lc.spline_px >= 16   # the hat is an Eval2
    assert ES.slot_count(lc.commands) < 20       # not a raster (257)
    np.testing.assert_array_equal(functional.render(lc.commands, 256)[0],
                                  np.clip(np.floor(r + 0.5), 0, 4095))


def _plan_cost(segs, knot, target):
    c = 0
    for a, b, spline in segs:
        if spline:
            c += WV.EVAL2_SLOTS + WV.SET_SLOTS * int(knot[a + 1:b - 1].sum())
        else:
            c += WV.EVAL0_SLOTS * (1 + int(np.count_nonzero(target[a + 1:b] != target[a:b - 1])))
    return c


@pytest.mark.parametrize("trial", range(5))
def test_segment_plan_is_optimal(trial):
    # O(n) running-minimum DP against an O(n^2) brute force over segment starts
    seed = _seed() + trial
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 60))
    knot = rng.random(n) < rng.random()
    knot[0] = knot[-1] = False
    target = np.cumsum(rng.random(n) < rng.random()).astype(np.int64)
    segs = WV.segment_plan(knot, target)
    assert segs[0][0] == 0 and segs[-1][1] == n
    assert all(s[1] == t[0] for s, t in zip(segs, segs[1:]))
    best = [0] + [None] * n
    for i in range(1, n + 1):
        best[i] = min(best[j] + min(_plan_cost([(j, i, True)], knot, target),
                                    _plan_cost([(j, i, False)], knot, target))
                      for j in range(i))
    assert _plan_cost(segs, knot, target) == best[n], f"SEED={seed}"


def test_line_commands_patch_out_of_range_values():
    # a line that overshoots 4095 and undershoots 0 must not wrap in the array
    r = np.concatenate([np.linspace(3900, 4300, 20), np.linspace(4300, -200, 30),
                        np.linspace(-200, 100, 14)])
    lc = WV.line_commands(r)
    want = np.clip(np.floor(r + 0.5), 0, 4095).astype(np.int64)
    np.testing.assert_array_equal(lc.pixels, want)
    np.testing.assert_array_equal(functional.render(lc.commands, len(r))[0], want)


# ---- entropy coder ----------------------------------------------------------------------------


def test_adaptive_probabilities_match_sequential_counts():
    seed = _seed()
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2, 500)
    ctx = rng.integers(0, 7, 500)
    got = EC.adaptive_probabilities(bits, ctx)
    n, n1 = [0] * 7, [0] * 7
    for i, (b, c) in enumerate(zip(bits, ctx)):
        want = min(max(((2 * n1[c] + 1) * EC.PONE) // (2 * n[c] + 2), 1), EC.PONE - 1)
        assert got[i] == want, f"bit {i} SEED={seed}"
        n[c] += 1
        n1[c] += int(b)


@pytest.mark.parametrize("trial", range(6))
def test_entropy_round_trip_random(trial):
    seed = _seed() + trial
    rng = np.random.default_rng(seed)
    bands, classes = [], []
    for _ in range(int(rng.integers(1, 8))):
        h, w = (int(v) for v in rng.integers(1, 40, 2))
        scale = float(10 ** rng.uniform(-1, 4.5))
        q = np.round(rng.laplace(0, scale, (h, w))).astype(np.int64)
        q[rng.random((h, w)) < rng.random()] = 0        # runs of zeros, varying density
        bands.append(q)
        classes.append(int(rng.integers(0, 256)))
    words = EC.encode_bands(bands, classes)
    out = EC.decode_bands(words, [b.shape for b in bands], classes)
    for a, b in zip(bands, out):
        np.testing.assert_array_equal(a, b, err_msg=f"SEED={seed}")


def test_entropy_edge_cases():
    big = np.array([[0, 1, -1, 2**40, -(2**40) - 7, 3]], dtype=np.int64)
    for bands in ([np.zeros((5, 5), np.int64)], [big], [np.zeros((1, 1), np.int64), big]):
        classes = list(range(len(bands)))
        out = EC.decode_bands(EC.encode_bands(bands, classes), [b.shape for b in bands],
                              classes)
        for a, b in zip(bands, out):
            np.testing.assert_array_equal(a, b)


def test_entropy_coder_adapts():
    # a skewed source costs far less than a bit per symbol: the model learns it
    rng = np.random.default_rng(5)
    q = (rng.random((64, 64)) < 0.02).astype(np.int64)
    nbytes = 4 * len(EC.encode_bands([q], [0]))
    assert nbytes * 8 < 0.25 * q.size


# ---- the codec, through commands and the golden model -------------------------------------------


def _crop(name, h, w, y0=0, x0=0):
    x = EN.load_image(REPO / "sw" / "images" / f"{name}.png")
    return x[y0:y0 + h, x0:x0 + w]


@pytest.mark.parametrize("name,shape", [("natural", (40, 72)), ("spheres", (33, 50)),
                                        ("bars", (24, 64))])
def test_codec_round_trip_through_commands(name, shape):
    x = _crop(name, *shape, y0=11, x0=17)
    prev_bytes, prev_psnr = 0, float("inf")
    for delta in (4096.0, 256.0, 16.0, 1.0):
        data = WV.encode_file(x, delta)
        streams, sim, st = WV.decode_file(data)
        assert len(streams) == (3 if x.ndim == 3 else 1)
        gold = _golden(streams, x.shape[1])
        np.testing.assert_array_equal(gold, sim)
        np.testing.assert_array_equal(gold, WV.float_decode(data))
        for s in streams:
            lines = isa.split_lines(s)
            assert len(lines) == x.shape[0]
        p = ES.psnr(gold, x)
        # finer steps: more bytes, better pictures (the last is near-lossless)
        assert len(data) > prev_bytes
        if prev_psnr != float("inf"):
            assert p > prev_psnr - 0.5, (delta, p, prev_psnr)
        prev_bytes, prev_psnr = len(data), p
    assert prev_psnr > 65.0


def test_codec_lines_use_knots_on_smooth_images():
    # a smooth ramp image at a coarse step: lines go out as Eval2 + SetdI, few instructions
    yy, xx = np.mgrid[0:32, 0:128]
    x = (300 + 20 * xx + 30 * yy + 200 * np.sin(xx / 17.0)).astype(np.int64)
    data = WV.encode_file(x, 64.0)
    streams, sim, st = WV.decode_file(data)
    assert st["spline_lines"] + st["mixed_lines"] == 32
    assert st["spline_px"] > 0.9 * x.size
    assert ES.slot_count(streams[0]) < 0.5 * 32 * 129
    np.testing.assert_array_equal(_golden(streams, 128), WV.float_decode(data))
    assert ES.psnr(sim, x) > 40.0


def test_bad_files_are_rejected():
    with pytest.raises(WV.WaveletError):
        WV.read_coefficients(b"JUNK" + bytes(40))
    data = WV.encode_file(_crop("natural", 16, 16), 32.0)
    with pytest.raises(WV.WaveletError):
        WV.read_coefficients(data[:-1])
    with pytest.raises(WV.WaveletError):
        WV.encode_file(np.zeros((4, 4)), 0.0)


# ---- the fetched photographs: checksum, no network needed ------------------------------------


def test_fetch_photo_checks_the_checksum(tmp_path, monkeypatch):
    import zipfile

    from diffengine.bench import recon_images as RI

    member, digest, _ = RI.PHOTOS["camera"]
    # a cached wheel whose camera.png is not the published one: rejected, not used
    with zipfile.ZipFile(tmp_path / "scikit_image-0.26.0-cp311-none-any.whl", "w") as z:
        z.writestr(member, b"not the photograph")
    with pytest.raises(RI.FetchError, match="SHA-256"):
        RI.fetch_photo("camera", tmp_path)
    assert not (tmp_path / "camera.png").exists()
    # a cached file with the right digest is used as it is (sha256 stubbed to the digest)
    (tmp_path / "camera.png").write_bytes(b"stand-in")
    monkeypatch.setattr(RI, "_sha256", lambda p: digest)
    assert RI.fetch_photo("camera", tmp_path) == tmp_path / "camera.png"
    with pytest.raises(RI.FetchError, match="unknown photograph"):
        RI.fetch_photo("lena", tmp_path)
