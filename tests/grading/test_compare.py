"""Tests of labkit.compare / labkit.pfm / labkit.heatmap on synthetic images.

No renderer is needed: "renders" are drawn from the statistical model the comparison assumes
(and, in one test, from a skewed Monte Carlo model with an estimated variance)."""

import json
import math
import os
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

from labkit import compare as cmp
from labkit.compare import (
    CHI_MEAN_MAX,
    InputError,
    compare,
    count_tests,
    critical_z,
    false_failure_rate,
    heatmap_png,
    normal_quantile,
)
from labkit.harness import ROOT
from labkit.heatmap import heatmap_scale
from labkit.pfm import PFMError, read_pfm, write_pfm

# ---------------------------------------------------------------------------------------
# Synthetic scenes


def scene(rng, h=64, w=64):
    """A smooth 'true' image in [0.1, 1] and a per-path variance (coefficient of variation
    about 1 per path, as for a diffusely lit scene)."""
    y, x = np.mgrid[0:h, 0:w]
    base = 0.55 + 0.45 * np.sin(x / 9.0)[..., None] * np.cos(y / 7.0)[..., None] * np.array(
        [1.0, 0.8, 0.6]
    )
    truth = np.clip(base, 0.1, 1.0) + 0.0 * rng.random((h, w, 3))
    variance = (truth * rng.uniform(0.5, 1.5, size=truth.shape)) ** 2
    return truth, variance


def draw(rng, truth, variance, spp):
    """A render with `spp` paths per pixel, from the model the test assumes (CLT)."""
    return truth + rng.standard_normal(truth.shape) * np.sqrt(variance / spp)


def golden_and_render(rng, truth, variance, test_spp, golden_spp):
    golden = draw(rng, truth, variance, golden_spp)
    image = draw(rng, truth, variance, test_spp)
    return image, golden


# ---------------------------------------------------------------------------------------
# Normal quantile and Bonferroni bookkeeping


def test_normal_quantile_known_values():
    assert normal_quantile(0.975) == pytest.approx(1.959963984540054, abs=1e-12)
    assert normal_quantile(0.5) == pytest.approx(0.0, abs=1e-15)
    assert normal_quantile(1 - 5e-5) == pytest.approx(3.890591886413094, abs=1e-9)
    assert normal_quantile(1e-10) == pytest.approx(-6.361340902404056, abs=1e-9)
    for p in (1e-300, 1e-12, 1e-6, 0.01, 0.3, 0.7, 0.99):
        x = normal_quantile(p)
        cdf = 0.5 * math.erfc(-x / math.sqrt(2))
        assert cdf == pytest.approx(p, rel=1e-10)
    with pytest.raises(ValueError):
        normal_quantile(0.0)


def test_test_count_and_critical_value():
    rng = np.random.default_rng(1)
    truth, var = scene(rng, 40, 48)  # 48 wide, 40 high: partial 16x16 blocks at the bottom
    image, golden = golden_and_render(rng, truth, var, 16, 1024)
    r = compare(image, 16, golden, var, 1024, alpha=1e-3)
    expected = 3 * (5 * 6) + 3 * (3 * 3) + 3
    assert r.n_tests == expected == count_tests(40, 48)
    assert r.critical_z == pytest.approx(critical_z(1e-3, expected))
    # two-sided: P(|Z| > c) = alpha / n_tests
    assert math.erfc(r.critical_z / math.sqrt(2)) == pytest.approx(1e-3 / expected, rel=1e-9)
    assert r.z_maps[16].shape == (3, 3, 3) and r.z_maps[8].shape == (5, 6, 3)


def test_false_failure_rate_bound_documented():
    assert false_failure_rate(1e-4, n_tests=195) == 1e-4
    inflated = false_failure_rate(1e-4, n_tests=195, variance_samples=16, block_pixels=64)
    c = critical_z(1e-4, 195)
    assert inflated == pytest.approx(1e-4 * math.exp(c ** 4 * 2 / (15 * 64) / 8))
    assert 1e-4 < inflated < 1.5e-4
    assert false_failure_rate(1e-4, n_tests=195, variance_samples=4096) < 1.001e-4
    assert "sqrt(2/(K-1))" in cmp.__doc__ and "union bound" in cmp.__doc__


