"""Analytic gradients of the rasterizer against central finite differences of its forward pass."""

import numpy as np
import pytest
import torch
from render_reference import blob, random_scene, rectangle

from samvg.render import rasterize


def mse_loss(points, colors, width, height, target):
    return ((rasterize(points, colors, width, height) - target) ** 2).sum()


def analytic(points, colors, width, height, target):
    p = torch.tensor(points, requires_grad=True)
    c = torch.tensor(colors, requires_grad=True)
    mse_loss(p, c, width, height, target).backward()
    return p.grad.numpy(), c.grad.numpy()


def value(points, colors, width, height, target) -> float:
    with torch.no_grad():
        return mse_loss(torch.tensor(points), torch.tensor(colors), width, height, target).item()


def relative_errors(a: np.ndarray, b: np.ndarray, floor: float) -> np.ndarray:
    keep = (np.abs(a) > floor) | (np.abs(b) > floor)
    return np.abs(a - b)[keep] / np.maximum(np.abs(a), np.abs(b))[keep]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_point_gradients_match_central_differences(seed):
    rng = np.random.default_rng(seed)
    width, height = 48, 40
    points, colors = random_scene(rng, 10, width, height)
    target = torch.tensor(rng.uniform(0, 1, (height, width, 3)))
    grad, _ = analytic(points, colors, width, height, target)
    eps = 1e-5
    numeric = np.zeros_like(points)
    for index in np.ndindex(points.shape):
        plus, minus = points.copy(), points.copy()
        plus[index] += eps
        minus[index] -= eps
        numeric[index] = (
            value(plus, colors, width, height, target) - value(minus, colors, width, height, target)
        ) / (2 * eps)
    errors = relative_errors(grad, numeric, 1e-4)
    assert errors.size > 50
    assert np.median(errors) <= 0.05
    assert np.quantile(errors, 0.9) <= 0.05
    # Paths entirely off the canvas have exactly zero gradient.
    np.testing.assert_array_equal(grad[np.abs(numeric).max(axis=(1, 2)) == 0], 0.0)


def test_colour_gradients_are_exact():
    rng = np.random.default_rng(3)
    width, height = 32, 32
    points, colors = random_scene(rng, 8, width, height)
    target = torch.tensor(rng.uniform(0, 1, (height, width, 3)))
    _, grad = analytic(points, colors, width, height, target)
    eps = 1e-6
    numeric = np.zeros_like(colors)
    for index in np.ndindex(colors.shape):
        plus, minus = colors.copy(), colors.copy()
        plus[index] += eps
        minus[index] -= eps
        numeric[index] = (
            value(points, plus, width, height, target) - value(points, minus, width, height, target)
        ) / (2 * eps)
    # The image is quadratic in each colour channel: central differences are exact up to rounding.
    np.testing.assert_allclose(grad, numeric, rtol=1e-6, atol=1e-6)


def test_colour_gradient_closed_form():
    square = rectangle(2, 2, 8, 8)[None]
    colors = torch.tensor([[0.2, 0.3, 0.4, 0.5]], requires_grad=True)
    image = rasterize(torch.tensor(square), colors, 10, 10, background=(1.0, 1.0, 1.0))
    image[..., 0].sum().backward()
    # 36 covered pixels: d/dr = a * 36, d/da = 36 * (r - 1).
    np.testing.assert_allclose(colors.grad.numpy(), [[18.0, 0.0, 0.0, 36 * (0.2 - 1)]], atol=1e-9)


def test_point_slid_along_straight_edge_gets_no_gradient():
    rng = np.random.default_rng(4)
    width = height = 40
    # One straight cubic segment from (5, 30) to (35, 8); the rest of the path is curved.
    a, b = np.array([5.0, 30.0]), np.array([35.0, 8.0])
    points = np.array(
        [
            a,
            a + 0.2 * (b - a),
            a + 0.7 * (b - a),
            b,
            [38, 30],
            [30, 38],
            [20, 36],
            [10, 38],
            [2, 36],
        ]
    )
    target = torch.tensor(rng.uniform(0, 1, (height, width, 3)))
    colors = np.array([[0.9, 0.1, 0.3, 0.8]])
    grad, _ = analytic(points[None], colors, width, height, target)
    direction = (b - a) / np.linalg.norm(b - a)
    normal = np.array([-direction[1], direction[0]])
    for index in (1, 2):
        along = grad[0, index] @ direction
        across = grad[0, index] @ normal
        assert abs(across) > 1e-2
        assert abs(along) <= 1e-9 * abs(across) + 1e-12


