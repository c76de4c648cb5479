"""Adam on a scene's control points and fill colours through the differentiable rasterizer:
loss = MSE to the target + λ_Xing · Xing loss + λ_LPIPS · LPIPS (the paper's objective)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from typing import cast

import numpy as np
import torch
from torch.nn import functional

from samvg.config import FitOptions
from samvg.errors import InputError, SamvgError
from samvg.imaging import halve
from samvg.optimize.adam import Adam
from samvg.optimize.losses import PerceptualLoss, lpips_loss, segment_indices, xing_loss
from samvg.optimize.paint_choice import choose_gradients
from samvg.optimize.ramp import widen_ramps
from samvg.render import rasterize
from samvg.render._paint_kernels import MAX_STOPS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.render.threads import render_threads
from samvg.scene import RGB, BackgroundGradient, Paint, Scene

#: A phase with ``plateau_steps`` set stops when its best loss improved by less than this
#: fraction over the last ``plateau_steps`` steps.
PLATEAU_GAIN = 1e-3
#: ... or by less than this much loss (a fit that is already exact).
PLATEAU_FLOOR = 1e-7
#: Canvases whose longer side is below this are fitted at full size only.
COARSE_MIN_SIDE = 128
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
    perceptual_every: int = 1
    """Evaluate LPIPS every this many steps and reuse its gradient in between (1: every step)."""
    perceptual_colours: bool = True
    """Whether the perceptual term moves paints (colours, gradient stops) as well as geometry;
    False: paints follow MSE alone, LPIPS shapes only the geometry."""
    coarse_fraction: float = 0.0
    """The share of the steps fitted first at half size (0: all at full size)."""
    coarse_perceptual: bool = True
    """Whether the half-size steps include the perceptual term (False: MSE + Xing there, LPIPS
    only at full size, where it costs the same per step but matters)."""
    plateau_steps: int | None = None
    """Stop a phase (each size of it) once its loss has stopped improving over this many steps
    (None: always run every step)."""
    draft_steps: int | None = None
    """Steps of a draft fit (`draft`), one whose scene is fitted again in full later (None:
    ``steps``)."""
    gradient_cost: float | None = None
    """Offer every flat path, and a flat background, a gradient fill before fitting
    (`samvg.optimize.paint_choice`), bought when it removes this much MSE per added parameter;
    None: fills stay as they are."""
    gradient_ramp: float = 0.0
    """The least share of its path's extent that a gradient's colour ramp spans after every
    step (`samvg.optimize.ramp`; 0: free)."""

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
            bounds = margin_box(canvas, options.margin)
        return cls(
            steps=options.iterations,
            point_learning_rate=options.point_learning_rate,
            colour_learning_rate=options.colour_learning_rate,
            xing_weight=options.xing_weight,
            perceptual=perceptual,
            perceptual_weight=options.lpips_weight if perceptual is not None else 0.0,
            learn_alpha=options.translucent,
            bounds=bounds,
            perceptual_every=options.lpips_every,
            perceptual_colours=options.lpips_colours,
            coarse_fraction=options.coarse_fraction,
            coarse_perceptual=options.coarse_lpips,
            plateau_steps=options.plateau_steps,
            gradient_cost=options.gradient_cost if options.gradients else None,
            gradient_ramp=options.gradient_ramp,
            draft_steps=min(options.draft_iterations, options.iterations),
        )

    def with_steps(self, steps: int) -> FitSettings:
        return replace(self, steps=steps)

    def draft(self) -> FitSettings:
        """A cheaper fit, ``draft_steps`` steps on MSE + Xing, half of them at half size, for a
        scene that is fitted again in full later."""
        return replace(
            self,
            steps=self.steps if self.draft_steps is None else self.draft_steps,
            perceptual=None,
            perceptual_weight=0.0,
            coarse_fraction=0.5,
            plateau_steps=None,
        )


def margin_box(canvas: tuple[int, int], fraction: float) -> tuple[float, float, float, float]:
    """The (width, height) canvas grown by ``fraction`` of its longer side on every side, as
    (x0, y0, x1, y1): where control points are kept."""
    margin = fraction * max(canvas)
    return (-margin, -margin, canvas[0] + margin, canvas[1] + margin)


@dataclass
class FitResult:
    """The fitted scene and the total loss after each step."""

    scene: Scene
    losses: list[float]


@contextlib.contextmanager
def fit_torch_threads(perceptual: bool) -> Iterator[None]:
    """Run torch inside the block on one thread: the per-step tensors of MSE and Xing are small
    (a thread pool costs more than it saves), and torch's OpenMP workers, spinning after each
    parallel operation, would take the cores from the rasterizer's threads (on two cores its
    backward pass ran no faster on two threads than on one). LPIPS, whose convolutions run about
    1.4x faster on two threads, gets the rasterizer's thread count on its own (`_Objective`).
    ``perceptual`` is kept for callers that patch this function."""
    del perceptual
    with torch_threads(1):
        yield


@contextlib.contextmanager
def torch_threads(count: int) -> Iterator[None]:
    """torch's intra-op thread count set to ``count`` inside the block."""
    threads = torch.get_num_threads()
    if count != threads:
        torch.set_num_threads(count)
    try:
        yield
    finally:
        if count != threads:
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


