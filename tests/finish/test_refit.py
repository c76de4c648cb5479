"""Outlines back into cubics: pieces of the source cubics where an outline follows them, a fresh
least-squares fit otherwise; both simple and inside the box."""

import numpy as np
import pytest
import shapely

import samvg.trace
from samvg.finish.cubics import sub_cubic
from samvg.finish.flatten import FLATTEN_TOLERANCE, flatten_path
from samvg.finish.refit import refit_ring
from samvg.finish.trim import redraw_ring
from tests.finish.shapes import ellipse, figure_eight, is_simple


def test_a_path_redrawn_from_its_own_outline_keeps_its_cubics():
    path = ellipse(200, 150, 120, 70)
    redrawn = redraw_ring(flatten_path(path), [path], tolerance=0.5)
    assert redrawn.shape == path.shape
    assert np.allclose(redrawn, path, atol=1e-9)


def test_a_clipped_ellipse_keeps_its_curves_inside_and_gets_a_straight_border():
    path = ellipse(100, 100, 80, 50)
    box = (0.0, 0.0, 150.0, 200.0)
    region = shapely.Polygon(flatten_path(path)).intersection(shapely.box(*box))
    ring = np.asarray(region.exterior.coords)[:-1]
    redrawn = redraw_ring(ring, [path], tolerance=0.5, box=box)
    assert is_simple(redrawn)
    assert np.all(redrawn >= 0) and np.all(redrawn[:, 0] <= 150)
    fine = shapely.Polygon(flatten_path(path, 0.001)).intersection(shapely.box(*box))
    drawn = shapely.Polygon(flatten_path(redrawn, 0.001))
    # The same curves, cut where their flattening meets the border (at most 0.1 px off).
    assert drawn.hausdorff_distance(fine) <= FLATTEN_TOLERANCE
    # Four quarter cubics, two of them cut by the border, plus the border line.
    assert len(redrawn) // 3 == 5


def test_sub_cubic_pieces_join_into_the_whole_cubic():
    cubic = ellipse(0, 0, 10, 10)[:4].copy()
    cubic[3] = ellipse(0, 0, 10, 10)[3]
    first, second = sub_cubic(cubic, 0.0, 0.3), sub_cubic(cubic, 0.3, 1.0)
    assert np.allclose(first[0], cubic[0]) and np.allclose(second[3], cubic[3])
    assert np.allclose(first[3], second[0])
    backwards = sub_cubic(cubic, 0.7, 0.2)
    assert np.allclose(backwards[::-1], sub_cubic(cubic, 0.2, 0.7))


@pytest.fixture(params=["tracer", "local"])
def fitter(request, monkeypatch):
    """Fresh fits by the tracer's ``refit_outline``, and by the local fitter without it."""
    if request.param == "local":
        monkeypatch.delattr(samvg.trace, "refit_outline", raising=False)
    elif not hasattr(samvg.trace, "refit_outline"):
        pytest.skip("samvg.trace has no refit_outline")
    return request.param


def test_a_fresh_fit_of_a_circle_needs_few_cubics_within_the_tolerance(fitter):
    angles = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    ring = np.stack([200 + 60 * np.cos(angles), 200 + 60 * np.sin(angles)], 1)
    path = refit_ring(ring, tolerance=0.5)
    assert len(path) // 3 <= 4
    assert is_simple(path)
    drawn = shapely.LinearRing(flatten_path(path))
    assert shapely.distance(drawn, shapely.points(ring)).max() < 0.5


def test_a_fresh_fit_keeps_square_corners_and_straight_sides(fitter):
    square = np.array([[10, 10], [110, 10], [110, 110], [10, 110]], float)
    path = refit_ring(square, tolerance=0.5)
    assert len(path) == 12
    assert {tuple(p) for p in np.round(path[0::3], 6)} == {tuple(p) for p in square}
    assert np.allclose(shapely.Polygon(flatten_path(path)).area, 100 * 100)


def test_a_fit_that_would_cross_falls_back_to_a_simple_polygon(fitter):
    # A thin zig-zag comb: cubics fitted at a large tolerance would cut across its teeth.
    teeth = [
        [x, y] for i, x in enumerate(range(0, 200, 10)) for y in ((0, 40) if i % 2 else (40, 0))
    ]
    comb = np.array(teeth + [[200, 60], [-10, 60]], float) + 50
    assert shapely.LinearRing(comb).is_simple
    path = refit_ring(comb, tolerance=8.0)
    assert is_simple(path)


def test_a_fresh_fit_stays_inside_the_box(fitter):
    angles = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ring = np.stack([50 + 50 * np.cos(angles), 50 + 50 * np.sin(angles)], 1)
    box = (-1.0, -1.0, 101.0, 101.0)
    path = refit_ring(ring, tolerance=0.5, box=box)
    assert np.all(path >= -1.0) and np.all(path <= 101.0)
    assert is_simple(path)
    drawn = shapely.Polygon(flatten_path(path))
    assert drawn.hausdorff_distance(shapely.Polygon(ring)) < 0.5 + FLATTEN_TOLERANCE


def test_figure_eight_lobes_redraw_on_their_own_curves():
    path = figure_eight()
    lobe = shapely.Polygon(flatten_path(path)[: len(flatten_path(path)) // 2])
    redrawn = redraw_ring(np.asarray(lobe.exterior.coords)[:-1], [path], tolerance=0.5)
    assert len(redrawn) // 3 == 2
    assert is_simple(redrawn)
