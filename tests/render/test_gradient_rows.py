"""Gradient colours and stop-colour gradients of the row kernels against a plain NumPy reference
of SVG pad gradients: clamped ends, coincident stops (hard steps), zero-length vectors."""

import numpy as np
import pytest
import torch

from samvg.render import rasterize
from samvg.render._paint_kernels import LINEAR, PARAMS, RADIAL
from samvg.render.rasterizer import GradientPaints
from tests.render.test_gradient_paints import blob

SIZE = 20


def reference(kind: int, row: np.ndarray, stops: int) -> tuple[np.ndarray, np.ndarray]:
    """(colour (H, W, 3), weight of every stop colour (H, W, stops)) at the pixel centres."""
    y, x = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    rx, ry = x - row[0], y - row[1]
    if kind == LINEAR:
        dx, dy = row[2] - row[0], row[3] - row[1]
        length2 = dx * dx + dy * dy
        t = np.clip((rx * dx + ry * dy) / length2, 0, 1) if length2 >= 1e-12 else np.ones_like(x)
    elif row[2] >= 1e-12:
        t = np.minimum(np.hypot(rx, ry) / row[2], 1.0)
    else:
        t = np.ones_like(x)
    offsets = row[4 : 4 + stops]
    weights = np.zeros((SIZE, SIZE, stops))
    for index, value in np.ndenumerate(t):
        if value <= offsets[0]:
            weights[index][0] = 1.0
            continue
        for j in range(stops - 1):
            if value < offsets[j + 1]:
                span = offsets[j + 1] - offsets[j]
                if span < 1e-12:
                    weights[index][j + 1] = 1.0
                else:
                    w = (value - offsets[j]) / span
                    weights[index][j : j + 2] = (1.0 - w, w)
                break
        else:
            weights[index][stops - 1] = 1.0
    colours = row[8 : 8 + 3 * stops].reshape(stops, 3)
    return weights @ colours, weights


CASES = [
    (LINEAR, 2, (3.0, 4.0, 15.0, 12.0), (0.0, 1.0)),
    (LINEAR, 3, (-5.0, 25.0, 30.0, -2.0), (0.2, 0.2, 0.7)),  # hard step, both ends clamped
    (LINEAR, 4, (8.0, 8.0, 8.0, 8.0), (0.1, 0.4, 0.6, 0.9)),  # zero length: the last stop
    (RADIAL, 3, (10.0, 9.0, 7.5, 0.0), (0.0, 0.5, 0.5)),
    (RADIAL, 4, (-3.0, 14.0, 30.0, 0.0), (0.15, 0.3, 0.8, 0.95)),
    (RADIAL, 2, (10.0, 10.0, 0.0, 0.0), (0.3, 0.6)),  # zero radius: the last stop
]


@pytest.mark.parametrize(("kind", "stops", "geometry", "offsets"), CASES)
def test_rows_paint_and_differentiate_the_reference_gradient(kind, stops, geometry, offsets):
    row = np.zeros(PARAMS)
    row[:4] = geometry
    row[4 : 4 + stops] = offsets
    row[8 : 8 + 3 * stops] = np.random.default_rng(stops).uniform(0, 1, 3 * stops)
    points = torch.tensor(blob(10.0, 10.0, 40.0)[None])  # covers the canvas
    colours = torch.tensor([[0.0, 0.0, 0.0, 1.0]], dtype=torch.float64)
    params = torch.tensor(row[None], requires_grad=True)
    paints = GradientPaints(np.array([kind]), np.array([stops]), params)
    image = rasterize(points, colours, SIZE, SIZE, background=(0.0, 0.0, 0.0), gradients=paints)
    expected, weights = reference(kind, row, stops)
    assert np.allclose(image.detach().numpy(), expected, rtol=0, atol=1e-12)

    target = np.random.default_rng(1).uniform(-1, 1, (SIZE, SIZE, 3))
    (image * torch.tensor(target)).sum().backward()
    # d loss / d (stop s, channel ch) = sum over pixels of target * weight of stop s
    expected_grad = np.einsum("hwc,hws->sc", target, weights).reshape(-1)
    assert np.allclose(params.grad[0, 8 : 8 + 3 * stops].numpy(), expected_grad, atol=1e-9)
    if np.all(weights[..., -1] == 1.0):  # the last stop everywhere: nothing else moves it
        assert np.all(params.grad[0, :8].numpy() == 0.0)
