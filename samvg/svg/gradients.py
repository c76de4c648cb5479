"""Gradient fills read from SVG: a ``<linearGradient>`` or ``<radialGradient>`` referenced by
``fill="url(#id)"`` becomes a `LinearGradient` or `RadialGradient` in canvas pixels.

What the scene holds is what samvg writes: ``gradientUnits="userSpaceOnUse"``, ``spreadMethod``
pad, 2 to 4 opaque stops, a radial focal point at the centre, and a shape transform that keeps
angles (translation, rotation, uniform scale) so that the gradient maps exactly. Anything else is
an `InputError` naming the element: the gradient would otherwise be drawn differently.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from xml.etree import ElementTree

import numpy as np

from samvg.errors import InputError
from samvg.scene import MAX_STOPS, LinearGradient, RadialGradient
from samvg.svg.values import number

_SIMILARITY_TOLERANCE = 1e-9
ColourParser = Callable[[str, str], tuple[float, float, float, float]]
"""The reader's CSS colour parser: (text, label) → RGBA."""


def _local_name(tag: object) -> str:
    return str(tag).rsplit("}", 1)[-1]


def _length(element: ElementTree.Element, name: str, default: str, label: str) -> float:
    text = (element.get(name) or default).strip()
    try:
        value = float(text)
    except ValueError:
        raise InputError(
            f"{label}: gradient {name}={text!r} must be a number in user units"
        ) from None
    if not math.isfinite(value):
        raise InputError(f"{label}: gradient {name}={text!r} is not finite")
    return value


def _stop_offset(text: str, label: str) -> float:
    return min(max(number(text, label), 0.0), 1.0)


def _stops(
    element: ElementTree.Element, label: str, colour: ColourParser
) -> tuple[tuple[float, tuple[float, float, float]], ...]:
    """The stops, offsets clamped and made non-decreasing as SVG does."""
    found = []
    highest = 0.0
    for stop in element:
        if _local_name(stop.tag) != "stop":
            continue
        style = dict(
            part.split(":", 1) for part in (stop.get("style") or "").split(";") if ":" in part
        )
        style = {key.strip(): value.strip() for key, value in style.items()}
        opacity = style.get("stop-opacity", stop.get("stop-opacity", "1"))
        if _stop_offset(opacity, label) < 1.0:
            raise InputError(f"{label}: translucent gradient stops are not supported")
        text = style.get("stop-color", stop.get("stop-color", "black"))
        red, green, blue, _ = colour(text, label)
        highest = max(highest, _stop_offset(stop.get("offset", "0"), label))
        found.append((highest, (red, green, blue)))
    if not 2 <= len(found) <= MAX_STOPS:
        raise InputError(f"{label}: a gradient needs 2 to {MAX_STOPS} stops, got {len(found)}")
    return tuple(found)


def _check_supported(element: ElementTree.Element, label: str) -> None:
    if (element.get("gradientUnits") or "objectBoundingBox") != "userSpaceOnUse":
        raise InputError(f'{label}: only gradientUnits="userSpaceOnUse" gradients are supported')
    for name in ("gradientTransform", "href", "{http://www.w3.org/1999/xlink}href"):
        if element.get(name) is not None:
            raise InputError(
                f"{label}: gradient attribute {name.rsplit('}', 1)[-1]!r} is not supported"
            )
    if (element.get("spreadMethod") or "pad") != "pad":
        raise InputError(f'{label}: only spreadMethod="pad" gradients are supported')


def _similarity_scale(matrix: np.ndarray, label: str) -> float:
    """The scale of a 2 × 2 linear map that keeps angles; `InputError` for any other."""
    (a, c), (b, d) = matrix
    scale = math.sqrt(abs(a * d - b * c))
    if scale == 0.0 or not (
        abs(a * a + b * b - c * c - d * d) <= _SIMILARITY_TOLERANCE * (a * a + b * b)
        and abs(a * c + b * d) <= _SIMILARITY_TOLERANCE * (a * a + b * b)
    ):
        raise InputError(
            f"{label}: a gradient under a skewed or stretched transform is not supported"
        )
    return scale


def gradient_paint(
    element: ElementTree.Element,
    to_pixels: tuple[np.ndarray, np.ndarray],
    opacity: float,
    label: str,
    colour: ColourParser,
) -> LinearGradient | RadialGradient:
    """The paint of gradient ``element`` on a shape whose user units map to canvas pixels by
    ``x ↦ linear @ x + shift`` (``to_pixels``); ``opacity`` is the fill's, ``colour`` the
    reader's CSS colour parser."""
    _check_supported(element, label)
    linear, shift = to_pixels
    scale = _similarity_scale(linear, label)
    stops = _stops(element, label, colour)
    if _local_name(element.tag) == "linearGradient":
        start = (
            linear
            @ np.array([_length(element, "x1", "0", label), _length(element, "y1", "0", label)])
            + shift
        )
        end = (
            linear
            @ np.array([_length(element, "x2", "1", label), _length(element, "y2", "0", label)])
            + shift
        )
        return LinearGradient(stops, opacity, (start[0], start[1]), (end[0], end[1]))
    centre_user = np.array(
        [_length(element, "cx", "0.5", label), _length(element, "cy", "0.5", label)]
    )
    for focal, axis in (("fx", 0), ("fy", 1)):
        if (
            element.get(focal) is not None
            and _length(element, focal, "0", label) != centre_user[axis]
        ):
            raise InputError(f"{label}: a radial gradient's focal point must be its centre")
    radius = _length(element, "r", "0.5", label) * scale
    if radius <= 0:
        raise InputError(f"{label}: a radial gradient needs a positive radius")
    centre = linear @ centre_user + shift
    return RadialGradient(stops, opacity, (centre[0], centre[1]), radius)
