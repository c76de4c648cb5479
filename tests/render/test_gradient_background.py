"""A linear or radial gradient as the scene's background: the torch image paints what the
kernels paint, ``rasterize`` passes the gradient to a background image, every background
gradient parameter matches central differences through the render, and resvg agrees with our
render of the SVG, which reads back to the same scene."""

from dataclasses import replace

import numpy as np
import pytest
import torch

from samvg.errors import InputError
from samvg.render import gradient_image, rasterize
from samvg.render._paint_kernels import LINEAR, PARAMS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene
from samvg.svg.writer import scene_to_svg
from samvg.vector_image import VectorImage
from tests.paths import square
from tests.render.paint_differences import check_paint_row
from tests.render.test_gradient_paints import blob, random_gradient_scene

WIDTH, HEIGHT = 23, 19


def background(kind: int, stops: int) -> GradientPaints:
    """One gradient row, float64, geometry inside the canvas."""
    params = np.zeros((1, PARAMS))
    params[0, :4] = (3.3, 4.1, 19.7, 14.2) if kind == LINEAR else (10.6, 8.3, 9.1, 0.0)
    params[0, 4 : 4 + stops] = np.linspace(0.12, 0.86, stops)
    params[0, 8 : 8 + 3 * stops] = np.random.default_rng(stops).uniform(0.1, 0.9, 3 * stops)
    return GradientPaints(np.array([kind]), np.array([stops]), torch.tensor(params))


def translucent_paths() -> tuple[torch.Tensor, torch.Tensor]:
    points = torch.tensor(np.stack([blob(8.0, 9.0, 5.5), blob(14.4, 10.1, 6.3)]))
    colours = torch.tensor([[0.8, 0.3, 0.2, 0.6], [0.1, 0.5, 0.9, 0.45]], dtype=torch.float64)
    return points, colours


def red_green_blue(*offsets: float) -> tuple:
    """Stops at ``offsets`` coloured red, green, blue in turn."""
    return tuple(zip(offsets, ((1, 0, 0), (0, 1, 0), (0, 0, 1))[: len(offsets)], strict=True))


@pytest.mark.parametrize(
    "paint",
    [
        LinearGradient(((0.1, (1, 0, 0)), (0.5, (0, 1, 0)), (0.5, (0, 0, 1)), (0.9, (1, 1, 0))),
                       1.0, (2.0, 3.0), (20.0, 12.0)),  # coincident middle stops
        LinearGradient(red_green_blue(0.0, 0.0, 1.0), 1.0, (2.0, 3.0), (20.0, 12.0)),
        RadialGradient(red_green_blue(0.0, 0.0, 1.0), 1.0, (10.5, 8.5), 9.0),  # on a centre
        RadialGradient(red_green_blue(0.2, 0.7, 1.0), 1.0, (-3.0, 4.0), 30.0),
        LinearGradient(red_green_blue(0.0, 1.0), 1.0, (2.0, 3.0), (2.0, 3.0)),  # no length
    ],
)  # fmt: skip
def test_the_background_image_is_what_the_kernels_paint_inside_a_path(paint):
    image = GradientPaints.of([paint]).image(0, WIDTH, HEIGHT).numpy()
    covering = Scene.from_paths(WIDTH, HEIGHT, [(square(-1, -1, 40), paint)])
    np.testing.assert_allclose(image, covering.render(), atol=1e-6)  # the render is float32
    assert image.dtype == np.float64


@pytest.mark.parametrize("kind", [LINEAR, RADIAL])
@pytest.mark.parametrize("stops", [2, 3, 4])
def test_every_background_gradient_parameter_matches_central_differences(kind, stops):
    points, colours = translucent_paths()
    base = background(kind, stops)
    weights = torch.tensor(np.random.default_rng(5).uniform(-1, 1, (HEIGHT, WIDTH, 3)))

    def loss(params: torch.Tensor) -> torch.Tensor:
        image = GradientPaints(base.kinds, base.stops, params).image(0, WIDTH, HEIGHT)
        return (rasterize(points, colours, WIDTH, HEIGHT, background=image) * weights).sum()

    analytic = check_paint_row(loss, base, 0, kind, stops)
    assert np.all(analytic != 0.0)  # every parameter moves the picture here


