"""Closed outline → closed cubic path with as few segments as a tolerance allows.

An outline is a closed (N, 2) polygon: a mask contour (``samvg.trace.contour``) or a flattened
path (:func:`refit_outline`). Its segment count K (1 to ``max_segments``) is the fewest this
greedy search finds such that every fitted outline point lies within ``tolerance`` pixels of
the curve (the distances ``samvg.trace.fit`` reports, ``TracedPath.max_error``; the role of
potrace's ``opttolerance``):

1. Joins start at the outline's real corners (turns of at least ``MIN_TURN_DEGREES``,
   ``samvg.trace.corners.find_corners``), which stay joins to the end: a square is four straight
   cubics with sharp corners (on mask contours, whose pixel corners are cut by a half-pixel
   diagonal, each corner join first moves out to where its two sides meet,
   ``sharpen_corners``). An outline without corners starts as one cubic round the loop.
2. Split: every stretch between two joins that misses the tolerance is cut at its worst point
   (kept in the middle half of the stretch, so no sliver appears) and both halves are refitted.
   Each stretch is fitted on its own with its ends pinned, so a split never disturbs the other
   stretches; one round fits the new halves of all outlines in one batch (``fit_cubics``).
   Where an outline would pass ``max_segments``, only its worst stretches are split.
3. Merge: the splits placed joins without looking ahead, so joins that are not corners are then
   removed, greedily (best merged fit first, in batched rounds), wherever the two stretches
   they separate fit as one cubic within the tolerance. Where merges freed room under
   ``max_segments``, stretches still over the tolerance are split again.

Every fit is cached by (outline, start, length), so a merge round refits only the pairs that
changed. A path ends within the tolerance unless it has ``max_segments`` segments.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import pairwise
from typing import NamedTuple

import numpy as np

from samvg.errors import InputError
from samvg.trace.corners import find_corners, sharpen_corners
from samvg.trace.fit import fit_cubics
from samvg.trace.outline import OutlineFit, densify, stretch_samples

#: Default most segments per path when the count follows a tolerance.
DEFAULT_MAX_SEGMENTS = 32
#: Most outline points a stretch contributes to its fit, and its error is measured on: more
#: than the fixed count's ``MAX_FIT_POINTS``, so that long stretches are judged on enough of
#: their points (with 64, one path in twenty on SAM masks was up to 30 % over a 1 px tolerance
#: between the measured points; with 128, none by more than 5 %).
FIT_POINTS = 128
#: Fewest points an outline is fitted on (short contours get points inserted along their
#: edges, so small specks are fitted and measured on more than their few boundary points).
MIN_OUTLINE_POINTS = 32
#: Farthest a corner join of a mask contour moves out to where its sides meet, in pixels (and
#: never farther than the tolerance).
SHARPEN_LIMIT = 1.0
#: Longest edge of a polygon given to :func:`refit_outline`, in pixels; longer ones are
#: subdivided (the corner detector and the fit count outline points, as on a mask contour).
POLYGON_SPACING = 1.0
#: Most points a polygon is subdivided into (beyond it, edges are cut more coarsely).
MAX_POLYGON_POINTS = 20_000

#: Most split-then-merge cycles: merges can free room under ``max_segments`` that a further
#: split uses (a last split always follows, so no stretch stays over the tolerance with room).
MERGE_CYCLES = 4

# A job: stretch ``length`` steps forward from index ``start`` of outline ``owner``.
_Job = tuple[int, int, int]


class _Stretch(NamedTuple):
    """The fit of one stretch: its length in outline steps, its cubic (4, 2), the max distance,
    the sum of squared distances and the count of its fitted points, and the steps from its
    start to its worst point."""

    length: int
    controls: np.ndarray
    max_error: float
    squares: float
    samples: int
    worst: int


def check_tolerance(value: object) -> float:
    """``value`` as a tolerance in pixels: a positive finite number, else :class:`InputError`."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"tolerance must be a number of pixels, got {value!r}")
    if not np.isfinite(value) or value <= 0:
        raise InputError(f"tolerance must be a positive finite number of pixels, got {value!r}")
    return float(value)


