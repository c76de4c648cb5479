"""Stage 4's prompts for SAM: components of the disc-averaged error map above ω."""

import numpy as np
import pytest

from samvg.missing import missing_component_map, missing_component_prompts


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
