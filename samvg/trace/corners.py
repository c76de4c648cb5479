"""Corners of a closed contour: the points where a traced path's segments meet.

``select_corners`` (a fixed segment count) is SAMVG's variant of Sarfraz & Khan (2004): every
contour point gets a sharpness score (the angle
the lightly smoothed contour turns through over a few points each way); the global maximum is the
first corner, candidates near it are suppressed, the next maximum is taken, and so on until
``count`` corners are chosen. Only local maxima turning by at least ``min_turn`` degrees count as
corners; when a shape has fewer (a disk, an ellipse), the remaining ones split the longest
stretch between chosen corners at its arclength middle, so smooth shapes get evenly spread
segments and every path has the same number of segments.

``find_corners`` is the count-free variant for adaptive tracing: all real corners, however many
(none on a smooth shape); the joins between them are chosen by the fit's error instead.
``sharpen_corners`` moves a corner of a mask contour out to where its two sides meet (marching
squares cut every pixel corner by a half-pixel diagonal).
"""

from __future__ import annotations

import numpy as np

#: Smallest turning angle (degrees, over ``reach`` points each way) of a real corner.
MIN_TURN_DEGREES = 45.0


def _circular(values: np.ndarray, before: int, after: int) -> np.ndarray:
    """``values`` extended cyclically by ``before`` items in front and ``after`` behind."""
    return np.concatenate([values[len(values) - before :], values, values[:after]])


def smooth_contour(contour: np.ndarray) -> np.ndarray:
    """The closed contour filtered with the binomial kernel [1, 4, 6, 4, 1] / 16."""
    n = len(contour)
    ext = _circular(np.asarray(contour, dtype=np.float64), 2, 2)
    return (ext[:n] + ext[4 : n + 4] + 4.0 * (ext[1 : n + 1] + ext[3 : n + 3]) + 6.0 * contour) / 16


def turning_score(contour: np.ndarray, reach: int) -> np.ndarray:
    """Angle (radians, in [0, π]) the contour turns through at each point, measured between the
    chords to the points ``reach`` steps behind and ahead."""
    n = len(contour)
    ext = _circular(contour, reach, reach)
    forward = ext[2 * reach : 2 * reach + n] - contour
    backward = contour - ext[:n]
    cross = backward[:, 0] * forward[:, 1] - backward[:, 1] * forward[:, 0]
    dot = np.einsum("ij,ij->i", backward, forward)
    return np.abs(np.arctan2(cross, dot))


def _candidates(contour: np.ndarray, reach: int, min_turn: float) -> np.ndarray:
    """Indices of the local maxima (over ±``reach``; plateaus keep their first point) of the
    turning score that turn by at least ``min_turn`` degrees, sharpest first."""
    total = len(contour)
    score = turning_score(smooth_contour(contour), reach)
    peak = np.ones(total, dtype=bool)
    ext = _circular(score, reach, reach)
    for shift in range(1, reach + 1):
        peak &= score >= ext[reach - shift : reach - shift + total]
        peak &= score > ext[reach + shift : reach + shift + total]
    candidates = np.flatnonzero(peak & (score >= np.deg2rad(min_turn)))
    return candidates[np.argsort(-score[candidates], kind="stable")]


def _suppress(candidates: np.ndarray, total: int, suppression: int, limit: int) -> list[int]:
    """Candidates in order, skipping any within ``suppression`` points (cyclically) of one
    already chosen, until ``limit`` are chosen."""
    chosen: list[int] = []
    for candidate in candidates:
        if chosen:
            offsets = np.abs(np.asarray(chosen) - candidate)
            if np.min(np.minimum(offsets, total - offsets)) <= suppression:
                continue
        chosen.append(int(candidate))
        if len(chosen) == limit:
            break
    return chosen


