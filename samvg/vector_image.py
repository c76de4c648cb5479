"""`VectorImage`: the SVG boundary. A thin view of a `samvg.scene.Scene` in the input image's
pixels, with SVG reading (`samvg.svg.reader`), writing (`samvg.svg.writer`) and rendering.

`VectorPath` is the per-path view a user builds scenes from or inspects: closed cubic control
points (3K, 2) and a straight RGBA fill.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from samvg.errors import InputError
from samvg.io import atomic_write_text
from samvg.scene import RGB, RGBA, FlatPaint, Scene
from samvg.svg.reader import read_svg
from samvg.svg.writer import DEFAULT_PRECISION, scene_to_svg


@dataclass
class VectorPath:
    """A closed piecewise-cubic path: ``points`` (3K, 2) in pixels, RGBA ``fill`` in [0, 1]."""

    points: np.ndarray
    fill: RGBA = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3 or points.shape[0] % 3:
            raise InputError(f"path points must have shape (3K, 2) with K >= 1, got {points.shape}")
        if not np.all(np.isfinite(points)):
            raise InputError("path points must be finite numbers")
        self.points = points
        self.fill = FlatPaint(self.fill).rgba

    @property
    def num_segments(self) -> int:
        return self.points.shape[0] // 3

    @property
    def paint(self) -> FlatPaint:
        return FlatPaint(self.fill)


class VectorImage:
    """A canvas of ``width`` × ``height`` pixels, an optional opaque background, and paths."""

    def __init__(
        self,
        width: int,
        height: int,
        paths: Sequence[VectorPath] = (),
        background: Sequence[float] | None = None,
    ) -> None:
        self._scene = Scene.from_paths(
            width, height, [(path.points, path.paint) for path in paths], background
        )

    @classmethod
    def from_scene(cls, scene: Scene) -> VectorImage:
        """The view of ``scene`` in its input pixels (see `Scene.in_input_pixels`)."""
        image = cls.__new__(cls)
        image._scene = scene.in_input_pixels()
        return image

    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def width(self) -> int:
        return self._scene.width

    @property
    def height(self) -> int:
        return self._scene.height

    @property
    def background(self) -> RGB | None:
        return self._scene.background

    @property
    def paths(self) -> list[VectorPath]:
        """Copies of the closed paths, in paint order (each piece of a compound path is one:
        see `Scene.elements` for the SVG's ``<path>`` elements)."""
        return [VectorPath(points.copy(), paint.rgba) for points, paint in self._scene.paths()]

    def __repr__(self) -> str:
        return (
            f"VectorImage({self.width}x{self.height}, {self._scene.element_count} paths, "
            f"background={self.background})"
        )

    # ------------------------------------------------------------------ output
    def to_svg(self, precision: int = DEFAULT_PRECISION) -> str:
        """SVG text: width, height, viewBox, an optional background rect and one ``<path>`` per
        element (a compound path's pieces are its subpaths)."""
        return scene_to_svg(self._scene, precision)

    def save(self, path: str | os.PathLike[str], precision: int = DEFAULT_PRECISION) -> None:
        """Write :meth:`to_svg` to ``path`` atomically (temporary file, then rename)."""
        atomic_write_text(path, self.to_svg(precision))

    def render(self, scale: float = 1.0) -> np.ndarray:
        """Rasterize to a float32 (H, W, 3) array in [0, 1]; no background means white."""
        return self._scene.render(scale)

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
        """Parse SVG made of filled shapes (see `samvg.svg.reader.read_svg`): a full-canvas
        ``<rect>`` drawn first becomes the background (a colour or a gradient). Elements or
        attributes this model cannot represent raise :class:`InputError` naming them."""
        parsed = read_svg(text)
        paths = [
            (points, FlatPaint(fill) if isinstance(fill, tuple) else fill)
            for points, fill in parsed.paths
        ]
        scene = Scene.from_paths(
            parsed.width,
            parsed.height,
            paths,
            parsed.background,
            background_gradient=parsed.background_gradient,
        )
        joined = np.array(parsed.joined, dtype=bool) if parsed.joined else None
        return cls.from_scene(replace(scene, joined=joined))
