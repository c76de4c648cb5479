"""Least-squares cubic Bézier fits of many point runs at once, endpoints pinned.

Schneider's method ("An algorithm for automatically fitting digitized curves", Graphics Gems,
1990) without the recursive splitting: chord-length parameters, a linear least-squares solve for
the two inner control points, then a few rounds of Newton reparameterization
``t ← t − f·f′ / (f′·f′ + f·f″)`` (``f = B(t) − p``), each followed by a new solve. All runs are
processed together with NumPy (``np.bincount`` sums the normal equations per run), so the cost
is a few dozen array operations over the concatenated points whatever the number of runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Newton reparameterization rounds after the chord-length fit.
NEWTON_ITERATIONS = 16
# Ridge weight pulling the inner control points towards the chord's thirds: makes runs of two or
# three points (no or one interior point) well posed and is negligible otherwise.
_RIDGE = 1e-6


@dataclass(frozen=True)
class CubicFits:
    """``controls`` (S, 4, 2): one cubic per run; ``distances`` (M,): distance of each input point
    to its parameter's point on its run's cubic (after a last Newton step, so close to the
    distance to the curve), zero at the pinned endpoints."""

    controls: np.ndarray
    distances: np.ndarray


class _Runs:
    """The concatenated runs with what every fitting step needs per point: the run it belongs
    to, its coordinates and its run's pinned start and end."""

    def __init__(self, points: np.ndarray, offsets: np.ndarray) -> None:
        self.count = len(offsets) - 1
        lengths = np.diff(offsets)
        self.run_of = np.repeat(np.arange(self.count), lengths)
        self.heads, self.tails = offsets[:-1], offsets[1:] - 1
        self.px, self.py = points[:, 0].copy(), points[:, 1].copy()
        self.sx, self.sy = self.px[self.heads], self.py[self.heads]
        self.ex, self.ey = self.px[self.tails], self.py[self.tails]
        # Each run's start and end, per point (the pinned terms of the Bézier).
        self.psx, self.psy = self.sx[self.run_of], self.sy[self.run_of]
        self.pex, self.pey = self.ex[self.run_of], self.ey[self.run_of]
        self.free = np.ones(len(self.px), dtype=bool)
        self.free[self.heads] = self.free[self.tails] = False

    def chord_parameters(self) -> np.ndarray:
        """Chord-length parameters, 0 at each run's first point and 1 at its last."""
        px, py, heads, run_of = self.px, self.py, self.heads, self.run_of
        steps = np.empty(len(px))
        steps[0] = 0.0
        steps[1:] = np.hypot(np.diff(px), np.diff(py))
        steps[heads] = 0.0
        cumulative = np.cumsum(steps)
        cumulative -= cumulative[heads][run_of]
        span = cumulative[self.tails]
        t = cumulative / np.where(span > 0, span, 1.0)[run_of]
        t[self.tails] = 1.0
        return t

    def per_run(self, weights: np.ndarray) -> np.ndarray:
        return np.bincount(self.run_of, weights=weights, minlength=self.count)

    def solve(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """Inner control points (c1x, c1y, c2x, c2y) per run minimizing the squared error."""
        sx, sy, ex, ey = self.sx, self.sy, self.ex, self.ey
        s = 1.0 - t
        b0, b1, b2, b3 = s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t
        rx = self.px - b0 * self.psx - b3 * self.pex
        ry = self.py - b0 * self.psy - b3 * self.pey
        a11 = self.per_run(b1 * b1) + _RIDGE
        a12 = self.per_run(b1 * b2)
        a22 = self.per_run(b2 * b2) + _RIDGE
        r1x = self.per_run(b1 * rx) + _RIDGE * (sx + (ex - sx) / 3.0)
        r1y = self.per_run(b1 * ry) + _RIDGE * (sy + (ey - sy) / 3.0)
        r2x = self.per_run(b2 * rx) + _RIDGE * (sx + 2.0 * (ex - sx) / 3.0)
        r2y = self.per_run(b2 * ry) + _RIDGE * (sy + 2.0 * (ey - sy) / 3.0)
        det = a11 * a22 - a12 * a12
        return (
            (a22 * r1x - a12 * r2x) / det,
            (a22 * r1y - a12 * r2y) / det,
            (a11 * r2x - a12 * r1x) / det,
            (a11 * r2y - a12 * r1y) / det,
        )

    def newton(
        self, t: np.ndarray, controls: tuple[np.ndarray, ...]
    ) -> tuple[np.ndarray, np.ndarray]:
        """Newton-updated parameters, and |B(t) − p| at the parameters given."""
        psx, psy, pex, pey = self.psx, self.psy, self.pex, self.pey
        c1x, c1y, c2x, c2y = (c[self.run_of] for c in controls)
        s = 1.0 - t
        b0, b1, b2, b3 = s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t
        fx = b0 * psx + b1 * c1x + b2 * c2x + b3 * pex - self.px
        fy = b0 * psy + b1 * c1y + b2 * c2y + b3 * pey - self.py
        # Derivatives: B' = 3 Σ Bernstein(2) × control differences, B'' = 6 Σ Bernstein(1) × ...
        q0, q1, q2 = 3.0 * s * s, 6.0 * s * t, 3.0 * t * t
        d1x = q0 * (c1x - psx) + q1 * (c2x - c1x) + q2 * (pex - c2x)
        d1y = q0 * (c1y - psy) + q1 * (c2y - c1y) + q2 * (pey - c2y)
        d2x = 6.0 * (s * (c2x - 2.0 * c1x + psx) + t * (pex - 2.0 * c2x + c1x))
        d2y = 6.0 * (s * (c2y - 2.0 * c1y + psy) + t * (pey - 2.0 * c2y + c1y))
        numerator = fx * d1x + fy * d1y
        denominator = d1x * d1x + d1y * d1y + fx * d2x + fy * d2y
        safe = self.free & (np.abs(denominator) > 1e-12)
        updated = t.copy()
        updated[safe] -= numerator[safe] / denominator[safe]
        return np.clip(updated, 0.0, 1.0), np.hypot(fx, fy)


def fit_cubics(
    points: np.ndarray, offsets: np.ndarray, iterations: int = NEWTON_ITERATIONS
) -> CubicFits:
    """Fit one cubic to each run ``points[offsets[j] : offsets[j + 1]]`` (two points or more),
    pinned to the run's first and last points."""
    points = np.asarray(points, dtype=np.float64)
    offsets = np.asarray(offsets, dtype=np.int64)
    if len(offsets) - 1 <= 0:
        return CubicFits(np.zeros((0, 4, 2)), np.zeros(0))
    if np.any(np.diff(offsets) < 2):
        raise ValueError("every run needs at least two points")
    runs = _Runs(points, offsets)
    t = runs.chord_parameters()
    controls = runs.solve(t)
    for _ in range(iterations):
        t, _ = runs.newton(t, controls)
        controls = runs.solve(t)
    t, _ = runs.newton(t, controls)
    _, distances = runs.newton(t, controls)
    c1x, c1y, c2x, c2y = controls
    stacked = np.stack([runs.sx, runs.sy, c1x, c1y, c2x, c2y, runs.ex, runs.ey], axis=1)
    return CubicFits(stacked.reshape(runs.count, 4, 2), distances)