# ---------------------------------------------------------------------------------------
# Correct renders pass (false-failure rate)


def test_pure_noise_passes():
    rng = np.random.default_rng(2)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 16, 4096)
    r = compare(image, 16, golden, var, 4096)
    assert r.passed, r.table()
    assert r.n_failed == 0 and r.nan_count == 0 and r.inf_count == 0
    assert r.max_abs_z < r.critical_z
    assert abs(r.bias) < 5 * r.bias_se
    assert "PASS" in r.summary() and "PASS" in r.table()


def test_empirical_false_failure_rate():
    """300 correct renders at alpha = 0.05: the family-wise rate must be <= alpha (up to
    binomial noise), and the statistics must be calibrated (z ~ N(0, 1)), i.e. the test is
    not passing merely because it is absurdly conservative."""
    rng = np.random.default_rng(3)
    truth, var = scene(rng, 40, 48)
    trials, alpha = 300, 0.05
    failures = 0
    global_z, block_z = [], []
    for _ in range(trials):
        image, golden = golden_and_render(rng, truth, var, 16, 1024)
        r = compare(image, 16, golden, var, 1024, alpha=alpha)
        failures += not r.passed
        global_z.extend(r.global_z)
        block_z.append(r.z_maps[8].ravel())
    rate = failures / trials
    print(f"empirical family-wise false-failure rate {rate:.3f} (alpha {alpha})")
    assert rate <= 0.08
    assert rate >= 0.01, "far below alpha: the threshold is far too conservative"
    # The global-mean test alone, at a per-test level of 5%, rejects about 5% of the time.
    g = np.abs(np.array(global_z))
    single = float(np.mean(g > normal_quantile(0.975)))
    assert 0.025 <= single <= 0.08, single
    # Block z-scores have unit variance (s2 includes the golden's noise) and zero mean.
    z = np.concatenate(block_z)
    assert np.mean(z * z) == pytest.approx(1.0, abs=0.05)
    assert abs(np.mean(z)) < 0.05


def test_bias_standard_error_is_calibrated():
    """bias / bias_se is standard normal when the channels are fully correlated (grey paths)
    and smaller (conservative) when they are independent."""
    rng = np.random.default_rng(16)
    truth, var = scene(rng, 24, 24)
    var[:] = var[:, :, :1]  # same variance in every channel
    correlated, independent = [], []
    for _ in range(300):
        noise = rng.standard_normal(truth.shape[:2] + (1,)) * np.sqrt(var * (1 / 16 + 1 / 64))
        r = compare(truth + noise, 16, truth, var, 64, alpha=0.05)
        correlated.append(r.bias / r.bias_se)
        r = compare(draw(rng, truth, var, 16), 16, draw(rng, truth, var, 64), var, 64)
        independent.append(r.bias / r.bias_se)
    assert np.mean(np.square(correlated)) == pytest.approx(1.0, abs=0.25)
    assert np.mean(np.square(independent)) == pytest.approx(1 / 3, abs=0.1)


def test_golden_noise_is_part_of_the_variance():
    """With a golden made from as few paths as the render, half of the difference's variance
    is the golden's own noise: leaving it out would fail correct renders en masse."""
    rng = np.random.default_rng(15)
    truth, var = scene(rng, 40, 48)
    zs, failures = [], 0
    for _ in range(100):
        image, golden = golden_and_render(rng, truth, var, 16, 16)
        r = compare(image, 16, golden, var, 16, alpha=0.05)
        failures += not r.passed
        zs.append(r.z_maps[16].ravel())
    z = np.concatenate(zs)
    assert np.mean(z * z) == pytest.approx(1.0, abs=0.1)
    assert failures <= 10