def select_corners(
    contour: np.ndarray, count: int, min_turn: float = MIN_TURN_DEGREES
) -> np.ndarray:
    """Indices of ``count`` corners of a closed (N, 2) contour, increasing.

    Returns all N indices when N <= ``count`` (the caller densifies short contours first).
    """
    total = len(contour)
    if total <= count:
        return np.arange(total)
    reach = max(1, min(total // (4 * count), 4))
    candidates = _candidates(contour, reach, min_turn)
    chosen = _suppress(candidates, total, max(reach, total // (2 * count)), count)
    return fill_by_arclength(contour, chosen, count)


def find_corners(
    contour: np.ndarray, limit: int | None = None, min_turn: float = MIN_TURN_DEGREES
) -> np.ndarray:
    """Indices (increasing) of the real corners of a closed (N, 2) contour: every local maximum
    of the turning score that turns by at least ``min_turn`` degrees, sharpest first, none
    within ``2 * reach`` points of a sharper one, at most ``limit`` of them. A smooth shape
    has none. The reach is that of :func:`select_corners` at four corners (≤ 4 points)."""
    total = len(contour)
    if total < 3:
        return np.zeros(0, dtype=np.int64)
    reach = max(1, min(total // 16, 4))
    candidates = _candidates(np.asarray(contour, dtype=np.float64), reach, min_turn)
    chosen = _suppress(candidates, total, 2 * reach, total if limit is None else limit)
    return np.sort(np.asarray(chosen, dtype=np.int64))


def fill_by_arclength(contour: np.ndarray, chosen: list[int], count: int) -> np.ndarray:
    """``chosen`` plus points splitting the longest stretches at their middle, up to ``count``."""
    steps = np.linalg.norm(np.diff(_circular(contour, 0, 1), axis=0), axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(steps)])
    perimeter = cumulative[-1]
    total = len(contour)
    corners = np.sort(np.asarray(chosen if chosen else [0], dtype=np.int64))
    while len(corners) < count:
        following = np.roll(corners, -1)
        lengths = (cumulative[following] - cumulative[corners]) % perimeter
        lengths[following == corners] = perimeter
        longest = int(np.argmax(lengths))
        middle = (cumulative[corners[longest]] + lengths[longest] / 2.0) % perimeter
        index = int(np.searchsorted(cumulative, middle)) % total
        if index in corners:  # stretch of a single step: cannot split at a contour point
            break
        corners = np.sort(np.append(corners, index))
    return corners


def sharpen_corners(
    contour: np.ndarray, corners: np.ndarray, reach: int = 4, limit: float = 1.0
) -> np.ndarray:
    """The contour with each corner point moved to where the straight runs on its two sides
    meet (the chords over up to ``reach`` points before and after it), if that is within
    ``limit`` pixels: marching squares cut a pixel corner by a half-pixel diagonal, so a
    square's corner join would sit half a pixel inside the corner and bend the sides' cubics
    towards it. Corners with fewer than two points a side before the next corner's half-way,
    or between almost parallel runs, stay where they are."""
    sharp = np.array(contour, dtype=np.float64)
    total = len(contour)
    if len(corners) == 0 or total < 5:
        return sharp
    gaps = np.diff(np.append(corners, corners[0] + total))  # to the next corner
    after = np.minimum(gaps // 2, reach) if len(corners) > 1 else np.full(1, reach)
    before = np.roll(after, 1)
    for corner, back, ahead in zip(corners.tolist(), before.tolist(), after.tolist(), strict=True):
        if min(back, ahead) < 2:
            continue
        a0, a1 = contour[(corner - back) % total], contour[(corner - 1) % total]
        b0, b1 = contour[(corner + 1) % total], contour[(corner + ahead) % total]
        u, v, w = a1 - a0, b1 - b0, b0 - a0
        cross = u[0] * v[1] - u[1] * v[0]
        if abs(cross) < 0.1 * np.hypot(*u) * np.hypot(*v):  # within ~6° of parallel
            continue
        meet = a0 + u * (w[0] * v[1] - w[1] * v[0]) / cross
        if np.hypot(*(meet - contour[corner])) <= limit:
            sharp[corner] = meet
    return sharp
