"""``rasterize``: exact-area, analytically differentiable CPU rasterizer of closed cubic paths.

This module validates input, converts tensors to float64 NumPy arrays, calls the numba kernels of
``samvg.render._kernels`` and wraps forward/backward in a ``torch.autograd.Function``. It is written
by hand because no maintained library offers exact box-filtered coverage with analytic gradients on
the CPU (diffvg samples edges randomly and needs a C++ build; resvg/Skia are not differentiable).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from samvg.errors import InputError
from samvg.render import _kernels as K
from samvg.render._paint_kernels import FLAT, LINEAR, MAX_STOPS, PARAMS, RADIAL
from samvg.render.gradient_image import gradient_image
from samvg.render.threads import render_threads, run_parts
from samvg.render.workspace import scratch
from samvg.scene import FlatPaint, LinearGradient, Paint, RadialGradient, Scene

#: Maximum chord error (pixels) of the polyline that replaces each cubic segment.
FLATTEN_TOLERANCE = 0.05
#: Largest canvas accepted, in pixels (width * height).
MAX_PIXELS = 1 << 28
# Coordinates beyond this many pixels are clamped (no effect on any real scene).
_FAR = 1e18

_Points = torch.Tensor | np.ndarray | Sequence[torch.Tensor | np.ndarray]


def _check_size(width: int, height: int) -> tuple[int, int]:
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise InputError(f"canvas {name} must be an integer, got {v!r}")
        if v <= 0:
            raise InputError(f"canvas {name} must be positive, got {v}")
    width, height = int(width), int(height)
    if width * height > MAX_PIXELS:
        raise InputError(
            f"canvas {width}x{height} is too large to rasterize "
            f"({width * height} pixels, limit {MAX_PIXELS})"
        )
    return width, height


_NO_BACKGROUND = np.zeros(0, np.float64)
"""Tells the forward kernel the canvas already holds the background image."""
_NO_IMAGE = torch.zeros(0)
"""Stands for the background image tensor where there is none (nothing to differentiate)."""
_Background = Sequence[float] | np.ndarray | torch.Tensor | None


def _background(background: _Background, width: int, height: int) -> np.ndarray:
    """The opaque RGB (3,) behind the paths, or an (H, W, 3) image to paint them over."""
    if background is None:
        return np.ones(3, np.float64)
    if isinstance(background, torch.Tensor) and background.dim() == 3:
        background = background.detach().cpu().numpy()
    if isinstance(background, np.ndarray) and background.ndim == 3:
        if background.shape != (height, width, 3) or not np.all(np.isfinite(background)):
            raise InputError(
                f"a background image must be finite with shape ({height}, {width}, 3), "
                f"got {background.shape}"
            )
        return background
    try:
        bg = np.asarray(
            background.detach().cpu() if isinstance(background, torch.Tensor) else background,
            dtype=np.float64,
        ).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise InputError(f"background must be three numbers (RGB), got {background!r}") from exc
    if bg.shape != (3,) or not np.all(np.isfinite(bg)):
        raise InputError(f"background must be three finite numbers (RGB), got {background!r}")
    return bg


def _as_tensor(x: torch.Tensor | np.ndarray, what: str) -> torch.Tensor:
    if isinstance(x, torch.Tensor):
        return x
    try:
        return torch.as_tensor(np.asarray(x, dtype=np.float64))
    except (TypeError, ValueError) as exc:
        raise InputError(f"{what} must be a numeric array") from exc


def _packed_points(
    points: torch.Tensor | np.ndarray, offsets: np.ndarray
) -> tuple[torch.Tensor, np.ndarray]:
    """Check packed control points (N, 2) against path offsets (P + 1)."""
    pts = _as_tensor(points, "points")
    starts = np.asarray(offsets, dtype=np.int64).reshape(-1)
    if pts.dim() != 2 or pts.shape[-1] != 2:
        raise InputError(f"packed points must have shape (N, 2), got {tuple(pts.shape)}")
    counts = np.diff(starts)
    if len(starts) < 1 or starts[0] != 0 or starts[-1] != pts.shape[0] or np.any(counts < 3):
        raise InputError("offsets must rise from 0 to the number of points, 3K points a path")
    if np.any(counts % 3):
        raise InputError("every path needs 3K control points")
    return pts, starts


def _flat_points(
    points: _Points, offsets: np.ndarray | None = None
) -> tuple[torch.Tensor, np.ndarray]:
    """Return the control points as one (N, 2) tensor and the path start offsets (P + 1)."""
    if offsets is not None:
        if not isinstance(points, (torch.Tensor, np.ndarray)):
            raise InputError("packed points (with offsets) must be one (N, 2) array")
        return _packed_points(points, offsets)
    if isinstance(points, (torch.Tensor, np.ndarray)):
        pts = _as_tensor(points, "points")
        if pts.dim() != 3 or pts.shape[-1] != 2 or (pts.shape[0] > 0 and pts.shape[1] % 3):
            raise InputError(f"points must have shape (P, 3K, 2), got {tuple(pts.shape)}")
        n_paths, n_per = pts.shape[0], pts.shape[1]
        if n_paths > 0 and n_per == 0:
            raise InputError("points must have at least one segment (3 points) per path")
        starts = np.arange(n_paths + 1, dtype=np.int64) * n_per
        return pts.reshape(n_paths * n_per, 2), starts
    parts = [_as_tensor(p, "points") for p in points]
    counts = [0]
    for i, p in enumerate(parts):
        if p.dim() != 2 or p.shape[-1] != 2 or p.shape[0] == 0 or p.shape[0] % 3:
            raise InputError(f"path {i} must have shape (3K, 2) with K >= 1, got {tuple(p.shape)}")
        counts.append(p.shape[0])
    starts = np.cumsum(np.asarray(counts, dtype=np.int64))
    if not parts:
        return torch.zeros((0, 2), dtype=torch.float32), starts
    dtype = torch.float64 if any(p.dtype == torch.float64 for p in parts) else torch.float32
    return torch.cat([p.to(dtype) for p in parts]), starts


def _report_nonfinite(arr: np.ndarray, starts: np.ndarray, what: str) -> None:
    bad = ~np.isfinite(arr).all(axis=-1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        path = int(np.searchsorted(starts, first, side="right") - 1)
        raise InputError(f"path {path} has non-finite {what}")


@dataclass(frozen=True)
class GradientPaints:
    """Per path: the paint kind (``FLAT``, ``LINEAR``, ``RADIAL``), the stop count (2 to
    ``MAX_STOPS``) and the parameters (P, ``PARAMS``): geometry, stop offsets, stop RGB (see
    ``samvg.render._paint_kernels``). Flat paths ignore their row."""

    kinds: np.ndarray
    stops: np.ndarray
    params: torch.Tensor

    @classmethod
    def of(cls, paints: Sequence[Paint], scale: float = 1.0) -> GradientPaints:
        """The gradient paints among ``paints`` (flat ones get empty rows), geometry × ``scale``."""
        kinds = np.zeros(len(paints), np.int64)
        stops = np.zeros(len(paints), np.int64)
        params = np.zeros((len(paints), PARAMS))
        for index, paint in enumerate(paints):
            if isinstance(paint, FlatPaint):
                continue
            if isinstance(paint, LinearGradient):
                kinds[index] = LINEAR
                params[index, :4] = (*paint.start, *paint.end)
                params[index, :4] *= scale
            else:
                kinds[index] = RADIAL
                params[index, :3] = (*paint.centre, paint.radius)
                params[index, :3] *= scale
            stops[index] = len(paint.stops)
            for number, (offset, rgb) in enumerate(paint.stops):
                params[index, 4 + number] = offset
                params[index, 8 + 3 * number : 11 + 3 * number] = rgb
        return cls(kinds, stops, torch.from_numpy(params))

    def paints(self, colours: np.ndarray) -> tuple[Paint, ...]:
        """Scene paints from these rows and RGBA ``colours`` (P, 4): flat fills from the
        colours, gradients from the parameters with the colours' alpha as opacity."""
        params = self.params.detach().cpu().numpy().astype(np.float64)
        rgba = np.clip(np.asarray(colours, dtype=np.float64), 0.0, 1.0)
        paints: list[Paint] = []
        for index, kind in enumerate(self.kinds):
            if kind == FLAT:
                paints.append(FlatPaint(tuple(rgba[index])))
                continue
            row, count = params[index], int(self.stops[index])
            offsets = np.maximum.accumulate(np.clip(row[4 : 4 + count], 0.0, 1.0))
            colour_rows = np.clip(row[8 : 8 + 3 * count].reshape(count, 3), 0.0, 1.0)
            stops = tuple(
                (float(offset), (float(c[0]), float(c[1]), float(c[2])))
                for offset, c in zip(offsets, colour_rows, strict=True)
            )
            opacity = float(rgba[index, 3])
            if kind == LINEAR:
                paints.append(LinearGradient(stops, opacity, tuple(row[0:2]), tuple(row[2:4])))
            else:
                radius = max(float(row[2]), 1e-6)
                paints.append(RadialGradient(stops, opacity, tuple(row[0:2]), radius))
        return tuple(paints)

    def image(self, index: int, width: int, height: int) -> torch.Tensor:
        """Gradient paint ``index`` over a whole ``width`` × ``height`` canvas, (height, width,
        3), differentiable with respect to ``params`` (`gradient_image`)."""
        kind, stops = int(self.kinds[index]), int(self.stops[index])
        return gradient_image(kind, stops, self.params[index], width, height)

    @classmethod
    def flat(cls, count: int) -> GradientPaints:
        return cls(
            np.zeros(count, np.int64), np.zeros(count, np.int64), torch.zeros((count, PARAMS))
        )

    def check(self, count: int) -> None:
        kinds, stops = self.kinds, self.stops
        if kinds.shape != (count,) or stops.shape != (count,):
            raise InputError(f"gradient paints must describe {count} paths")
        if tuple(self.params.shape) != (count, PARAMS):
            raise InputError(f"gradient parameters must have shape ({count}, {PARAMS})")
        if not np.isin(kinds, (FLAT, LINEAR, RADIAL)).all():
            raise InputError("paint kinds must be flat (0), linear (1) or radial (2)")
        shaded = kinds != FLAT
        if np.any((stops[shaded] < 2) | (stops[shaded] > MAX_STOPS)):
            raise InputError(f"a gradient needs 2 to {MAX_STOPS} stops")
        if count and not torch.isfinite(self.params.detach()).all():
            raise InputError("gradient parameters must be finite")


