"""SVG text of a `Scene`: width, height and viewBox, an optional background rectangle, and one
``<path>`` per SVG element of the scene (`Scene.elements`: one path, or the pieces of a
compound path, each a subpath, all drawn the same way round): an absolute move, then relative
cubic commands (``c``, repeated implicitly), coordinates rounded to a fixed precision first
so the relative steps add up to exactly the rounded points, numbers written as short as SVG
allows (no leading zero, no separator before a minus sign, nor before a point after a number
that has one). A segment that is straight as written (its controls on its chord) is a line
(``h``, ``v``, ``l``, or the closing ``z``) and one of no length is left out: the same shape
in fewer bytes (the bench's icons and wallpapers: 8 % fewer; tango_media_optical 12 %).

A gradient fill is a ``<linearGradient>`` or ``<radialGradient>`` (userSpaceOnUse) in
``<defs>``, ids ``g0``, ``g1``, … with paths of identical gradients sharing one, referenced by
``fill="url(#…)"``; a background gradient is the background rectangle's fill, id ``bg``.

Written by hand: the output is a dozen lines of fixed shape, and its bytes must not depend on
a library's formatting choices (tests compare them).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from samvg.errors import InputError
from samvg.finish.compound import same_way_round
from samvg.scene import FlatPaint, LinearGradient, Paint, Scene

SVG_NAMESPACE = "http://www.w3.org/2000/svg"
MAX_PRECISION = 10
"""Decimals beyond this only repeat float noise (coordinates are float64 pixels)."""
DEFAULT_PRECISION = 1
"""Decimals written unless asked otherwise: a twentieth of a pixel at most, which no render
shows at the input's size, for about 15 % fewer bytes than two decimals."""
STOP_DECIMALS = 3
"""Decimals of gradient stop offsets: a thousandth of the gradient's length, a quarter of a
pixel at most along a 500-pixel ramp (whole-pixel paths move their points up to half a pixel)."""


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
    """``value`` with at most ``precision`` decimals, shortest form: trailing zeros, a leading
    zero and ``-0`` dropped (``.5``, ``-.25``, ``12``)."""
    return _unit_text(round(value * 10**precision), precision)


def hex_colour(rgb: Sequence[float]) -> str:
    """``#rrggbb`` of RGB values in [0, 1] (clamped), or its short form ``#rgb`` where every
    channel's two digits are equal (``#ffffff`` is ``#fff``)."""
    digits = "".join(f"{round(min(max(c, 0.0), 1.0) * 255):02x}" for c in rgb)
    if digits[0::2] == digits[1::2]:
        return "#" + digits[0::2]
    return "#" + digits


def _unit_text(units: int, precision: int) -> str:
    """A value given in units of ``10 ** -precision``, shortest form (``-.5``, ``12``, ``3.25``)."""
    whole, fraction = divmod(abs(int(units)), 10**precision)
    sign = "-" if units < 0 else ""
    if not fraction:
        return f"{sign}{whole}"
    digits = f"{fraction:0{precision}d}".rstrip("0")
    return f"{sign}{whole or ''}.{digits}"


def _joined(numbers: list[str]) -> str:
    """Numbers of one command, separated by a space except before a minus sign, or before a
    point where the number before already has one (``1.5.5`` reads as 1.5 and .5)."""
    text = numbers[0] if numbers else ""
    for before, after in zip(numbers, numbers[1:], strict=False):
        joins = after[0] == "-" or (after[0] == "." and "." in before)
        text += after if joins else f" {after}"
    return text


def _straight(steps: np.ndarray) -> np.ndarray:
    """Which cubics of relative ``steps`` ((K, 3, 2) integer units: control 1, control 2, end)
    are straight as written: both controls within half a unit of the chord, between its ends, or
    every step zero (a segment of no length). In floats: at 10 decimals squares overflow int64."""
    values = steps.astype(np.float64)
    chord = values[:, 2]
    length_squared = (chord**2).sum(axis=1)
    reach = 0.5 * np.sqrt(length_squared)[:, None]
    controls = values[:, :2]
    along = (controls * chord[:, None]).sum(axis=2)
    across = controls[..., 0] * chord[:, None, 1] - controls[..., 1] * chord[:, None, 0]
    on_chord = (
        (np.abs(across) <= reach) & (along >= -reach) & (along <= length_squared[:, None] + reach)
    )
    return ((length_squared > 0) & on_chord.all(axis=1)) | ~steps.any(axis=(1, 2))


