"""Tests of samvg.svg.writer: compact path data that reads back to exactly the rounded points,
and one gradient element per distinct gradient."""

import re

import numpy as np

from samvg.scene import FlatPaint, LinearGradient, RadialGradient, Scene
from samvg.svg.reader import read_svg
from samvg.svg.writer import path_data, scene_to_svg


def test_numbers_are_short_and_steps_relative():
    points = np.array(
        [[10.5, 20.25], [10.0, 19.75], [9.04, 20.0], [12.0, 20.0], [13.5, 21.0], [11.0, 22.0]]
    )
    # steps from (10.5, 20.25): (-.5, -.5) (-1.46, -.25) (1.5, -.25); then from (12, 20): ...
    # no space before ".25": the number before already has its point
    assert path_data(points, 2) == "M10.5 20.25c-.5-.5-1.46-.25 1.5-.25 1.5 1-1 2-1.5.25z"


def test_straight_segments_are_lines_and_the_closing_one_is_z():
    # a rectangle traced with controls on its edges (not at thirds), one corner doubled
    corners = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [10.0, 10.0], [3.0, 7.0]])
    rows = []
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        rows += [a, a + 0.2 * (b - a), a + 0.9 * (b - a)]
    text = path_data(np.array(rows), 1)
    assert text == "M0 0h10v10l-7-3z"
    read = read_svg(
        f'<svg xmlns="http://www.w3.org/2000/svg" width="12" height="12"><path d="{text}"/></svg>'
    ).paths[0][0]
    # read back: the same corners, each joined to the next by a straight cubic
    np.testing.assert_allclose(read[0::3], corners[[0, 1, 2, 4]], atol=1e-9)


def test_a_path_of_no_length_keeps_one_segment_and_reads_back():
    text = path_data(np.full((6, 2), 3.0), 1)
    assert text == "M3 3h0z"
    svg = f'<svg xmlns="http://www.w3.org/2000/svg" width="9" height="9"><path d="{text}"/></svg>'
    assert read_svg(svg).paths[0][0].shape == (3, 2)


def test_a_control_off_the_chord_keeps_the_cubic():
    points = np.array([[0.0, 0.0], [3.0, 0.1], [7.0, 0.0], [10.0, 0.0], [10.0, 5.0], [0.0, 5.0]])
    assert path_data(points, 1).startswith("M0 0c3 .1 7 0 10 0")
    assert path_data(points, 0).startswith("M0 0h10")  # within half a unit once rounded
    beyond = points.copy()
    beyond[1] = (12.0, 0.0)  # on the chord's line but past its end: the curve overshoots
    assert path_data(beyond, 0).startswith("M0 0c12 0 7 0 10 0")


def test_precision_zero_writes_integers():
    points = np.array([[1.4, 2.6], [3.0, 4.0], [5.5, 6.0]])
    assert path_data(points, 0) == "M1 3c2 1 5 3 0 0z"


def test_read_back_equals_the_rounded_points():
    rng = np.random.default_rng(0)
    points = rng.uniform(-50, 550, (4, 12, 2))
    offsets = np.arange(5) * 12
    paints = tuple(FlatPaint((0.2, 0.4, 0.6, 1.0)) for _ in range(4))
    scene = Scene(512, 512, points.reshape(-1, 2), offsets, paints)
    for precision in (0, 1, 2, 3):
        parsed = read_svg(scene_to_svg(scene, precision))
        read = np.concatenate([p for p, _ in parsed.paths])
        np.testing.assert_allclose(read, np.round(scene.points, precision), rtol=0, atol=1e-9)


def test_identical_gradients_share_one_element():
    square = np.array([[0, 0], [5, 0], [10, 0], [10, 5], [10, 10], [0, 10]], dtype=float)
    stops = ((0.0, (1.0, 0.0, 0.0)), (1.0, (0.0, 0.0, 1.0)))
    ramp = LinearGradient(stops=stops, start=(0.0, 0.0), end=(10.0, 0.0))
    disc = RadialGradient(stops=stops, centre=(5.0, 5.0), radius=4.0)
    paints = (ramp, FlatPaint((0.0, 1.0, 0.0, 1.0)), disc, ramp)
    scene = Scene(12, 12, np.concatenate([square] * 4), np.arange(5) * 6, paints)
    text = scene_to_svg(scene)
    assert len(re.findall(r"<(?:linear|radial)Gradient ", text)) == 2
    assert re.findall(r'fill="([^"]+)"', text) == ["url(#g0)", "#0f0", "url(#g1)", "url(#g0)"]
    fills = [fill for _, fill in read_svg(text).paths]
    assert fills[0] == fills[3] and isinstance(fills[0], LinearGradient)
    assert isinstance(fills[2], RadialGradient)


def test_gradient_numbers_are_short_and_read_back_unchanged():
    square = np.array([[0, 0], [5, 0], [10, 0], [10, 5], [10, 10], [0, 10]], dtype=float)
    stops = ((0.0, (1.0, 0.0, 0.0)), (0.25, (0.0, 1.0, 0.0)), (1.0, (0.0, 0.0, 1.0)))
    ramp = LinearGradient(stops=stops, start=(0.5, -0.25), end=(10.0, 0.0))
    scene = Scene(12, 12, square, np.array([0, 6]), (ramp,))
    text = scene_to_svg(scene, precision=2)
    assert 'x1=".5" y1="-.25" x2="10" y2="0"' in text
    # the first stop's offset is SVG's initial value, so it is left out
    assert '<stop stop-color="#f00"/><stop offset=".25" stop-color="#0f0"/>' in text
    fill = read_svg(text).paths[0][1]
    assert isinstance(fill, LinearGradient)
    assert fill.stops == stops
    assert fill.start == (0.5, -0.25) and fill.end == (10.0, 0.0)