def check_max_segments(value: object) -> int:
    """``value`` as a segment cap: an integer >= 1, else :class:`InputError`."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"max_segments must be an integer >= 1, got {value!r}")
    return int(value)


class _Outlines:
    """The outlines of one call, concatenated, with the joins of each (the starts of its
    stretches) and the fit of every stretch."""

    def __init__(self, contours: list[np.ndarray], corners: list[np.ndarray]) -> None:
        self.totals = np.array([len(contour) for contour in contours], dtype=np.int64)
        self.bases = np.cumsum(self.totals) - self.totals
        self.points = np.concatenate(contours)
        self.corners = [frozenset(int(index) for index in found) for found in corners]
        self.stretches: list[dict[int, _Stretch]] = [{} for _ in contours]
        self.fitted: dict[_Job, _Stretch] = {}

    def fit(self, jobs: list[_Job]) -> list[_Stretch]:
        """One cubic per job's stretch: those not fitted before, all in one batch."""
        new = list(dict.fromkeys(job for job in jobs if job not in self.fitted))
        self.fitted.update(zip(new, self._fit_batch(new), strict=True))
        return [self.fitted[job] for job in jobs]

    def _fit_batch(self, jobs: list[_Job]) -> list[_Stretch]:
        if not jobs:
            return []
        owners, starts, lengths = np.array(jobs, dtype=np.int64).T
        totals = self.totals[owners]
        indices, sizes = stretch_samples(starts, lengths, totals, FIT_POINTS)
        offsets = np.concatenate([[0], np.cumsum(sizes)])
        fits = fit_cubics(self.points[indices + np.repeat(self.bases[owners], sizes)], offsets)
        distances, heads = fits.distances, offsets[:-1]
        maxima = np.maximum.reduceat(distances, heads)
        squares = np.add.reduceat(distances**2, heads)
        run_of = np.repeat(np.arange(len(jobs)), sizes)
        hits = np.flatnonzero(distances == maxima[run_of])
        _, first = np.unique(run_of[hits], return_index=True)
        worst = (indices[hits[first]] - starts) % totals
        return [
            _Stretch(int(length), controls, float(error), float(square), int(size), int(at))
            for length, controls, error, square, size, at in zip(
                lengths, fits.controls, maxima, squares, sizes, worst, strict=True
            )
        ]

    def store(self, jobs: list[_Job]) -> None:
        """Fit the jobs' stretches and record them under their outline and start."""
        for (owner, start, _), stretch in zip(jobs, self.fit(jobs), strict=True):
            self.stretches[owner][start] = stretch

    def split(self, tolerance: float, max_segments: int) -> None:
        """Split stretches over the tolerance until none is left or their outline has
        ``max_segments``; one batch per round."""
        jobs = self.split_jobs(tolerance, max_segments)
        while jobs:
            self.store(jobs)
            jobs = self.split_jobs(tolerance, max_segments)

    def split_jobs(self, tolerance: float, max_segments: int) -> list[_Job]:
        """Cut every stretch over the tolerance in two (the worst ones only where the outline
        would pass ``max_segments``); the halves, still to be fitted."""
        jobs: list[_Job] = []
        for owner, stretches in enumerate(self.stretches):
            over = sorted(
                (
                    (stretch.max_error, start)
                    for start, stretch in stretches.items()
                    if stretch.max_error > tolerance and stretch.length >= 2
                ),
                reverse=True,
            )
            total = int(self.totals[owner])
            for _, start in over[: max(max_segments - len(stretches), 0)]:
                old = stretches.pop(start)
                cut = min(max(old.worst, -(-old.length // 4)), 3 * old.length // 4)
                jobs += [(owner, start, cut), (owner, (start + cut) % total, old.length - cut)]
        return jobs

    def merge(self, tolerance: float) -> bool:
        """One round of merges: remove non-corner joins whose two stretches fit as one cubic
        within the tolerance, best first, no stretch in two merges. Whether any merged."""
        jobs: list[_Job] = []
        pairs: list[tuple[int, int]] = []
        for owner, stretches in enumerate(self.stretches):
            joins = sorted(stretches)
            if len(joins) < 2:
                continue
            for previous, join in zip([joins[-1], *joins[:-1]], joins, strict=True):
                if join not in self.corners[owner]:
                    length = stretches[previous].length + stretches[join].length
                    jobs.append((owner, previous, length))
                    pairs.append((previous, join))
        fitted = self.fit(jobs)
        used: list[set[int]] = [set() for _ in self.stretches]
        merged = False
        for job in sorted(range(len(jobs)), key=lambda index: fitted[index].max_error):
            if fitted[job].max_error > tolerance:
                break
            owner, (previous, join) = jobs[job][0], pairs[job]
            if previous in used[owner] or join in used[owner]:
                continue
            used[owner].update((previous, join))
            del self.stretches[owner][join]
            self.stretches[owner][previous] = fitted[job]
            merged = True
        return merged

    def result(self, owner: int) -> OutlineFit:
        """The outline's path, starting at its first corner (at its first join if none)."""
        stretches = self.stretches[owner]
        joins = sorted(stretches)
        first = joins.index(min(self.corners[owner])) if self.corners[owner] else 0
        ordered = [stretches[join] for join in joins[first:] + joins[:first]]
        controls = np.stack([stretch.controls for stretch in ordered])
        squares = sum(stretch.squares for stretch in ordered)
        samples = sum(stretch.samples for stretch in ordered)
        return OutlineFit(
            points=controls[:, :3, :].reshape(3 * len(ordered), 2),
            max_error=max(stretch.max_error for stretch in ordered),
            rms_error=float(np.sqrt(squares / samples)),
        )


def _prepared(
    contour: np.ndarray, max_segments: int, sharpen: float
) -> tuple[np.ndarray, np.ndarray]:
    """The outline densified to ``MIN_OUTLINE_POINTS`` and its corners (found on the outline as
    given, at most ``max_segments``, indexed in the densified one), moved out to where the
    sides meet by up to ``sharpen`` pixels (``sharpen_corners``)."""
    corners = find_corners(contour, limit=max_segments)
    if sharpen > 0:
        contour = sharpen_corners(contour, corners, limit=sharpen)
    dense = densify(contour, MIN_OUTLINE_POINTS)
    return dense, corners * (len(dense) // len(contour))


def _initial_jobs(totals: np.ndarray, corners: list[np.ndarray]) -> list[_Job]:
    """The stretches between consecutive corners; a whole loop from index 0 without any."""
    jobs: list[_Job] = []
    for owner, (total, found) in enumerate(zip(totals.tolist(), corners, strict=True)):
        joins = found.tolist() if len(found) else [0]
        lengths = [(following - join) % total for join, following in pairwise(joins)]
        lengths.append(total - sum(lengths))
        jobs += [(owner, join, length) for join, length in zip(joins, lengths, strict=True)]
    return jobs


def fit_adaptive(
    contours: list[np.ndarray],
    tolerance: float,
    max_segments: int = DEFAULT_MAX_SEGMENTS,
    sharpen: bool = False,
) -> list[OutlineFit]:
    """Each closed (N, 2) contour as a path of the fewest cubics (at most ``max_segments``)
    found to fit it within ``tolerance`` pixels (see the module docstring); one batch of fits
    per round for all contours. ``sharpen``: move each corner join out to where its sides meet
    (mask contours, whose pixel corners marching squares cut by a half-pixel diagonal), by at
    most ``min(1, tolerance)`` pixels, so the paths stay within the tolerance of the contours
    as given. Arguments are not checked (see :func:`check_tolerance`)."""
    if not contours:
        return []
    shift = min(SHARPEN_LIMIT, tolerance) if sharpen else 0.0
    prepared = [
        _prepared(np.asarray(contour, np.float64), max_segments, shift) for contour in contours
    ]
    dense = [points for points, _ in prepared]
    corners = [found for _, found in prepared]
    outlines = _Outlines(dense, corners)
    outlines.store(_initial_jobs(outlines.totals, corners))
    for _ in range(MERGE_CYCLES):
        outlines.split(tolerance, max_segments)
        merged = False
        while outlines.merge(tolerance):
            merged = True
        if not merged:
            break
    else:
        outlines.split(tolerance, max_segments)
    return [outlines.result(owner) for owner in range(len(contours))]


def _as_polygon(polygon: object, name: str = "polygon") -> np.ndarray:
    """The polygon as float64 (N, 2) without repeated consecutive points (nor a closing copy of
    the first), checked: numbers, finite, at least three distinct points."""
    try:
        array = np.asarray(polygon)
    except (TypeError, ValueError):  # ragged nested sequences
        array = np.asarray(None)
    if array.dtype.kind not in "iuf" or array.ndim != 2 or array.shape[1] != 2:
        raise InputError(
            f"{name} must be an (N, 2) array of point coordinates, got {_describe(array)}"
        )
    array = array.astype(np.float64)
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} points must be finite (no NaN or infinity)")
    distinct = np.any(array != np.roll(array, 1, axis=0), axis=1)
    array = array[distinct] if distinct.any() else array[:1]
    if len(array) < 3:
        raise InputError(f"{name} needs at least 3 distinct points, got {len(array)}")
    return array


def _describe(array: np.ndarray) -> str:
    if array.dtype == object:
        return "something else"
    return f"shape {array.shape} of dtype {array.dtype}"


def _subdivided(polygon: np.ndarray) -> np.ndarray:
    """The closed polygon with points inserted on every edge longer than the spacing:
    ``POLYGON_SPACING``, finer for a polygon shorter than ``MIN_OUTLINE_POINTS`` of them (so
    corners are found on enough points), coarser past ``MAX_POLYGON_POINTS`` points."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    perimeter = float(lengths.sum())
    spacing = min(POLYGON_SPACING, perimeter / MIN_OUTLINE_POINTS)
    spacing = max(spacing, perimeter / MAX_POLYGON_POINTS)
    pieces = np.maximum(np.ceil(lengths / spacing), 1).astype(np.int64)
    step = np.arange(int(pieces.sum())) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    fractions = step / np.repeat(pieces, pieces)
    return np.repeat(polygon, pieces, axis=0) + fractions[:, None] * np.repeat(
        edges, pieces, axis=0
    )


def refit_outline(
    polygon: np.ndarray, tolerance: float, max_segments: int = DEFAULT_MAX_SEGMENTS
) -> np.ndarray:
    """Re-trace a closed polygon (an (N, 2) array of outline points in order, e.g. a flattened
    path; the first point is not repeated, or is ignored if it is) as the fewest cubics found to
    fit it within ``tolerance`` pixels, at most ``max_segments``: (3K, 2) control points in
    :class:`~samvg.scene.Scene` layout, starting at a corner when the polygon has one.

    Every sharp turn (45° or more) is a join, a corner of the result; edges longer than a
    pixel get points inserted first, so the fit and its error follow the outline rather than
    its vertices. Bad arguments raise :class:`InputError`. Many polygons at once:
    :func:`refit_outlines` (one batch: about 3x faster than a loop for 100 paths).
    """
    tolerance = check_tolerance(tolerance)
    max_segments = check_max_segments(max_segments)
    outline = _subdivided(_as_polygon(polygon))
    return fit_adaptive([outline], tolerance, max_segments)[0].points


def refit_outlines(
    polygons: Sequence[np.ndarray], tolerance: float, max_segments: int = DEFAULT_MAX_SEGMENTS
) -> list[np.ndarray]:
    """:func:`refit_outline` of each polygon, fitted together in one batch."""
    tolerance = check_tolerance(tolerance)
    max_segments = check_max_segments(max_segments)
    if isinstance(polygons, np.ndarray) or not isinstance(polygons, Sequence):
        raise InputError("polygons must be a list of (N, 2) arrays")
    outlines = [
        _subdivided(_as_polygon(polygon, f"polygon {index}"))
        for index, polygon in enumerate(polygons)
    ]
    return [fit.points for fit in fit_adaptive(outlines, tolerance, max_segments)]