def _segment_command(steps: np.ndarray, straight: bool, precision: int) -> tuple[str, list[str]]:
    """The command letter and numbers of one segment: ``h``, ``v`` or ``l`` where it is
    ``straight``, else ``c``."""
    if straight:
        dx, dy = steps[2]
        if dy == 0:
            return "h", [_unit_text(dx, precision)]
        if dx == 0:
            return "v", [_unit_text(dy, precision)]
        return "l", [_unit_text(dx, precision), _unit_text(dy, precision)]
    return "c", [_unit_text(v, precision) for v in steps.ravel()]


def path_data(points: np.ndarray, precision: int) -> str:
    """``M…z`` for one closed path of 3K control points: the start absolute, then each segment
    relative to the end of the one before (its offsets taken between rounded points): a cubic
    ``c``, or where it is straight as written a line (``h``, ``v``, ``l``; the closing one is
    ``z`` alone), a segment of no length left out, a letter written only where it changes."""
    units = np.rint(np.asarray(points, dtype=np.float64) * 10**precision).astype(np.int64)
    count = units.shape[0] // 3
    ends = np.roll(units[0::3], -1, axis=0)
    steps = np.stack([units[1::3], units[2::3], ends], axis=1) - units[0::3, None]
    straight = _straight(steps)
    parts = [f"M{_joined([_unit_text(v, precision) for v in units[0]])}"]
    # z draws the closing line; a segment of no length draws nothing (but a path of no length
    # keeps one segment: a path reads back with at least one)
    drawn = [
        k for k in range(count) if not (straight[k] and (k == count - 1 or not steps[k, 2].any()))
    ]
    letter = ""
    numbers: list[str] = []
    for k in drawn or [0]:
        command, values = _segment_command(steps[k], bool(straight[k]), precision)
        if command != letter:
            parts += [_joined(numbers), command]
            letter, numbers = command, []
        numbers += values
    parts += [_joined(numbers), "z"]
    return "".join(parts)


def scene_to_svg(scene: Scene, precision: int = DEFAULT_PRECISION) -> str:
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
    gradient_ids, gradient_definitions = _shared_gradients(scene.paints, precision)
    definitions += gradient_definitions
    if definitions:
        lines += ["<defs>", *definitions, "</defs>"]
    for element in scene.elements():
        index = element[0]
        paint = scene.paints[index]
        opacity = paint.rgba[3]
        opacity_attribute = "" if opacity >= 1.0 else f' fill-opacity="{number(opacity, 3)}"'
        fill = (
            f"url(#{gradient_ids[index]})" if index in gradient_ids else hex_colour(paint.rgba[:3])
        )
        pieces = [scene.path_points(path) for path in element]
        if len(pieces) > 1:
            pieces = same_way_round(pieces)
        data = "".join(path_data(piece, precision) for piece in pieces)
        lines.append(f'<path d="{data}" fill="{fill}"{opacity_attribute}/>')
    lines.append("</svg>")
    return "\n".join(lines) + "\n"


def _shared_gradients(paints: Sequence[Paint], precision: int) -> tuple[dict[int, str], list[str]]:
    """The gradient id of every path with a gradient fill (``g0``, ``g1``, … in order of first
    use, one per distinct element as written: a path split in two keeps one gradient) and the
    elements, in id order."""
    ids: dict[int, str] = {}
    seen: dict[str, str] = {}
    elements: list[str] = []
    for index, paint in enumerate(paints):
        if isinstance(paint, FlatPaint):
            continue
        text = gradient_element(paint, "", precision)
        if text not in seen:
            seen[text] = f"g{len(seen)}"
            elements.append(gradient_element(paint, seen[text], precision))
        ids[index] = seen[text]
    return ids, elements


def _offset_attribute(offset: float) -> str:
    """`` offset="…"`` of a gradient stop, or nothing where it is 0 (SVG's initial value)."""
    text = number(offset, STOP_DECIMALS)
    return "" if text == "0" else f' offset="{text}"'


def gradient_element(paint: Paint, identifier: str, precision: int) -> str:
    """The ``<linearGradient>`` or ``<radialGradient>`` element of a gradient paint."""
    if isinstance(paint, FlatPaint):
        raise InputError("a flat fill has no gradient element")
    stops = "".join(
        f'<stop{_offset_attribute(offset)} stop-color="{hex_colour(rgb)}"/>'
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