def test_false_failure_rate_monte_carlo_with_estimated_variance():
    """A skewed path-radiance distribution (exponential per path, so pixel means are Gamma
    distributed, exactly), a black zero-variance region, and a variance image estimated
    from K = 16 golden renders as in the real pipeline: still <= alpha."""
    rng = np.random.default_rng(4)
    h, w, K, golden_spp, test_spp = 32, 40, 16, 1024, 16
    truth, _ = scene(rng, h, w)
    truth[:, :8] = 0.0  # black: every path returns exactly 0
    m = golden_spp // K
    trials, alpha, failures = 200, 0.05, 0
    for _ in range(trials):
        renders = rng.gamma(m, truth / m, size=(K,) + truth.shape)
        golden = renders.mean(axis=0)
        variance = m * renders.var(axis=0, ddof=1)  # per-path variance estimate
        image = rng.gamma(test_spp, truth / test_spp)
        r = compare(image, test_spp, golden, variance, golden_spp, alpha=alpha)
        failures += not r.passed
    rate = failures / trials
    print(f"Monte Carlo model, K={K}: false-failure rate {rate:.3f} (alpha {alpha})")
    assert rate <= 0.09


# ---------------------------------------------------------------------------------------
# Wrong renders fail


def test_constant_bias_of_two_percent_fails():
    rng = np.random.default_rng(5)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth * 1.02, var, 64, 4096)
    golden = draw(rng, truth, var, 4096)
    r = compare(image, 64, golden, var, 4096)
    assert not r.passed
    assert all(z > r.critical_z for z in r.global_z), r.global_z
    mean_shift = float(np.mean(truth * 0.02))
    assert r.bias == pytest.approx(mean_shift, abs=4 * r.bias_se)
    assert any(f.block_size == 0 for f in r.failures)
    assert "whole image is too bright" in r.table()


def test_bright_block_fails_and_is_located():
    rng = np.random.default_rng(6)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 256, 4096)
    image[16:24, 24:32] += 0.10 * truth[16:24, 24:32]  # rows y 16..23, columns x 24..31
    r = compare(image, 256, golden, var, 4096)
    assert not r.passed
    wb = r.worst_block
    assert (wb.block_size, wb.x0, wb.y0) == (8, 24, 16) and wb.z > r.critical_z
    assert abs(r.global_z[0]) < r.critical_z  # too small to show in the global mean
    assert "8x8 block x 24..31, y 16..23" in r.table()
    assert "local" in r.table()


def test_misaligned_bright_patch_is_caught_by_larger_blocks():
    rng = np.random.default_rng(7)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 256, 4096)
    image[20:28, 20:28] += 0.10 * truth[20:28, 20:28]  # straddles four 8x8 blocks
    r = compare(image, 256, golden, var, 4096)
    assert not r.passed
    assert (r.worst_block.block_size, r.worst_block.x0, r.worst_block.y0) == (16, 16, 16)
    only8 = compare(image, 256, golden, var, 4096, block_sizes=(8,))
    assert only8.max_abs_z < r.max_abs_z


def test_missing_light_fails():
    rng = np.random.default_rng(8)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 16, 4096)
    r = compare(image * 0.5, 16, golden, var, 4096)
    assert not r.passed
    assert all(z < -r.critical_z for z in r.global_z)
    assert r.bias < 0 and "too dark" in r.table()
    assert r.n_failed > 100


def test_nan_pixel_fails():
    rng = np.random.default_rng(9)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 16, 4096)
    image[5, 3, 1] = np.nan
    r = compare(image, 16, golden, var, 4096)
    assert not r.passed
    assert r.nan_count == 1 and r.inf_count == 0
    assert r.first_nonfinite == (3, 5)
    assert math.isfinite(r.rmse) and math.isfinite(r.bias) and math.isfinite(r.max_abs_z)
    assert "NaN pixels 1" in r.table() and "x=3, y=5" in r.table()
    image[5, 3, 1] = golden[5, 3, 1]
    image[60, 60] = np.inf
    r = compare(image, 16, golden, var, 4096)
    assert not r.passed and r.nan_count == 0 and r.inf_count == 1


