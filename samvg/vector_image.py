"""The scene model: a canvas with an optional background and closed cubic Bézier paths, read from
and written to SVG.

A path with K segments holds 3K control points; segment k runs from ``points[3k]`` through
``points[3k+1]`` and ``points[3k+2]`` to ``points[(3k+3) % 3K]``, so the last segment returns to
the first point. Fills are straight (non-premultiplied) RGBA with the nonzero rule; paint order is
list order, bottom first.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from samvg.errors import InputError
from samvg.io import atomic_write_text

SVG_NAMESPACE = "http://www.w3.org/2000/svg"
_CLOSE_TOLERANCE = 1e-6
_PASS_THROUGH_TAGS = {"title", "desc", "metadata", "defs", "style"}


@dataclass
class VectorPath:
    """A closed piecewise-cubic path: ``points`` (3K, 2) in pixels, RGBA ``fill`` in [0, 1]."""

    points: np.ndarray
    fill: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3 or points.shape[0] % 3:
            raise InputError(f"path points must have shape (3K, 2) with K >= 1, got {points.shape}")
        self.points = points
        fill = tuple(float(value) for value in self.fill)
        if len(fill) == 3:
            fill = (*fill, 1.0)
        if len(fill) != 4 or not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in fill):
            raise InputError(f"path fill must be RGBA values in [0, 1], got {self.fill}")
        self.fill = fill  # type: ignore[assignment]

    @property
    def num_segments(self) -> int:
        return self.points.shape[0] // 3


@dataclass
class VectorImage:
    """A canvas of ``width`` × ``height`` pixels, an optional opaque background, and paths."""

    width: int
    height: int
    paths: list[VectorPath] = field(default_factory=list)
    background: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        for name in ("width", "height"):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or value < 1:
                raise InputError(f"canvas {name} must be a positive integer, got {value!r}")
            setattr(self, name, int(value))
        if self.background is not None:
            background = tuple(float(v) for v in self.background)
            if len(background) != 3 or not all(0.0 <= v <= 1.0 for v in background):
                raise InputError(f"background must be RGB values in [0, 1], got {self.background}")
            self.background = background  # type: ignore[assignment]
        self.paths = list(self.paths)

    # ------------------------------------------------------------------ output
    def to_svg(self, precision: int = 2) -> str:
        """SVG text: width, height, viewBox, an optional background rect and one path each."""
        lines = [
            f'<svg xmlns="{SVG_NAMESPACE}" width="{self.width}" height="{self.height}" '
            f'viewBox="0 0 {self.width} {self.height}">'
        ]
        if self.background is not None:
            lines.append(
                f'<rect width="{self.width}" height="{self.height}" '
                f'fill="{_hex_colour(self.background)}"/>'
            )
        for path in self.paths:
            opacity = path.fill[3]
            opacity_attribute = "" if opacity >= 1.0 else f' fill-opacity="{_number(opacity, 3)}"'
            lines.append(
                f'<path d="{_path_data(path.points, precision)}" '
                f'fill="{_hex_colour(path.fill[:3])}"{opacity_attribute}/>'
            )
        lines.append("</svg>")
        return "\n".join(lines) + "\n"

    def save(self, path: str | os.PathLike[str], precision: int = 2) -> None:
        """Write :meth:`to_svg` to ``path`` atomically (temporary file, then rename)."""
        atomic_write_text(path, self.to_svg(precision))

    def render(self, scale: float = 1.0) -> np.ndarray:
        """Rasterize to a float32 (H, W, 3) array in [0, 1]; no background means white."""
        from samvg.render import render_array

        if not (math.isfinite(scale) and scale > 0):
            raise InputError(f"render scale must be a positive number, got {scale}")
        width = max(1, round(self.width * scale))
        height = max(1, round(self.height * scale))
        background = self.background if self.background is not None else (1.0, 1.0, 1.0)
        points, colours = self.stacked_paths()
        return render_array(points * scale, colours, width, height, background=background)

    def stacked_paths(self) -> tuple[np.ndarray, np.ndarray]:
        """All paths as arrays (P, 3K, 2) and RGBA (P, 4) for the rasterizer.

        Paths with fewer segments are padded with zero-length segments at their first point,
        which leaves their shape unchanged.
        """
        if not self.paths:
            return np.zeros((0, 3, 2)), np.zeros((0, 4))
        most = max(path.num_segments for path in self.paths)
        stacked = np.empty((len(self.paths), 3 * most, 2))
        for index, path in enumerate(self.paths):
            padding = 3 * (most - path.num_segments)
            stacked[index, :padding] = path.points[0]
            stacked[index, padding:] = path.points
        colours = np.array([path.fill for path in self.paths], dtype=np.float64)
        return stacked, colours

    # ------------------------------------------------------------------ input
    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> VectorImage:
        """Read an SVG file (see :meth:`from_svg`)."""
        source = Path(path)
        if not source.is_file():
            raise InputError(f"SVG file not found: {source}")
        try:
            text = source.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise InputError(f"cannot read SVG {source}: {error}") from None
        return cls.from_svg(text)

    @classmethod
    def from_svg(cls, text: str) -> VectorImage:
        """Parse SVG made of closed, filled paths (M/L/H/V/C/S/Q/T/Z, absolute or relative).

        A full-canvas ``<rect>`` drawn first becomes the background; other rects become paths.
        Elements or attributes this model cannot represent raise :class:`InputError` naming them.
        """
        try:
            root = ElementTree.fromstring(text)
        except ElementTree.ParseError as error:
            raise InputError(f"not valid SVG/XML: {error}") from None
        if _local_name(root.tag) != "svg":
            raise InputError(f"root element is <{_local_name(root.tag)}>, expected <svg>")
        width, height, to_pixels = _canvas_geometry(root)
        image = cls(width=width, height=height)
        _read_children(root, image, to_pixels, inherited={}, element_path="svg")
        return image


# ---------------------------------------------------------------------- formatting helpers
def _number(value: float, precision: int) -> str:
    text = f"{value:.{precision}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    if text in ("-0", ""):
        text = "0"
    return text


def _hex_colour(rgb) -> str:  # type: ignore[no-untyped-def]
    return "#" + "".join(f"{round(min(max(c, 0.0), 1.0) * 255):02x}" for c in rgb)


def _path_data(points: np.ndarray, precision: int) -> str:
    def pair(p: np.ndarray) -> str:
        return f"{_number(p[0], precision)} {_number(p[1], precision)}"

    count = points.shape[0]
    parts = [f"M{pair(points[0])}"]
    for k in range(count // 3):
        c1, c2, end = points[3 * k + 1], points[3 * k + 2], points[(3 * k + 3) % count]
        parts.append(f"C{pair(c1)} {pair(c2)} {pair(end)}")
    parts.append("Z")
    return "".join(parts)


# ---------------------------------------------------------------------- parsing helpers
def _local_name(tag: str) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else str(tag)


_LENGTH = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(px)?\s*$")


def _length(value: str | None, what: str) -> float | None:
    if value is None:
        return None
    match = _LENGTH.match(value)
    if not match:
        raise InputError(f"<svg> {what}={value!r}: only plain pixel lengths are supported")
    return float(match.group(1))


def _canvas_geometry(root: ElementTree.Element):  # type: ignore[no-untyped-def]
    width = _length(root.get("width"), "width")
    height = _length(root.get("height"), "height")
    view_box = root.get("viewBox")
    if view_box is not None:
        try:
            vx, vy, vw, vh = (float(v) for v in re.split(r"[\s,]+", view_box.strip()))
        except ValueError:
            raise InputError(f"<svg> viewBox={view_box!r} is not four numbers") from None
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
    aspect = (root.get("preserveAspectRatio") or "xMidYMid meet").split()
    if aspect[0] != "none" and abs(scale_x - scale_y) > 1e-9 * max(scale_x, scale_y):
        scale = min(scale_x, scale_y) if aspect[-1] != "slice" else max(scale_x, scale_y)
        offset_x = (pixel_width - vw * scale) / 2
        offset_y = (pixel_height - vh * scale) / 2
        scale_x = scale_y = scale
    else:
        offset_x = offset_y = 0.0

    def to_pixels(points: np.ndarray) -> np.ndarray:
        result = np.empty_like(points)
        result[:, 0] = (points[:, 0] - vx) * scale_x + offset_x
        result[:, 1] = (points[:, 1] - vy) * scale_y + offset_y
        return result

    return pixel_width, pixel_height, to_pixels


def _style_attributes(element: ElementTree.Element) -> dict[str, str]:
    attributes = {key: value for key, value in element.attrib.items()}
    style = attributes.pop("style", None)
    if style:
        for declaration in style.split(";"):
            if ":" in declaration:
                key, value = declaration.split(":", 1)
                attributes[key.strip()] = value.strip()
    return attributes


_UNSUPPORTED_ATTRIBUTES = ("transform", "clip-path", "mask", "filter")


def _read_children(
    parent: ElementTree.Element,
    image: VectorImage,
    to_pixels,  # type: ignore[no-untyped-def]
    inherited: dict[str, str],
    element_path: str,
) -> None:
    counts: dict[str, int] = {}
    for child in parent:
        name = _local_name(child.tag)
        counts[name] = counts.get(name, 0) + 1
        label = f"{element_path}/{name}[{counts[name]}]"
        if child.get("id"):
            label += f" (id={child.get('id')!r})"
        if not isinstance(child.tag, str) or name in _PASS_THROUGH_TAGS:
            continue
        if child.tag.startswith("{") and not child.tag.startswith("{" + SVG_NAMESPACE + "}"):
            continue  # editor metadata in a foreign namespace (e.g. Inkscape's namedview)
        attributes = _style_attributes(child)
        for unsupported in _UNSUPPORTED_ATTRIBUTES:
            if unsupported in attributes:
                raise InputError(f"{label}: attribute {unsupported!r} is not supported")
        if attributes.get("stroke", "none") != "none":
            raise InputError(f"{label}: strokes are not supported (only filled paths)")
        merged = {**inherited, **{k: v for k, v in attributes.items() if k.startswith("fill")}}
        if "opacity" in attributes:
            merged["opacity"] = str(
                float(inherited.get("opacity", "1")) * _float(attributes["opacity"], label)
            )
        if name == "g":
            _read_children(child, image, to_pixels, merged, label)
        elif name == "path":
            points = _parse_path_data(attributes.get("d", ""), label)
            image.paths.append(VectorPath(to_pixels(points), _fill(merged, label)))
        elif name == "rect":
            _read_rect(child, attributes, merged, image, to_pixels, label)
        else:
            raise InputError(f"{label}: element <{name}> is not supported")


def _float(text: str, label: str) -> float:
    try:
        value = float(text.strip().rstrip("%")) / (100.0 if text.strip().endswith("%") else 1.0)
    except ValueError:
        raise InputError(f"{label}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise InputError(f"{label}: {text!r} is not a finite number")
    return value


def _fill(attributes: dict[str, str], label: str) -> tuple[float, float, float, float]:
    from PIL import ImageColor

    colour_text = attributes.get("fill", "black").strip()
    if colour_text == "none" or colour_text.startswith("url("):
        raise InputError(f"{label}: fill={colour_text!r} is not supported (only solid fills)")
    try:
        rgb = ImageColor.getrgb(colour_text)[:3]
    except ValueError:
        raise InputError(f"{label}: cannot read fill colour {colour_text!r}") from None
    opacity = _float(attributes.get("fill-opacity", "1"), label)
    opacity *= _float(attributes.get("opacity", "1"), label)
    if attributes.get("fill-rule", "nonzero") != "nonzero":
        raise InputError(f"{label}: fill-rule={attributes['fill-rule']!r} is not supported")
    return (rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0, min(max(opacity, 0.0), 1.0))


def _read_rect(element, attributes, merged, image, to_pixels, label) -> None:  # type: ignore[no-untyped-def]
    if any(float(attributes.get(key, "0") or 0) != 0 for key in ("rx", "ry")):
        raise InputError(f"{label}: rounded rectangles are not supported")
    x = _float(attributes.get("x", "0"), label)
    y = _float(attributes.get("y", "0"), label)
    corners_view = np.array([[x, y]], dtype=np.float64)
    width_text, height_text = attributes.get("width", "0"), attributes.get("height", "0")
    full_width = width_text.strip() == "100%"
    full_height = height_text.strip() == "100%"
    top_left = to_pixels(corners_view)[0]
    if full_width or full_height:
        bottom_right = np.array([float(image.width), float(image.height)])
    else:
        w, h = _float(width_text, label), _float(height_text, label)
        bottom_right = to_pixels(np.array([[x + w, y + h]]))[0]
    fill = _fill(merged, label)
    covers_canvas = (
        top_left[0] <= 0.5
        and top_left[1] <= 0.5
        and bottom_right[0] >= image.width - 0.5
        and bottom_right[1] >= image.height - 0.5
    )
    if covers_canvas and not image.paths and image.background is None and fill[3] >= 1.0:
        image.background = fill[:3]
        return
    (x0, y0), (x1, y1) = top_left, bottom_right
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    segments = [(corners[i], corners[(i + 1) % 4]) for i in range(4)]
    image.paths.append(VectorPath(_lines_to_points(segments), fill))


def _lines_to_points(segments) -> np.ndarray:  # type: ignore[no-untyped-def]
    points = []
    for start, end in segments:
        start, end = np.asarray(start, float), np.asarray(end, float)
        points.extend([start, start + (end - start) / 3.0, start + 2.0 * (end - start) / 3.0])
    return np.array(points, dtype=np.float64)


_TOKEN = re.compile(r"[MmLlHhVvCcSsQqTtZzAa]|[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_ARGUMENT_COUNTS = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "Z": 0, "A": 7}


def _parse_path_data(data: str, label: str) -> np.ndarray:
    """Parse path data of one closed subpath into (3K, 2) cubic control points."""
    leftover = _TOKEN.sub(" ", data).replace(",", " ").strip()
    if leftover:
        raise InputError(f"{label}: cannot parse path data near {leftover[:20]!r}")
    tokens = _TOKEN.findall(data)
    if not tokens:
        raise InputError(f"{label}: empty path data")
    segments: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
    current = np.zeros(2)
    start: np.ndarray | None = None
    last_cubic_control: np.ndarray | None = None
    last_quad_control: np.ndarray | None = None
    closed = False
    index = 0
    command = ""
    while index < len(tokens):
        token = tokens[index]
        if token.isalpha():
            command = token
            index += 1
        elif not command:
            raise InputError(f"{label}: path data must start with a command")
        upper = command.upper()
        if upper == "A":
            raise InputError(f"{label}: arc commands (A) are not supported")
        count = _ARGUMENT_COUNTS[upper]
        if closed and upper != "Z":
            raise InputError(
                f"{label}: several subpaths in one <path> are not supported; "
                "split them into separate paths"
            )
        arguments = tokens[index : index + count]
        if len(arguments) < count or any(a.isalpha() for a in arguments):
            raise InputError(f"{label}: command {command!r} needs {count} numbers")
        values = np.array([float(a) for a in arguments], dtype=np.float64)
        if not np.all(np.isfinite(values)):
            raise InputError(f"{label}: non-finite coordinate in path data")
        index += count
        relative = command.islower()
        base = current if relative else np.zeros(2)
        cubic_control: np.ndarray | None = None
        quad_control: np.ndarray | None = None
        if upper == "M":
            if start is not None:
                raise InputError(
                    f"{label}: several subpaths in one <path> are not supported; "
                    "split them into separate paths"
                )
            current = base + values
            start = current.copy()
            command = "l" if relative else "L"
            continue
        if start is None:
            raise InputError(f"{label}: path data must start with M")
        if upper == "Z":
            closed = True
            command = ""
            continue
        if upper in ("L", "H", "V"):
            if upper == "L":
                end = base + values
            elif upper == "H":
                end = np.array([values[0] + (current[0] if relative else 0.0), current[1]])
            else:
                end = np.array([current[0], values[0] + (current[1] if relative else 0.0)])
            segments.append(_line(current, end))
        elif upper in ("C", "S"):
            if upper == "C":
                c1, c2, end = base + values[0:2], base + values[2:4], base + values[4:6]
            else:
                c1 = 2 * current - last_cubic_control if last_cubic_control is not None else current
                c2, end = base + values[0:2], base + values[2:4]
            segments.append((current.copy(), c1, c2, end))
            cubic_control = c2
        else:
            if upper == "Q":
                q, end = base + values[0:2], base + values[2:4]
            else:
                q = 2 * current - last_quad_control if last_quad_control is not None else current
                end = base + values[0:2]
            segments.append(
                (
                    current.copy(),
                    current + 2.0 / 3.0 * (q - current),
                    end + 2.0 / 3.0 * (q - end),
                    end,
                )
            )
            quad_control = q
        current = segments[-1][3]
        last_cubic_control, last_quad_control = cubic_control, quad_control
    if start is None or not segments:
        raise InputError(f"{label}: path has no segments")
    if np.max(np.abs(current - start)) > _CLOSE_TOLERANCE:
        segments.append(_line(current, start))
    points = []
    for segment_start, c1, c2, _ in segments:
        points.extend([segment_start, c1, c2])
    return np.array(points, dtype=np.float64)


def _line(start: np.ndarray, end: np.ndarray):  # type: ignore[no-untyped-def]
    return (
        start.copy(),
        start + (end - start) / 3.0,
        start + 2.0 * (end - start) / 3.0,
        end.copy(),
    )
