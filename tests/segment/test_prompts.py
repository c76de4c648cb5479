"""Stage 1's prompts for SAM: centres of large uncovered regions."""

import numpy as np

from samvg.segment import circular_kernel, uncovered_prompts


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
