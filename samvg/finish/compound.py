"""Compound paths: neighbours in paint order with the same paint become one SVG ``<path>``
element (`Scene.joined`), the pieces of one shape that Illustrator calls a compound path and
VTracer writes as one path. Nothing in the picture changes. The writer draws every piece of an
element the same way round (`same_way_round`), so under SVG's nonzero rule the element paints
the union of its pieces; for an opaque paint that is what they paint one by one, overlaps
included (a repair's pieces overlap by up to its half-pixel tolerance where they share an edge).
A translucent paint would show an overlap twice, so its pieces join only where they share no
area.

Under a path budget this is what a crossing path's repair needs. The repair splits a path that
crosses itself into the simple pieces it paints. Those pieces are one shape of one fill, not more
paths, and removing them to meet the budget lost real area (arctic_greyling at 16 paths: MSE
36.7 -> 56.0e-3).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

import numpy as np
from shapely.geometry.base import BaseGeometry

from samvg.finish.flatten import flatten_paths
from samvg.finish.outline import path_regions, signed_polygon_areas
from samvg.scene import Scene

#: Pieces that share at most this much area (px²: where a split's pieces touch at the crossing
#: point, and rounding to the SVG's precision may shift them) count as not overlapping.
MAX_SHARED_AREA = 0.5


def join_pieces(scene: Scene, limit: int) -> tuple[Scene, int]:
    """``scene`` with neighbours of one paint joined into compound paths, bottom first, until it
    has at most ``limit`` SVG elements (or no more can be joined); returns it and how many paths
    were joined to the one below."""
    excess = scene.element_count - limit
    if excess <= 0:
        return scene, 0
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    regions = path_regions(vertices, vertex_offsets)
    joined = scene.joined_paths().copy()
    run: list[BaseGeometry] = [regions[0]] if scene.path_count else []
    made = 0
    for index in range(1, scene.path_count):
        same_paint = scene.paints[index] == scene.paints[index - 1]
        if joined[index] and same_paint:
            run.append(regions[index])
            continue
        opaque = scene.paints[index].opaque
        if made < excess and same_paint and (opaque or _apart(regions[index], run)):
            joined[index] = True
            run.append(regions[index])
            made += 1
            continue
        joined[index] = False
        run = [regions[index]]
    return replace(scene, joined=joined), made


def pieces_apart(pieces: list[np.ndarray]) -> bool:
    """Whether closed cubic paths ((3K, 2) control points each) paint (almost) no area in
    common, so that one ``<path>`` of them all paints what they paint one by one."""
    regions = path_regions(*_outlines(pieces))
    return all(_apart(regions[index], regions[:index]) for index in range(1, len(regions)))


def _apart(region: BaseGeometry, run: Iterable[BaseGeometry]) -> bool:
    """Whether ``region`` shares (almost) no area with any region of ``run``."""
    return all(region.intersection(other).area <= MAX_SHARED_AREA for other in run)


def same_way_round(pieces: list[np.ndarray]) -> list[np.ndarray]:
    """Closed cubic paths ((3K, 2) control points each), those that run against the first one
    reversed, so that all run the same way round."""
    signs = _turns(pieces)
    return [
        piece if sign * signs[0] >= 0 else np.concatenate([piece[:1], piece[:0:-1]])
        for piece, sign in zip(pieces, signs, strict=True)
    ]


def one_way_round(pieces: list[np.ndarray]) -> bool:
    """Whether closed cubic paths all run the same way round."""
    signs = _turns(pieces)
    return bool(np.all(signs * signs[0] >= 0))


def _turns(pieces: list[np.ndarray]) -> np.ndarray:
    """The sign of each closed path's area: +1 clockwise on the screen, -1 the other way."""
    return np.sign(signed_polygon_areas(*_outlines(pieces)))


def _outlines(pieces: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The flattened outlines of closed cubic paths: vertices and vertex offsets."""
    offsets = np.cumsum([0] + [len(piece) for piece in pieces])
    return flatten_paths(np.concatenate(pieces), offsets)
