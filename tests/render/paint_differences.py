"""Central differences of a loss against the analytic gradient of one gradient paint's row."""

from collections.abc import Callable

import numpy as np
import pytest
import torch

from samvg.render._paint_kernels import LINEAR, PARAMS
from samvg.render.rasterizer import GradientPaints


def check_paint_row(
    loss: Callable[[torch.Tensor], torch.Tensor],
    base: GradientPaints,
    row: int,
    kind: int,
    stops: int,
    step: float = 1e-6,
) -> np.ndarray:
    """Assert that d loss / d params[row] matches central differences on every parameter the
    paint uses and is exactly 0 on the others; returns the analytic row."""
    params = base.params.clone().requires_grad_(True)
    loss(params).backward()
    assert params.grad is not None
    analytic = params.grad[row].numpy()
    used = [*range(4 if kind == LINEAR else 3), *range(4, 4 + stops), *range(8, 8 + 3 * stops)]
    for index in used:
        shifted = []
        for sign in (1.0, -1.0):
            moved = base.params.clone()
            moved[row, index] += sign * step
            shifted.append(float(loss(moved)))
        numeric = (shifted[0] - shifted[1]) / (2 * step)
        assert analytic[index] == pytest.approx(numeric, rel=1e-4, abs=1e-6), index
    unused = sorted(set(range(PARAMS)) - set(used))
    assert np.all(analytic[unused] == 0.0)
    return analytic[used]
