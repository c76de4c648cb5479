"""Linear and radial gradient paints in the rasterizer: the colours they paint, and analytic
gradients of every paint parameter against central finite differences."""

import numpy as np
import pytest
import torch

from samvg.errors import InputError
from samvg.render import rasterize
from samvg.render._paint_kernels import FLAT, LINEAR, PARAMS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene
from samvg.svg.writer import scene_to_svg
from samvg.vector_image import VectorImage
from tests.render.paint_differences import check_paint_row

SIZE = 24


def blob(cx: float, cy: float, radius: float) -> np.ndarray:
    """A closed 4-segment cubic circle."""
    k = 0.5523 * radius
    anchors = [(cx + radius, cy), (cx, cy + radius), (cx - radius, cy), (cx, cy - radius)]
    handles = [((0, k), (k, 0)), ((-k, 0), (0, k)), ((0, -k), (-k, 0)), ((k, 0), (0, -k))]
    points = []
    for index, (x, y) in enumerate(anchors):
        nx, ny = anchors[(index + 1) % 4]
        (ax, ay), (bx, by) = handles[index]
        points += [(x, y), (x + ax, y + ay), (nx + bx, ny + by)]
    return np.asarray(points)


def paints(kind: int, stops: int) -> GradientPaints:
    params = np.zeros((2, PARAMS))
    if kind == LINEAR:
        params[1, :4] = (5.3, 6.1, 18.7, 15.2)
    else:
        params[1, :4] = (11.6, 12.3, 9.1, 0.0)
    params[1, 4 : 4 + stops] = np.linspace(0.12, 0.86, stops)
    rng = np.random.default_rng(stops)
    params[1, 8 : 8 + 3 * stops] = rng.uniform(0.1, 0.9, 3 * stops)
    kinds = np.array([FLAT, kind])
    return GradientPaints(kinds, np.array([0, stops]), torch.tensor(params, dtype=torch.float64))


def scene() -> tuple[torch.Tensor, torch.Tensor]:
    points = torch.tensor(np.stack([blob(9.0, 10.0, 6.5), blob(12.4, 12.1, 9.3)]))
    colours = torch.tensor([[0.8, 0.3, 0.2, 1.0], [0.0, 0.0, 0.0, 0.85]], dtype=torch.float64)
    return points, colours


@pytest.mark.parametrize("kind", [LINEAR, RADIAL])
def test_a_gradient_paints_its_stops_along_its_vector(kind):
    points = torch.tensor(blob(12.0, 12.0, 30.0)[None])  # covers the whole canvas
    colours = torch.tensor([[0.0, 0.0, 0.0, 1.0]], dtype=torch.float64)
    params = np.zeros((1, PARAMS))
    params[0, :4] = (0.0, 0.0, 24.0, 0.0) if kind == LINEAR else (0.0, 0.0, 24.0, 0.0)
    params[0, 4:6] = (0.0, 1.0)
    params[0, 8:14] = (1.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # red to blue
    gradient = GradientPaints(np.array([kind]), np.array([2]), torch.tensor(params))
    image = rasterize(points, colours, SIZE, SIZE, gradients=gradient).numpy()
    expected_t = (np.arange(SIZE) + 0.5) / SIZE  # along the first row
    if kind == RADIAL:
        expected_t = np.minimum(np.hypot(np.arange(SIZE) + 0.5, 0.5) / SIZE, 1.0)
    assert np.allclose(image[0, :, 0], 1.0 - expected_t, atol=1e-9)
    assert np.allclose(image[0, :, 2], expected_t, atol=1e-9)


@pytest.mark.parametrize("kind", [LINEAR, RADIAL])
@pytest.mark.parametrize("stops", [2, 3, 4])
def test_every_paint_parameter_matches_central_differences(kind, stops):
    points, colours = scene()
    base = paints(kind, stops)
    weights = torch.tensor(np.random.default_rng(7).uniform(-1, 1, (SIZE, SIZE, 3)))

    def loss(params: torch.Tensor) -> torch.Tensor:
        gradient = GradientPaints(base.kinds, base.stops, params)
        return (rasterize(points, colours, SIZE, SIZE, gradients=gradient) * weights).sum()

    check_paint_row(loss, base, 1, kind, stops)


def test_geometry_and_alpha_gradients_still_flow_under_a_gradient_paint():
    points, colours = scene()
    gradient = paints(LINEAR, 3)
    points = points.clone().requires_grad_(True)
    colours = colours.clone().requires_grad_(True)
    image = rasterize(points, colours, SIZE, SIZE, gradients=gradient)
    image.sum().backward()
    assert points.grad[1].abs().sum() > 0
    assert colours.grad[1, 3] != 0 and torch.all(colours.grad[1, :3] == 0)


def test_bad_gradient_paints_are_refused():
    points, colours = scene()
    good = paints(LINEAR, 2)
    with pytest.raises(InputError, match="2 to 4 stops"):
        rasterize(
            points,
            colours,
            8,
            8,
            gradients=GradientPaints(good.kinds, np.array([0, 5]), good.params),
        )
    with pytest.raises(InputError, match="flat .0., linear"):
        rasterize(
            points,
            colours,
            8,
            8,
            gradients=GradientPaints(np.array([0, 7]), good.stops, good.params),
        )
    bad = good.params.clone()
    bad[1, 0] = float("nan")
    with pytest.raises(InputError, match="finite"):
        rasterize(points, colours, 8, 8, gradients=GradientPaints(good.kinds, good.stops, bad))


def random_gradient_scene(seed: int) -> Scene:
    """Overlapping blobs, some translucent and some partly off the canvas, most with gradients."""
    rng = np.random.default_rng(seed)
    paths = []
    for index in range(7):
        centre = rng.uniform(-4, 52, 2)
        points = blob(*centre, rng.uniform(6, 20))
        stops = tuple(
            (float(offset), tuple(rng.uniform(0, 1, 3)))
            for offset in np.sort(rng.uniform(0, 1, rng.integers(2, 5)))
        )
        opacity = 1.0 if index % 3 else float(rng.uniform(0.4, 0.9))
        if index % 3 == 2:
            paint = FlatPaint((*rng.uniform(0, 1, 3), opacity))
        elif index % 2:
            start, end = rng.uniform(-10, 58, 2), rng.uniform(-10, 58, 2)
            paint = LinearGradient(stops, opacity, tuple(start), tuple(end))
        else:
            paint = RadialGradient(stops, opacity, tuple(rng.uniform(0, 48, 2)), rng.uniform(5, 40))
        paths.append((points, paint))
    return Scene.from_paths(48, 48, paths, background=(0.95, 0.9, 0.85))


@pytest.mark.parametrize("seed", range(4))
def test_our_render_of_a_gradient_scene_agrees_with_resvg_of_its_svg(seed):
    from tests.render.render_reference import resvg_render

    scene = random_gradient_scene(seed)
    svg = scene_to_svg(scene, precision=4)
    assert svg.count("Gradient id=") >= 4 and "url(#g" in svg
    ours = scene.render()
    theirs = resvg_render(svg)
    assert np.abs(ours - theirs).mean() <= 1 / 255


@pytest.mark.parametrize("seed", range(2))
def test_gradient_scenes_round_trip_through_svg(seed):
    scene = random_gradient_scene(seed)
    back = VectorImage.from_svg(scene_to_svg(scene, precision=4)).scene
    assert [type(paint) for paint in back.paints] == [type(paint) for paint in scene.paints]
    assert np.allclose(back.points, scene.points, atol=1e-4)
    assert np.abs(back.render() - scene.render()).mean() < 0.5 / 255  # 8-bit stop colours
