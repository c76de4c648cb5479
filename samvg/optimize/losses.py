"""Regularizing losses on path geometry: LIVE's Xing loss against self-intersecting segments."""

from __future__ import annotations

import torch


def _cross(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def xing_loss(points: torch.Tensor, eps: float = 1e-8) -> torch.Tensor:
    """Mean Xing loss over all cubic segments of closed paths ``points`` (P, 3K, 2).

    Per segment with handles a = P1 − P0, b = P2 − P1, c = P3 − P2: D = 1 if a × b >= 0 else 0
    (no gradient through D), s = (a × c) / (|a||c| + eps); the term D·ReLU(−s) + (1 − D)·ReLU(s)
    is zero when the two handles turn the same way as the curve and grows as they cross.
    """
    if points.numel() == 0:
        return points.sum() * 0.0
    start = points[:, 0::3]
    first = points[:, 1::3]
    second = points[:, 2::3]
    end = torch.roll(points, shifts=-3, dims=1)[:, 0::3]
    a, b, c = first - start, second - first, end - second
    turns_left = (_cross(a, b) >= 0).to(points.dtype).detach()
    sine = _cross(a, c) / (a.norm(dim=-1) * c.norm(dim=-1) + eps)
    term = turns_left * torch.relu(-sine) + (1.0 - turns_left) * torch.relu(sine)
    return term.mean()
