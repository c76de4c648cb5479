"""The scene: the one type every stage takes and returns.

Closed cubic Bézier paths, each with its own number of segments and its own paint, over an
optional opaque background, in *working* pixels (the canvas the pipeline computes on), with the
frame that maps them back to the input image held once.

Geometry is packed for the numba kernels and for Adam: ``points`` is one (N, 2) float64 array
of every path's control points in paint order (bottom first) and ``offsets`` (P + 1) marks where
each path starts. A path with K segments owns 3K points; segment k runs from ``p[3k]`` through
``p[3k+1]`` and ``p[3k+2]`` to ``p[(3k+3) % 3K]``, so the last segment returns to the first
point. Pixel (row r, column c) is the square [c, c+1] × [r, r+1].

Paints are immutable values, one per path: a flat RGBA fill, or a linear or radial gradient
(2 to 4 stops, geometry in the scene's pixels, one opacity for the whole fill). Every paint has
``rgba``, a flat stand-in (its mean stop colour) for the steps that compare fills by colour.

The background is an opaque RGB colour, or an opaque linear or radial gradient
(``background_gradient``); with a gradient, ``background`` holds its flat stand-in.

An SVG ``<path>`` element may hold several paths: a path ``joined`` to the one below it, with the
same paint, is one more subpath of that element (a compound path, as Illustrator and VTracer
write one shape of one fill in several pieces). The element paints what its paths paint one by
one: opaque pieces may overlap, translucent ones may not (`samvg.finish.compound`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from samvg.errors import InputError

RGB = tuple[float, float, float]
RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class FlatPaint:
    """A solid fill: straight (non-premultiplied) RGBA in [0, 1], nonzero fill rule."""

    rgba: RGBA

    def __post_init__(self) -> None:
        values = tuple(float(value) for value in self.rgba)
        if len(values) == 3:
            values = (*values, 1.0)
        if len(values) != 4 or not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in values):
            raise InputError(f"fill must be RGBA values in [0, 1], got {self.rgba}")
        object.__setattr__(self, "rgba", values)

    @property
    def parameter_count(self) -> int:
        return 4

    @property
    def opaque(self) -> bool:
        return self.rgba[3] >= 1.0

    def scaled(self, _factor: float) -> FlatPaint:
        """The paint on a canvas scaled by ``factor`` (a flat fill has no geometry)."""
        return self

    def shifted(self, _dx: float, _dy: float) -> FlatPaint:
        """The paint with the canvas origin moved (a flat fill has no geometry)."""
        return self


Stop = tuple[float, RGB]
"""A gradient stop: offset in [0, 1] and RGB in [0, 1]."""
MAX_STOPS = 4


def _check_stops(stops: Sequence[tuple[float, Sequence[float]]]) -> tuple[Stop, ...]:
    checked: list[Stop] = []
    for offset, rgb in stops:
        colour = tuple(float(value) for value in rgb)
        if len(colour) != 3 or not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in colour):
            raise InputError(f"gradient stop colours must be RGB values in [0, 1], got {rgb}")
        checked.append((float(offset), (colour[0], colour[1], colour[2])))
    offsets = [offset for offset, _ in checked]
    if not 2 <= len(checked) <= MAX_STOPS:
        raise InputError(f"a gradient needs 2 to {MAX_STOPS} stops, got {len(checked)}")
    if not all(math.isfinite(o) and 0.0 <= o <= 1.0 for o in offsets) or offsets != sorted(offsets):
        raise InputError(f"gradient stop offsets must rise within [0, 1], got {offsets}")
    return tuple(checked)


def _check_opacity(opacity: float) -> float:
    value = float(opacity)
    if not (math.isfinite(value) and 0.0 <= value <= 1.0):
        raise InputError(f"fill opacity must be in [0, 1], got {opacity}")
    return value


def _check_point(point: Sequence[float], name: str) -> tuple[float, float]:
    values = tuple(float(v) for v in point)
    if len(values) != 2 or not all(math.isfinite(v) for v in values):
        raise InputError(f"gradient {name} must be two finite numbers, got {point}")
    return (values[0], values[1])


@dataclass(frozen=True)
class _Gradient:
    stops: tuple[Stop, ...]
    opacity: float = 1.0

    @property
    def rgba(self) -> RGBA:
        """The mean of the stop colours, with the opacity: a flat stand-in for this paint."""
        mean = np.mean([rgb for _, rgb in self.stops], axis=0)
        return (float(mean[0]), float(mean[1]), float(mean[2]), self.opacity)

    @property
    def opaque(self) -> bool:
        return self.opacity >= 1.0

    @property
    def parameter_count(self) -> int:
        """Geometry, then an offset and RGB per stop, and the opacity."""
        return 4 * len(self.stops) + 1 + self.geometry_count

    geometry_count = 4


@dataclass(frozen=True)
class LinearGradient(_Gradient):
    """Colours along the vector ``start`` → ``end`` (SVG ``linearGradient``, userSpaceOnUse,
    pad)."""

    start: tuple[float, float] = (0.0, 0.0)
    end: tuple[float, float] = (1.0, 0.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "stops", _check_stops(self.stops))
        object.__setattr__(self, "opacity", _check_opacity(self.opacity))
        object.__setattr__(self, "start", _check_point(self.start, "start"))
        object.__setattr__(self, "end", _check_point(self.end, "end"))

    def scaled(self, factor: float) -> LinearGradient:
        start = (self.start[0] * factor, self.start[1] * factor)
        return replace(self, start=start, end=(self.end[0] * factor, self.end[1] * factor))

    def shifted(self, dx: float, dy: float) -> LinearGradient:
        start = (self.start[0] + dx, self.start[1] + dy)
        return replace(self, start=start, end=(self.end[0] + dx, self.end[1] + dy))


@dataclass(frozen=True)
class RadialGradient(_Gradient):
    """Colours by distance from ``centre`` over ``radius`` (SVG ``radialGradient``, focal point
    at the centre, userSpaceOnUse, pad)."""

    centre: tuple[float, float] = (0.0, 0.0)
    radius: float = 1.0
    geometry_count = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "stops", _check_stops(self.stops))
        object.__setattr__(self, "opacity", _check_opacity(self.opacity))
        object.__setattr__(self, "centre", _check_point(self.centre, "centre"))
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise InputError(f"gradient radius must be a positive number, got {self.radius}")
        object.__setattr__(self, "radius", float(self.radius))

    def scaled(self, factor: float) -> RadialGradient:
        centre = (self.centre[0] * factor, self.centre[1] * factor)
        return replace(self, centre=centre, radius=self.radius * factor)

    def shifted(self, dx: float, dy: float) -> RadialGradient:
        return replace(self, centre=(self.centre[0] + dx, self.centre[1] + dy))


Paint = FlatPaint | LinearGradient | RadialGradient
"""Every paint a path can have."""
BackgroundGradient = LinearGradient | RadialGradient
"""What a background can be besides a flat colour (opaque)."""


@dataclass(frozen=True)
class Frame:
    """Where the working canvas sits in the input image: input pixels = working pixels / scale,
    on an input canvas of ``width`` × ``height`` pixels."""

    width: int
    height: int
    scale: float = 1.0


def _check_background(background: Sequence[float] | None) -> RGB | None:
    if background is None:
        return None
    values = tuple(float(v) for v in background)
    if len(values) != 3 or not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in values):
        raise InputError(f"background must be RGB values in [0, 1], got {background}")
    return (values[0], values[1], values[2])


def _check_background_gradient(gradient: object) -> BackgroundGradient | None:
    if gradient is None:
        return None
    if not isinstance(gradient, (LinearGradient, RadialGradient)):
        raise InputError(
            f"a background gradient must be a linear or radial gradient, got {gradient!r}"
        )
    if not gradient.opaque:
        raise InputError(f"a background gradient must be opaque, got opacity {gradient.opacity}")
    return gradient


def _pack(paths: Sequence[tuple[np.ndarray, Paint]]) -> tuple[np.ndarray, np.ndarray]:
    """Packed (N, 2) points and (P + 1) offsets of (points (3K, 2), paint) pairs."""
    arrays = [np.asarray(points, dtype=np.float64) for points, _ in paths]
    for index, array in enumerate(arrays):
        if array.ndim != 2 or array.shape[1] != 2 or array.shape[0] < 3 or array.shape[0] % 3:
            raise InputError(
                f"path {index} points must have shape (3K, 2) with K >= 1, got {array.shape}"
            )
    counts = [len(array) for array in arrays]
    points = np.concatenate(arrays) if arrays else np.zeros((0, 2))
    return points, np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)


def _flat_paints(colours: np.ndarray) -> tuple[Paint, ...]:
    """Flat fills of RGBA ``colours`` (P, 4), clipped to [0, 1]."""
    clipped = np.clip(np.asarray(colours, dtype=np.float64), 0.0, 1.0)
    return tuple(FlatPaint(tuple(row)) for row in clipped.reshape(-1, 4))


def _check_canvas(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"canvas {name} must be a positive integer, got {value!r}")
    return int(value)


@dataclass(frozen=True, eq=False)
class Scene:
    """Paths with paints on a ``width`` × ``height`` canvas (see the module docstring)."""

    width: int
    height: int
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(1, dtype=np.int64))
    paints: tuple[Paint, ...] = ()
    background: RGB | None = None
    frame: Frame | None = None
    """The input canvas; None when the scene is already in input pixels."""
    background_gradient: BackgroundGradient | None = None
    """An opaque gradient drawn behind the paths; ``background`` is then its flat stand-in (the
    mean stop colour), whatever was given."""
    fixed: np.ndarray | None = None
    """(P,) bool: paths whose outline a fit leaves as traced (only their paint is fitted), or
    None for none. Kept by `with_geometry`, `stacked` and `subset`; new paths start free."""

    joined: np.ndarray | None = None
    """(P,) bool: paths that are one more subpath of the SVG element of the path below them
    (see the module docstring), or None for none. Kept by `with_geometry`, `stacked` and
    `subset` (while the path below stays); new paths start on their own."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", _check_canvas(self.width, "width"))
        object.__setattr__(self, "height", _check_canvas(self.height, "height"))
        points = np.ascontiguousarray(self.points, dtype=np.float64)
        offsets = np.asarray(self.offsets, dtype=np.int64)
        if points.ndim != 2 or points.shape[1] != 2:
            raise InputError(f"scene points must have shape (N, 2), got {points.shape}")
        if offsets.ndim != 1 or len(offsets) < 1 or offsets[0] != 0 or offsets[-1] != len(points):
            raise InputError("scene offsets must run from 0 to the number of points")
        counts = np.diff(offsets)
        if np.any(counts < 3) or np.any(counts % 3):
            raise InputError("every path needs 3K control points with K >= 1")
        if len(self.paints) != len(counts):
            raise InputError(f"{len(counts)} paths but {len(self.paints)} paints")
        if not np.all(np.isfinite(points)):
            bad = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            path = int(np.searchsorted(offsets, bad, side="right") - 1)
            raise InputError(f"path {path} has non-finite coordinates")
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "offsets", offsets)
        object.__setattr__(self, "paints", tuple(self.paints))
        gradient = _check_background_gradient(self.background_gradient)
        object.__setattr__(self, "background_gradient", gradient)
        background = self.background if gradient is None else gradient.rgba[:3]
        object.__setattr__(self, "background", _check_background(background))
        if self.fixed is not None:
            fixed = np.asarray(self.fixed, dtype=bool)
            if fixed.shape != (len(counts),):
                raise InputError(f"{len(counts)} paths but {len(fixed)} fixed flags")
            object.__setattr__(self, "fixed", fixed if fixed.any() else None)
        if self.joined is not None:
            joined = np.asarray(self.joined, dtype=bool)
            if joined.shape != (len(counts),):
                raise InputError(f"{len(counts)} paths but {len(joined)} joined flags")
            object.__setattr__(self, "joined", joined if joined[1:].any() else None)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_paths(
        cls,
        width: int,
        height: int,
        paths: Sequence[tuple[np.ndarray, Paint]],
        background: Sequence[float] | None = None,
        frame: Frame | None = None,
        background_gradient: BackgroundGradient | None = None,
    ) -> Scene:
        """A scene from (points (3K, 2), paint) pairs in paint order."""
        points, offsets = _pack(paths)
        return cls(
            width,
            height,
            points,
            offsets,
            tuple(paint for _, paint in paths),
            _check_background(background),
            frame,
            background_gradient,
        )

    @classmethod
    def from_arrays(
        cls,
        width: int,
        height: int,
        points: np.ndarray,
        offsets: np.ndarray,
        colours: np.ndarray,
        background: Sequence[float] | None = None,
        frame: Frame | None = None,
        background_gradient: BackgroundGradient | None = None,
    ) -> Scene:
        """Packed points and offsets with flat RGBA ``colours`` (P, 4), clipped to [0, 1]."""
        return cls(
            width,
            height,
            points,
            offsets,
            _flat_paints(colours),
            _check_background(background),
            frame,
            background_gradient,
        )

    # ------------------------------------------------------------------ views
    @property
    def path_count(self) -> int:
        return len(self.offsets) - 1

    def elements(self) -> list[range]:
        """The SVG ``<path>`` elements as runs of paths, bottom first: a path `joined` to the one
        below it with the very same paint extends that path's run."""
        if self.path_count == 0:
            return []
        joined = self.joined_paths()
        starts = [0]
        for index in range(1, self.path_count):
            if not (joined[index] and self.paints[index] == self.paints[index - 1]):
                starts.append(index)
        return [range(a, b) for a, b in zip(starts, [*starts[1:], self.path_count], strict=True)]

    @property
    def element_count(self) -> int:
        """How many ``<path>`` elements the SVG of this scene holds (see `elements`)."""
        return len(self.elements()) if self.joined is not None else self.path_count

    def joined_paths(self) -> np.ndarray:
        """(P,) bool: which paths are joined to the one below (`joined`, all False when None)."""
        return np.zeros(self.path_count, bool) if self.joined is None else self.joined

    def joined_runs(self) -> np.ndarray:
        """(P,) int: which run of `joined` paths each path is in, 0 first, by the flags alone
        (`elements` also asks for one paint)."""
        return np.cumsum(~self.joined_paths()) - 1

    def segment_counts(self) -> np.ndarray:
        """K of every path, (P,) int64."""
        return np.diff(self.offsets) // 3

    def path_points(self, index: int) -> np.ndarray:
        """The (3K, 2) control points of path ``index`` (a view)."""
        return self.points[self.offsets[index] : self.offsets[index + 1]]

    def paths(self) -> Iterator[tuple[np.ndarray, Paint]]:
        """(points (3K, 2), paint) of every path in paint order."""
        for index, paint in enumerate(self.paints):
            yield self.path_points(index), paint

    @property
    def has_gradients(self) -> bool:
        return any(not isinstance(paint, FlatPaint) for paint in self.paints)

    def colours(self) -> np.ndarray:
        """RGBA of every path, (P, 4) float64: the flat fill, or a gradient's flat stand-in
        (the rasterizer takes a gradient's RGB from its stops and its alpha from here)."""
        if not self.paints:
            return np.zeros((0, 4))
        return np.array([paint.rgba for paint in self.paints], dtype=np.float64)

    @property
    def background_or_white(self) -> RGB:
        return self.background if self.background is not None else (1.0, 1.0, 1.0)

    @property
    def parameter_count(self) -> int:
        """Coordinates and paint values of all paths (6K + 4 per flat path), plus what a
        background gradient adds over a flat background (whose colour is not counted)."""
        paths = int(2 * len(self.points)) + sum(paint.parameter_count for paint in self.paints)
        if self.background_gradient is None:
            return paths
        # less its fixed opacity and the RGB it replaces
        return paths + self.background_gradient.parameter_count - 4

    # ------------------------------------------------------------------ derived scenes
    def with_geometry(self, points: np.ndarray, colours: np.ndarray | None = None) -> Scene:
        """The same paths with new packed ``points`` and, optionally, new flat colours."""
        if colours is None:
            return replace(self, points=points)
        return replace(self, points=points, paints=_flat_paints(colours))

    def with_paths(self, paths: Sequence[tuple[np.ndarray, Paint]]) -> Scene:
        """These (points (3K, 2), paint) pairs, in paint order, in place of this scene's paths
        (canvas, background and frame kept)."""
        points, offsets = _pack(paths)
        paints = tuple(paint for _, paint in paths)
        return replace(self, points=points, offsets=offsets, paints=paints, fixed=None, joined=None)

    def with_background(self, background: Sequence[float] | None) -> Scene:
        """The scene over a flat ``background`` (None: white); a background gradient goes."""
        return replace(self, background=_check_background(background), background_gradient=None)

    def stacked(self, above: Scene) -> Scene:
        """This scene with the paths of ``above`` painted on top."""
        if (above.width, above.height) != (self.width, self.height):
            raise InputError("scenes to stack must share a canvas")
        return replace(
            self,
            points=np.concatenate([self.points, above.points]),
            offsets=np.concatenate([self.offsets, above.offsets[1:] + len(self.points)]),
            paints=self.paints + above.paints,
            fixed=np.concatenate([self.fixed_paths(), above.fixed_paths()]),
            joined=np.concatenate([self.joined_paths(), above.joined_paths()]),
        )

    def subset(self, keep: Sequence[int] | np.ndarray) -> Scene:
        """Only the paths at indices ``keep`` (in the order given)."""
        indices = np.asarray(keep, dtype=np.int64).reshape(-1)
        kept = self.with_paths([(self.path_points(int(i)), self.paints[int(i)]) for i in indices])
        joined = None
        if self.joined is not None and len(indices):
            run = self.joined_runs()
            joined = np.concatenate([[False], run[indices[1:]] == run[indices[:-1]]])
        return replace(kept, fixed=self.fixed_paths()[indices], joined=joined)

    def fixed_paths(self) -> np.ndarray:
        """(P,) bool: which paths keep their outline in a fit (`fixed`, all False when None)."""
        return np.zeros(self.path_count, bool) if self.fixed is None else self.fixed

    def with_fixed_from(self, before: Scene) -> Scene:
        """This scene (``before`` after some edit that rebuilt its paths) with each path fixed
        that ``before`` had fixed with the very same points: an edit that left a fixed path as
        it was keeps its flag, one that changed it frees it."""
        if before.fixed is None:
            return self
        kept = {before.path_points(int(i)).tobytes() for i in np.flatnonzero(before.fixed)}
        flags = [self.path_points(i).tobytes() in kept for i in range(self.path_count)]
        return replace(self, fixed=np.asarray(flags, dtype=bool))

    def with_fixed_outlines(self) -> Scene:
        """This scene with every path's outline fixed (its paint still fitted)."""
        return replace(self, fixed=np.ones(self.path_count, bool))

    def in_input_pixels(self) -> Scene:
        """The scene on the input canvas (``frame``), coordinates divided by its scale."""
        if self.frame is None:
            return self
        factor = 1.0 / self.frame.scale
        gradient = self.background_gradient
        return replace(
            self,
            width=self.frame.width,
            height=self.frame.height,
            points=self.points / self.frame.scale,
            paints=tuple(paint.scaled(factor) for paint in self.paints),
            frame=None,
            background_gradient=None if gradient is None else gradient.scaled(factor),
        )

    def on_canvas(self, width: int, height: int, factor: float) -> Scene:
        """The scene drawn ``factor`` times as large on a ``width`` × ``height`` canvas (points
        and gradient geometry scaled; paths, paints and frame kept)."""
        gradient = self.background_gradient
        return replace(
            self,
            width=width,
            height=height,
            points=self.points * factor,
            paints=tuple(paint.scaled(factor) for paint in self.paints),
            background_gradient=None if gradient is None else gradient.scaled(factor),
        )

    def window(self, left: int, top: int, width: int, height: int) -> Scene:
        """The part of the canvas from pixel (``left``, ``top``), ``width`` × ``height``, as a
        scene of its own: geometry moved so that pixel is the origin, paths and paints kept. Its
        render is that rectangle of this scene's render."""
        gradient = self.background_gradient
        return replace(
            self,
            width=width,
            height=height,
            points=self.points - np.array([left, top], dtype=np.float64),
            paints=tuple(paint.shifted(-left, -top) for paint in self.paints),
            background_gradient=None if gradient is None else gradient.shifted(-left, -top),
        )

    def path_boxes(self) -> np.ndarray:
        """(P, 4) float: each path's control-point box (x0, y0, x1, y1), which holds its
        outline (a cubic lies in the hull of its control points)."""
        if self.path_count == 0:
            return np.zeros((0, 4))
        starts = self.offsets[:-1]
        low = np.minimum.reduceat(self.points, starts, axis=0)
        high = np.maximum.reduceat(self.points, starts, axis=0)
        return np.concatenate([low, high], axis=1)

    def render(self, scale: float = 1.0) -> np.ndarray:
        """Rasterize to a float32 (H, W, 3) array in [0, 1] at ``scale`` × the canvas size; no
        background means white."""
        from samvg.render import render_scene  # lazy: the rasterizer loads torch and numba

        return render_scene(self, scale)
