"""Tests of the baselines on small real images: random init, LIVE-style layers and VTracer."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from samvg import InputError, VectorImage, VectorPath
from samvg.baselines import (
    TracedSvg,
    blob,
    count_shapes,
    live,
    parameter_count,
    path_count,
    random_blobs,
    random_init,
    run_baseline,
    schedule,
    vtracer_trace,
)
from samvg.baselines.live import find_seeds
from samvg.imaging import error_map
from samvg.optimize import FitSettings


def load(bench_dir: Path, relative: str, side: int) -> np.ndarray:
    with Image.open(bench_dir / relative) as opened:
        image = opened.convert("RGB").resize((side, side), Image.Resampling.LANCZOS)
    return np.asarray(image, dtype=np.float32) / 255.0


@pytest.fixture(scope="module")
def cactus(bench_dir: Path) -> np.ndarray:
    return load(bench_dir, "emoji/noto_cactus.png", 64)


def mse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.mean((np.asarray(a, np.float64) - b) ** 2))


def test_blob_without_jitter_is_a_circle():
    points = blob((32.0, 32.0), 20.0, 5)
    assert points.shape == (15, 2)
    np.testing.assert_allclose(np.hypot(*(points[0::3] - 32.0).T), 20.0)
    render = VectorImage(64, 64, [VectorPath(points, (0, 0, 0, 1))]).render()
    area = float((1.0 - render[:, :, 0]).sum())
    assert abs(area - np.pi * 20.0**2) < 0.01 * np.pi * 20.0**2


def test_random_blobs_follow_the_seed():
    first = random_blobs(64, 48, 7, 5, np.random.default_rng(3))
    again = random_blobs(64, 48, 7, 5, np.random.default_rng(3))
    other = random_blobs(64, 48, 7, 5, np.random.default_rng(4))
    np.testing.assert_array_equal(first[0], again[0])
    np.testing.assert_array_equal(first[1], again[1])
    assert not np.allclose(first[0], other[0])
    assert first[0].shape == (7, 15, 2) and first[1].shape == (7, 4)
    assert np.all((first[1] >= 0) & (first[1] <= 1))


def test_random_init_is_deterministic_and_fitting_lowers_the_error(cactus):
    start = random_init(cactus, 8, steps=0, seed=5)
    fitted = random_init(cactus, 8, steps=60, seed=5)
    repeat = random_init(cactus, 8, steps=60, seed=5)
    assert fitted.path_count == 8 and (fitted.width, fitted.height) == (64, 64)
    np.testing.assert_array_equal(fitted.points, repeat.points)
    before, after = mse(start.render(), cactus), mse(fitted.render(), cactus)
    assert after < 0.6 * before, (before, after)


def test_schedule_doubles_and_sums_to_the_path_count():
    assert schedule(1) == [1]
    assert schedule(10) == [1, 2, 4, 3]
    assert schedule(15) == [1, 2, 4, 8]
    assert all(sum(schedule(n)) == n for n in range(1, 70))


def two_squares() -> np.ndarray:
    target = np.ones((64, 64, 3), np.float32)
    target[8:40, 8:40] = (0.9, 0.1, 0.1)  # large red square
    target[48:58, 44:54] = (0.1, 0.2, 0.8)  # small blue square
    return target


def test_seeds_go_to_the_largest_regions_of_error_with_their_colour():
    target = two_squares()
    error = error_map(target, np.ones_like(target))
    first, second = find_seeds(error, target, 2)
    assert 8 < first.centre[0] < 40 and 8 < first.centre[1] < 40
    np.testing.assert_allclose(first.colour, (0.9, 0.1, 0.1), atol=1e-4)
    assert first.area == 32 * 32
    assert 44 < second.centre[0] < 54 and 48 < second.centre[1] < 58
    np.testing.assert_allclose(second.colour, (0.1, 0.2, 0.8), atol=1e-4)
    # no error left: the extra seeds fall back to the worst pixels, still one per request
    assert len(find_seeds(np.zeros((16, 16)), np.ones((16, 16, 3)), 3)) == 3


def test_live_adds_paths_where_the_error_is():
    target = two_squares()
    # stage 1 puts one small circle in the red square; stage 2 adds two: one in what is left
    # of the red square (the largest error region), one in the blue square
    result = live(target, 3, steps=0)
    render = result.render()
    assert result.path_count == 3
    np.testing.assert_allclose(render[24, 24], (0.9, 0.1, 0.1), atol=0.02)
    np.testing.assert_allclose(render[53, 49], (0.1, 0.2, 0.8), atol=0.02)
    assert np.allclose(render[4, 60], 1.0)  # nothing placed where there was no error


def test_live_fits_a_real_image(cactus):
    calls = []
    result = live(cactus, 6, steps=40, progress=lambda done, total: calls.append((done, total)))
    assert result.path_count == 6
    assert calls[-1] == (40, 40) and len(calls) == 40
    assert mse(result.render(), cactus) < 0.5 * mse(np.ones_like(cactus), cactus)


def test_vtracer_path_count_lands_near_the_target_without_exceeding_it(bench_dir):
    image = load(bench_dir, "emoji/twemoji_sunflower.png", 128)
    for wanted in (6, 20):
        traced = vtracer_trace(image, wanted)
        assert isinstance(traced, TracedSvg)
        assert wanted - max(2, wanted // 5) <= traced.path_count <= wanted, traced.settings
        assert traced.shape_count >= traced.path_count
        by_shapes = vtracer_trace(image, wanted, count="shapes")
        assert wanted - max(2, wanted // 5) <= by_shapes.shape_count <= wanted
        render = traced.render()
        assert render.shape == (128, 128, 3) and render.dtype == np.float32
        assert mse(render, image) < 0.02
        assert parameter_count(traced) > 6 * traced.path_count
    assert traced.svg.startswith("<?xml")


def test_count_shapes_counts_every_subpath():
    svg = '<svg><path d="M0 0L4 0L4 4Z M1 1L2 1L2 2Z"/><path d="m5 5l1 0l0 1z"/></svg>'
    assert count_shapes(svg) == 3
    assert count_shapes("<svg></svg>") == 0


def test_run_baseline_gives_one_shape_for_every_method(cactus):
    options = FitSettings(steps=5, point_learning_rate=1.0, colour_learning_rate=0.01)
    for name in ("diffvg", "live", "vtracer", "vtracer-shapes"):
        result = run_baseline(name, (cactus * 255).astype(np.uint8), 4, options, seed=1)
        assert result.render().shape == (64, 64, 3)
        assert "<svg" in result.to_svg()
        if not name.startswith("vtracer"):
            assert path_count(result) == 4
            assert parameter_count(result) == 4 * 34  # the paper's 34 numbers per path


def test_run_baseline_rejects_bad_requests(cactus):
    with pytest.raises(InputError, match="unknown baseline"):
        run_baseline("potrace", cactus, 4, FitSettings(steps=1))
    with pytest.raises(InputError, match="count must be 'paths' or 'shapes'"):
        vtracer_trace(cactus, 4, count="holes")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="path count"):
        run_baseline("diffvg", cactus, 0, FitSettings(steps=1))
    with pytest.raises(InputError, match="steps"):
        run_baseline("live", cactus, 3)
    with pytest.raises(InputError, match="steps"):
        random_init(cactus, 3, steps=-1)
