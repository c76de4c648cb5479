"""Differentiable CPU rasterizer (exact pixel-area coverage, analytic gradients, numba kernels).

Public API: ``rasterize(points, colors, width, height, background)``, ``render_array`` (the same
for numpy scenes, no gradients) and ``warmup()``.
Written by hand because no maintained library does exact-area differentiable rasterization of
vector paths on the CPU; see ``samvg.render._kernels`` for the method.
"""

from samvg.render.rasterizer import (
    FLATTEN_TOLERANCE,
    MAX_PIXELS,
    rasterize,
    render_array,
    warmup,
)

__all__ = ["FLATTEN_TOLERANCE", "MAX_PIXELS", "rasterize", "render_array", "warmup"]
