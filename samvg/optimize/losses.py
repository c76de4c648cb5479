"""The fitting objective's terms besides MSE: LIVE's Xing loss against self-intersecting
segments, and LPIPS against a fixed target as a differentiable perceptual loss."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import torch
import torch.nn.functional as functional

from samvg.metrics.lpips import load_lpips

PerceptualLoss = Callable[[torch.Tensor], torch.Tensor]
"""``loss(rendered)``: a differentiable scalar for an (H, W, 3) render (its target bound inside)."""


def _cross(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def segment_indices(offsets: np.ndarray) -> tuple[torch.Tensor, ...]:
    """For packed paths with start ``offsets`` (P + 1), the indices of every segment's start,
    first handle, second handle and end point, path by path: four (S,) int64 tensors."""
    offsets = np.asarray(offsets, dtype=np.int64)
    counts = np.diff(offsets)
    segments = counts // 3
    path = np.repeat(np.arange(len(counts)), segments)
    first_segment = np.repeat(np.cumsum(segments) - segments, segments)
    local = 3 * (np.arange(int(segments.sum())) - first_segment)
    start = offsets[path] + local
    end = offsets[path] + (local + 3) % counts[path]
    return tuple(torch.from_numpy(index) for index in (start, start + 1, start + 2, end))


def xing_loss(
    points: torch.Tensor,
    offsets: np.ndarray | None = None,
    eps: float = 1e-8,
    indices: tuple[torch.Tensor, ...] | None = None,
) -> torch.Tensor:
    """Mean Xing loss over all cubic segments of closed paths.

    ``points`` is packed (N, 2) with path ``offsets`` (P + 1), or (P, 3K, 2) for paths of equal
    length; ``indices`` (from `segment_indices`) may be passed to skip recomputing them. Per
    segment with handles a = P1 − P0, b = P2 − P1, c = P3 − P2: D = 1 if a × b >= 0 else 0 (no
    gradient through D), s = (a × c) / (|a||c| + eps); the term D·ReLU(−s) + (1 − D)·ReLU(s) is
    zero when the two handles turn the same way as the curve and grows as they cross.
    """
    if points.numel() == 0:
        return points.sum() * 0.0
    if points.dim() == 3:
        paths, per_path = points.shape[:2]
        offsets = np.arange(paths + 1, dtype=np.int64) * per_path
        points = points.reshape(-1, 2)
    if indices is None:
        if offsets is None:
            raise ValueError("packed points need their path offsets")
        indices = segment_indices(offsets)
    start, first, second, end = (points.index_select(0, index) for index in indices)
    a, b, c = first - start, second - first, end - second
    turns_left = (_cross(a, b) >= 0).to(points.dtype).detach()
    sine = _cross(a, c) / (a.norm(dim=-1) * c.norm(dim=-1) + eps)
    term = turns_left * torch.relu(-sine) + (1.0 - turns_left) * torch.relu(sine)
    return term.mean()


def lpips_loss(target: np.ndarray, size: int, weights: str | None = None) -> PerceptualLoss:
    """LPIPS of a render against ``target``, both resized so the longer side is ``size``.

    Raises `WeightsError` when the LPIPS weights cannot be found.
    """
    model = load_lpips(weights)
    height, width = target.shape[:2]
    factor = min(1.0, size / max(height, width))
    shape = (max(16, round(height * factor)), max(16, round(width * factor)))

    def prepare(image: torch.Tensor) -> torch.Tensor:
        batch = image.permute(2, 0, 1)[None]
        if tuple(batch.shape[-2:]) != shape:
            batch = functional.interpolate(batch, size=shape, mode="bilinear", antialias=True)
        return batch

    target_batch = prepare(torch.from_numpy(np.ascontiguousarray(target, dtype=np.float32)))
    against_target = model.fixed_target(target_batch)

    def loss(rendered: torch.Tensor) -> torch.Tensor:
        return against_target(prepare(rendered)).mean()

    return loss