class _GradientVariables:
    """Adam's view of gradient paints (`GradientPaints` rows): their geometry (pixels, moved at
    the points' learning rate) and their stop offsets and colours (the colours' rate)."""

    def __init__(self, paints: Sequence[Paint]) -> None:
        gradients = GradientPaints.of(paints)
        self.kinds, self.stops = gradients.kinds, gradients.stops
        params = gradients.params.to(torch.float32)
        self.geometry = params[:, :4].clone().requires_grad_(True)
        self.values = params[:, 4:].clone().requires_grad_(True)

    def current(self) -> GradientPaints:
        return GradientPaints(self.kinds, self.stops, torch.cat([self.geometry, self.values], 1))

    @torch.no_grad()
    def project(self, points: np.ndarray, offsets: np.ndarray, ramp: float) -> None:
        """Stop colours into [0, 1], offsets non-decreasing in [0, 1], radii at least 0.5 px,
        ramps at least ``ramp`` of their path's extent (`widen_ramps`; the paths' control
        points ``points`` packed by ``offsets``)."""
        self.values.clamp_(0.0, 1.0)
        stop_offsets = self.values[:, :MAX_STOPS]
        stop_offsets.copy_(torch.cummax(stop_offsets, dim=1).values)
        radial = torch.from_numpy(self.kinds == RADIAL)
        self.geometry[radial, 2] = self.geometry[radial, 2].clamp(min=0.5)
        if not bool(torch.isfinite(self.geometry).all()):
            raise SamvgError(_DIVERGED)
        if ramp > 0:
            params = torch.cat([self.geometry, self.values], 1).numpy().astype(np.float64)
            changed = widen_ramps(self.kinds, self.stops, params, points, offsets, ramp)
            if changed.any():
                rows = torch.from_numpy(changed)
                widened = torch.from_numpy(params[changed]).to(self.geometry.dtype)
                self.geometry[rows] = widened[:, :4]
                self.values[rows] = widened[:, 4:]

    def paints(self, colours: np.ndarray) -> tuple[Paint, ...]:
        return self.current().paints(colours)


