"""Bad and unusual input to the rasterizer; the JIT cache; work bounded by path size."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import torch
from render_reference import blob

from samvg.errors import InputError
from samvg.render import MAX_PIXELS, rasterize
from samvg.render import _kernels as kernels

COLORS3 = torch.tensor([[1.0, 0, 0, 1], [0, 1.0, 0, 0.5], [0, 0, 1.0, 0.7]])


def three_paths() -> torch.Tensor:
    rng = np.random.default_rng(0)
    return torch.tensor(np.stack([blob(rng, 10, 10, 5), blob(rng, 20, 12, 6), blob(rng, 8, 20, 4)]))


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_coordinates_name_the_path(bad):
    points = three_paths()
    points[2, 4, 1] = bad
    with pytest.raises(ValueError, match="path 2 has non-finite coordinates"):
        rasterize(points, COLORS3, 30, 30)
    paths = list(three_paths())
    paths[1] = paths[1].clone()
    paths[1][0, 0] = bad
    with pytest.raises(InputError, match="path 1 has non-finite coordinates"):
        rasterize(paths, COLORS3, 30, 30)


def test_non_finite_colour_names_the_path():
    colors = COLORS3.clone()
    colors[1, 3] = float("nan")
    with pytest.raises(InputError, match="path 1 has a non-finite colour"):
        rasterize(three_paths(), colors, 30, 30)


def test_empty_scene_renders_background():
    for points in (torch.zeros((0, 12, 2)), torch.zeros((0, 3, 2)), []):
        image = rasterize(points, torch.zeros((0, 4)), 7, 5, background=(0.25, 0.5, 1.0))
        assert image.shape == (5, 7, 3)
        np.testing.assert_array_equal(image.numpy(), np.broadcast_to([0.25, 0.5, 1.0], (5, 7, 3)))
    white = rasterize(torch.zeros((0, 12, 2)), torch.zeros((0, 4)), 3, 3, background=None)
    np.testing.assert_array_equal(white.numpy(), 1.0)


def test_far_off_canvas_paths_are_fine():
    rng = np.random.default_rng(1)
    far = [
        blob(rng, -1e7, 10, 50),
        blob(rng, 1e9, -3e8, 1e6),
        blob(rng, 15, 1e12, 3),
        blob(rng, -40, 15, 20),  # left of the canvas, spans its rows
        blob(rng, 1e15, 1e15, 1e15),  # huge, covers everything: flattened coarsely but valid
        blob(rng, 0, 0, 1e300),  # absurd but finite
        blob(rng, 1e308, -1e308, 1e307),  # coordinate differences would overflow
    ]
    points = torch.tensor(np.stack(far), requires_grad=True)
    colors = torch.tensor(np.tile([0.3, 0.6, 0.9, 0.5], (7, 1)), requires_grad=True)
    image = rasterize(points, colors, 30, 20)
    assert torch.isfinite(image).all()
    image.sum().backward()
    assert torch.isfinite(points.grad).all()
    assert torch.isfinite(colors.grad).all()
    np.testing.assert_array_equal(points.grad[:4].numpy(), 0.0)
    # Without the huge path, nothing touches the canvas.
    alone = rasterize(points[:4].detach(), colors[:4].detach(), 30, 20)
    np.testing.assert_array_equal(alone.numpy(), 1.0)


def test_zero_area_paths_are_fine():
    point = torch.full((1, 12, 2), 5.5, requires_grad=True)
    line = torch.tensor(np.linspace([2.0, 3.0], [9.0, 7.0], 12)[None], requires_grad=True)
    for points in (point, line):
        image = rasterize(points, torch.tensor([[0.0, 0.0, 0.0, 1.0]]), 12, 12)
        np.testing.assert_allclose(image.detach().numpy(), 1.0, atol=1e-9)
        image.sum().backward()
        assert torch.isfinite(points.grad).all()


@pytest.mark.parametrize(
    ("width", "height", "message"),
    [
        (0, 10, "width must be positive"),
        (10, -3, "height must be positive"),
        (10.5, 10, "width must be an integer"),
        (1 << 15, 1 << 14, "too large"),
        (MAX_PIXELS + 1, 1, "too large"),
    ],
)
def test_bad_canvas_size(width, height, message):
    with pytest.raises(InputError, match=message):
        rasterize(three_paths(), COLORS3, width, height)


def test_bad_shapes():
    with pytest.raises(InputError, match=r"shape \(P, 3K, 2\)"):
        rasterize(torch.zeros((3, 10, 2)), COLORS3, 10, 10)
    with pytest.raises(InputError, match=r"shape \(P, 3K, 2\)"):
        rasterize(torch.zeros((12, 2)), COLORS3, 10, 10)
    with pytest.raises(InputError, match=r"colors must have shape \(3, 4\)"):
        rasterize(three_paths(), COLORS3[:, :3], 10, 10)
    with pytest.raises(InputError, match="path 1 must have shape"):
        rasterize([torch.zeros((3, 2)), torch.zeros((4, 2))], COLORS3[:2], 10, 10)
    with pytest.raises(InputError, match="background"):
        rasterize(three_paths(), COLORS3, 10, 10, background=(1.0, 0.0))


def test_numpy_input_and_no_grad():
    points = three_paths().numpy()
    image = rasterize(points, COLORS3.numpy(), 30, 30)
    assert image.dtype == torch.float64 and not image.requires_grad
    np.testing.assert_array_equal(image.numpy(), rasterize(three_paths(), COLORS3, 30, 30).numpy())


def test_work_is_bounded_by_path_boxes():
    # Many tiny paths on a large canvas: per-path buffers cover their boxes, not the canvas.
    rng = np.random.default_rng(2)
    size = 4096
    paths = np.stack([blob(rng, *rng.uniform(0, size, 2), 2.0) for _ in range(500)])
    starts = np.arange(501, dtype=np.int64) * 12
    _, vstart, verts = kernels.plan_and_flatten(paths.reshape(-1, 2), starts, size, size, 0.05)
    box, off = kernels.path_boxes(verts, vstart, size, size)
    assert off[-1] < 500 * 8 * 9  # each box at most 8 x (8 + 1) cells
    image = rasterize(torch.tensor(paths), torch.rand(500, 4), size, size)
    assert image.shape == (size, size, 3)


def test_second_process_loads_kernels_from_cache():
    script = textwrap.dedent(
        """
        from samvg.render import _kernels, warmup
        warmup()
        names = [n for n in dir(_kernels) if hasattr(getattr(_kernels, n), "stats")]
        print(sum(len(getattr(_kernels, n).stats.cache_misses) for n in names))
        """
    )
    env = dict(os.environ)
    env.pop("NUMBA_DISABLE_JIT", None)
    runs = [
        subprocess.run(
            [sys.executable, "-c", script], capture_output=True, text=True, check=True, env=env
        ).stdout.split()[-1]
        for _ in range(2)
    ]
    assert runs[1] == "0"


def test_low_precision_and_integer_inputs_render_in_float32():
    points = three_paths()
    expected = rasterize(points.float(), COLORS3, 30, 30)
    for dtype in (torch.float16, torch.bfloat16):
        leaf = points.to(dtype).requires_grad_()
        image = rasterize(leaf, COLORS3.to(dtype), 30, 30)
        assert image.dtype == torch.float32
        assert (image - expected).abs().mean() < 0.02
        image.sum().backward()
        assert leaf.grad.dtype == dtype
    grid = torch.tensor([[[2, 2], [5, 2], [8, 2], [8, 8], [5, 8], [2, 8]]])
    assert rasterize(grid, COLORS3[:1], 10, 10).dtype == torch.float32


def test_paths_are_painted_over_a_background_image():
    rng = np.random.default_rng(3)
    under = rng.random((12, 16, 3))
    points = torch.tensor([[[2.0, 2.0], [6, 2], [10, 2], [10, 2], [10, 6], [10, 10],
                            [10, 10], [6, 10], [2, 10], [2, 10], [2, 6], [2, 2]]])  # fmt: skip
    colours = torch.tensor([[0.2, 0.9, 0.4, 0.5]], requires_grad=True)
    image = rasterize(points, colours, 16, 12, background=under)
    np.testing.assert_allclose(image[0, 0].detach().numpy(), under[0, 0], atol=1e-6)
    inside = 0.5 * under[5, 5] + 0.5 * np.array([0.2, 0.9, 0.4])
    np.testing.assert_allclose(image[5, 5].detach().numpy(), inside, atol=1e-6)
    image.sum().backward()
    assert colours.grad is not None and torch.isfinite(colours.grad).all()
    with pytest.raises(InputError, match="background image"):
        rasterize(points, colours, 16, 12, background=under[:5])
