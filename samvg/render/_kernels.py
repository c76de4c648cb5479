"""Numba kernels of the exact-area differentiable rasterizer (forward and backward).

Why by hand: no maintained library computes exact box-filtered path coverage *and* its analytic
gradient on the CPU. diffvg estimates the boundary gradient from random edge samples (and needs a
C++/CUDA build), soft rasterizers blur the image, and real renderers (resvg, Skia, Cairo) are not
differentiable. So the kernels are written here, in numba (installs from wheels, no compiler).

Pipeline (all geometry in float64, pixel units, pixel (r, c) is the square [c, c+1] x [r, r+1]):

1. ``plan_and_flatten``: each cubic segment is cut into ``n`` uniform pieces, ``n`` chosen from the
   second differences of its control polygon so the chord error is <= ``tol``. For a fixed ``n`` the
   polyline vertices are a linear map (Bernstein weights; evaluated by de Casteljau so straight,
   axis-aligned segments stay exactly axis-aligned) of the control points, so the backward pass
   chains through it exactly (``flatten_backward``).
2. ``path_boxes``: per path, the bounding box of its polyline clipped to the canvas, widened by one
   pixel up and left (the backward pass of grid-aligned edges reads the neighbour pixel) and one
   spill column on the right. Each box gets a slice of one flat buffer.
3. ``render_forward``, per path in paint order: signed-area accumulation (the font-rs /
   stb_truetype v2 technique). Every line piece inside a pixel deposits ``h * (c + 1 - x_mid)`` in
   its cell and ``h * (x_mid - c)`` in the next one (``h`` = signed height), so the prefix sum
   along a row is the winding-weighted area ``acc`` of each pixel. Pieces left of the canvas
   deposit their full height in column 0 (everything right of them is covered), pieces right of
   the canvas or above/below it deposit nothing. Nonzero-rule coverage is ``min(1, |acc|)``, and
   the path is composited at once with straight-alpha "over":
   ``out = out * (1 - a cov) + rgb * a cov``. For the backward pass ``acc`` and the colour under
   the path are kept per box pixel (20 bytes per box pixel); a no-grad call keeps nothing.

Backward (``render_backward``), per path in reverse paint order: dL/dcov of every box pixel and
the colour gradients from the compositing, then the exact boundary integral for the vertices:
the coverage of a pixel only changes where an edge crosses it, and with ``F'(x) = -dL/dacc`` of
the pixel under the edge, an edge a->b gets ``(1 - s) F' (dy, -dx)`` on ``a`` and
``s F' (dy, -dx)`` on ``b``, integrated over the parameter ``s`` of each piece (exactly: ``F'``
is constant per pixel). Endpoint terms cancel between consecutive edges of a closed path.
Axis-aligned edges lying exactly on pixel grid lines use the average of the left and right
one-sided derivatives (otherwise the kink of ``min(1, |acc|)`` would give them a zero gradient).
Work is O(sum of path box areas + number of edge/pixel crossings), never paths x canvas.

Limits: ``min(1, |acc|)`` is the exact nonzero-rule area except in pixels where regions of
different winding numbers meet (a self-intersection inside the pixel); there it approximates, like
font rasterizers do. The kernels are single-threaded on purpose: on the 2-core target machine the
numba OpenMP/workqueue layers cost more in wake-up latency (and fight torch's own threads) than the
~1 ms of work per call they would split.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from samvg.render._paint_kernels import FLAT, paint_row, paint_row_backward

_MAX_PIECES = 256
_EPS_ACC = 1e-9


# --------------------------------------------------------------------------------------------
# Flattening
# --------------------------------------------------------------------------------------------


@njit(cache=True, nogil=True)
def _seg_end(i0: int, a: int, b: int) -> int:
    return i0 + 3 if i0 + 3 < b else a


@njit(cache=True, nogil=True)
def plan_and_flatten(
    ctrl: np.ndarray, path_start: np.ndarray, width: int, height: int, tol: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Choose the piece count of every segment and flatten all paths.

    Returns ``(seg_n, path_vstart, verts)``: pieces per segment, the first vertex of each path in
    ``verts`` (length P + 1) and the polyline vertices (V, 2).
    """
    n_paths = path_start.shape[0] - 1
    n_seg = ctrl.shape[0] // 3
    seg_n = np.empty(n_seg, np.int64)
    path_vstart = np.zeros(n_paths + 1, np.int64)
    total = 0
    for p in range(n_paths):
        a = path_start[p]
        b = path_start[p + 1]
        for s in range(a // 3, b // 3):
            i0 = 3 * s
            i3 = _seg_end(i0, a, b)
            x0, y0 = ctrl[i0, 0], ctrl[i0, 1]
            x1, y1 = ctrl[i0 + 1, 0], ctrl[i0 + 1, 1]
            x2, y2 = ctrl[i0 + 2, 0], ctrl[i0 + 2, 1]
            x3, y3 = ctrl[i3, 0], ctrl[i3, 1]
            minx = min(min(x0, x1), min(x2, x3))
            maxx = max(max(x0, x1), max(x2, x3))
            miny = min(min(y0, y1), min(y2, y3))
            maxy = max(max(y0, y1), max(y2, y3))
            n = 1
            # A segment above, below or right of the canvas contributes nothing however it is cut
            # (one lying on the border still needs its pieces: its gradient is one-sided there).
            if not (maxy < 0.0 or miny > height or minx > width):
                ax = x0 - 2.0 * x1 + x2
                ay = y0 - 2.0 * y1 + y2
                bx = x1 - 2.0 * x2 + x3
                by = y1 - 2.0 * y2 + y3
                if maxx < 0.0:
                    # Left of the canvas only the rows it spans matter: flatten y only.
                    ax = 0.0
                    bx = 0.0
                m = max(math.sqrt(ax * ax + ay * ay), math.sqrt(bx * bx + by * by))
                # Uniform cut of a cubic: chord error <= |B''|max / (8 n^2), |B''| <= 6 m.
                nf = math.ceil(math.sqrt(0.75 * m / tol))
                if nf > _MAX_PIECES:
                    n = _MAX_PIECES
                elif nf > 1:
                    n = int(nf)
            seg_n[s] = n
            total += n
        path_vstart[p + 1] = total

    verts = np.empty((total, 2), np.float64)
    for p in range(n_paths):
        a = path_start[p]
        b = path_start[p + 1]
        v = path_vstart[p]
        for s in range(a // 3, b // 3):
            i0 = 3 * s
            i3 = _seg_end(i0, a, b)
            n = seg_n[s]
            for i in range(n):
                t = i / n
                for d in range(2):
                    # de Casteljau: the same linear map as the Bernstein form, but equal
                    # coordinates stay exactly equal (grid-aligned edges stay grid-aligned).
                    p0 = ctrl[i0, d]
                    p1 = ctrl[i0 + 1, d]
                    p2 = ctrl[i0 + 2, d]
                    p3 = ctrl[i3, d]
                    q0 = p0 + t * (p1 - p0)
                    q1 = p1 + t * (p2 - p1)
                    q2 = p2 + t * (p3 - p2)
                    r0 = q0 + t * (q1 - q0)
                    r1 = q1 + t * (q2 - q1)
                    verts[v, d] = r0 + t * (r1 - r0)
                v += 1
    return seg_n, path_vstart, verts


@njit(cache=True, nogil=True)
def flatten_backward(
    gverts: np.ndarray,
    path_start: np.ndarray,
    seg_n: np.ndarray,
    path_vstart: np.ndarray,
    n_ctrl: int,
) -> np.ndarray:
    """Chain vertex gradients (V, 2) to control-point gradients (N, 2) via the Bernstein weights."""
    g = np.zeros((n_ctrl, 2), np.float64)
    n_paths = path_start.shape[0] - 1
    for p in range(n_paths):
        a = path_start[p]
        b = path_start[p + 1]
        v = path_vstart[p]
        for s in range(a // 3, b // 3):
            i0 = 3 * s
            i3 = _seg_end(i0, a, b)
            n = seg_n[s]
            for i in range(n):
                t = i / n
                mt = 1.0 - t
                b0 = mt * mt * mt
                b1 = 3.0 * mt * mt * t
                b2 = 3.0 * mt * t * t
                b3 = t * t * t
                for d in range(2):
                    gv = gverts[v, d]
                    g[i0, d] += b0 * gv
                    g[i0 + 1, d] += b1 * gv
                    g[i0 + 2, d] += b2 * gv
                    g[i3, d] += b3 * gv
                v += 1
    return g


@njit(cache=True, nogil=True)
def path_boxes(
    verts: np.ndarray, path_vstart: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray]:
    """Per path ``(bx0, by0, bw, bh)`` (bw without the spill column) and buffer offsets.

    The box is the clipped polyline bounding box widened by one pixel up and left; the buffer
    slice of a path is ``bh * (bw + 1)`` values (one spill column on the right).
    """
    n_paths = path_vstart.shape[0] - 1
    box = np.zeros((n_paths, 4), np.int64)
    off = np.zeros(n_paths + 1, np.int64)
    for p in range(n_paths):
        v0 = path_vstart[p]
        v1 = path_vstart[p + 1]
        size = 0
        if v1 > v0:
            minx = verts[v0, 0]
            maxx = minx
            miny = verts[v0, 1]
            maxy = miny
            for v in range(v0 + 1, v1):
                x = verts[v, 0]
                y = verts[v, 1]
                minx = min(minx, x)
                maxx = max(maxx, x)
                miny = min(miny, y)
                maxy = max(maxy, y)
            if maxx >= 0.0 and minx <= width and maxy >= 0.0 and miny <= height:
                # Clamp before converting: huge coordinates must not overflow int64.
                bx0 = max(0, int(math.floor(max(minx, 0.0))) - 1)
                by0 = max(0, int(math.floor(max(miny, 0.0))) - 1)
                bx1 = min(width, int(math.floor(min(maxx, float(width)))) + 1)
                by1 = min(height, int(math.floor(min(maxy, float(height)))) + 1)
                if bx1 > bx0 and by1 > by0:
                    box[p, 0] = bx0
                    box[p, 1] = by0
                    box[p, 2] = bx1 - bx0
                    box[p, 3] = by1 - by0
                    size = (by1 - by0) * (bx1 - bx0 + 1)
        off[p + 1] = off[p] + size
    return box, off


# --------------------------------------------------------------------------------------------
# Forward coverage
# --------------------------------------------------------------------------------------------


@njit(cache=True, nogil=True)
def _row_deposit(xa: float, xb: float, h: float, acc: np.ndarray, base: int, bw: int) -> None:
    """Deposit a line piece inside one pixel row (x linear from xa to xb, signed height h)."""
    lo = min(xa, xb)
    hi = max(xa, xb)
    if lo >= bw:
        return
    if hi <= 0.0:
        acc[base] += h
        return
    if hi == lo:
        c = int(math.floor(lo))
        acc[base + c] += h * (c + 1 - lo)
        acc[base + c + 1] += h * (lo - c)
        return
    inv = h / (hi - lo)
    x = lo
    if lo < 0.0:
        acc[base] += inv * (0.0 - lo)
        x = 0.0
    end = min(hi, float(bw))
    c = int(math.floor(x))
    while x < end:
        nx = min(float(c + 1), end)
        hh = inv * (nx - x)
        xm = 0.5 * (x + nx)
        acc[base + c] += hh * (c + 1 - xm)
        acc[base + c + 1] += hh * (xm - c)
        x = nx
        c += 1


@njit(cache=True, nogil=True)
def _edge_deposit(
    x0: float, y0: float, x1: float, y1: float, bw: int, bh: int,
    acc: np.ndarray, off: int, stride: int, rlo: int, rhi: int,
) -> None:  # fmt: skip
    """Deposit edge (x0, y0) -> (x1, y1) in the box rows ``rlo`` to ``rhi`` (exclusive); a row's
    deposits do not depend on which rows are asked for."""
    if y0 == y1:
        return
    ylo = min(y0, y1)
    yhi = max(y0, y1)
    if yhi <= 0.0 or ylo >= bh or min(x0, x1) >= bw:
        return
    ys = max(ylo, 0.0)
    ye = min(yhi, float(bh))
    dy = y1 - y0
    dx = x1 - x0
    inv_dy = 1.0 / dy
    sgn = 1.0 if dy > 0.0 else -1.0
    r0 = max(int(math.floor(ys)), rlo)
    r1 = min(int(math.ceil(ye)), rhi)
    for r in range(r0, r1):
        ya = max(ys, float(r))
        yb = min(ye, float(r + 1))
        if yb <= ya:
            continue
        xa = x0 + ((ya - y0) * inv_dy) * dx
        xb = x0 + ((yb - y0) * inv_dy) * dx
        _row_deposit(xa, xb, (yb - ya) * sgn, acc, off + r * stride, bw)


@njit(cache=True, nogil=True)
def _path_deposits(
    verts: np.ndarray, v0: int, v1: int, bx0: int, by0: int, bw: int, bh: int,
    acc: np.ndarray, off: int, rlo: int, rhi: int,
) -> None:  # fmt: skip
    """Zero box rows ``rlo`` to ``rhi`` of one path's buffer and deposit its edges there
    (before the row prefix sums)."""
    stride = bw + 1
    for i in range(off + rlo * stride, off + rhi * stride):
        acc[i] = 0.0
    n = v1 - v0
    for e in range(n):
        j = v0 + e + 1 if e + 1 < n else v0
        _edge_deposit(
            verts[v0 + e, 0] - bx0,
            verts[v0 + e, 1] - by0,
            verts[j, 0] - bx0,
            verts[j, 1] - by0,
            bw,
            bh,
            acc,
            off,
            stride,
            rlo,
            rhi,
        )


@njit(cache=True, nogil=True)
def row_bands(box: np.ndarray, height: int, parts: int) -> np.ndarray:
    """``parts + 1`` row boundaries that split the canvas into bands of about equal work (the
    box pixels of all paths in each band; a band may be empty)."""
    work = np.zeros(height + 1, np.float64)
    for p in range(box.shape[0]):
        if box[p, 2] > 0 and box[p, 3] > 0:
            work[box[p, 1]] += box[p, 2] + 1
            work[box[p, 1] + box[p, 3]] -= box[p, 2] + 1
    row_work = np.empty(height, np.float64)
    running = 0.0
    for y in range(height):
        running += work[y]
        row_work[y] = running + 1.0  # the background fill and the row itself
    return _split_work(row_work, parts)


@njit(cache=True, nogil=True)
def _split_work(work: np.ndarray, parts: int) -> np.ndarray:
    """``parts + 1`` boundaries that cut the items of ``work`` (their costs, in order) into
    ``parts`` consecutive runs of about equal cost (a run may be empty)."""
    count = work.shape[0]
    total = 0.0
    for i in range(count):
        total += work[i]
    bounds = np.empty(parts + 1, np.int64)
    bounds[0] = 0
    bounds[parts] = count
    done = 0.0
    item = 0
    for i in range(1, parts):
        goal = total * i / parts
        while item < count and done + work[item] <= goal:
            done += work[item]
            item += 1
        bounds[i] = max(item, bounds[i - 1])
    return bounds


@njit(cache=True, nogil=True)
def render_forward(
    verts: np.ndarray, path_vstart: np.ndarray, box: np.ndarray, off: np.ndarray,
    colors: np.ndarray, background: np.ndarray, canvas: np.ndarray, acc: np.ndarray,
    under: np.ndarray, keep: bool, kinds: np.ndarray, stops: np.ndarray, params: np.ndarray,
    row0: int, row1: int,
) -> None:  # fmt: skip
    """Coverage and straight-alpha "over" compositing of canvas rows ``row0`` to ``row1``
    (exclusive), path by path in paint order, over the opaque RGB ``background`` (3,); an empty
    ``background`` (0,) paints over ``canvas`` as given (an image the caller filled it with).
    Every pixel's value is the same whichever band computes it, so bands can run on threads.

    A path whose ``kinds`` entry is not ``FLAT`` takes its RGB per pixel from its gradient paint
    (``samvg.render._paint_kernels``); its alpha is still ``colors[p, 3]``.

    ``canvas`` (H, W, 3, float32 or float64) receives the image. With ``keep`` the winding-area
    of every box pixel stays in ``acc`` at ``off[p]`` and the colour under it in ``under`` (for the
    backward pass); without, ``acc`` is a scratch buffer of the largest box and ``under`` unused.
    """
    if background.shape[0] == 3:
        for y in range(row0, row1):
            for x in range(canvas.shape[1]):
                for ch in range(3):
                    canvas[y, x, ch] = background[ch]
    n_paths = box.shape[0]
    rgb = np.empty((canvas.shape[1], 3), np.float64)  # a gradient's colours along one box row
    for p in range(n_paths):
        bw = box[p, 2]
        bh = box[p, 3]
        by0 = box[p, 1]
        rlo = max(0, row0 - by0)
        rhi = min(bh, row1 - by0)
        if bw <= 0 or rhi <= rlo:
            continue
        bx0 = box[p, 0]
        o = off[p] if keep else 0
        _path_deposits(
            verts, path_vstart[p], path_vstart[p + 1], bx0, by0, bw, bh, acc, o, rlo, rhi
        )
        a = colors[p, 3]
        cr = colors[p, 0]
        cg = colors[p, 1]
        cb = colors[p, 2]
        flat = kinds[p] == FLAT
        stride = bw + 1
        for r in range(rlo, rhi):
            y = by0 + r
            base = o + r * stride
            wind = 0.0
            if not flat:
                paint_row(kinds, stops, params, p, y, bx0, bw, rgb)
            for c in range(bw):
                k = base + c
                wind += acc[k]
                acc[k] = wind
                x = bx0 + c
                if keep:
                    under[k, 0] = canvas[y, x, 0]
                    under[k, 1] = canvas[y, x, 1]
                    under[k, 2] = canvas[y, x, 2]
                cov = min(1.0, abs(wind))
                if cov > 0.0:
                    if not flat:
                        cr = rgb[c, 0]
                        cg = rgb[c, 1]
                        cb = rgb[c, 2]
                    ac = a * cov
                    keep_c = 1.0 - ac
                    canvas[y, x, 0] = canvas[y, x, 0] * keep_c + cr * ac
                    canvas[y, x, 1] = canvas[y, x, 1] * keep_c + cg * ac
                    canvas[y, x, 2] = canvas[y, x, 2] * keep_c + cb * ac


# --------------------------------------------------------------------------------------------
# Backward
# --------------------------------------------------------------------------------------------


@njit(cache=True, nogil=True)
def _dacc(acc_v: float) -> float:
    """d min(1, |acc|) / d acc away from the kinks (0 at the kinks)."""
    a = abs(acc_v)
    if a <= _EPS_ACC or a >= 1.0 - _EPS_ACC:
        return 0.0
    return 1.0 if acc_v > 0.0 else -1.0


@njit(cache=True, nogil=True)
def _one_sided(acc_v: float, direction: float) -> float:
    """One-sided derivative of min(1, |acc|) when acc moves in ``direction`` (+1 / -1)."""
    a = abs(acc_v)
    if a <= _EPS_ACC:
        return 1.0
    sa = 1.0 if acc_v > 0.0 else -1.0
    if a < 1.0 - _EPS_ACC:
        return sa * direction
    if a < 1.0 + _EPS_ACC and sa * direction < 0.0:
        return -1.0
    return 0.0


@njit(cache=True, nogil=True)
def _piece_weights(fp: float, s0: float, s1: float) -> tuple[float, float]:
    """Integrals of ``(1 - s) fp`` and ``s fp`` over the parameter interval between s0 and s1."""
    if s0 > s1:
        s0, s1 = s1, s0
    i1 = 0.5 * (s1 * s1 - s0 * s0)
    return fp * ((s1 - s0) - i1), fp * i1


@njit(cache=True, nogil=True)
def _horizontal_weights(
    xa: float, ya: float, xb: float, bw: int, bh: int,
    acc: np.ndarray, dcov: np.ndarray, off: int, doff: int, stride: int,
) -> tuple[float, float]:  # fmt: skip
    """(integral of (1 - s) F' ds, integral of s F' ds) along a horizontal edge a->b."""
    dx = xb - xa
    ga = 0.0
    gb = 0.0
    if dx == 0.0 or ya < 0.0 or ya > bh:
        return ga, gb
    r = int(math.floor(ya))
    degenerate = ya == r
    lo = max(min(xa, xb), 0.0)
    hi = min(max(xa, xb), float(bw))
    if hi <= lo:
        return ga, gb
    sdx = 1.0 if dx > 0.0 else -1.0
    c = int(math.floor(lo))
    x = lo
    while x < hi:
        nx = min(float(c + 1), hi)
        s0 = (x - xa) / dx
        s1 = (nx - xa) / dx
        if degenerate:
            # dL/dy from below (row r) and from above (row r - 1), averaged.
            down = 0.0
            up = 0.0
            if r < bh:
                k = off + r * stride + c
                down = dcov[k - off + doff] * _one_sided(acc[k], sdx)
            if r >= 1:
                k = off + (r - 1) * stride + c
                up = -dcov[k - off + doff] * _one_sided(acc[k], -sdx)
            # dL/dy = -dx_piece F'  ->  F' = -(dL/dy per unit |dx|) * sign / ...
            fp = -0.5 * (down + up) * sdx
        else:
            if r >= bh:
                break
            k = off + r * stride + c
            fp = -dcov[k - off + doff] * _dacc(acc[k])
        da, db = _piece_weights(fp, s0, s1)
        ga += da
        gb += db
        x = nx
        c += 1
    return ga, gb


@njit(cache=True, nogil=True)
def _grid_vertical_row(
    ga: float, gb: float, y_lo: float, y_hi: float, xa: float, ya: float, inv_dy: float,
    sdy: float, bw: int, base: int, acc: np.ndarray, dcov: np.ndarray, off: int, doff: int,
) -> tuple[float, float]:  # fmt: skip
    """``(ga, gb)`` plus one row of a vertical edge lying on a pixel boundary."""
    s0 = (y_lo - ya) * inv_dy
    s1 = (y_hi - ya) * inv_dy
    c = int(xa)
    right = 0.0
    left = 0.0
    if 0 <= c < bw:
        right = dcov[base + c - off + doff] * _one_sided(acc[base + c], -sdy) * sdy
    if 1 <= c <= bw:
        left = -dcov[base + c - 1 - off + doff] * _one_sided(acc[base + c - 1], sdy) * sdy
    fp = 0.5 * (right + left)
    da, db = _piece_weights(fp, s0, s1)
    return ga + da, gb + db


@njit(cache=True, nogil=True)
def _sloped_row(
    ga: float, gb: float, y_lo: float, y_hi: float, xa: float, ya: float, dx: float,
    inv_dy: float, bw: int, base: int, acc: np.ndarray, dcov: np.ndarray, off: int, doff: int,
) -> tuple[float, float]:  # fmt: skip
    """``(ga, gb)`` plus the pieces of one row crossed by a sloped edge, pixel by pixel (the
    sums keep the order of the pieces)."""
    s_lo = (y_lo - ya) * inv_dy
    s_hi = (y_hi - ya) * inv_dy
    x_lo = xa + s_lo * dx
    x_hi = xa + s_hi * dx
    lo = min(x_lo, x_hi)
    hi = max(x_lo, x_hi)
    if lo >= bw or hi <= 0.0:
        return ga, gb  # F is constant there: no gradient
    if hi == lo:
        c = int(math.floor(lo))
        fp = -dcov[base + c - off + doff] * _dacc(acc[base + c])
        da, db = _piece_weights(fp, s_lo, s_hi)
        return ga + da, gb + db
    x = max(lo, 0.0)
    end = min(hi, float(bw))
    c = int(math.floor(x))
    # s as a function of x inside this row (well conditioned for near-vertical edges too).
    ds_dx = (s_hi - s_lo) / (x_hi - x_lo)
    while x < end:
        nx = min(float(c + 1), end)
        s0 = s_lo + (x - x_lo) * ds_dx
        s1 = s_lo + (nx - x_lo) * ds_dx
        fp = -dcov[base + c - off + doff] * _dacc(acc[base + c])
        da, db = _piece_weights(fp, s0, s1)
        ga += da
        gb += db
        x = nx
        c += 1
    return ga, gb


@njit(cache=True, nogil=True)
def _edge_backward(
    xa: float, ya: float, xb: float, yb: float, bw: int, bh: int,
    acc: np.ndarray, dcov: np.ndarray, off: int, doff: int, stride: int,
) -> tuple[float, float, float, float]:  # fmt: skip
    """Return (gxa, gya, gxb, gyb): dL/d endpoints of edge a->b (box coordinates)."""
    dx = xb - xa
    dy = yb - ya
    if dy == 0.0:
        ga, gb = _horizontal_weights(xa, ya, xb, bw, bh, acc, dcov, off, doff, stride)
        return ga * dy, -ga * dx, gb * dy, -gb * dx
    ga = 0.0  # integral of (1 - s) F' ds
    gb = 0.0  # integral of s F' ds
    ylo = min(ya, yb)
    yhi = max(ya, yb)
    if yhi <= 0.0 or ylo >= bh or min(xa, xb) > bw:
        return 0.0, 0.0, 0.0, 0.0
    ys = max(ylo, 0.0)
    ye = min(yhi, float(bh))
    inv_dy = 1.0 / dy
    sdy = 1.0 if dy > 0.0 else -1.0
    vertical_on_grid = dx == 0.0 and 0.0 <= xa <= bw and xa == math.floor(xa)
    for r in range(int(math.floor(ys)), int(math.ceil(ye))):
        y_lo = max(ys, float(r))
        y_hi = min(ye, float(r + 1))
        if y_hi <= y_lo:
            continue
        base = off + r * stride
        if vertical_on_grid:
            ga, gb = _grid_vertical_row(
                ga, gb, y_lo, y_hi, xa, ya, inv_dy, sdy, bw, base, acc, dcov, off, doff
            )
        else:
            ga, gb = _sloped_row(
                ga, gb, y_lo, y_hi, xa, ya, dx, inv_dy, bw, base, acc, dcov, off, doff
            )
    return ga * dy, -ga * dx, gb * dy, -gb * dx


@njit(cache=True, nogil=True)
def _path_edges_backward(
    verts: np.ndarray, path_vstart: np.ndarray, p: int, bx0: int, by0: int, bw: int, bh: int,
    acc: np.ndarray, dcov: np.ndarray, o: int, gverts: np.ndarray,
) -> None:  # fmt: skip
    """Add to ``gverts`` what the edges of path ``p`` get from dL/dcov of its box (``dcov``, laid
    out like ``acc``)."""
    stride = bw + 1
    v0 = path_vstart[p]
    n = path_vstart[p + 1] - v0
    for e in range(n):
        i = v0 + e
        j = v0 + e + 1 if e + 1 < n else v0
        gxa, gya, gxb, gyb = _edge_backward(
            verts[i, 0] - bx0,
            verts[i, 1] - by0,
            verts[j, 0] - bx0,
            verts[j, 1] - by0,
            bw,
            bh,
            acc,
            dcov,
            o,
            o,
            stride,
        )
        gverts[i, 0] += gxa
        gverts[i, 1] += gya
        gverts[j, 0] += gxb
        gverts[j, 1] += gyb


@njit(cache=True, nogil=True)
def _path_pixels_backward(
    grad_out: np.ndarray, p: int, bx0: int, by0: int, bw: int, rlo: int, rhi: int, o: int,
    colors: np.ndarray, acc: np.ndarray, under: np.ndarray, dcov: np.ndarray,
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray,
    rgb: np.ndarray, grgb: np.ndarray, gsum: np.ndarray,
) -> tuple[float, float, float, float]:  # fmt: skip
    """Box rows ``rlo`` to ``rhi`` of path ``p``: dL/dcov into ``dcov`` (laid out like ``acc``)
    and ``grad_out`` passed under the path. Returns dL/d its RGBA from these rows; a gradient
    path's RGB gradient goes to its paint parameters instead (added to ``gsum``, row by row;
    ``rgb`` and ``grgb`` are scratch rows of the canvas width).
    """
    a = colors[p, 3]
    cr = colors[p, 0]
    cg = colors[p, 1]
    cb = colors[p, 2]
    flat = kinds[p] == FLAT
    stride = bw + 1
    sr = 0.0
    sg = 0.0
    sb = 0.0
    sa = 0.0
    for r in range(rlo, rhi):
        y = by0 + r
        if not flat:
            paint_row(kinds, stops, params, p, y, bx0, bw, rgb)
        for c in range(bw):
            x = bx0 + c
            k = o + r * stride + c
            g0 = grad_out[y, x, 0]
            g1 = grad_out[y, x, 1]
            g2 = grad_out[y, x, 2]
            if not flat:
                cr = rgb[c, 0]
                cg = rgb[c, 1]
                cb = rgb[c, 2]
            dot = g0 * (cr - under[k, 0]) + g1 * (cg - under[k, 1]) + g2 * (cb - under[k, 2])
            dcov[k] = a * dot
            cov = min(1.0, abs(acc[k]))
            if cov > 0.0:
                ac = a * cov
                if flat:
                    sr += g0 * ac
                    sg += g1 * ac
                    sb += g2 * ac
                else:
                    grgb[c, 0] = g0 * ac
                    grgb[c, 1] = g1 * ac
                    grgb[c, 2] = g2 * ac
                sa += cov * dot
                keep = 1.0 - ac
                grad_out[y, x, 0] = g0 * keep
                grad_out[y, x, 1] = g1 * keep
                grad_out[y, x, 2] = g2 * keep
            elif not flat:
                grgb[c, 0] = 0.0
                grgb[c, 1] = 0.0
                grgb[c, 2] = 0.0
        if not flat:
            paint_row_backward(kinds, stops, params, p, y, bx0, bw, grgb, gsum)
    return sr, sg, sb, sa


@njit(cache=True, nogil=True)
def render_backward_pixels(
    grad_out: np.ndarray, box: np.ndarray, off: np.ndarray, colors: np.ndarray,
    acc: np.ndarray, under: np.ndarray, dcov: np.ndarray,
    kinds: np.ndarray, stops: np.ndarray, params: np.ndarray,
    gcol: np.ndarray, gparams: np.ndarray, row0: int, row1: int,
) -> None:  # fmt: skip
    """The pixel part of ``render_forward``'s gradient on canvas rows ``row0`` to ``row1``:
    paths in reverse paint order, each getting dL/dcov of its box pixels (``dcov``, laid out
    like ``acc``) and its colour gradient from these rows (``gcol`` (P, 4), and ``gparams``
    (P, PARAMS) for gradient paints, both zeroed by the caller), while the canvas gradient
    ``grad_out`` (H, W, 3, float64, overwritten) is passed under it. Each band of rows has its
    own ``gcol`` and ``gparams`` (bands run on threads); one band over the whole canvas sums
    every path's pixels in row-major order."""
    rgb = np.empty((grad_out.shape[1], 3), np.float64)
    grgb = np.empty((grad_out.shape[1], 3), np.float64)
    for p in range(box.shape[0] - 1, -1, -1):
        bw = box[p, 2]
        by0 = box[p, 1]
        rlo = max(0, row0 - by0)
        rhi = min(box[p, 3], row1 - by0)
        if bw <= 0 or rhi <= rlo:
            continue
        gcol[p, 0], gcol[p, 1], gcol[p, 2], gcol[p, 3] = _path_pixels_backward(
            grad_out, p, box[p, 0], by0, bw, rlo, rhi, off[p], colors, acc, under, dcov,
            kinds, stops, params, rgb, grgb, gparams[p],
        )  # fmt: skip


@njit(cache=True, nogil=True)
def path_bands(box: np.ndarray, path_vstart: np.ndarray, parts: int) -> np.ndarray:
    """``parts + 1`` path boundaries that split the edge pass into runs of about equal work."""
    n_paths = box.shape[0]
    work = np.empty(n_paths, np.float64)
    for p in range(n_paths):
        work[p] = path_vstart[p + 1] - path_vstart[p] + box[p, 2] + box[p, 3] + 1.0
    return _split_work(work, parts)


@njit(cache=True, nogil=True)
def render_backward_edges(
    verts: np.ndarray, path_vstart: np.ndarray, box: np.ndarray, off: np.ndarray,
    acc: np.ndarray, dcov: np.ndarray, gverts: np.ndarray, p0: int, p1: int,
) -> None:  # fmt: skip
    """The edge part of the gradient for paths ``p0`` to ``p1`` (exclusive): dL/dcov turned into
    dL/d their vertices, added to ``gverts`` (V, 2). Paths own disjoint vertex rows, so runs of
    paths can go to threads."""
    for p in range(p1 - 1, p0 - 1, -1):
        bw = box[p, 2]
        bh = box[p, 3]
        if bw <= 0 or bh <= 0:
            continue
        _path_edges_backward(
            verts, path_vstart, p, box[p, 0], box[p, 1], bw, bh, acc, dcov, off[p], gverts
        )
