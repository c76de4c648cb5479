"""Which paths take a gradient fill: a ramp gets a linear one, a glow a radial one, a flat area
and a gradient too small for its parameters stay flat."""

import numpy as np
import pytest

from samvg.errors import InputError
from samvg.optimize.paint_choice import choose_gradients, shown_labels
from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene
from tests.paths import square

SIZE = 64


def covering_scene() -> Scene:
    """One square path over most of the canvas, a small one on top."""
    return Scene.from_paths(
        SIZE,
        SIZE,
        [(square(2, 2, 60), FlatPaint((0.5, 0.5, 0.5))), (square(40, 40, 8), FlatPaint((0, 0, 0)))],
        background=(1, 1, 1),
    )


def grid() -> tuple[np.ndarray, np.ndarray]:
    rows, cols = np.mgrid[:SIZE, :SIZE]
    return cols + 0.5, rows + 0.5


def test_shown_labels_follow_paint_order():
    labels = shown_labels(covering_scene())
    assert labels[0, 0] == -1 and labels[10, 10] == 0 and labels[44, 44] == 1


def test_a_ramp_gets_a_linear_gradient_and_a_glow_a_radial_one():
    x, y = grid()
    along = (x + 0.5 * y) / (1.5 * SIZE)
    ramp = np.stack([along, 0.2 + 0 * x, 1 - along], axis=2)
    glow = np.clip(1 - np.hypot(x - 30, y - 28) / 40, 0, 1)[:, :, None] * [0.9, 0.8, 0.6]
    for target, kind in ((ramp, LinearGradient), (glow, RadialGradient)):
        chosen, switched = choose_gradients(covering_scene(), target.astype(np.float32))
        assert isinstance(chosen.paints[0], kind) and switched >= 1
        shown = shown_labels(chosen) == 0
        flat_error = np.mean((covering_scene().render() - target)[shown] ** 2)
        assert np.mean((chosen.render() - target)[shown] ** 2) < flat_error / 4


def test_flat_areas_and_costly_gradients_stay_flat():
    x, _ = grid()
    flat = np.full((SIZE, SIZE, 3), 0.4, np.float32)
    assert choose_gradients(covering_scene(), flat)[1] == 0
    faint = (0.4 + 0.01 * x / SIZE)[:, :, None].repeat(3, axis=2).astype(np.float32)
    assert choose_gradients(covering_scene(), faint)[1] == 0  # 1 % of a ramp: not worth it
    ramp = (x / SIZE)[:, :, None].repeat(3, axis=2).astype(np.float32)
    assert isinstance(choose_gradients(covering_scene(), ramp)[0].paints[0], LinearGradient)
    assert choose_gradients(covering_scene(), ramp, cost=1.0)[1] == 0
    with pytest.raises(InputError, match="does not match"):
        choose_gradients(covering_scene(), ramp[:10])


def test_a_ramp_behind_the_paths_gives_the_background_a_linear_gradient():
    x, _ = grid()
    ramp = np.stack([x / SIZE, 0.3 + 0 * x, 1 - x / SIZE], axis=2).astype(np.float32)
    small = [(square(40, 40, 5), FlatPaint((0, 0, 0)))]  # too few pixels for a gradient
    for paths in ([], small):
        scene = Scene.from_paths(SIZE, SIZE, paths, background=(0.5, 0.3, 0.5))
        chosen, switched = choose_gradients(scene, ramp)
        assert isinstance(chosen.background_gradient, LinearGradient) and switched == 1
        start, end = chosen.background_gradient.start, chosen.background_gradient.end
        assert abs(end[0] - start[0]) > 40 and abs(end[1] - start[1]) < 1  # horizontal
        shown = shown_labels(scene) == -1
        error = np.mean((chosen.render() - ramp)[shown] ** 2)
        assert error < np.mean((scene.render() - ramp)[shown] ** 2) / 100
        assert chosen.paints == scene.paints  # the small black path stays flat
        again, switched = choose_gradients(chosen, ramp)  # a gradient is not offered again
        assert again is chosen and switched == 0


def test_a_uniform_background_and_no_background_stay_as_they_are():
    uniform = np.full((SIZE, SIZE, 3), 0.4, np.float32)
    scene = Scene(SIZE, SIZE, background=(0.4, 0.4, 0.4))
    assert choose_gradients(scene, uniform) == (scene, 0)
    x, _ = grid()
    ramp = (x / SIZE)[:, :, None].repeat(3, axis=2).astype(np.float32)
    assert choose_gradients(Scene(SIZE, SIZE), ramp)[1] == 0  # no background: transparent
    assert choose_gradients(scene, ramp, background=False)[1] == 0
    assert choose_gradients(scene, ramp, cost=1.0)[1] == 0
    hidden = covering_scene().with_paths([(square(-1, -1, 66), FlatPaint((0, 0, 0)))])
    assert choose_gradients(hidden, ramp)[0].background_gradient is None  # none shows