class _Rasterize(torch.autograd.Function):
    @staticmethod
    def forward(
        ctx: Any,
        flat_pts: torch.Tensor,
        colors: torch.Tensor,
        params: torch.Tensor,
        image: torch.Tensor,
        kinds: np.ndarray,
        stops: np.ndarray,
        starts: np.ndarray,
        width: int,
        height: int,
        bg: np.ndarray,
        tol: float,
        grad_enabled: bool,
    ) -> torch.Tensor:
        # C-contiguous float64: one compiled specialization of every kernel serves all inputs.
        pts = np.ascontiguousarray(flat_pts.detach().cpu().numpy(), dtype=np.float64)
        # Absurdly far points are pulled in so no coordinate difference overflows float64.
        clipped = np.abs(pts) > _FAR
        if clipped.any():
            pts = np.clip(pts, -_FAR, _FAR)
        cols = np.ascontiguousarray(colors.detach().cpu().numpy(), dtype=np.float64)
        paint = np.ascontiguousarray(params.detach().cpu().numpy(), dtype=np.float64)
        seg_n, vstart, verts = K.plan_and_flatten(pts, starts, width, height, tol)
        box, off = K.path_boxes(verts, vstart, width, height)
        # needs_input_grad ignores torch.no_grad(); keep backward state only if it can be used.
        keep = grad_enabled and any(ctx.needs_input_grad[:4])
        n_cells = int(off[-1])
        largest = int(np.max(np.diff(off))) if len(off) > 1 else 0
        out_dtype = np.float64 if flat_pts.dtype == torch.float64 else np.float32
        try:
            canvas = np.empty((height, width, 3), out_dtype)
            if bg.ndim == 3:
                canvas[...] = bg
            acc = scratch(n_cells if keep else largest, np.float64)
            under = scratch((n_cells if keep else 0, 3), np.float32)
        except MemoryError as exc:
            raise InputError(
                f"scene too large to rasterize: {n_cells} path-box pixels on a "
                f"{width}x{height} canvas"
            ) from exc
        parts = min(render_threads(), height)
        bands = K.row_bands(box, height, parts)
        # With keep the bands fill disjoint rows of one buffer; without, each needs a scratch.
        buffers = [acc] * parts
        if not keep:
            buffers[1:] = [scratch(acc.shape, np.float64) for _ in range(1, parts)]
        fill = bg if bg.ndim == 1 else _NO_BACKGROUND

        def forward_band(part: int) -> None:
            K.render_forward(
                verts, vstart, box, off, cols, fill, canvas, buffers[part],
                under, keep, kinds, stops, paint, bands[part], bands[part + 1],
            )  # fmt: skip

        run_parts(forward_band, parts)
        ctx.col_dtype = colors.dtype
        ctx.paint_dtype = params.dtype
        ctx.image_dtype = image.dtype
        if keep:
            ctx.state = (pts.shape[0], starts, seg_n, vstart, verts, box, off, acc, under, cols)
            ctx.paints = (kinds, stops, paint)
            ctx.clipped = clipped if clipped.any() else None
        return torch.from_numpy(canvas).to(dtype=flat_pts.dtype, device=flat_pts.device)

    @staticmethod
    @torch.autograd.function.once_differentiable
    def backward(ctx: Any, grad_out: torch.Tensor) -> tuple[torch.Tensor | None, ...]:
        n_ctrl, starts, seg_n, vstart, verts, box, off, acc, under, cols = ctx.state
        go = scratch(tuple(grad_out.shape), np.float64)
        go[...] = grad_out.detach().cpu().numpy()
        gverts, gcol, gpaint = _backward(go, verts, vstart, box, off, cols, acc, under, ctx.paints)
        g_pts = g_col = g_paint = g_image = None
        if ctx.needs_input_grad[0]:
            g = K.flatten_backward(gverts, starts, seg_n, vstart, n_ctrl)
            if ctx.clipped is not None:
                g[ctx.clipped] = 0.0
            g_pts = torch.from_numpy(g).to(dtype=grad_out.dtype, device=grad_out.device)
        if ctx.needs_input_grad[1]:
            g_col = torch.from_numpy(gcol).to(dtype=ctx.col_dtype, device=grad_out.device)
        if ctx.needs_input_grad[2]:
            g_paint = torch.from_numpy(gpaint).to(dtype=ctx.paint_dtype, device=grad_out.device)
        if ctx.needs_input_grad[3]:
            # render_backward has passed the canvas gradient under every path, in reverse paint
            # order: what is left is the gradient with respect to the canvas before any path.
            g_image = torch.from_numpy(go).to(dtype=ctx.image_dtype, device=grad_out.device)
        return g_pts, g_col, g_paint, g_image, *([None] * 8)


