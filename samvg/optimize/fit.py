"""Adam on control points and fill colours through the differentiable rasterizer: loss = MSE to
the target + λ_Xing · Xing loss + λ_LPIPS · LPIPS (the paper's objective).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import torch

from samvg.errors import InputError
from samvg.optimize.losses import xing_loss
from samvg.render import rasterize

PerceptualLoss = Callable[[torch.Tensor], torch.Tensor]
"""``loss(rendered)``: a differentiable scalar for an (H, W, 3) render (its target bound inside)."""


@dataclass
class FitResult:
    """Optimised ``points`` (P, 3K, 2), ``colours`` (P, 4) and the total loss after each step."""

    points: np.ndarray
    colours: np.ndarray
    losses: list[float]


@contextlib.contextmanager
def single_torch_thread() -> Iterator[None]:
    """Run torch on one thread inside the block.

    The per-step tensors are small: a thread pool costs more than it saves, and it slows down
    badly whenever another process holds one of the cores.
    """
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


def fit_paths(
    points: np.ndarray,
    colours: np.ndarray,
    target: np.ndarray,
    steps: int = 300,
    point_learning_rate: float = 1.0,
    colour_learning_rate: float = 0.01,
    background: tuple[float, float, float] = (1.0, 1.0, 1.0),
    on_step: Callable[[int, float], None] | None = None,
    xing_weight: float = 0.0,
    lpips: PerceptualLoss | None = None,
    lpips_weight: float = 0.0,
) -> FitResult:
    """Fit paths to ``target`` (H, W, 3) float in [0, 1] for ``steps`` Adam steps.

    ``lpips`` is a perceptual loss of the render (see `PerceptualLoss`), weighted by
    ``lpips_weight``; ``on_step(step, loss)`` is called after every step (progress reporting).
    Colours are clamped to [0, 1] after every step.
    """
    target_array = np.asarray(target, dtype=np.float32)
    if target_array.ndim != 3 or target_array.shape[2] != 3:
        raise InputError(f"target must be an (H, W, 3) image, got shape {target_array.shape}")
    height, width = target_array.shape[:2]
    target_tensor = torch.from_numpy(np.ascontiguousarray(target_array))
    point_tensor = torch.tensor(points, dtype=torch.float32, requires_grad=True)
    colour_tensor = torch.tensor(colours, dtype=torch.float32, requires_grad=True)
    losses: list[float] = []
    if steps > 0 and len(point_tensor) > 0:
        optimizer = torch.optim.Adam(
            [
                {"params": [point_tensor], "lr": point_learning_rate},
                {"params": [colour_tensor], "lr": colour_learning_rate},
            ]
        )
        with single_torch_thread():
            for step in range(steps):
                optimizer.zero_grad(set_to_none=True)
                rendered = rasterize(
                    point_tensor, colour_tensor, width, height, background=background
                )
                loss = torch.mean((rendered - target_tensor) ** 2)
                if xing_weight > 0:
                    loss = loss + xing_weight * xing_loss(point_tensor)
                if lpips is not None and lpips_weight > 0:
                    loss = loss + lpips_weight * lpips(rendered)
                loss.backward()
                optimizer.step()
                with torch.no_grad():
                    colour_tensor.clamp_(0.0, 1.0)
                losses.append(float(loss.detach()))
                if on_step is not None:
                    on_step(step, losses[-1])
    return FitResult(
        points=point_tensor.detach().numpy().astype(np.float64),
        colours=colour_tensor.detach().numpy().astype(np.float64),
        losses=losses,
    )
