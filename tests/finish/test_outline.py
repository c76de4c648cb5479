"""Outlines of a painted area: parts cut round their large holes, small holes filled."""

import shapely

from samvg.finish import outline
from samvg.finish.outline import hole_free_pieces


def two_holes() -> shapely.Polygon:
    """A 40 x 20 plate with two 6 x 6 holes side by side."""
    left = shapely.box(6, 7, 12, 13).exterior.coords
    right = shapely.box(26, 7, 32, 13).exterior.coords
    return shapely.Polygon(shapely.box(0, 0, 40, 20).exterior.coords, [left, right])


def test_large_holes_are_cut_round_into_pieces_that_paint_the_same_area():
    plate = two_holes()
    pieces = hole_free_pieces(plate)
    assert len(pieces) > 1 and all(len(piece.interiors) == 0 for piece in pieces)
    assert shapely.union_all(pieces).symmetric_difference(plate).area < 1e-6


def test_small_holes_are_filled():
    pinhole = shapely.box(10, 10, 11, 11).exterior.coords
    plate = shapely.Polygon(shapely.box(0, 0, 20, 20).exterior.coords, [pinhole])
    assert [piece.area for piece in hole_free_pieces(plate)] == [400.0]


def test_a_missed_cut_fills_only_its_own_hole(monkeypatch):
    real_sides = outline._sides
    missed = []

    def missing_the_first_hole(polygon, hole):
        if not missed:
            missed.append(hole.bounds)
            return [polygon]  # as if the cut had not crossed the hole
        return real_sides(polygon, hole)

    monkeypatch.setattr(outline, "_sides", missing_the_first_hole)
    plate = two_holes()
    painted = shapely.union_all(hole_free_pieces(plate))
    first = shapely.box(*missed[0])
    other = shapely.box(26, 7, 32, 13) if missed[0][0] < 20 else shapely.box(6, 7, 12, 13)
    assert painted.contains(first.buffer(-0.1))  # the missed hole is painted over
    assert painted.intersection(other).area < 1e-6  # the other hole still shows
