"""Test helpers for the rasterizer: random scenes, SVG text, resvg renders and a 16x16 supersampled
reference renderer (nonzero winding at point samples, written independently of samvg.render)."""

from __future__ import annotations

import io

import numpy as np
from numba import njit

SUPERSAMPLE = 16


# ------------------------------------------------------------------------------------ scenes
def rectangle(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    """Axis-aligned rectangle as a closed path of four straight cubics (controls at thirds)."""
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)
    points = []
    for i in range(4):
        start, end = corners[i], corners[(i + 1) % 4]
        points += [start, start + (end - start) / 3, start + 2 * (end - start) / 3]
    return np.array(points)


def blob(rng: np.random.Generator, cx: float, cy: float, r: float, k: int = 4) -> np.ndarray:
    """Star-shaped closed path of ``k`` cubic segments around (cx, cy), radius about ``r``."""
    ang = np.sort(rng.uniform(0, 2 * np.pi, 3 * k))
    rad = r * (1 + 0.35 * rng.uniform(-1, 1, 3 * k))
    return np.stack([cx + rad * np.cos(ang), cy + rad * np.sin(ang)], 1)


def tangle(rng: np.random.Generator, cx: float, cy: float, r: float, k: int = 4) -> np.ndarray:
    """Self-intersecting path: control points scattered at random in a box."""
    return np.stack([cx + rng.uniform(-r, r, 3 * k), cy + rng.uniform(-r, r, 3 * k)], 1)


def random_scene(
    rng: np.random.Generator, n_paths: int, width: int, height: int, k: int = 4
) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping, translucent, partly off-canvas, sub-pixel and self-intersecting paths.

    Colours are quantized to what SVG text carries (8-bit RGB, 3-decimal opacity).
    """
    size = max(width, height)
    paths = []
    for i in range(n_paths):
        kind = i % 5
        cx = rng.uniform(-0.15, 1.15) * width
        cy = rng.uniform(-0.15, 1.15) * height
        if kind == 0:
            paths.append(blob(rng, cx, cy, rng.uniform(0.2, 1.5), k))  # sub-pixel / tiny
        elif kind == 1:
            paths.append(tangle(rng, cx, cy, rng.uniform(5, 0.3 * size), k))
        else:
            paths.append(blob(rng, cx, cy, rng.uniform(3, 0.35 * size), k))
    colors = rng.uniform(0, 1, (n_paths, 4))
    colors[:, 3] = rng.uniform(0.25, 1.0, n_paths)
    colors[rng.uniform(size=n_paths) < 0.3, 3] = 1.0
    colors[:, :3] = np.round(colors[:, :3] * 255) / 255
    colors[:, 3] = np.round(colors[:, 3], 3)
    return np.stack(paths), colors


# ------------------------------------------------------------------------------------ SVG / resvg
def svg_text(points: np.ndarray, colors: np.ndarray, width: int, height: int) -> str:
    """The scene as SVG text, through samvg's own writer (6 decimals: rounding is negligible)."""
    from samvg.vector_image import VectorImage, VectorPath

    image = VectorImage(
        width,
        height,
        [
            VectorPath(np.asarray(p), tuple(float(v) for v in c))
            for p, c in zip(points, colors, strict=True)
        ],
        (1.0, 1.0, 1.0),
    )
    return image.to_svg(precision=6)


def resvg_render(svg: str) -> np.ndarray:
    """resvg-py render composited over white, as a float64 (H, W, 3) array in [0, 1]."""
    import resvg_py
    from PIL import Image

    png = resvg_py.svg_to_bytes(svg_string=svg, background="#ffffff")
    image = Image.open(io.BytesIO(bytes(png))).convert("RGB")
    return np.asarray(image, dtype=np.float64) / 255.0


# ------------------------------------------------------------------------------------ supersampled
def fine_polygon(ctrl: np.ndarray, pieces: int = 96) -> np.ndarray:
    """Closed polygon through ``pieces`` uniform samples of every cubic of the path."""
    n = ctrl.shape[0]
    t = np.arange(pieces) / pieces
    bern = np.stack([(1 - t) ** 3, 3 * (1 - t) ** 2 * t, 3 * (1 - t) * t**2, t**3], 1)
    out = []
    for s in range(n // 3):
        quad = ctrl[[3 * s, 3 * s + 1, 3 * s + 2, (3 * s + 3) % n]]
        out.append(bern @ quad)
    return np.concatenate(out)


@njit(cache=True)
def _path_coverage_ss(poly, width, height, ss):
    """Fraction of ss x ss point samples per pixel with nonzero winding."""
    count = np.zeros((height, width), np.float64)
    n = poly.shape[0]
    miny = poly[:, 1].min()
    maxy = poly[:, 1].max()
    k0 = max(0, int(np.floor(miny * ss - 0.5)))
    k1 = min(height * ss, int(np.ceil(maxy * ss + 0.5)))
    xs = np.empty(n, np.float64)
    ws = np.empty(n, np.int64)
    for k in range(k0, k1):
        ys = (k + 0.5) / ss
        m = 0
        for e in range(n):
            x0, y0 = poly[e, 0], poly[e, 1]
            j = e + 1 if e + 1 < n else 0
            x1, y1 = poly[j, 0], poly[j, 1]
            if (y0 <= ys < y1) or (y1 <= ys < y0):
                xs[m] = x0 + (ys - y0) * (x1 - x0) / (y1 - y0)
                ws[m] = 1 if y1 > y0 else -1
                m += 1
        if m == 0:
            continue
        order = np.argsort(xs[:m])
        wind = 0
        row = k // ss
        for q in range(m - 1):
            wind += ws[order[q]]
            if wind != 0:
                xa = xs[order[q]]
                xb = xs[order[q + 1]]
                i0 = max(0, int(np.ceil(xa * ss - 0.5)))
                i1 = min(width * ss, int(np.ceil(xb * ss - 0.5)))
                for i in range(i0, i1):
                    count[row, i // ss] += 1.0
    return count / (ss * ss)


def supersampled_render(
    points, colors: np.ndarray, width: int, height: int, ss: int = SUPERSAMPLE
) -> np.ndarray:
    """Reference image: 16x16 point samples per pixel, nonzero rule, straight-alpha over white."""
    canvas = np.ones((height, width, 3), np.float64)
    for ctrl, col in zip(points, colors, strict=True):
        cov = _path_coverage_ss(fine_polygon(np.asarray(ctrl, np.float64)), width, height, ss)
        ac = (col[3] * cov)[..., None]
        canvas = canvas * (1 - ac) + np.asarray(col[:3])[None, None, :] * ac
    return canvas