def test_zero_variance_region():
    rng = np.random.default_rng(10)
    truth, var = scene(rng)
    truth[:, :24] = [0.2, 0.3, 0.4]  # constant background, seen identically by every path
    var[:, :24] = 0.0
    image, golden = golden_and_render(rng, truth, var, 16, 4096)
    assert np.array_equal(image[:, :24], golden[:, :24])
    r = compare(image, 16, golden, var, 4096)
    assert r.passed, r.table()
    # float rounding noise is tolerated ...
    nudged = image.copy()
    nudged[:, :24] = np.float32(nudged[:, :24]).astype(np.float64) * (1 + 1e-7)
    assert compare(nudged, 16, golden, var, 4096).passed
    # ... but any real difference fails, with z = inf, at the right place
    image[10, 5, 2] += 1e-3
    r = compare(image, 16, golden, var, 4096)
    assert not r.passed
    assert math.isinf(r.max_abs_z) and r.worst_block.z == math.inf
    assert (r.worst_block.x0, r.worst_block.y0, r.worst_block.channel) == (0, 8, 2)
    assert "z = inf" in r.table()


def test_bad_inputs_raise_value_error():
    rng = np.random.default_rng(11)
    truth, var = scene(rng, 16, 16)
    with pytest.raises(ValueError, match="size mismatch"):
        compare(truth[:, :15], 16, truth, var, 1024)
    with pytest.raises(ValueError, match="size mismatch"):
        compare(truth, 16, truth, var[:15], 1024)
    with pytest.raises(ValueError):
        compare(truth, 0, truth, var, 1024)
    with pytest.raises(ValueError):
        compare(truth, 16, truth, -var, 1024)
    bad = truth.copy()
    bad[0, 0, 0] = np.nan
    with pytest.raises(InputError):
        compare(truth, 16, bad, var, 1024)


# ---------------------------------------------------------------------------------------
# Files: PFM, PNG heatmap, command line


def test_pfm_round_trip_exact(tmp_path):
    rng = np.random.default_rng(12)
    img = (rng.standard_normal((5, 7, 3)) * 10.0 ** rng.integers(-30, 30, (5, 7, 3))).astype(
        np.float32
    )
    img[0, 0] = [np.inf, -0.0, 1e-45]
    path = tmp_path / "x.pfm"
    write_pfm(path, img)
    back = read_pfm(path)
    assert back.dtype == np.float32 and back.shape == (5, 7, 3)
    assert np.array_equal(back, img) and np.signbit(back[0, 0, 1])
    data = path.read_bytes()
    header = b"PF\n7 5\n-1.0\n"
    assert data.startswith(header) and len(data) == len(header) + 5 * 7 * 12
    # rows are stored bottom to top, little endian
    first = struct.unpack("<3f", data[len(header):len(header) + 12])
    assert first == tuple(float(v) for v in img[4, 0])
    assert os.listdir(tmp_path) == ["x.pfm"]  # no temporary file left behind
    # big-endian files (positive scale) are read too
    be = tmp_path / "be.pfm"
    be.write_bytes(b"PF\n7 5\n1.0\n" + np.ascontiguousarray(img[::-1], dtype=">f4").tobytes())
    assert np.array_equal(read_pfm(be), img)
    trunc = tmp_path / "t.pfm"
    trunc.write_bytes(data[:-4])
    with pytest.raises(PFMError, match="bytes"):
        read_pfm(trunc)
    trunc.write_bytes(b"P6\n7 5\n255\n" + bytes(105))
    with pytest.raises(ValueError):
        read_pfm(trunc)