def _backward(
    grad_out: np.ndarray,
    verts: np.ndarray,
    vstart: np.ndarray,
    box: np.ndarray,
    off: np.ndarray,
    cols: np.ndarray,
    acc: np.ndarray,
    under: np.ndarray,
    paints: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """dL/d vertices, colours and gradient paint parameters from dL/d image ``grad_out``
    (overwritten with dL/d the canvas under every path), on the rasterizer's threads: the
    pixel part in row bands, then the edge part in runs of paths. The image and the vertex
    gradients are the same on any thread count; colour gradients are summed per band, then
    over the bands (one band sums in the order of a single-threaded pass)."""
    kinds, stops, paint = paints
    height = grad_out.shape[0]
    parts = min(render_threads(), height)
    colour_sums = np.zeros((parts, box.shape[0], 4), np.float64)
    paint_sums = np.zeros((parts, *paint.shape), np.float64)
    dcov = scratch(acc.shape[0], np.float64)
    rows = K.row_bands(box, height, parts)

    def pixel_band(part: int) -> None:
        K.render_backward_pixels(
            grad_out, box, off, cols, acc, under, dcov, kinds, stops, paint,
            colour_sums[part], paint_sums[part], rows[part], rows[part + 1],
        )  # fmt: skip

    run_parts(pixel_band, parts)
    gverts = np.zeros(verts.shape, np.float64)
    paths = K.path_bands(box, vstart, parts)

    def edge_run(part: int) -> None:
        K.render_backward_edges(
            verts, vstart, box, off, acc, dcov, gverts, paths[part], paths[part + 1]
        )

    run_parts(edge_run, parts)
    return gverts, colour_sums.sum(axis=0), paint_sums.sum(axis=0)


def rasterize(
    points: _Points,
    colors: torch.Tensor | np.ndarray,
    width: int,
    height: int,
    background: _Background = (1.0, 1.0, 1.0),
    *,
    offsets: np.ndarray | None = None,
    tolerance: float = FLATTEN_TOLERANCE,
    gradients: GradientPaints | None = None,
) -> torch.Tensor:
    """Render closed cubic Bézier paths with exact box-filtered coverage, differentiably.

    Args:
        points: control points in pixel units, either a tensor ``(P, 3K, 2)`` or a sequence of
            ``P`` tensors ``(3K_i, 2)`` (paths with different segment counts). Segment ``k`` of a
            path uses points ``3k, 3k+1, 3k+2`` and ``(3k+3) mod 3K``; every path is closed.
            Pixel ``(r, c)`` covers ``[c, c+1] x [r, r+1]``. With ``offsets`` (P + 1 starts),
            ``points`` is the packed ``(N, 2)`` array of a `samvg.scene.Scene`.
        colors: ``(P, 4)`` straight RGBA in ``[0, 1]`` (used as given, not clamped).
        width, height: canvas size in pixels.
        background: opaque RGB behind the paths, ``None`` meaning white; or an
            ``(height, width, 3)`` array or tensor, an image to paint the paths over (a tensor
            receives the gradient: a gradient background drawn by `gradient_image`).
        tolerance: maximum chord error (pixels) when flattening the cubics.
        gradients: linear and radial gradient paints (`GradientPaints`); a path whose kind is
            not flat takes its RGB from them (its alpha stays ``colors[p, 3]``).

    Returns:
        ``(height, width, 3)`` tensor, float64 for float64 ``points``, float32 otherwise,
        paths composited with straight-alpha "over" in paint order, nonzero fill rule.
        Differentiable w.r.t. ``points``, ``colors``, the gradient parameters (analytic
        boundary gradients) and a background image tensor.

    Raises:
        InputError (a ValueError): bad shapes, non-finite coordinates/colours (naming the path),
            non-positive or too large canvas.
    """
    width, height = _check_size(width, height)
    bg = _background(background, width, height)
    flat, starts = _flat_points(points, offsets)
    cols = _as_tensor(colors, "colors")
    n_paths = len(starts) - 1
    if cols.dim() != 2 or cols.shape[1] != 4 or cols.shape[0] != n_paths:
        raise InputError(f"colors must have shape ({n_paths}, 4), got {tuple(cols.shape)}")
    # Computation is float64 inside; the image comes back as float64 for float64 points and as
    # float32 otherwise (integers, half precision and bfloat16 included).
    if flat.dtype not in (torch.float32, torch.float64):
        flat = flat.to(torch.float32)
    if cols.dtype not in (torch.float32, torch.float64):
        cols = cols.to(torch.float32)
    if not (tolerance > 0 and np.isfinite(tolerance)):
        raise InputError(f"tolerance must be a positive number, got {tolerance!r}")
    with torch.no_grad():
        pts_np = flat.detach().cpu().numpy()
        _report_nonfinite(pts_np, starts, "coordinates")
        col_np = cols.detach().cpu().numpy()
        if col_np.size and not np.isfinite(col_np).all():
            bad = int(np.flatnonzero(~np.isfinite(col_np).all(axis=1))[0])
            raise InputError(f"path {bad} has a non-finite colour")
    paints = gradients if gradients is not None else GradientPaints.flat(n_paths)
    paints.check(n_paths)
    image = background if isinstance(background, torch.Tensor) and background.dim() == 3 else None
    try:
        return _Rasterize.apply(
            flat,
            cols,
            paints.params,
            image if image is not None else _NO_IMAGE,
            paints.kinds,
            paints.stops,
            starts,
            width,
            height,
            bg,
            float(tolerance),
            torch.is_grad_enabled(),
        )
    except MemoryError as exc:
        raise InputError(f"canvas {width}x{height} is too large to allocate") from exc


def render_array(
    points: np.ndarray,
    colors: np.ndarray,
    width: int,
    height: int,
    background: Sequence[float] | np.ndarray | None = (1.0, 1.0, 1.0),
    offsets: np.ndarray | None = None,
    gradients: GradientPaints | None = None,
) -> np.ndarray:
    """`rasterize` for numpy scenes, without gradients: points (P, 3K, 2), or packed (N, 2) with
    ``offsets``, and RGBA (P, 4) to a float32 (height, width, 3) array; ``background`` an RGB
    or an (height, width, 3) image."""
    with torch.no_grad():
        image = rasterize(
            torch.from_numpy(np.asarray(points)).float(),
            torch.from_numpy(np.asarray(colors)).float(),
            width,
            height,
            background=background,
            offsets=offsets,
            gradients=gradients,
        )
    return image.numpy().astype(np.float32, copy=False)


def _scaled_size(scene: Scene, scale: float) -> tuple[int, int]:
    """(width, height) of the scene's canvas drawn at ``scale``, at least one pixel each."""
    return max(1, round(scene.width * scale)), max(1, round(scene.height * scale))


def background_image(scene: Scene, scale: float = 1.0) -> np.ndarray | None:
    """The float64 (H, W, 3) image of the scene's background gradient at ``scale`` × its canvas
    size (None when its background is flat)."""
    if scene.background_gradient is None:
        return None
    width, height = _scaled_size(scene, scale)
    with torch.no_grad():
        paint = GradientPaints.of([scene.background_gradient], scale)
        return paint.image(0, width, height).numpy()


def render_scene(scene: Scene, scale: float = 1.0) -> np.ndarray:
    """Render a `Scene` at ``scale`` × its canvas size: float32 (H, W, 3) in [0, 1], no
    background meaning white."""
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise InputError(f"render scale must be a positive number, got {scale}")
    width, height = _scaled_size(scene, scale)
    image = background_image(scene, scale)
    return render_array(
        scene.points * scale,
        scene.colours(),
        width,
        height,
        background=scene.background_or_white if image is None else image,
        offsets=scene.offsets,
        gradients=GradientPaints.of(scene.paints, scale) if scene.has_gradients else None,
    )


def warmup() -> None:
    """Compile (or load from the on-disk cache) every kernel, forward and backward."""
    pts = torch.tensor(
        [[[1.0, 1.0], [6.0, 0.5], [7.5, 3.0], [7.0, 7.0], [3.0, 7.5], [0.5, 5.0]]],
        dtype=torch.float64,
        requires_grad=True,
    )
    cols = torch.tensor([[0.2, 0.4, 0.6, 0.7]], dtype=torch.float64, requires_grad=True)
    img = rasterize(pts, cols, 8, 8)
    img.sum().backward()
    # Grid-aligned edges take their own code path in the backward kernel.
    box = torch.tensor(
        [[[1.0, 1.0], [2.0, 1.0], [3.0, 1.0], [3.0, 1.0], [3.0, 2.0], [3.0, 3.0]]],
        dtype=torch.float32,
        requires_grad=True,
    )
    rasterize(box, cols.float(), 4, 4).sum().backward()
    # A gradient background: its image and its derivatives.
    ramp = torch.zeros(PARAMS, dtype=torch.float64)
    ramp[2], ramp[5] = 4.0, 1.0
    gradient_image(LINEAR, 2, ramp.requires_grad_(True), 4, 4).sum().backward()
