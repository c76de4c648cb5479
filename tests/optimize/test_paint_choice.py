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