def parse_png(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, chunks = 8, []
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        chunks.append((kind, body))
        pos += 12 + length
    assert chunks[0][0] == b"IHDR" and chunks[-1] == (b"IEND", b"")
    w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    assert (depth, ctype, interlace) == (8, 2, 0)
    raw = zlib.decompress(b"".join(b for k, b in chunks if k == b"IDAT"))
    assert len(raw) == h * (1 + 3 * w)
    rows = np.frombuffer(raw, np.uint8).reshape(h, 1 + 3 * w)
    assert not rows[:, 0].any()  # filter 0 on every row
    return rows[:, 1:].reshape(h, w, 3)


def test_heatmap_written_on_failure_only(tmp_path):
    rng = np.random.default_rng(13)
    truth, var = scene(rng, 40, 48)
    image, golden = golden_and_render(rng, truth, var, 256, 4096)
    ok_path = tmp_path / "ok.png"
    assert compare(image, 256, golden, var, 4096, heatmap_path=ok_path).passed
    assert not ok_path.exists()

    image[16:24, 24:32] *= 1.15
    path = tmp_path / "fail.png"
    r = compare(image, 256, golden, var, 4096, heatmap_path=path)
    assert not r.passed and r.heatmap_path == str(path)
    rgb = parse_png(path.read_bytes())
    s = heatmap_scale(40, 48)
    assert s > 1 and rgb.shape == (40 * s, 48 * s, 3)
    assert tuple(rgb[16 * s, 24 * s + 4 * s]) == (0, 190, 0)  # worst block outlined in green
    r_, g_, b_ = (int(v) for v in rgb[20 * s, 28 * s])   # its interior: red (|z| >> limit)
    assert r_ > 200 and g_ < 60 and b_ < 60
    r_, g_, b_ = (int(v) for v in rgb[36 * s + 3, 4 * s])  # a correct block: bluish
    assert b_ > r_
    assert str(path) in r.table()

    # the standalone function, with a NaN block drawn black
    image[2, 2] = np.nan
    path2 = tmp_path / "standalone.png"
    heatmap_png(path2, image, golden, var, 256, 4096, block=8)
    rgb2 = parse_png(path2.read_bytes())
    assert rgb2.shape == rgb.shape and tuple(rgb2[4 * s, 4 * s]) == (0, 0, 0)


def write_reference(directory, golden, variance, golden_spp):
    os.makedirs(directory, exist_ok=True)
    write_pfm(os.path.join(directory, "golden.pfm"), golden)
    write_pfm(os.path.join(directory, "variance.pfm"), variance)
    with open(os.path.join(directory, "meta.json"), "w") as f:
        json.dump({"golden_spp": golden_spp, "scene": "synthetic"}, f)


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "labkit.compare", *map(str, args)],
                          cwd=ROOT, capture_output=True, text=True, timeout=60)


def test_cli_exit_codes(tmp_path):
    rng = np.random.default_rng(14)
    truth, var = scene(rng, 32, 32)
    image, golden = golden_and_render(rng, truth, var, 16, 4096)
    ref = tmp_path / "ref"
    write_reference(ref, golden.astype(np.float32), var.astype(np.float32), 4096)
    good = tmp_path / "good.pfm"
    write_pfm(good, image)
    bad = tmp_path / "bad.pfm"
    write_pfm(bad, image * 0.5)
    small = tmp_path / "small.pfm"
    write_pfm(small, image[:16])

    p = run_cli(good, "--golden", ref, "--spp", 16)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "PASS" in p.stdout and not (tmp_path / "good.heatmap.png").exists()

    p = run_cli(bad, "--golden", ref, "--spp", 16)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "FAIL" in p.stdout and "too dark" in p.stdout
    parse_png((tmp_path / "bad.heatmap.png").read_bytes())

    p = run_cli(small, "--golden", ref, "--spp", 16)
    assert p.returncode == 2 and "size mismatch" in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and p.stdout == ""

    p = run_cli(tmp_path / "nope.pfm", "--golden", ref, "--spp", 16)
    assert p.returncode == 2 and "nope.pfm: file not found" in p.stderr

    os.remove(ref / "variance.pfm")
    p = run_cli(good, "--golden", ref, "--spp", 16)
    assert p.returncode == 2 and "variance.pfm: file not found" in p.stderr

    p = run_cli(good, "--golden", tmp_path / "missing-dir", "--spp", 16)
    assert p.returncode == 2 and "not found" in p.stderr


# ---------------------------------------------------------------------------------------
# The per-pixel test: noise the block means cannot see


def test_per_pixel_statistics_are_calibrated():
    """A correct render: mean d^2/s2 near 1, median near chi-square(1)'s 0.455."""
    rng = np.random.default_rng(21)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 64, 16384)
    r = compare(image, 64, golden, var, 16384)
    assert r.passed, r.table()
    assert r.chi_mean == pytest.approx(1.0, abs=0.1)
    assert r.chi_median == pytest.approx(0.455, abs=0.05)


