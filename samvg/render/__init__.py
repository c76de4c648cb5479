"""Differentiable CPU rasterizer (exact pixel-area coverage, analytic gradients, numba kernels).

Public API: ``rasterize(points, colors, width, height, background)``, ``render_array`` (the same
for numpy arrays, no gradients), ``render_scene``, ``gradient_image`` (a gradient over the whole
canvas, in torch: a gradient background), ``background_image`` and ``warmup()``.
Written by hand because no maintained library does exact-area differentiable rasterization of
vector paths on the CPU; see ``samvg.render._kernels`` for the method.
"""

from samvg.render.gradient_image import gradient_image
from samvg.render.rasterizer import (
    FLATTEN_TOLERANCE,
    MAX_PIXELS,
    background_image,
    rasterize,
    render_array,
    render_scene,
    warmup,
)

__all__ = [
    "FLATTEN_TOLERANCE",
    "MAX_PIXELS",
    "background_image",
    "gradient_image",
    "rasterize",
    "render_array",
    "render_scene",
    "warmup",
]