def test_grid_aligned_edges_get_two_sided_average():
    # Axis-aligned square on integer pixel boundaries: the loss has a kink there; the gradient
    # must be the average of the left and right derivatives, not zero.
    rng = np.random.default_rng(6)
    width = height = 12
    x0, y0, x1, y1 = 2.0, 3.0, 9.0, 10.0
    square = np.array(
        [
            [x0, y0],
            [x0 + 1, y0],
            [x1 - 1, y0],
            [x1, y0],
            [x1, y0 + 1],
            [x1, y1 - 1],
            [x1, y1],
            [x1 - 1, y1],
            [x0 + 1, y1],
            [x0, y1],
            [x0, y1 - 1],
            [x0, y0 + 1],
        ]
    )
    colors = np.array([[0.2, 0.5, 0.9, 0.8]])
    target = torch.tensor(rng.uniform(0, 1, (height, width, 3)))
    for points in (square, square[::-1].copy()):
        grad, _ = analytic(points[None], colors, width, height, target)
        base = value(points[None], colors, width, height, target)
        eps = 1e-7  # one-sided differences: O(eps) bias where the loss is smooth but curved
        for index in np.ndindex(points.shape):
            plus, minus = points.copy(), points.copy()
            plus[index] += eps
            minus[index] -= eps
            right = (value(plus[None], colors, width, height, target) - base) / eps
            left = (base - value(minus[None], colors, width, height, target)) / eps
            assert grad[0][index] == pytest.approx(0.5 * (left + right), rel=2e-3, abs=1e-4)
        assert np.abs(grad).max() > 0.1


def test_float32_and_path_list_gradients_agree_with_float64():
    rng = np.random.default_rng(7)
    width, height = 30, 30
    paths = [blob(rng, 12, 14, 8, k=3), blob(rng, 18, 15, 10, k=5)]
    colors = np.array([[1, 0, 0, 0.6], [0, 0.5, 1, 0.8]])
    target = torch.tensor(rng.uniform(0, 1, (height, width, 3)), dtype=torch.float32)
    leaves = [torch.tensor(p, dtype=torch.float32, requires_grad=True) for p in paths]
    cols = torch.tensor(colors, dtype=torch.float32, requires_grad=True)
    ((rasterize(leaves, cols, width, height) - target) ** 2).sum().backward()
    assert leaves[0].grad.dtype == torch.float32 and cols.grad.dtype == torch.float32
    for leaf, path in zip(leaves, paths, strict=True):
        p64 = torch.tensor(path, requires_grad=True)
        others = [torch.tensor(q) if q is not path else p64 for q in paths]
        (
            (rasterize(others, torch.tensor(colors), width, height) - target.double()) ** 2
        ).sum().backward()
        np.testing.assert_allclose(leaf.grad.numpy(), p64.grad.numpy(), rtol=1e-3, atol=1e-3)


def test_gradient_descent_moves_square_onto_target():
    # End-to-end sanity: optimise a square's position towards a shifted target render.
    def square(cx, cy, half):
        x0, x1, y0, y1 = cx - half, cx + half, cy - half, cy + half
        return torch.stack(
            [
                torch.stack(v)
                for v in [
                    (x0, y0),
                    (x0 + (x1 - x0) / 3, y0),
                    (x1 - (x1 - x0) / 3, y0),
                    (x1, y0),
                    (x1, y0 + (y1 - y0) / 3),
                    (x1, y1 - (y1 - y0) / 3),
                    (x1, y1),
                    (x1 - (x1 - x0) / 3, y1),
                    (x0 + (x1 - x0) / 3, y1),
                    (x0, y1),
                    (x0, y1 - (y1 - y0) / 3),
                    (x0, y0 + (y1 - y0) / 3),
                ]
            ]
        )[None]

    colors = torch.tensor([[0.1, 0.2, 0.7, 1.0]])
    target = rasterize(
        square(torch.tensor(20.0), torch.tensor(18.0), torch.tensor(8.0)), colors, 40, 40
    ).detach()
    centre = torch.tensor([14.0, 23.0], requires_grad=True)
    optimiser = torch.optim.Adam([centre], lr=0.5)
    for _ in range(60):
        optimiser.zero_grad()
        loss = (
            (rasterize(square(centre[0], centre[1], torch.tensor(8.0)), colors, 40, 40) - target)
            ** 2
        ).mean()
        loss.backward()
        optimiser.step()
    np.testing.assert_allclose(centre.detach().numpy(), [20.0, 18.0], atol=0.2)


def test_non_contiguous_inputs_and_partial_requires_grad():
    rng = np.random.default_rng(9)
    points, colors = random_scene(rng, 6, 24, 24)
    reference = analytic(points, colors, 24, 24, torch.zeros(24, 24, 3))
    # Points stored transposed (non-contiguous view), loss through an expanded gradient.
    storage = torch.tensor(points.transpose(0, 2, 1).copy(), requires_grad=True)
    image = rasterize(storage.transpose(1, 2), torch.tensor(colors), 24, 24)
    (image**2).sum().backward()
    np.testing.assert_allclose(storage.grad.transpose(1, 2).numpy(), reference[0], rtol=1e-9)
    # Gradients for colours only, then points only.
    cols = torch.tensor(colors, requires_grad=True)
    (rasterize(torch.tensor(points), cols, 24, 24) ** 2).sum().backward()
    np.testing.assert_allclose(cols.grad.numpy(), reference[1], rtol=1e-9)
    pts = torch.tensor(points, requires_grad=True)
    image = rasterize(pts, torch.tensor(colors), 24, 24)
    image.sum().backward()  # expanded (stride-0) incoming gradient
    assert torch.isfinite(pts.grad).all() and pts.grad.abs().sum() > 0