def test_the_background_image_gradient_of_rasterize_matches_finite_differences():
    points, colours = translucent_paths()
    points = points.clone().requires_grad_(True)
    rng = np.random.default_rng(2)
    under = rng.uniform(0, 1, (HEIGHT, WIDTH, 3))
    weights = torch.tensor(rng.uniform(-1, 1, (HEIGHT, WIDTH, 3)))
    image = torch.tensor(under, requires_grad=True)
    (rasterize(points, colours, WIDTH, HEIGHT, background=image) * weights).sum().backward()
    assert points.grad is not None and points.grad.abs().sum() > 0  # paths still differentiable

    def loss(array: np.ndarray) -> float:
        with torch.no_grad():
            return float((rasterize(points, colours, WIDTH, HEIGHT, array) * weights).sum())

    step = 1e-4  # the render is linear in the background: differences are exact
    for y, x, c in [(0, 0, 0), (9, 8, 1), (10, 14, 2), (9, 11, 0), (18, 22, 1), (4, 19, 2)]:
        moved = [under.copy(), under.copy()]
        moved[0][y, x, c] += step
        moved[1][y, x, c] -= step
        numeric = (loss(moved[0]) - loss(moved[1])) / (2 * step)
        assert float(image.grad[y, x, c]) == pytest.approx(numeric, rel=1e-6, abs=1e-9)
    # under the paths the gradient is damped by what they cover, away from them it is the loss's
    assert float(image.grad[0, 0, 0]) == pytest.approx(float(weights[0, 0, 0]))
    assert abs(float(image.grad[9, 8, 1])) < abs(float(weights[9, 8, 1]))


def test_a_numpy_background_image_is_an_underlay_without_a_gradient():
    points, colours = translucent_paths()
    colours = colours.clone().requires_grad_(True)
    under = np.random.default_rng(3).uniform(0, 1, (HEIGHT, WIDTH, 3))
    image = rasterize(points, colours, WIDTH, HEIGHT, background=under)
    image.sum().backward()
    assert colours.grad is not None
    as_tensor = rasterize(points, colours.detach(), WIDTH, HEIGHT, torch.tensor(under))
    torch.testing.assert_close(as_tensor, image.detach())  # no gradient wanted: no state kept
    with pytest.raises(InputError, match="shape"):
        rasterize(points, colours, WIDTH, HEIGHT, background=torch.zeros(HEIGHT, 3, 3))


def test_bad_background_gradients_are_refused():
    stops = ((0.0, (1, 0, 0)), (1.0, (0, 0, 1)))
    with pytest.raises(InputError, match="opaque"):
        Scene(8, 8, background_gradient=LinearGradient(stops, 0.5, (0, 0), (8, 0)))
    with pytest.raises(InputError, match="linear or radial"):
        Scene(8, 8, background_gradient=FlatPaint((1, 0, 0)))
    with pytest.raises(InputError, match="linear .1. or radial"):
        gradient_image(0, 2, torch.zeros(PARAMS), 4, 4)
    with pytest.raises(InputError, match="2 to 4 stops"):
        gradient_image(LINEAR, 5, torch.zeros(PARAMS), 4, 4)


def random_background(seed: int) -> LinearGradient | RadialGradient:
    rng = np.random.default_rng(seed + 100)
    stops = tuple(
        (float(offset), tuple(rng.uniform(0, 1, 3)))
        for offset in np.sort(rng.uniform(0, 1, rng.integers(2, 5)))
    )
    if seed % 2:
        return RadialGradient(stops, 1.0, tuple(rng.uniform(0, 48, 2)), rng.uniform(8, 40))
    start, end = tuple(rng.uniform(-10, 58, 2)), tuple(rng.uniform(-10, 58, 2))
    return LinearGradient(stops, 1.0, start, end)


@pytest.mark.parametrize("seed", range(4))
def test_our_render_of_a_gradient_background_agrees_with_resvg(seed):
    from tests.render.render_reference import resvg_render

    scene = replace(random_gradient_scene(seed), background_gradient=random_background(seed))
    assert any(paint.rgba[3] < 1 for paint in scene.paints)  # translucent paths over it
    svg = scene_to_svg(scene, precision=4)
    assert 'fill="url(#bg)"' in svg and 'Gradient id="bg"' in svg
    assert np.abs(scene.render() - resvg_render(svg)).mean() <= 1 / 255
    alone = Scene(48, 40, background_gradient=random_background(seed))
    difference = np.abs(alone.render() - resvg_render(scene_to_svg(alone, 4)))
    assert difference.mean() <= 0.5 / 255 and difference.max() <= 1.5 / 255  # 8-bit stops


@pytest.mark.parametrize("seed", range(2))
def test_a_gradient_background_round_trips_through_svg(seed):
    scene = replace(random_gradient_scene(seed), background_gradient=random_background(seed))
    back = VectorImage.from_svg(scene_to_svg(scene, precision=4)).scene
    assert type(back.background_gradient) is type(scene.background_gradient)
    assert back.path_count == scene.path_count  # the rect is the background, not a path
    assert back.background == pytest.approx(back.background_gradient.rgba[:3])
    assert np.abs(back.render() - scene.render()).mean() < 0.5 / 255  # 8-bit stop colours
