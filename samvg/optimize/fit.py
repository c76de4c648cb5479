"""Adam on a scene's control points and fill colours through the differentiable rasterizer:
loss = MSE to the target + λ_Xing · Xing loss + λ_LPIPS · LPIPS (the paper's objective)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

import numpy as np
import torch

from samvg.config import FitOptions
from samvg.errors import InputError, SamvgError
from samvg.optimize.losses import PerceptualLoss, lpips_loss, segment_indices, xing_loss
from samvg.optimize.paint_choice import choose_gradients
from samvg.render import rasterize
from samvg.render._paint_kernels import MAX_STOPS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.scene import Scene

_DIVERGED = "optimization diverged (non-finite coordinates); try a lower learning rate"

StepCallback = Callable[[int, float], None]
"""``on_step(step, loss)``: called after every Adam step (progress reporting)."""


@dataclass(frozen=True)
class FitSettings:
    """One optimization phase: Adam ``steps``, learning rates and loss weights.

    ``perceptual`` is a loss bound to the target (see `PerceptualLoss`), weighted by
    ``perceptual_weight``; None switches that term off. With ``learn_alpha`` False every fill
    stays opaque (alpha 1). ``bounds`` (x0, y0, x1, y1), when given, is the box control points
    are kept in after every step (the canvas plus a margin).
    """

    steps: int = 300
    point_learning_rate: float = 1.0
    colour_learning_rate: float = 0.01
    xing_weight: float = 0.0
    perceptual: PerceptualLoss | None = None
    perceptual_weight: float = 0.0
    learn_alpha: bool = True
    bounds: tuple[float, float, float, float] | None = None
    gradient_cost: float | None = None
    """Offer every flat path a gradient fill before fitting (`samvg.optimize.paint_choice`),
    bought when it removes this much MSE per added parameter; None: fills stay as they are."""

    @classmethod
    def from_options(
        cls,
        options: FitOptions,
        target: np.ndarray | None = None,
        canvas: tuple[int, int] | None = None,
    ) -> FitSettings:
        """The settings of ``options``; with ``target`` and LPIPS wanted, the LPIPS loss is
        loaded and bound to it (raises `WeightsError` when its weights cannot be found). With
        the ``canvas`` (width, height) and ``options.margin`` set, points are kept within the
        canvas plus that fraction of its longer side."""
        perceptual = None
        if target is not None and options.wants_lpips:
            perceptual = lpips_loss(target, options.lpips_size, options.lpips_weights)
        bounds = None
        if canvas is not None and options.margin is not None:
            margin = options.margin * max(canvas)
            bounds = (-margin, -margin, canvas[0] + margin, canvas[1] + margin)
        return cls(
            steps=options.iterations,
            point_learning_rate=options.point_learning_rate,
            colour_learning_rate=options.colour_learning_rate,
            xing_weight=options.xing_weight,
            perceptual=perceptual,
            perceptual_weight=options.lpips_weight if perceptual is not None else 0.0,
            learn_alpha=options.translucent,
            bounds=bounds,
            gradient_cost=options.gradient_cost if options.gradients else None,
        )

    def with_steps(self, steps: int) -> FitSettings:
        return replace(self, steps=steps)


@dataclass
class FitResult:
    """The fitted scene and the total loss after each step."""

    scene: Scene
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


def _check_target(target: np.ndarray, scene: Scene) -> torch.Tensor:
    array = np.asarray(target, dtype=np.float32)
    if array.ndim != 3 or array.shape[2] != 3:
        raise InputError(f"target must be an (H, W, 3) image, got shape {array.shape}")
    if array.shape[:2] != (scene.height, scene.width):
        raise InputError(
            f"target is {array.shape[1]}x{array.shape[0]} but the scene is "
            f"{scene.width}x{scene.height}"
        )
    return torch.from_numpy(np.ascontiguousarray(array))


class _Parameters:
    """What Adam moves: packed points, RGBA colours and, for a scene with gradient paints, their
    geometry (pixels, the points' learning rate) and their stop offsets and colours (the
    colours' learning rate)."""

    def __init__(self, scene: Scene, settings: FitSettings) -> None:
        self.scene = scene
        self.points = torch.tensor(scene.points, dtype=torch.float32, requires_grad=True)
        colours = scene.colours()
        if not settings.learn_alpha:
            colours[:, 3] = 1.0
        self.colours = torch.tensor(colours, dtype=torch.float32, requires_grad=True)
        self.gradients: GradientPaints | None = None
        self.paint_geometry = self.paint_values = torch.zeros(0)
        if scene.has_gradients:
            self.gradients = GradientPaints.of(scene.paints)
            params = self.gradients.params.to(torch.float32)
            self.paint_geometry = params[:, :4].clone().requires_grad_(True)
            self.paint_values = params[:, 4:].clone().requires_grad_(True)

    def optimizer(self, settings: FitSettings) -> torch.optim.Adam:
        point_group = [self.points]
        colour_group = [self.colours]
        if self.gradients is not None:
            point_group.append(self.paint_geometry)
            colour_group.append(self.paint_values)
        return torch.optim.Adam(
            [
                {"params": point_group, "lr": settings.point_learning_rate},
                {"params": colour_group, "lr": settings.colour_learning_rate},
            ]
        )

    def render(self) -> torch.Tensor:
        gradients = None
        if self.gradients is not None:
            params = torch.cat([self.paint_geometry, self.paint_values], dim=1)
            gradients = GradientPaints(self.gradients.kinds, self.gradients.stops, params)
        scene = self.scene
        return rasterize(
            self.points,
            self.colours,
            scene.width,
            scene.height,
            background=scene.background_or_white,
            offsets=scene.offsets,
            gradients=gradients,
        )

    @torch.no_grad()
    def project(self, settings: FitSettings) -> None:
        _project(self.points, self.colours, settings)
        if self.gradients is not None:
            self.paint_values.clamp_(0.0, 1.0)
            offsets = self.paint_values[:, :MAX_STOPS]
            offsets.copy_(torch.cummax(offsets, dim=1).values)
            radial = torch.from_numpy(self.gradients.kinds == RADIAL)
            self.paint_geometry[radial, 2] = self.paint_geometry[radial, 2].clamp(min=0.5)
            if not bool(torch.isfinite(self.paint_geometry).all()):
                raise SamvgError(_DIVERGED)

    def fitted(self) -> Scene:
        points = self.points.detach().numpy().astype(np.float64)
        colours = self.colours.detach().numpy().astype(np.float64)
        if not (np.all(np.isfinite(points)) and np.all(np.isfinite(colours))):
            raise SamvgError(_DIVERGED)
        if self.gradients is None:
            return self.scene.with_geometry(points, colours)
        params = torch.cat([self.paint_geometry, self.paint_values], dim=1).detach()
        paints = GradientPaints(self.gradients.kinds, self.gradients.stops, params).paints(colours)
        return replace(self.scene, points=points, paints=paints)


def _project(points: torch.Tensor, colours: torch.Tensor, settings: FitSettings) -> None:
    """After a step: colours back into [0, 1] (alpha to 1 unless learned), points into the
    bounds; non-finite points mean the fit diverged."""
    colours.clamp_(0.0, 1.0)
    if not settings.learn_alpha:
        colours[:, 3] = 1.0
    if not bool(torch.isfinite(points).all()):
        raise SamvgError(_DIVERGED)
    if settings.bounds is not None:
        x0, y0, x1, y1 = settings.bounds
        points[:, 0].clamp_(x0, x1)
        points[:, 1].clamp_(y0, y1)


def fit_scene(
    scene: Scene,
    target: np.ndarray,
    settings: FitSettings,
    on_step: StepCallback | None = None,
) -> FitResult:
    """Fit the scene's geometry and paints (flat colours, gradient geometry, stops) to
    ``target`` (H, W, 3) float in [0, 1], after offering flat paths a gradient when
    ``settings.gradient_cost`` is set.

    Colours are clamped to [0, 1] after every step; a fit that diverges to non-finite values
    raises `SamvgError`.
    """
    target_tensor = _check_target(target, scene)
    if settings.gradient_cost is not None:
        scene, _ = choose_gradients(scene, np.asarray(target), settings.gradient_cost)
    parameters = _Parameters(scene, settings)
    losses: list[float] = []
    if settings.steps > 0 and scene.path_count > 0:
        optimizer = parameters.optimizer(settings)
        indices = segment_indices(scene.offsets)
        with single_torch_thread():
            for step in range(settings.steps):
                optimizer.zero_grad(set_to_none=True)
                rendered = parameters.render()
                loss = torch.mean((rendered - target_tensor) ** 2)
                if settings.xing_weight > 0:
                    loss = loss + settings.xing_weight * xing_loss(
                        parameters.points, indices=indices
                    )
                if settings.perceptual is not None and settings.perceptual_weight > 0:
                    loss = loss + settings.perceptual_weight * settings.perceptual(rendered)
                loss.backward()
                optimizer.step()
                parameters.project(settings)
                losses.append(float(loss.detach()))
                if on_step is not None:
                    on_step(step, losses[-1])
    return FitResult(parameters.fitted(), losses)
