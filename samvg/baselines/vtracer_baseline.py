"""The vtracer baseline: VTracer (PyPI ``vtracer``) with its settings searched per image so that
its path count comes as close as possible to a target count without exceeding it.

VTracer's paths are compound (holes as extra subpaths) and carry ``translate`` transforms, which
:class:`samvg.VectorImage` cannot hold, so its SVG is kept as text and rendered with resvg.
"""

from __future__ import annotations

import io
import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from samvg.baselines.common import as_target, check_counts
from samvg.errors import InputError, SamvgError
from samvg.imaging import to_float_rgb
from samvg.io import atomic_write_text

#: (color_precision, layer_difference) pairs tried in turn, VTracer's defaults first; for each,
#: filter_speckle is bisected.
SETTINGS_GRID = ((6, 16), (8, 16), (4, 16), (6, 48), (8, 48), (4, 48), (3, 32), (2, 64))
#: filter_speckle range searched (VTracer discards patches smaller than this many pixels wide).
SPECKLE_RANGE = (1, 128)
#: Decimal places of path coordinates (samvg writes 2 as well, so SVG sizes compare).
PATH_PRECISION = 2
_INSTALL_HINT = "the vtracer baseline needs the bench extra: pip install 'samvg[bench]'"


@dataclass
class TracedSvg:
    """VTracer's SVG for one image, with the settings that made it and how many were tried."""

    svg: str
    width: int
    height: int
    settings: dict[str, int] = field(default_factory=dict)
    evaluations: int = 1
    run_seconds: float = 0.0
    """Time of the one VTracer run that made ``svg`` (the search took ``evaluations`` runs)."""

    @property
    def path_count(self) -> int:
        """Number of ``<path>`` elements (VTracer's first one is the full-canvas background)."""
        return count_paths(self.svg)

    @property
    def parameter_count(self) -> int:
        """All numbers of the path data and transforms, plus three per fill colour (RGB)."""
        numbers = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
        data = " ".join(re.findall(r'\bd="([^"]*)"', self.svg))
        transforms = " ".join(re.findall(r'\btransform="([^"]*)"', self.svg))
        return (
            len(re.findall(numbers, data))
            + len(re.findall(numbers, transforms))
            + 3 * len(re.findall(r'\bfill="#', self.svg))
        )

    @property
    def shape_count(self) -> int:
        """Number of closed shapes: subpaths (one per move-to) over all ``<path>`` elements."""
        return count_shapes(self.svg)

    def to_svg(self) -> str:
        return self.svg

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the SVG atomically."""
        atomic_write_text(path, self.svg)

    def render(self) -> np.ndarray:
        """Rasterize with resvg over white: float32 (H, W, 3) in [0, 1]."""
        return render_svg(self.svg, self.width, self.height)


def count_paths(svg: str) -> int:
    """Number of ``<path>`` elements in SVG text."""
    return len(re.findall(r"<path\b", svg))


def count_shapes(svg: str) -> int:
    """Closed shapes in SVG text: move-to commands over all path data (a compound path with
    holes counts once per subpath, as LIVE and DiffVG count one closed curve per path)."""
    data = " ".join(re.findall(r'\bd="([^"]*)"', svg))
    return len(re.findall(r"[Mm]", data))


def _counter(count: str) -> Callable[[str], int]:
    """`count_paths` or `count_shapes` by name; `InputError` for another name."""
    counters = {"paths": count_paths, "shapes": count_shapes}
    if count not in counters:
        raise InputError(f"count must be 'paths' or 'shapes', got {count!r}")
    return counters[count]


def render_svg(svg: str, width: int, height: int) -> np.ndarray:
    """Render SVG text with resvg at ``width`` × ``height`` over white, float32 (H, W, 3)."""
    from PIL import Image

    try:
        import resvg_py
    except ImportError:
        raise SamvgError(_INSTALL_HINT + " (resvg-py is missing)") from None
    try:
        png = resvg_py.svg_to_bytes(
            svg_string=svg, background="#ffffff", width=width, height=height
        )
    except ValueError as error:
        raise SamvgError(f"resvg cannot render the SVG: {error}") from None
    with Image.open(io.BytesIO(bytes(png))) as opened:
        return to_float_rgb(opened.convert("RGB"))


def trace_once(png: bytes, filter_speckle: int, color_precision: int, layer_difference: int) -> str:
    """One VTracer run (colour, stacked, spline) on PNG bytes; returns the SVG text."""
    try:
        import vtracer
    except ImportError:
        raise SamvgError(_INSTALL_HINT + " (vtracer is missing)") from None
    return vtracer.convert_raw_image_to_svg(
        png,
        img_format="png",
        colormode="color",
        hierarchical="stacked",
        mode="spline",
        filter_speckle=int(filter_speckle),
        color_precision=int(color_precision),
        layer_difference=int(layer_difference),
        path_precision=PATH_PRECISION,
    )


def vtracer_trace(
    target: np.ndarray,
    path_count: int,
    max_evaluations: int = 48,
    tolerance: float = 0.02,
    count: Literal["paths", "shapes"] = "paths",
) -> TracedSvg:
    """VTracer's SVG of ``target`` with the most paths found that do not exceed ``path_count``;
    with ``count="shapes"``, closed shapes (subpaths, see `count_shapes`) instead of paths.

    For each (color_precision, layer_difference) of :data:`SETTINGS_GRID`, filter_speckle is
    bisected on a log scale (path counts fall as it grows); the search stops once a count at
    most ``path_count`` is within ``tolerance`` × ``path_count`` of it (rounded down, so exact
    below 50 paths) or after ``max_evaluations`` runs, and keeps the closest count that does not
    exceed ``path_count`` (the first one on ties). Only when every run gave more paths does it
    keep the fewest found.
    """
    from PIL import Image

    check_counts(path_count, 1)
    counted = _counter(count)
    image = np.round(as_target(target) * 255.0).astype(np.uint8)
    height, width = image.shape[:2]
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    png = buffer.getvalue()
    good_enough = int(tolerance * path_count)
    cache: dict[tuple[int, int, int], str] = {}
    seconds: dict[tuple[int, int, int], float] = {}
    best: tuple[tuple[bool, int], tuple[int, int, int]] | None = None

    def measure(speckle: int, precision: int, difference: int) -> int:
        nonlocal best
        key = (speckle, precision, difference)
        if key not in cache:
            started = time.perf_counter()
            cache[key] = trace_once(png, speckle, precision, difference)
            seconds[key] = time.perf_counter() - started
        found = counted(cache[key])
        rank = (found > path_count, abs(found - path_count))
        if best is None or rank < best[0]:
            best = (rank, key)
        return found

    def close_enough() -> bool:
        return best is not None and best[0] <= (False, good_enough)

    low_bound, high_bound = SPECKLE_RANGE
    for precision, difference in SETTINGS_GRID:
        if len(cache) >= max_evaluations or close_enough():
            break
        low, high = low_bound, high_bound
        if measure(low, precision, difference) <= path_count:
            continue  # even the finest speckle filter gives too few paths with these settings
        if measure(high, precision, difference) >= path_count:
            continue
        while high - low > 1 and len(cache) < max_evaluations:
            middle = min(high - 1, max(low + 1, round(math.sqrt(low * high))))
            found = measure(middle, precision, difference)
            if close_enough():
                break
            if found > path_count:
                low = middle
            else:
                high = middle
    assert best is not None
    speckle, precision, difference = best[1]
    return TracedSvg(
        svg=cache[best[1]],
        width=width,
        height=height,
        settings={
            "filter_speckle": speckle,
            "color_precision": precision,
            "layer_difference": difference,
        },
        evaluations=len(cache),
        run_seconds=seconds[best[1]],
    )
