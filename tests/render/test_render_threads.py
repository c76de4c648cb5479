"""The rasterizer on several threads: the same image and point gradients as on one, to the bit;
colour gradients summed per band (equal to the last bits), and the same bits on every run with
one thread count."""

import numpy as np
import pytest
import torch
from render_reference import random_scene

from samvg.errors import InputError
from samvg.render import rasterize
from samvg.render._paint_kernels import LINEAR, PARAMS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.render.threads import run_parts, using_render_threads


def gradient_paints(rng: np.random.Generator, count: int, width: int, height: int):
    """Every third path flat, the others linear and radial 3-stop gradients."""
    kinds = np.array([(0, LINEAR, RADIAL)[p % 3] for p in range(count)], np.int64)
    params = np.zeros((count, PARAMS))
    params[:, :4] = rng.uniform(0, [width, height, width, height], (count, 4))
    params[kinds == RADIAL, 2] = rng.uniform(3, width, int(np.sum(kinds == RADIAL)))
    params[:, 4:7] = np.sort(rng.uniform(0, 1, (count, 3)), axis=1)
    params[:, 8:17] = rng.uniform(0, 1, (count, 9))
    stops = np.where(kinds == 0, 0, 3).astype(np.int64)
    params[kinds == 0] = 0.0
    return GradientPaints(kinds, stops, torch.tensor(params, requires_grad=True))


def render_with_gradients(threads: int, seed: int, grid: bool):
    rng = np.random.default_rng(seed)
    width, height = 61, 47
    points, colors = random_scene(rng, 12, width, height)
    if grid:
        points = np.round(points)  # edges on pixel boundaries take their own backward code
    paints = gradient_paints(rng, len(points), width, height)
    weights = torch.tensor(rng.normal(size=(height, width, 3)))
    p = torch.tensor(points, requires_grad=True)
    c = torch.tensor(colors, requires_grad=True)
    with using_render_threads(threads):
        image = rasterize(p, c, width, height, gradients=paints)
        (image * weights).sum().backward()
    return image.detach().numpy(), p.grad.numpy(), c.grad.numpy(), paints.params.grad.numpy()


@pytest.mark.parametrize("seed,grid", [(0, False), (1, True), (2, False)])
def test_thread_counts_agree(seed, grid):
    image, points, colours, paints = render_with_gradients(1, seed, grid)
    assert np.abs(points).max() > 0 and np.abs(paints).max() > 0  # gradients reach everything
    for threads in (2, 3, 7):
        other = render_with_gradients(threads, seed, grid)
        assert np.array_equal(image, other[0]) and np.array_equal(points, other[1])
        np.testing.assert_allclose(other[2], colours, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(other[3], paints, rtol=1e-10, atol=1e-12)
        again = render_with_gradients(threads, seed, grid)
        for a, b in zip(other, again, strict=True):
            assert np.array_equal(a, b)


def test_more_threads_than_rows_still_renders():
    points, colors = random_scene(np.random.default_rng(3), 4, 20, 2)
    with using_render_threads(1):
        one = rasterize(torch.tensor(points), torch.tensor(colors), 20, 2)
    with using_render_threads(8):
        many = rasterize(torch.tensor(points), torch.tensor(colors), 20, 2)
    assert torch.equal(one, many)


def test_a_failing_part_raises_after_every_part_has_finished():
    finished = []

    def job(part: int) -> None:
        finished.append(part)
        if part == 1:
            raise RuntimeError("part 1 failed")

    with pytest.raises(RuntimeError, match="part 1 failed"):
        run_parts(job, 3)
    assert sorted(finished) == [0, 1, 2]


@pytest.mark.parametrize("threads", [0, -2, 1.5, True])
def test_thread_counts_must_be_positive_integers(threads):
    with (
        pytest.raises(InputError, match="threads must be a positive integer"),
        using_render_threads(threads),
    ):
        pass
