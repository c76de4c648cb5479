"""Helpers the baselines share: target conversion, circular blobs as cubic paths, fit options."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from samvg.errors import InputError
from samvg.io import to_rgb_uint8
from samvg.vector_image import VectorImage, VectorPath

StepProgress = Callable[[int, int], None]
"""``progress(done, total)``: optimisation steps finished out of the baseline's total."""

WHITE = (1.0, 1.0, 1.0)


def as_target(image: np.ndarray) -> np.ndarray:
    """An (H, W, 3) float32 copy of ``image`` in [0, 1].

    Float images already in [0, 1] are kept as they are; anything else goes through
    :func:`samvg.io.to_rgb_uint8` (grey, alpha, uint16, PIL images ...).
    """
    array = np.asarray(image)
    if (
        array.ndim == 3
        and array.shape[2] == 3
        and np.issubdtype(array.dtype, np.floating)
        and array.size
        and np.isfinite(array).all()
        and array.min() >= 0.0
        and array.max() <= 1.0
        and min(array.shape[:2]) >= 2
    ):
        return array.astype(np.float32)
    return to_rgb_uint8(image).astype(np.float32) / 255.0


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


def fit_arguments(fit_options: Mapping[str, Any] | None) -> dict[str, Any]:
    """The keyword arguments for :func:`samvg.optimize.fit_paths` from ``fit_options``.

    ``steps`` is dropped (each baseline sets its own step budget) and so are ``background``
    and ``on_step``, which the baselines manage themselves.
    """
    options = dict(fit_options or {})
    for key in ("steps", "background", "on_step"):
        options.pop(key, None)
    return options


def to_vector_image(
    points: np.ndarray,
    colours: np.ndarray,
    width: int,
    height: int,
    background: tuple[float, float, float],
) -> VectorImage:
    """Fitted arrays as a :class:`VectorImage`; a diverged fit raises :class:`InputError`."""
    if not (np.all(np.isfinite(points)) and np.all(np.isfinite(colours))):
        raise InputError("optimisation diverged (non-finite coordinates or colours)")
    paths = [
        VectorPath(p, tuple(np.clip(c, 0.0, 1.0))) for p, c in zip(points, colours, strict=True)
    ]
    return VectorImage(width, height, paths, background=background)
