"""Prompts for SAM: centres of large uncovered regions and of missing components."""

import numpy as np
import pytest

from samvg.segment import (
    circular_kernel,
    missing_component_map,
    missing_component_prompts,
    uncovered_prompts,
)


def test_circular_kernel_is_a_disc():
    kernel = circular_kernel(3)
    assert kernel.shape == (7, 7) and kernel[3, 3] == 1 and kernel[0, 0] == 0
    assert kernel.sum() == 29  # lattice points within radius 3
    assert circular_kernel(0).sum() == 1


def test_uncovered_prompts_land_in_each_large_hole_only():
    covered = np.ones((120, 160), bool)
    covered[10:50, 10:60] = False  # large hole
    covered[70:110, 100:150] = False  # large hole
    covered[100:104, 10:14] = False  # too small for the kernel
    prompts = uncovered_prompts(covered, radius=6)
    assert 2 <= len(prompts) <= 4
    holes = set()
    for x, y in prompts:
        assert not covered[int(y), int(x)]
        holes.add(int(x) > 80)
    assert holes == {False, True}
    assert len(uncovered_prompts(np.ones((50, 50), bool), radius=4)) == 0


def test_uncovered_prompt_is_inside_a_non_convex_region():
    covered = np.ones((100, 100), bool)
    covered[10:90, 10:30] = False
    covered[70:90, 10:90] = False  # an L
    for x, y in uncovered_prompts(covered, radius=5):
        assert not covered[int(y), int(x)]


def test_missing_component_threshold_is_on_the_rgb_sum_scale():
    target = np.zeros((60, 60, 3), np.float32)
    render = target.copy()
    render[20:40, 20:40] = 0.30  # |I - I'| summed over RGB = 0.9 >= 0.784
    render[0:10, 45:60] = 0.25  # 0.75 < 0.784: not missing
    averaged, above = missing_component_map(target, render, radius=3, threshold=0.784)
    assert averaged.max() == pytest.approx(0.9, abs=1e-5)
    prompts = missing_component_prompts(averaged, above)
    assert len(prompts) == 1
    np.testing.assert_allclose(prompts[0], (30.0, 30.0), atol=1.0)


def test_missing_component_prompts_largest_first_and_inside():
    above = np.zeros((50, 50), bool)
    above[5:10, 5:10] = True
    yy, xx = np.mgrid[:50, :50]
    ring = (np.hypot(xx - 30, yy - 30) < 15) & (np.hypot(xx - 30, yy - 30) > 10)
    above |= ring
    averaged = above.astype(np.float32)
    prompts = missing_component_prompts(averaged, above)
    assert len(prompts) == 2
    x, y = prompts[0]
    assert ring[int(y), int(x)]  # the ring is larger; its centroid is outside, so snapped
