"""Filter by impact: impacts are exact fractions of the image's error, redundant masks go."""

import numpy as np
import pytest

from samvg.segment import ImpactCanvas, filter_by_impact, keep_all


def square(shape, top, left, size):
    mask = np.zeros(shape, dtype=bool)
    mask[top : top + size, left : left + size] = True
    return mask


def test_impact_of_exact_mask_on_blank_canvas_is_its_area_fraction():
    target = np.zeros((40, 50, 3), np.float32)
    target[10:20, 10:20] = (1.0, 0.5, 0.0)
    canvas = ImpactCanvas(target, threshold=0.0)
    decision = canvas.offer(square((40, 50), 10, 10, 10))
    assert decision.kept
    assert decision.impact == pytest.approx(100 / 2000)
    np.testing.assert_allclose(decision.colour, (1.0, 0.5, 0.0))
    assert canvas.mean_error == pytest.approx(1.0 - 100 / 2000)


def test_dark_images_are_not_favoured():
    """Uncovered pixels are at maximum error, so painting black on black still helps."""
    target = np.zeros((20, 20, 3), np.float32)
    kept, canvas = filter_by_impact([square((20, 20), 0, 0, 20)], target, threshold=0.5)
    assert kept == [0]
    assert canvas.mean_error == pytest.approx(0.0)


def test_duplicate_and_useless_masks_are_dropped_and_canvas_reverts():
    target = np.zeros((30, 30, 3), np.float32)
    target[:, 15:] = 1.0
    left, right = np.zeros((30, 30), bool), np.zeros((30, 30), bool)
    left[:, :15] = True
    right[:, 15:] = True
    whole = np.ones((30, 30), bool)
    kept, canvas = filter_by_impact([left, right, whole, left.copy()], target, threshold=1e-3)
    # largest first: the whole-image mask (grey) helps a blank canvas; both halves refine it;
    # the duplicate of the left half changes nothing.
    assert sorted(kept) == [0, 1, 2]
    assert canvas.mean_error == pytest.approx(0.0, abs=1e-7)
    before = canvas.canvas.copy()
    assert not canvas.offer(whole).kept  # would undo the halves: negative impact
    np.testing.assert_array_equal(canvas.canvas, before)


def test_threshold_trades_paths_for_error():
    rng = np.random.default_rng(1)
    target = rng.uniform(0, 1, (64, 64, 3)).astype(np.float32)
    masks = [square((64, 64), r, c, s) for r, c, s in rng.integers(0, 48, (40, 3)) + (0, 0, 4)]
    counts, errors = [], []
    for threshold in (0.0, 1e-3, 1e-2):
        kept, canvas = filter_by_impact(masks, target, threshold)
        counts.append(len(kept))
        errors.append(canvas.mean_error)
    assert counts[0] > counts[1] > counts[2]
    assert errors[0] < errors[1] < errors[2]
    assert len(keep_all(masks, target)[0]) == len(masks)


def test_mask_below_smaller_kept_masks_only_counts_visible_pixels():
    target = np.zeros((20, 20, 3), np.float32)
    small = square((20, 20), 5, 5, 5)
    canvas = ImpactCanvas(target, threshold=0.0)
    canvas.offer(small)
    impact_below, _ = canvas.impact_of(np.ones((20, 20), bool), below=True)
    assert impact_below == pytest.approx((400 - 25) / 400)


def test_start_canvas_counts_as_covered():
    target = np.full((10, 10, 3), 0.5, np.float32)
    canvas = ImpactCanvas(target, threshold=0.0, start=np.zeros_like(target))
    assert canvas.covered.all() and canvas.mean_error == pytest.approx(0.25)
    assert canvas.offer(square((10, 10), 0, 0, 5)).impact == pytest.approx(0.25 * 25 / 100)


def test_bad_shapes_are_errors():
    canvas = ImpactCanvas(np.zeros((10, 10, 3)), threshold=0.0)
    with pytest.raises(ValueError, match="does not match"):
        canvas.offer(np.ones((5, 5), bool))
    assert not canvas.offer(np.zeros((10, 10), bool)).kept
