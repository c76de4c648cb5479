"""SVG text of a `Scene`: width, height and viewBox, an optional background rectangle, and one
``<path>`` of absolute cubic commands per path, coordinates rounded to a fixed precision. A
gradient fill is a ``<linearGradient>`` or ``<radialGradient>`` (userSpaceOnUse) in ``<defs>``,
one id per path (``g<path number>``), referenced by ``fill="url(#…)"``; a background gradient
is the background rectangle's fill, id ``bg``.

Written by hand: the output is a dozen lines of fixed shape, and its bytes must not depend on
a library's formatting choices (tests compare them).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from samvg.errors import InputError
from samvg.scene import FlatPaint, LinearGradient, Paint, Scene

SVG_NAMESPACE = "http://www.w3.org/2000/svg"
MAX_PRECISION = 10
"""Decimals beyond this only repeat float noise (coordinates are float64 pixels)."""


def check_precision(precision: object) -> int:
    """``precision`` if it is a number of decimals samvg writes (0 to 10); `InputError` if not."""
    if (
        isinstance(precision, bool)
        or not isinstance(precision, (int, np.integer))
        or not 0 <= precision <= MAX_PRECISION
    ):
        raise InputError(
            f"precision must be an integer from 0 to {MAX_PRECISION} (decimals), got {precision!r}"
        )
    return int(precision)


def number(value: float, precision: int) -> str:
    """``value`` with at most ``precision`` decimals, trailing zeros and ``-0`` dropped."""
    text = f"{value:.{precision}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    if text in ("-0", ""):
        text = "0"
    return text


def hex_colour(rgb: Sequence[float]) -> str:
    """``#rrggbb`` of RGB values in [0, 1] (clamped)."""
    return "#" + "".join(f"{round(min(max(c, 0.0), 1.0) * 255):02x}" for c in rgb)


def path_data(points: np.ndarray, precision: int) -> str:
    """``M…C…Z`` for one closed path of 3K control points."""

    def pair(p: np.ndarray) -> str:
        return f"{number(p[0], precision)} {number(p[1], precision)}"

    count = points.shape[0]
    parts = [f"M{pair(points[0])}"]
    for k in range(count // 3):
        c1, c2, end = points[3 * k + 1], points[3 * k + 2], points[(3 * k + 3) % count]
        parts.append(f"C{pair(c1)} {pair(c2)} {pair(end)}")
    parts.append("Z")
    return "".join(parts)


def scene_to_svg(scene: Scene, precision: int = 2) -> str:
    """SVG text of ``scene`` on its own canvas (convert with `Scene.in_input_pixels` first)."""
    check_precision(precision)
    lines = [
        f'<svg xmlns="{SVG_NAMESPACE}" width="{scene.width}" height="{scene.height}" '
        f'viewBox="0 0 {scene.width} {scene.height}">'
    ]
    definitions: list[str] = []
    if scene.background is not None:
        fill = hex_colour(scene.background)
        if scene.background_gradient is not None:
            definitions.append(gradient_element(scene.background_gradient, "bg", precision))
            fill = "url(#bg)"
        lines.append(f'<rect width="{scene.width}" height="{scene.height}" fill="{fill}"/>')
    definitions += [
        gradient_element(paint, f"g{index}", precision)
        for index, paint in enumerate(scene.paints)
        if not isinstance(paint, FlatPaint)
    ]
    if definitions:
        lines += ["<defs>", *definitions, "</defs>"]
    for index, (points, paint) in enumerate(scene.paths()):
        opacity = paint.rgba[3]
        opacity_attribute = "" if opacity >= 1.0 else f' fill-opacity="{number(opacity, 3)}"'
        fill = hex_colour(paint.rgba[:3]) if isinstance(paint, FlatPaint) else f"url(#g{index})"
        lines.append(f'<path d="{path_data(points, precision)}" fill="{fill}"{opacity_attribute}/>')
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def gradient_element(paint: Paint, identifier: str, precision: int) -> str:
    """The ``<linearGradient>`` or ``<radialGradient>`` element of a gradient paint."""
    if isinstance(paint, FlatPaint):
        raise InputError("a flat fill has no gradient element")
    stops = "".join(
        f'<stop offset="{number(offset, 4)}" stop-color="{hex_colour(rgb)}"/>'
        for offset, rgb in paint.stops
    )
    if isinstance(paint, LinearGradient):
        (x1, y1), (x2, y2) = paint.start, paint.end
        geometry = " ".join(
            f'{name}="{number(value, precision)}"'
            for name, value in (("x1", x1), ("y1", y1), ("x2", x2), ("y2", y2))
        )
        return (
            f'<linearGradient id="{identifier}" gradientUnits="userSpaceOnUse" {geometry}>'
            f"{stops}</linearGradient>"
        )
    (cx, cy), radius = paint.centre, paint.radius
    geometry = " ".join(
        f'{name}="{number(value, precision)}"'
        for name, value in (("cx", cx), ("cy", cy), ("r", radius))
    )
    return (
        f'<radialGradient id="{identifier}" gradientUnits="userSpaceOnUse" {geometry}>'
        f"{stops}</radialGradient>"
    )
