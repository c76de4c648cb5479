"""Helpers the baselines share: target conversion, argument checks, circular blobs as cubic
paths."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from samvg.errors import InputError
from samvg.imaging import to_float_rgb

StepProgress = Callable[[int, int], None]
"""``progress(done, total)``: optimisation steps finished out of the baseline's total."""

WHITE = (1.0, 1.0, 1.0)


def as_target(image: np.ndarray) -> np.ndarray:
    """An (H, W, 3) float32 copy of ``image`` in [0, 1] (see `samvg.imaging.to_float_rgb`)."""
    return to_float_rgb(image, "target")


def check_counts(path_count: int, segments: int) -> None:
    """Raise :class:`InputError` unless both are integers >= 1."""
    for name, value in (("path count", path_count), ("segments", segments)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise InputError(f"{name} must be an integer >= 1, got {value!r}")


def blob(
    centre: tuple[float, float] | np.ndarray,
    radius: float,
    segments: int,
    radius_jitter: np.ndarray | None = None,
) -> np.ndarray:
    """A closed cubic path (3K, 2) approximating a circle, anchors at equal angles.

    ``radius_jitter`` (K,) multiplies the radius at each anchor, giving an irregular blob.
    Handles have the length (4/3)·tan(π/2K)·r along the tangent, which makes an exact-looking
    circle when there is no jitter.
    """
    angles = 2.0 * math.pi * np.arange(segments) / segments
    radii = radius * (np.ones(segments) if radius_jitter is None else np.asarray(radius_jitter))
    direction = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    tangent = np.stack([-np.sin(angles), np.cos(angles)], axis=1)
    anchors = np.asarray(centre, dtype=np.float64) + radii[:, None] * direction
    handle = (4.0 / 3.0) * math.tan(math.pi / (2 * segments)) * radii[:, None]
    following = np.roll(np.arange(segments), -1)
    points = np.empty((3 * segments, 2))
    points[0::3] = anchors
    points[1::3] = anchors + handle * tangent
    points[2::3] = anchors[following] - handle[following] * tangent[following]
    return points


def check_steps(steps: object) -> int:
    """``steps`` as an int, or :class:`InputError` unless it is an integer >= 0."""
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
        raise InputError(f"steps must be an integer >= 0, got {steps!r}")
    return int(steps)
