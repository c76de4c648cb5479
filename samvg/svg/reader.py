"""Read SVG text into samvg's scene form: a pixel canvas, an optional background (a colour or a
gradient) and closed cubic Bézier paths with straight RGBA or gradient fills. That is this module's
one job.

It is built on the maintained library svgelements, which resolves transforms, ``style`` and CSS,
inheritance through groups and ``<use>``, units, and every path command (absolute or relative,
arcs included), so none of that is written by hand here. This module adds what svgelements leaves
lenient or gets wrong: a strict standard-library XML check (refusing entity declarations), strict
path, length and transform syntax, element labels for errors (``svg/g[1]/path[3] (id='x')``),
refusal of what the scene cannot hold, and the viewBox-to-pixel map, computed here so that SVG
written by samvg reads back to exactly the numbers in its text.

A ``<path>`` of several subpaths reads as a compound path (`Scene.joined`) when its subpaths
paint no area in common, or when its fill is opaque and they all run the same way round (it
paints their union then); others (holes) are refused.

A path with K segments holds 3K control points; segment k runs from ``points[3k]`` through
``points[3k+1]`` and ``points[3k+2]`` to ``points[(3k+3) % 3K]``.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ElementTree
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import svgelements

from samvg.errors import InputError
from samvg.finish.compound import one_way_round, pieces_apart
from samvg.scene import LinearGradient, RadialGradient
from samvg.svg.gradients import gradient_paint
from samvg.svg.values import number

__all__ = ["ParsedSvg", "read_svg"]

_SVG_NAMESPACE = "http://www.w3.org/2000/svg"
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_CLOSE_TOLERANCE = 1e-6
# Element labels travel through svgelements as an attribute; it keeps every element's own
# attributes in ``values["attributes"]``.
_LABEL = "data-samvg-label"
# Dropped before svgelements sees the document: no pixels of their own (svgelements would
# otherwise draw the children of <metadata> or <mask> as if they were ordinary shapes).
_DROPPED_TAGS = {
    "title",
    "desc",
    "metadata",
    "script",
    "linearGradient",
    "radialGradient",
    "pattern",
    "clipPath",
    "mask",
    "marker",
    "filter",
    "symbol",
}
# Attributes (or CSS properties) that change the pixels in ways the scene cannot hold, with the
# value that makes them harmless.
_UNSUPPORTED_ATTRIBUTES = {
    "clip-path": "none",
    "mask": "none",
    "filter": "none",
    "marker": "none",
    "marker-start": "none",
    "marker-mid": "none",
    "marker-end": "none",
    "mix-blend-mode": "normal",
}
_LENGTH_ATTRIBUTES = {
    "rect": ("x", "y", "width", "height", "rx", "ry"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
    "line": ("x1", "y1", "x2", "y2"),
    "use": ("x", "y", "width", "height"),
}
# Inherited properties this module reads, with their initial values.
_INHERITED_PROPERTIES = {
    "fill": "black",
    "fill-opacity": "1",
    "fill-rule": "nonzero",
    "stroke": "none",
    "visibility": "visible",
}
# Expanded element count (each <use> counting its target again) above which a document is refused.
_MAX_ELEMENTS = 1_000_000
# Nesting depth above which a document is refused, checked before any recursive pass over it
# (real drawings nest a few dozen levels; Python's recursion limit is 1000 frames).
_MAX_DEPTH = 500

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_NUMBER_AT = re.compile(r"[\s,]*(" + _NUMBER + ")")
_FLAG_AT = re.compile(r"[\s,]*([01])")
_COMMAND_AT = re.compile(r"\s*([MmLlHhVvCcSsQqTtAaZz])")
_ARGUMENT_COUNTS = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "A": 7, "Z": 0}
_LENGTH = re.compile(r"^\s*(" + _NUMBER + r")\s*(px|mm|cm|in|pt|pc|%)?\s*$")
_PIXEL_LENGTH = re.compile(r"^\s*(" + _NUMBER + r")\s*(px)?\s*$")
_TRANSFORM_AT = re.compile(r"[\s,]*(matrix|translate|scale|rotate|skewX|skewY)\s*\(([^()]*)\)")
_TRANSFORM_COUNTS = {
    "matrix": (6,),
    "translate": (1, 2),
    "scale": (1, 2),
    "rotate": (1, 3),
    "skewX": (1,),
    "skewY": (1,),
}
_HEX_COLOUR = re.compile(r"^#(?:[0-9a-fA-F]{3,4}|[0-9a-fA-F]{6}|[0-9a-fA-F]{8})$")

_Rgba = tuple[float, float, float, float]
_Gradient = LinearGradient | RadialGradient
_Fill = _Rgba | _Gradient
_URL = re.compile(r"url\(\s*#([^)\s]+)\s*\)")


@dataclass(frozen=True)
class ParsedSvg:
    """A canvas of ``width`` × ``height`` pixels, an optional opaque background and filled paths.

    ``paths`` holds ``(points, fill)`` pairs in paint order: ``points`` a float64 (3K, 2) array of
    closed cubic control points in canvas pixels, ``fill`` straight RGBA in [0, 1] or a gradient
    paint in canvas pixels (see `samvg.svg.gradients`). A gradient background is
    ``background_gradient`` (canvas pixels), and ``background`` then its mean stop colour.
    """

    width: int
    height: int
    background: tuple[float, float, float] | None
    paths: list[tuple[np.ndarray, _Fill]]
    background_gradient: _Gradient | None = None
    joined: list[bool] = field(default_factory=list)
    """Per path, whether it is one more subpath of the ``<path>`` of the path before it (a
    compound path, see `read_svg`); empty for none."""


def read_svg(text: str) -> ParsedSvg:
    """Parse SVG text made of filled shapes into a :class:`ParsedSvg`.

    A full-canvas, opaque, axis-aligned ``<rect>`` drawn before any other shape becomes the
    background (its colour, or its gradient). A ``<path>`` of several subpaths becomes a
    compound path (``joined``) when they paint no area in common, or when its fill is opaque and
    they all run the same way round. Anything the scene cannot represent raises
    :class:`InputError` naming the element.
    """
    root = _parse_xml(text)
    geometry = _Geometry.of(root)
    try:
        ids = _ids(root)
        _prepare(root, "svg", ids)
        _check_use_expansion(root)
        document = _parse_with_svgelements(root, geometry)
        scene = _Scene(geometry, ids)
        if document is not None:  # None: the root is not rendered (display:none), no shapes
            _read_group(document, scene, _opacity(document, 1.0, "svg"), use_label=None)
    except RecursionError:
        raise InputError("svg: elements or <use> references are nested too deeply") from None
    except (ValueError, TypeError, ArithmeticError, LookupError, AttributeError) as error:
        if isinstance(error, InputError):
            raise
        # svgelements computing something this module's checks let through
        reason = f"{type(error).__name__}: {error}"
        raise InputError(f"svg: cannot read the document: {reason}") from None
    background = scene.background
    if isinstance(background, (LinearGradient, RadialGradient)):
        red, green, blue, _ = background.rgba
        return ParsedSvg(
            geometry.pixel_width,
            geometry.pixel_height,
            (red, green, blue),
            scene.paths,
            background,
            scene.joined,
        )
    return ParsedSvg(
        geometry.pixel_width, geometry.pixel_height, background, scene.paths, joined=scene.joined
    )


# ---------------------------------------------------------------------- XML and canvas
def _parse_xml(text: str) -> ElementTree.Element:
    if "<!ENTITY" in text:
        raise InputError("not valid SVG/XML: entity declarations (<!ENTITY>) are not supported")
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise InputError(f"not valid SVG/XML: {error}") from None
    if _local_name(root.tag) != "svg":
        raise InputError(f"root element is <{_local_name(root.tag)}>, expected <svg>")
    if _is_foreign(root.tag):
        raise InputError(f"root element {root.tag} is not in the SVG namespace ({_SVG_NAMESPACE})")
    _check_depth(root)
    return root


def _check_depth(root: ElementTree.Element) -> None:
    """Refuse documents nested over `_MAX_DEPTH` levels (iteratively: no recursion here)."""
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        if depth > _MAX_DEPTH:
            raise InputError(f"svg: elements are nested over {_MAX_DEPTH} levels deep")
        stack.extend((child, depth + 1) for child in element)


def _local_name(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else str(tag)


def _is_foreign(tag: object) -> bool:
    """Comments, processing instructions and elements in other namespaces (editor metadata)."""
    if not isinstance(tag, str):
        return True
    return tag.startswith("{") and not tag.startswith("{" + _SVG_NAMESPACE + "}")


def _pixel_length(value: str | None, what: str) -> float | None:
    if value is None:
        return None
    match = _PIXEL_LENGTH.match(value)
    if not match or not math.isfinite(float(match.group(1))):
        raise InputError(f"<svg> {what}={value!r}: only plain pixel lengths are supported")
    length = float(match.group(1))
    if length <= 0:
        raise InputError(f"<svg> {what}={value!r}: the canvas needs a positive {what}")
    return length


@dataclass(frozen=True)
class _Geometry:
    """The map from root user units (viewBox) to canvas pixels: ``(p - view) * scale + offset``."""

    pixel_width: int
    pixel_height: int
    view: tuple[float, float, float, float]
    scale: tuple[float, float]
    offset: tuple[float, float]

    @staticmethod
    def of(root: ElementTree.Element) -> _Geometry:
        width = _pixel_length(root.get("width"), "width")
        height = _pixel_length(root.get("height"), "height")
        view_box = root.get("viewBox")
        if view_box is not None:
            try:
                vx, vy, vw, vh = (float(v) for v in re.split(r"[\s,]+", view_box.strip()))
            except ValueError:
                raise InputError(f"<svg> viewBox={view_box!r} is not four numbers") from None
            if not all(math.isfinite(v) for v in (vx, vy, vw, vh)):
                raise InputError(f"<svg> viewBox={view_box!r} is not four finite numbers")
            if vw <= 0 or vh <= 0:
                raise InputError(f"<svg> viewBox={view_box!r} has no area")
        else:
            if width is None or height is None:
                raise InputError("<svg> needs width and height, or a viewBox")
            vx, vy, vw, vh = 0.0, 0.0, width, height
        width = vw if width is None else width
        height = vh if height is None else height
        pixel_width, pixel_height = max(1, round(width)), max(1, round(height))
        scale_x, scale_y = pixel_width / vw, pixel_height / vh
        aspect = (root.get("preserveAspectRatio") or "xMidYMid meet").split() or ["xMidYMid"]
        align = aspect[0]
        offset_x = offset_y = 0.0
        if align != "none" and abs(scale_x - scale_y) > 1e-9 * max(scale_x, scale_y):
            if not re.fullmatch(r"x(Min|Mid|Max)Y(Min|Mid|Max)", align):
                raise InputError(f"<svg> preserveAspectRatio={' '.join(aspect)!r} is not valid")
            scale = min(scale_x, scale_y) if aspect[-1] != "slice" else max(scale_x, scale_y)
            fraction = {"Min": 0.0, "Mid": 0.5, "Max": 1.0}
            offset_x = (pixel_width - vw * scale) * fraction[align[1:4]]
            offset_y = (pixel_height - vh * scale) * fraction[align[5:8]]
            scale_x = scale_y = scale
        return _Geometry(
            pixel_width, pixel_height, (vx, vy, vw, vh), (scale_x, scale_y), (offset_x, offset_y)
        )

    def to_pixels(self, points: np.ndarray) -> np.ndarray:
        result = np.empty_like(points)
        result[:, 0] = (points[:, 0] - self.view[0]) * self.scale[0] + self.offset[0]
        result[:, 1] = (points[:, 1] - self.view[1]) * self.scale[1] + self.offset[1]
        return result


# ---------------------------------------------------------------------- preparing the tree
def _ids(root: ElementTree.Element) -> dict[str, ElementTree.Element]:
    return {element.get("id", ""): element for element in root.iter() if element.get("id")}


def _prepare(
    parent: ElementTree.Element, parent_label: str, ids: dict[str, ElementTree.Element]
) -> None:
    """Label every element, check the syntax svgelements would silently skip, drop non-drawing
    elements."""
    counts: dict[str, int] = {}
    dropped = []
    for child in parent:
        name = _local_name(child.tag)
        counts[name] = counts.get(name, 0) + 1
        label = f"{parent_label}/{name}[{counts[name]}]"
        if child.get("id"):
            label += f" (id={child.get('id')!r})"
        if _is_foreign(child.tag) or name in _DROPPED_TAGS:
            dropped.append(child)
            continue
        child.set(_LABEL, label)
        if child.get("transform") is not None:
            _check_transform(child.get("transform", ""), label)
        for attribute in _LENGTH_ATTRIBUTES.get(name, ()):
            _check_length(child.get(attribute), attribute, label)
        if name == "path":
            _check_path_data(child.get("d", ""), label)
        elif name in ("polygon", "polyline"):
            _check_points(child.get("points", ""), label)
        elif name == "use":
            _check_use_target(child, ids, label)
        _prepare(child, label, ids)
    for child in dropped:
        parent.remove(child)


def _check_length(value: str | None, attribute: str, label: str) -> None:
    if value is None or (attribute in ("rx", "ry") and value.strip() == "auto"):
        return
    match = _LENGTH.match(value)
    if not match:
        if re.match(r"^\s*" + _NUMBER + r"\s*e[mx]\s*$", value):
            raise InputError(f"{label}: {attribute}={value!r}: em and ex lengths are not supported")
        raise InputError(f"{label}: {attribute}={value!r} is not a length")
    if not math.isfinite(float(match.group(1))):
        raise InputError(f"{label}: {attribute}={value!r} is not a finite number")
    if attribute == "r" and match.group(2) == "%":
        raise InputError(f"{label}: a percentage radius is not supported")


def _check_points(value: str, label: str) -> None:
    numbers = re.split(r"[\s,]+", value.strip()) if value.strip() else []
    if any(not re.fullmatch(_NUMBER, number) for number in numbers) or len(numbers) % 2:
        raise InputError(f"{label}: points={value[:40]!r} must be pairs of numbers")
    if not all(math.isfinite(float(number)) for number in numbers):
        raise InputError(f"{label}: non-finite coordinate in points")


def _check_transform(value: str, label: str) -> None:
    position = 0
    while value[position:].strip(" \t\r\n,"):
        match = _TRANSFORM_AT.match(value, position)
        arguments = re.split(r"[\s,]+", match.group(2).strip()) if match else []
        if (
            match is None
            or len(arguments) not in _TRANSFORM_COUNTS[match.group(1)]
            or any(not re.fullmatch(_NUMBER, argument) for argument in arguments)
        ):
            raise InputError(f"{label}: cannot read transform={value!r}")
        position = match.end()


def _check_path_data(data: str, label: str) -> None:
    """Strict path grammar: svgelements stops quietly at the first error and keeps the rest."""
    if not data.strip():
        raise InputError(f"{label}: empty path data")
    position = 0
    while data[position:].strip():
        match = _COMMAND_AT.match(data, position)
        if match is None:
            near = data[position:].strip()[:20]
            raise InputError(f"{label}: cannot parse path data near {near!r}")
        if position == 0 and match.group(1) not in "Mm":
            raise InputError(f"{label}: path data must start with M")
        command, position = match.group(1), match.end()
        count = _ARGUMENT_COUNTS[command.upper()]
        groups = 0
        while count:
            values = []
            for index in range(count):
                pattern = _FLAG_AT if command in "Aa" and index in (3, 4) else _NUMBER_AT
                argument = pattern.match(data, position)
                if argument is None:
                    break
                values.append(float(argument.group(1)))
                position = argument.end()
            if not values and groups:
                break
            if len(values) < count:
                raise InputError(f"{label}: command {command!r} needs {count} numbers")
            if not all(math.isfinite(v) for v in values):
                raise InputError(f"{label}: non-finite coordinate in path data")
            groups += 1


def _check_use_target(
    element: ElementTree.Element, ids: dict[str, ElementTree.Element], label: str
) -> None:
    reference = (element.get("href") or element.get(_XLINK_HREF) or "").strip()
    if not reference.startswith("#"):
        raise InputError(
            f"{label}: <use> must reference an element of this file, got {reference!r}"
        )
    target = ids.get(reference[1:])
    if target is not None and _local_name(target.tag) in ("symbol", "svg"):
        raise InputError(f"{label}: <use> of <{_local_name(target.tag)}> is not supported")


def _check_use_expansion(root: ElementTree.Element) -> None:
    """Refuse circular ``<use>`` references and documents that expand to too many elements."""
    ids = _ids(root)
    sizes: dict[int, int] = {}
    visiting: set[int] = set()

    def size(element: ElementTree.Element) -> int:
        key = id(element)
        if key in sizes:
            return sizes[key]
        if key in visiting:
            raise InputError(f"{element.get(_LABEL, 'svg')}: circular <use> reference")
        visiting.add(key)
        total = 1
        for child in element:  # a loop, not a generator: one frame per level
            total += size(child)
        if _local_name(element.tag) == "use":
            reference = (element.get("href") or element.get(_XLINK_HREF) or "").strip()
            target = ids.get(reference[1:])
            total += size(target) if target is not None else 0
        visiting.discard(key)
        if total > _MAX_ELEMENTS:
            raise InputError(f"svg: <use> references expand to over {_MAX_ELEMENTS} elements")
        sizes[key] = total
        return total

    size(root)


def _parse_with_svgelements(root: ElementTree.Element, geometry: _Geometry) -> Any:
    """svgelements' document in root user units: its own viewport mapping is made the identity
    (the pixel mapping is :class:`_Geometry`'s), with the viewBox size as viewport so percentages
    resolve as in SVG (without a viewBox, svgelements 1.9.6 swaps width and height for them)."""
    _, _, view_width, view_height = geometry.view
    for attribute in ("x", "y", "width", "height", "viewBox", "preserveAspectRatio"):
        root.attrib.pop(attribute, None)
    root.set("width", repr(view_width))
    root.set("height", repr(view_height))
    root.set("viewBox", f"0 0 {view_width!r} {view_height!r}")
    root.set("preserveAspectRatio", "none")
    text = ElementTree.tostring(root, encoding="unicode")
    try:
        return svgelements.SVG.parse(
            io.StringIO(text), reify=False, ppi=96.0, color="black", on_error="raise"
        )
    except (ValueError, TypeError, ArithmeticError, LookupError, AttributeError) as error:
        raise InputError(
            f"svg: cannot read the document: {error or type(error).__name__}"
        ) from None


# ---------------------------------------------------------------------- reading svgelements' tree
@dataclass
class _Scene:
    geometry: _Geometry
    ids: dict[str, ElementTree.Element] = field(default_factory=dict)
    background: tuple[float, float, float] | _Gradient | None = None
    paths: list[tuple[np.ndarray, _Fill]] = field(default_factory=list)
    joined: list[bool] = field(default_factory=list)


def _label(element: Any, use_label: str | None) -> str:
    attributes = element.values.get("attributes", {})
    own = attributes.get(_LABEL) or f"<{_local_name(element.values.get('tag', '?'))}>"
    return own if use_label is None else f"{use_label} -> {own}"


def _read_group(group: Iterable[Any], scene: _Scene, opacity: float, use_label: str | None) -> None:
    parent_values = getattr(group, "values", {})
    for element in group:
        label = _label(element, use_label)
        _resolve_inherit(element, parent_values)
        if isinstance(element, (svgelements.Title, svgelements.Desc)):
            continue
        own_opacity = _opacity(element, opacity, label)
        if isinstance(element, svgelements.Use):
            _read_group(element, scene, own_opacity, label)
        elif isinstance(element, svgelements.SVG):
            raise InputError(f"{label}: nested <svg> elements are not supported")
        elif isinstance(element, svgelements.Group):
            _read_group(element, scene, own_opacity, use_label)
        elif isinstance(element, svgelements.Shape):
            _read_shape(element, scene, own_opacity, label)
        else:
            name = _local_name(element.values.get("tag", type(element).__name__))
            raise InputError(f"{label}: element <{name}> is not supported")


def _resolve_inherit(element: Any, parent_values: dict[str, Any]) -> None:
    """Replace the keyword ``inherit``, which svgelements keeps as text, by the parent's value."""
    values = getattr(element, "values", None)
    if values is None:
        return
    for key, initial in _INHERITED_PROPERTIES.items():
        if str(values.get(key, "")).strip() == "inherit":
            values[key] = parent_values.get(key, initial)


def _opacity(element: Any, inherited: float, label: str) -> float:
    """Check the element's own attributes; the group opacity times its own ``opacity``."""
    attributes: dict[str, str] = element.values.get("attributes", {})
    for name, harmless in _UNSUPPORTED_ATTRIBUTES.items():
        if str(attributes.get(name, harmless)).strip() != harmless:
            raise InputError(f"{label}: attribute {name!r} is not supported")
    return inherited * number(attributes.get("opacity", "1"), label)


def _read_shape(shape: Any, scene: _Scene, opacity: float, label: str) -> None:
    values = shape.values
    if str(values.get("visibility", "visible")).strip() in ("hidden", "collapse"):
        return
    if str(values.get("stroke", "none")).strip() != "none":
        raise InputError(f"{label}: strokes are not supported (only filled paths)")
    if isinstance(shape, svgelements.SimpleLine):
        raise InputError(f"{label}: <line> has no area (only filled shapes are supported)")
    if isinstance(shape, svgelements.Rect) and (shape.rx or shape.ry):
        raise InputError(f"{label}: rounded rectangles are not supported")
    fill = _fill(values, opacity, label, scene, shape.transform)
    # Cubics in the shape's own coordinates, then its transform: svgelements' transformed arcs
    # are wrong under skews (it keeps ellipse axes orthogonal), while cubics map exactly.
    pieces = []
    for segments in _subpaths(shape.segments(transformed=False)):
        local = _cubic_points(segments, label)
        points = scene.geometry.to_pixels(_affine(shape.transform, local))
        if not np.all(np.isfinite(points)):
            raise InputError(f"{label}: non-finite coordinates")
        pieces.append(points)
    if not pieces:
        raise InputError(f"{label}: path has no segments")
    opaque = fill[3] >= 1.0 if isinstance(fill, tuple) else fill.opaque
    if len(pieces) > 1 and not ((opaque and one_way_round(pieces)) or pieces_apart(pieces)):
        raise InputError(
            f"{label}: subpaths of one <path> that overlap (holes) are not supported; "
            "split them into separate paths"
        )
    if (
        len(pieces) == 1
        and isinstance(shape, svgelements.Rect)
        and not scene.paths
        and scene.background is None
        and opaque
        and _covers_canvas(pieces[0], scene.geometry)
    ):
        scene.background = (fill[0], fill[1], fill[2]) if isinstance(fill, tuple) else fill
        return
    for index, points in enumerate(pieces):
        scene.paths.append((points, fill))
        scene.joined.append(index > 0)


def _covers_canvas(points: np.ndarray, geometry: _Geometry) -> bool:
    """Whether four straight segments form an axis-aligned box covering the canvas to 0.5 px."""
    if points.shape != (12, 2):
        return False
    corners = points[[0, 3, 6, 9]]
    tolerance = 1e-9 * (1.0 + float(np.max(np.abs(corners))))
    aligned = (
        abs(corners[0, 1] - corners[1, 1]) <= tolerance
        and abs(corners[1, 0] - corners[2, 0]) <= tolerance
        and abs(corners[2, 1] - corners[3, 1]) <= tolerance
        and abs(corners[3, 0] - corners[0, 0]) <= tolerance
    )
    low, high = corners.min(axis=0), corners.max(axis=0)
    return bool(
        aligned
        and low[0] <= 0.5
        and low[1] <= 0.5
        and high[0] >= geometry.pixel_width - 0.5
        and high[1] >= geometry.pixel_height - 0.5
    )


# ---------------------------------------------------------------------- fills
def _fill(
    values: dict[str, Any], opacity: float, label: str, scene: _Scene, transform: Any
) -> _Fill:
    """The element's resolved fill (svgelements has applied CSS, ``style`` and inheritance): RGBA,
    or a gradient paint in canvas pixels."""
    colour_text = str(values.get("fill", "black")).strip()
    reference = _URL.fullmatch(colour_text)
    if reference is not None:
        target = scene.ids.get(reference.group(1))
        if target is None or _local_name(target.tag) not in ("linearGradient", "radialGradient"):
            raise InputError(f"{label}: fill={colour_text!r} names no gradient")
        _check_fill_rule(values, label)
        alpha = number(values.get("fill-opacity", "1"), label) * opacity
        alpha = min(max(alpha, 0.0), 1.0)
        return gradient_paint(
            target, _user_to_pixels(transform, scene.geometry), alpha, label, _colour
        )
    if colour_text == "none" or colour_text.startswith("url("):
        raise InputError(f"{label}: fill={colour_text!r} is not supported (only solid fills)")
    _check_fill_rule(values, label)
    red, green, blue, alpha = _colour(colour_text, label)
    alpha *= number(values.get("fill-opacity", "1"), label) * opacity
    return (red, green, blue, min(max(alpha, 0.0), 1.0))


def _check_fill_rule(values: dict[str, Any], label: str) -> None:
    fill_rule = str(values.get("fill-rule", "nonzero")).strip()
    if fill_rule != "nonzero":
        raise InputError(f"{label}: fill-rule={fill_rule!r} is not supported")


def _user_to_pixels(transform: Any, geometry: _Geometry) -> tuple[np.ndarray, np.ndarray]:
    """(linear, shift): a shape's user units to canvas pixels, ``x ↦ linear @ x + shift``."""
    scale = np.diag(geometry.scale)
    linear = scale @ np.array([[transform.a, transform.c], [transform.b, transform.d]], float)
    shift = scale @ (np.array([transform.e, transform.f], float) - geometry.view[:2])
    return linear, shift + np.asarray(geometry.offset)


def _colour(text: str, label: str) -> _Rgba:
    """RGBA of a CSS colour. svgelements turns unknown text into black (and has aliceblue wrong),
    so names come from Pillow's CSS table and other syntax must match svgelements' patterns."""
    from PIL import ImageColor

    name = text.replace(" ", "").lower()
    if name == "transparent":
        return (0.0, 0.0, 0.0, 0.0)
    if name in ImageColor.colormap:
        red, green, blue = ImageColor.getrgb(name)[:3]
        return (red / 255.0, green / 255.0, blue / 255.0, 1.0)
    if _HEX_COLOUR.match(text):
        colour = svgelements.Color(text)
        return (colour.red / 255.0, colour.green / 255.0, colour.blue / 255.0, colour.alpha / 255.0)
    for pattern in (
        svgelements.REGEX_COLOR_RGB,
        svgelements.REGEX_COLOR_RGB_PERCENT,
        svgelements.REGEX_COLOR_HSL,
    ):
        match = pattern.fullmatch(text)
        if match:
            colour = svgelements.Color(text)
            # Alpha from the text itself: svgelements keeps only 8 bits of it.
            alpha = 1.0 if match.group(4) is None else min(max(float(match.group(4)), 0.0), 1.0)
            return (colour.red / 255.0, colour.green / 255.0, colour.blue / 255.0, alpha)
    raise InputError(f"{label}: cannot read fill colour {text!r}")


# ---------------------------------------------------------------------- segments to cubics
def _subpaths(segments: Iterable[Any]) -> list[list[Any]]:
    """svgelements segments cut before every move: one list per subpath."""
    found: list[list[Any]] = []
    for segment in segments:
        if isinstance(segment, svgelements.Move) or not found:
            found.append([])
        found[-1].append(segment)
    return found


def _cubic_points(segments: Iterable[Any], label: str) -> np.ndarray:
    """One closed subpath of svgelements segments as (3K, 2) cubic control points."""
    several = f"{label}: a subpath after z must start with M"
    rows: list[tuple[float, float]] = []
    start: tuple[float, float] | None = None
    current = (0.0, 0.0)
    closed = False
    previous: Any = None
    previous_quad_control: tuple[float, float] | None = None
    for segment in segments:
        if isinstance(segment, svgelements.Move):
            if start is not None:
                raise InputError(several)
            start = current = _xy(segment.end)
            continue
        if start is None:
            raise InputError(f"{label}: path data must start with M")
        end = _xy(segment.end)
        if isinstance(segment, svgelements.Close):
            if not closed and _far(current, start):
                rows.extend(_line(current, start))
            closed, current = True, start
            continue
        if closed:
            raise InputError(several)
        # svgelements reflects the previous curve's control for S and T whatever that curve was;
        # SVG reflects only a cubic's for S and a quadratic's for T, else uses the current point.
        quad_control = None
        if isinstance(segment, svgelements.CubicBezier):
            wrongly_reflected = segment.smooth and not isinstance(previous, svgelements.CubicBezier)
            control1 = current if wrongly_reflected else _xy(segment.control1)
            rows.extend([current, control1, _xy(segment.control2)])
        elif isinstance(segment, svgelements.QuadraticBezier):
            quad_control = _xy(segment.control)
            if segment.smooth:
                quad_control = current
                if previous_quad_control is not None:
                    quad_control = (
                        2.0 * current[0] - previous_quad_control[0],
                        2.0 * current[1] - previous_quad_control[1],
                    )
            rows.extend(_quadratic(current, quad_control, end))
        elif isinstance(segment, svgelements.Arc):
            cubics = list(segment.as_cubic_curves())
            if not cubics and _far(current, end):
                rows.extend(_line(current, end))  # a radius of zero: a straight line
            for index, cubic in enumerate(cubics):
                piece_start = current if index == 0 else _xy(cubic.start)
                rows.extend([piece_start, _xy(cubic.control1), _xy(cubic.control2)])
        elif isinstance(segment, svgelements.Line):
            rows.extend(_line(current, end))
        else:
            raise InputError(f"{label}: unexpected path segment {type(segment).__name__}")
        current, previous, previous_quad_control = end, segment, quad_control
    if start is None or not rows:
        raise InputError(f"{label}: path has no segments")
    if not closed and _far(current, start):
        rows.extend(_line(current, start))
    return np.array(rows, dtype=np.float64)


def _affine(matrix: Any, points: np.ndarray) -> np.ndarray:
    """``points`` mapped by an svgelements Matrix: (a x + c y + e, b x + d y + f)."""
    a, b, c, d, e, f = (float(getattr(matrix, name)) for name in "abcdef")
    if (a, b, c, d, e, f) == (1.0, 0.0, 0.0, 1.0, 0.0, 0.0):
        return points
    result = np.empty_like(points)
    with np.errstate(invalid="ignore", over="ignore"):  # non-finite results are refused later
        result[:, 0] = a * points[:, 0] + c * points[:, 1] + e
        result[:, 1] = b * points[:, 0] + d * points[:, 1] + f
    return result


def _xy(point: Any) -> tuple[float, float]:
    return (float(point.x), float(point.y))


def _far(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return max(abs(a[0] - b[0]), abs(a[1] - b[1])) > _CLOSE_TOLERANCE


def _line(start: tuple[float, float], end: tuple[float, float]) -> list[tuple[float, float]]:
    """A straight segment as a cubic with its controls at one and two thirds."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    return [
        start,
        (start[0] + dx / 3.0, start[1] + dy / 3.0),
        (start[0] + 2.0 * dx / 3.0, start[1] + 2.0 * dy / 3.0),
    ]


def _quadratic(
    start: tuple[float, float], control: tuple[float, float], end: tuple[float, float]
) -> list[tuple[float, float]]:
    """The exact cubic of a quadratic: controls two thirds of the way to the quadratic control."""
    third = 2.0 / 3.0
    return [
        start,
        (start[0] + third * (control[0] - start[0]), start[1] + third * (control[1] - start[1])),
        (end[0] + third * (control[0] - end[0]), end[1] + third * (control[1] - end[1])),
    ]
