"""Tests of the gradient ramp rule: a fill's colour ramp spans at least a share of its path."""

import numpy as np
import torch

from samvg.optimize import FitSettings, fit_scene
from samvg.optimize.ramp import widen_ramps
from samvg.render._paint_kernels import FLAT, LINEAR, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene
from tests.paths import square

RED, BLUE = (0.9, 0.1, 0.1), (0.1, 0.2, 0.9)


def rows_of(*paints):
    rows = GradientPaints.of(list(paints))
    return rows.kinds, rows.stops, rows.params.numpy().copy()


def ramp_of(paint) -> float:
    """The length in pixels between the first and last stop."""
    first, last = paint.stops[0][0], paint.stops[-1][0]
    if isinstance(paint, LinearGradient):
        return (last - first) * float(np.hypot(*np.subtract(paint.end, paint.start)))
    return (last - first) * paint.radius


def test_a_step_becomes_a_ramp_of_a_quarter_of_the_path_about_the_same_place():
    outline = square(10, 0, 100)  # x from 10 to 110
    step = LinearGradient(((0.5, RED), (0.5, BLUE)), 1.0, (10.0, 50.0), (110.0, 50.0))
    kinds, stops, params = rows_of(FlatPaint((0, 0, 0, 1)), step)
    points = np.concatenate([square(0, 0, 4), outline])
    offsets = np.array([0, 12, 24])
    changed = widen_ramps(kinds, stops, params, points, offsets, 0.25)
    assert list(changed) == [False, True]
    widened = GradientPaints(kinds, stops, torch.from_numpy(params)).paints(np.ones((2, 4)))[1]
    assert np.allclose(widened.start, (47.5, 50.0)) and np.allclose(widened.end, (72.5, 50.0))
    assert [offset for offset, _ in widened.stops] == [0.0, 1.0]
    assert widened.stops[0][1] == RED and widened.stops[1][1] == BLUE


def test_wide_ramps_and_flat_fills_are_left_alone_and_zero_means_free():
    outline = square(0, 0, 40)
    wide = LinearGradient(((0.1, RED), (0.9, BLUE)), 1.0, (0.0, 0.0), (0.0, 40.0))
    glow = RadialGradient(((0.0, RED), (0.6, BLUE)), 1.0, (20.0, 20.0), 30.0)
    kinds, stops, params = rows_of(wide, glow, FlatPaint((0, 0, 0, 1)))
    before = params.copy()
    points = np.concatenate([outline, outline, outline])
    offsets = np.array([0, 12, 24, 36])
    assert not widen_ramps(kinds, stops, params, points, offsets, 0.25).any()
    assert list(kinds) == [LINEAR, RADIAL, FLAT] and np.array_equal(params, before)
    narrow = LinearGradient(((0.5, RED), (0.5, BLUE)), 1.0, (0.0, 0.0), (0.0, 40.0))
    kinds, stops, params = rows_of(narrow)
    assert not widen_ramps(kinds, stops, params, outline, np.array([0, 12]), 0.0).any()


def test_a_radial_ring_is_widened_within_the_centre_and_keeps_a_middle_stop_in_proportion():
    outline = square(0, 0, 60)  # centre (30, 30): distances 30 to 42.4 at the control points
    thin = ((0.50, RED), (0.51, (0.5, 0.5, 0.5)), (0.52, BLUE))
    ring = RadialGradient(thin, 1.0, (0.0, 0.0), 50.0)
    kinds, stops, params = rows_of(ring)
    distances = np.hypot(*outline.T)
    assert widen_ramps(kinds, stops, params, outline, np.array([0, 12]), 0.5)[0]
    inner, middle, outer = params[0, 4:7] * params[0, 2]
    assert np.isclose(outer - inner, 0.5 * (distances.max() - distances.min()))
    assert np.isclose(middle, (inner + outer) / 2) and inner >= 0
    assert np.isclose((inner + outer) / 2, 25.5)  # the middle of the old ramp


def test_a_fit_keeps_a_two_colour_square_as_a_broad_ramp():
    """Left free, Adam sharpens a gradient over a half-red, half-blue square into a step; with
    the rule its ramp stays at least the asked share of the square."""
    target = np.ones((48, 48, 3))
    target[8:40, 8:24] = RED
    target[8:40, 24:40] = BLUE
    start_paint = LinearGradient(((0.0, RED), (1.0, BLUE)), 1.0, (8.0, 24.0), (40.0, 24.0))
    start = Scene.from_paths(48, 48, [(square(8, 8, 32), start_paint)], background=(1, 1, 1))
    settings = FitSettings(steps=150, point_learning_rate=0.3, colour_learning_rate=0.02)
    free = fit_scene(start, target, settings).scene.paints[0]
    kept = fit_scene(start, target, FitSettings(**{**settings.__dict__, "gradient_ramp": 0.5}))
    assert ramp_of(free) < 10  # the fill draws the edge
    along = kept.scene.path_points(0)[:, 0]
    assert ramp_of(kept.scene.paints[0]) >= 0.5 * (along.max() - along.min()) - 1e-3
    assert np.mean((kept.scene.render() - target) ** 2) < 0.03  # and still the two colours