def test_a_quarter_of_the_paths_is_too_noisy():
    """Rendered with 16 paths, claimed as 64: the block means of a smooth image still pass at
    this size, the per-pixel test does not."""
    rng = np.random.default_rng(22)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 16, 16384)
    r = compare(image, 64, golden, var, 16384)
    assert not r.passed and "too noisy" in r.summary(), r.summary()
    assert r.chi_mean > 3


def test_a_few_underestimated_variances_do_not_make_a_correct_render_noisy():
    """Golden data estimated from few renders miss a glass ball's rare paths in some pixels:
    there the variance is far too small and d^2/s2 huge. Each value is capped in the mean, so
    a correct render still passes (uncapped, these pixels alone would lift the mean past the
    limit), and a quarter of the paths still fails."""
    rng = np.random.default_rng(25)
    truth, var = scene(rng)
    golden = draw(rng, truth, var, 16384)
    estimated = var.copy()
    rare = rng.choice(truth.shape[0] * truth.shape[1], size=40, replace=False)
    estimated.reshape(-1, 3)[rare] *= 0.01
    for spp, should_pass in ((64, True), (16, False)):
        image = draw(rng, truth, var, spp)
        r = compare(image, 64, golden, estimated, 16384)
        uncapped = float(np.mean((image - golden) ** 2 / (estimated * (1 / 64 + 1 / 16384))))
        assert r.passed == should_pass, r.summary()
        if should_pass:
            assert uncapped > CHI_MEAN_MAX >= r.chi_mean, (uncapped, r.chi_mean)
        else:
            assert "too noisy" in r.summary(), r.summary()


def test_pooled_variance_borrows_what_the_neighbours_saw():
    """Around a glass ball every pixel's paths are heavy-tailed; golden data from few renders
    caught the rare paths in some pixels and in none of one 4x4 block, whose estimated
    variance is then a hundredth of the truth: a correct render fails there. Pooled, each
    pixel of the block takes the larger variance its neighbours outside it saw, and the
    render passes; a 4x4 patch of pixels at half their brightness elsewhere still fails."""
    rng = np.random.default_rng(26)
    truth, var = scene(rng, 32, 32)
    var[11:17, 11:17] *= 100.0  # the ball's pixels, the block and a ring around it
    golden = draw(rng, truth, var, 16384)
    estimated = var.copy()
    estimated[12:16, 12:16] *= 0.01  # the block whose renders saw no rare path
    image = draw(rng, truth, var, 64)
    image[12, 13] += 3.0 * np.sqrt(var[12, 13] / 64)  # the render saw a rare path there
    blocks = (4, 8, 16)
    raw = compare(image, 64, golden, estimated, 16384, block_sizes=blocks)
    pooled = compare(image, 64, golden, estimated, 16384, block_sizes=blocks,
                     pooled_variance=True)
    assert not raw.passed and raw.worst_block.block_size == 4, raw.summary()
    assert pooled.passed, pooled.summary()
    dark = image.copy()
    dark[20:24, 4:8] *= 0.5
    r = compare(dark, 64, golden, estimated, 16384, block_sizes=blocks, pooled_variance=True)
    assert not r.passed and r.n_failed > 0, r.summary()


def test_a_denoised_image_is_too_smooth():
    """The truth plus a tenth of the noise (a denoiser's output): every block passes, the
    median d^2/s2 is far too small."""
    rng = np.random.default_rng(23)
    truth, var = scene(rng)
    golden = draw(rng, truth, var, 16384)
    image = truth + 0.1 * rng.standard_normal(truth.shape) * np.sqrt(var / 64)
    r = compare(image, 64, golden, var, 16384)
    assert r.n_failed == 0 and not r.passed and "too smooth" in r.summary(), r.summary()


def test_values_near_the_float_limit_do_not_pass():
    """Finite float32 values near 3.4e38 would overflow a float32 sum into inf and a NaN
    difference reads as no error through max(0, nan); the statistics are float64 and a NaN
    fails."""
    rng = np.random.default_rng(24)
    truth, var = scene(rng)
    image, golden = golden_and_render(rng, truth, var, 64, 16384)
    image = image.astype(np.float32)
    image[::2, ::2] = 3.3e38
    r = compare(image, 64, golden, var, 16384)
    assert not r.passed, r.summary()