class _Parameters:
    """What Adam moves: packed points, RGBA colours, the gradient paints of paths and a
    background gradient (see `_GradientVariables`; none with an ``underlay``)."""

    def __init__(
        self, scene: Scene, settings: FitSettings, underlay: np.ndarray | None = None
    ) -> None:
        self.scene = scene
        self.underlay = underlay
        self.points = torch.tensor(scene.points, dtype=torch.float32, requires_grad=True)
        colours = scene.colours()
        if not settings.learn_alpha:
            colours[:, 3] = 1.0
        self.colours = torch.tensor(colours, dtype=torch.float32, requires_grad=True)
        self.gradients = _GradientVariables(scene.paints) if scene.has_gradients else None
        self.background: _GradientVariables | None = None
        if underlay is None and scene.background_gradient is not None:
            self.background = _GradientVariables([scene.background_gradient])

    @property
    def learns(self) -> bool:
        """Whether there is anything to fit: a path or a background gradient."""
        return self.scene.path_count > 0 or self.background is not None

    def geometry(self) -> list[torch.Tensor]:
        """The tensors of shape: points and the geometry of gradient paints."""
        return [self.points] + [
            variables.geometry
            for variables in (self.gradients, self.background)
            if variables is not None
        ]

    def optimizer(self, settings: FitSettings) -> Adam:
        point_group = [self.points]
        colour_group = [self.colours]
        for variables in (self.gradients, self.background):
            if variables is not None:
                point_group.append(variables.geometry)
                colour_group.append(variables.values)
        point_rate: float | torch.Tensor = settings.point_learning_rate
        if self.scene.fixed is not None:  # fixed outlines: their points' rate is 0
            moving = np.repeat(~self.scene.fixed, np.diff(self.scene.offsets)).astype(np.float32)
            point_rate = point_rate * torch.from_numpy(moving)[:, None]
        return Adam(
            [
                ([self.points], point_rate),
                (point_group[1:], settings.point_learning_rate),
                (colour_group, settings.colour_learning_rate),
            ]
        )

    def render(self) -> torch.Tensor:
        scene = self.scene
        background: np.ndarray | torch.Tensor | RGB = scene.background_or_white
        if self.underlay is not None:
            background = self.underlay
        elif self.background is not None:
            background = self.background.current().image(0, scene.width, scene.height)
        return rasterize(
            self.points,
            self.colours,
            scene.width,
            scene.height,
            background=background,
            offsets=scene.offsets,
            gradients=None if self.gradients is None else self.gradients.current(),
        )

    @torch.no_grad()
    def project(self, settings: FitSettings) -> None:
        _project(self.points, self.colours, settings)
        if self.gradients is not None:
            points = self.points.detach().numpy()
            self.gradients.project(points, self.scene.offsets, settings.gradient_ramp)
        if self.background is not None:
            width, height = self.scene.width, self.scene.height
            corners = np.array([[0.0, 0.0], [width, 0.0], [0.0, height], [width, height]])
            self.background.project(corners, np.array([0, 4]), settings.gradient_ramp)

    def fitted(self) -> Scene:
        points = self.points.detach().numpy().astype(np.float64)
        colours = self.colours.detach().numpy().astype(np.float64)
        if not (np.all(np.isfinite(points)) and np.all(np.isfinite(colours))):
            raise SamvgError(_DIVERGED)
        if self.gradients is None:
            scene = self.scene.with_geometry(points, colours)
        else:
            scene = replace(self.scene, points=points, paints=self.gradients.paints(colours))
        scene = replace(scene, joined=None)  # fitted pieces may overlap: each its own element
        if self.background is None:
            return scene
        gradient = cast(BackgroundGradient, self.background.paints(np.ones((1, 4)))[0])
        return replace(scene, background_gradient=gradient)


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
    underlay: np.ndarray | None = None,
) -> FitResult:
    """Fit the scene's geometry and paints (flat colours, gradient geometry, stops; a
    background gradient's geometry and stops) to ``target`` (H, W, 3) float in [0, 1], after
    offering flat paths and a flat background a gradient when ``settings.gradient_cost`` is set.
    With an ``underlay`` (H, W, 3), the paths are painted over that fixed image instead of the
    scene's background (paths added on top of a scene that stays as it is), and the background
    is left alone.

    With ``settings.coarse_fraction`` set, that share of the steps runs first on the scene and
    target at half size (a quarter of the pixels to draw), the rest at full size.

    Colours are clamped to [0, 1] after every step; a fit that diverges to non-finite values
    raises `SamvgError`.
    """
    target_tensor = _check_target(target, scene)
    if underlay is not None:
        underlay = np.asarray(underlay, np.float64)
        if underlay.shape != np.shape(target):
            raise InputError(f"underlay must have the target's shape, got {underlay.shape}")
    if settings.gradient_cost is not None:
        scene, _ = choose_gradients(
            scene, np.asarray(target), settings.gradient_cost, background=underlay is None
        )
    coarse = _coarse_steps(scene, settings)
    losses: list[float] = []
    if coarse:
        width, height = -(-scene.width // 2), -(-scene.height // 2)
        small_scene = scene.on_canvas(width, height, 0.5)
        small = _fit_level(
            small_scene,
            _check_target(halve(target_tensor.numpy()), small_scene),
            _coarse_settings(settings, coarse),
            on_step,
            underlay=None if underlay is None else halve(underlay),
        )
        scene = small.scene.on_canvas(scene.width, scene.height, 2.0)
        losses = small.losses
        settings = replace(settings, steps=settings.steps - coarse)
    full = _fit_level(scene, target_tensor, settings, on_step, coarse, underlay)
    return FitResult(full.scene, losses + full.losses)


def _coarse_steps(scene: Scene, settings: FitSettings) -> int:
    """Steps of the half-size level: none for small canvases or short fits."""
    if max(scene.width, scene.height) < COARSE_MIN_SIDE or scene.path_count == 0:
        return 0
    return int(round(settings.steps * settings.coarse_fraction))


def _coarse_settings(settings: FitSettings, steps: int) -> FitSettings:
    """The half-size level's settings: ``steps`` steps, bounds halved, LPIPS as asked."""
    coarse = replace(settings, steps=steps, bounds=_halved(settings.bounds))
    if not settings.coarse_perceptual:
        coarse = replace(coarse, perceptual=None, perceptual_weight=0.0)
    return coarse


def _halved(
    bounds: tuple[float, float, float, float] | None,
) -> tuple[float, float, float, float] | None:
    if bounds is None:
        return None
    x0, y0, x1, y1 = bounds
    return (x0 / 2, y0 / 2, x1 / 2, y1 / 2)


def _fit_level(
    scene: Scene,
    target: torch.Tensor,
    settings: FitSettings,
    on_step: StepCallback | None = None,
    first_step: int = 0,
    underlay: np.ndarray | None = None,
) -> FitResult:
    """Adam on one canvas size, against ``target`` (checked, float32): ``settings.steps`` steps
    (progress counted from ``first_step``)."""
    parameters = _Parameters(scene, settings, underlay)
    losses: list[float] = []
    if settings.steps > 0 and parameters.learns:
        optimizer = parameters.optimizer(settings)
        objective = _Objective(target, settings, segment_indices(scene.offsets))
        with fit_torch_threads(settings.perceptual is not None):
            for step in range(settings.steps):
                optimizer.zero_grad()
                loss, perceptual, reported = objective(parameters.render(), parameters.points, step)
                _backward(loss, perceptual, parameters, settings.perceptual_colours)
                optimizer.step()
                parameters.project(settings)
                losses.append(reported)
                if on_step is not None:
                    on_step(first_step + step, reported)
                if _plateaued(losses, settings.plateau_steps):
                    if on_step is not None:
                        on_step(first_step + settings.steps - 1, reported)
                    break
    return FitResult(parameters.fitted(), losses)


def _backward(
    loss: torch.Tensor,
    perceptual: torch.Tensor | None,
    parameters: _Parameters,
    perceptual_colours: bool,
) -> None:
    """Gradients of ``loss`` + ``perceptual`` into the parameters; without
    ``perceptual_colours``, the perceptual term reaches only their geometry."""
    if perceptual is None:
        loss.backward()
    elif perceptual_colours:
        (loss + perceptual).backward()
    else:
        loss.backward(retain_graph=True)
        geometry = parameters.geometry()
        extra = torch.autograd.grad(perceptual, geometry, allow_unused=True)
        for tensor, gradient in zip(geometry, extra, strict=True):
            if gradient is not None:
                tensor.grad = gradient if tensor.grad is None else tensor.grad + gradient


def _plateaued(losses: list[float], window: int | None) -> bool:
    """Whether the best loss of the last ``window`` steps is within `PLATEAU_GAIN` (relative) or
    `PLATEAU_FLOOR` (absolute) of the best before them (None: never)."""
    if window is None or len(losses) < 2 * window:
        return False
    before = min(losses[:-window])
    return before - min(losses[-window:]) < PLATEAU_GAIN * before + PLATEAU_FLOOR


class _Objective:
    """MSE + λ_Xing · Xing + λ_LPIPS · LPIPS of a render.

    LPIPS and its gradient G with respect to the render are computed apart, on the rasterizer's
    thread count (`torch_threads`), and the loss to differentiate adds the linear term
    ⟨G, render⟩, whose gradient is exactly LPIPS's. With ``settings.perceptual_every`` k > 1,
    G is evaluated every k-th step only and the steps between reuse the last one, so every step
    still feels LPIPS while paying for it once in k (the render changes little over a few
    steps). k = 1 is the exact objective.
    """

    def __init__(
        self, target: torch.Tensor, settings: FitSettings, indices: tuple[torch.Tensor, ...]
    ) -> None:
        self.target = target
        self.settings = settings
        self.indices = indices
        self.perceptual_gradient: torch.Tensor | None = None
        self.perceptual_value = 0.0

    def __call__(
        self, rendered: torch.Tensor, points: torch.Tensor, step: int
    ) -> tuple[torch.Tensor, torch.Tensor | None, float]:
        """The loss to differentiate (MSE + Xing), the perceptual term's linear stand-in (None
        without it) and the objective's value to report."""
        settings = self.settings
        loss = functional.mse_loss(rendered, self.target)
        if settings.xing_weight > 0:
            loss = loss + settings.xing_weight * xing_loss(points, indices=self.indices)
        perceptual = settings.perceptual
        if perceptual is None or settings.perceptual_weight <= 0:
            return loss, None, float(loss.detach())
        if step % settings.perceptual_every == 0 or self.perceptual_gradient is None:
            with torch_threads(render_threads()):
                image = rendered.detach().requires_grad_(True)
                value = perceptual(image)
                (gradient,) = torch.autograd.grad(value, image)
            self.perceptual_gradient = gradient * settings.perceptual_weight
            self.perceptual_value = settings.perceptual_weight * float(value.detach())
        reported = float(loss.detach()) + self.perceptual_value
        return loss, torch.sum(rendered * self.perceptual_gradient), reported
