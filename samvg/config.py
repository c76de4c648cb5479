"""`Config`: every setting of the vectorization pipeline, grouped by stage and checked once.

`Config.paper()` is the paper's procedure (32x32 AMG grid, 5 cubic segments per path, i.e. 34
numbers per path with RGBA, one stage-4 round, ...; see `PAPER`). The default keeps the paper's
Adam learning rates (1 for points, 0.01 for colours) and missing-component threshold (0.784) and
departs where a benchmark measured better (a 16x16 grid, segments per outline, draft fits until
stage 4 ends; `benchmarks/results/`). Where the paper gives no value (impact threshold, kernel
radii, loss weights) it was chosen on ``../shared/bench`` with ``benchmarks/bench_vectorize.py``.

Settings here are in the user's terms (fractions of the image, counts); each stage turns its
group into typed settings in working pixels once, when the canvas size is known.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from samvg.errors import InputError

SAM_MODELS = ("mobile_sam", "vit_b", "vit_l", "vit_h")
MAX_SEED = 2**32 - 1
"""The largest seed: numpy's legacy generators take seeds below 2**32, torch below 2**64."""
_DEVICE = re.compile(r"cpu|mps|cuda(:\d+)?")


def _label(name: str) -> str:
    return name.replace("_", " ")


def _check_integer(owner: object, name: str, smallest: int) -> None:
    value = getattr(owner, name)
    if isinstance(value, bool) or not isinstance(value, int) or value < smallest:
        raise InputError(f"{_label(name)} must be an integer >= {smallest}, got {value!r}")


def _check_non_negative(owner: object, name: str) -> None:
    value = getattr(owner, name)
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not 0.0 <= float(value) < float("inf")
    ):
        raise InputError(f"{_label(name)} must be a finite number >= 0, got {value!r}")


def _check_radius(owner: object, name: str) -> None:
    value = getattr(owner, name)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value <= 0.5:
        raise InputError(f"{_label(name)} must be in (0, 0.5], got {value!r}")


@dataclass(frozen=True)
class SegmentOptions:
    """Stage 1: SAM's automatic masks, filter by impact, re-prompts in uncovered regions."""

    model: str = "mobile_sam"
    checkpoint: str | None = None
    points_per_side: int = 16
    """SAM's automatic grid: this many points a side (the paper: 32). Stage 4's rounds and the
    colour parts find what a coarser grid misses; on 24 bench images 16 beat 32 on MSE and
    LPIPS (x0.92 each), a third faster (benchmarks/results/speed.md)."""
    skip_covered_points: bool = False
    """Prompt every other row and column of the grid first and skip later grid points inside
    the finest mask an earlier prompt found, of its colour: fewer decoder runs (stage 1 1.35x
    faster on 24 bench images) but flat images lose parts (MSE +10 to +19 % on the emoji, icon
    and digital-art means, `benchmarks/results/speed.md`), so it is off by default."""
    crop_n_layers: int = 0
    """SAM's test-time augmentation: layers of zoomed, overlapping crops (0 = off)."""
    filter_by_impact: bool = True
    impact_threshold: float = 2e-4
    """A mask is kept when it lowers the canvas error by at least this (see `samvg.segment`)."""
    reprompt_uncovered: bool = True
    uncovered_radius: float = 0.03
    """Radius of the circular kernel that finds large uncovered regions, × the longer side."""
    min_area: float = 0.0002
    """Mask components smaller than this fraction of the image are not traced."""
    max_paths: int | None = None
    """Keep at most this many paths (the masks with the largest impact); None = no limit."""
    colour_split: bool = True
    """Split a mask that holds distinct colours into colour-coherent parts painted on top of it
    (the paper does not)."""
    split_contrast: float = 10.0
    """Smallest colour difference (CIELAB ΔE) that splits a mask."""
    tonal_regions: bool = True
    """Under a path budget, offer the blurred image's tonal regions (`samvg.segment.tonal`) to
    the filter by impact as well, beneath SAM's masks and their colour parts."""

    def __post_init__(self) -> None:
        if self.model not in SAM_MODELS:
            raise InputError(
                f"unknown SAM model {self.model!r}; choose one of {', '.join(SAM_MODELS)}"
            )
        _check_integer(self, "points_per_side", 1)
        _check_integer(self, "crop_n_layers", 0)
        if self.max_paths is not None and (
            isinstance(self.max_paths, bool)
            or not isinstance(self.max_paths, int)
            or self.max_paths < 1
        ):
            raise InputError(f"max paths must be a positive integer, got {self.max_paths!r}")
        _check_non_negative(self, "impact_threshold")
        _check_non_negative(self, "min_area")
        _check_non_negative(self, "split_contrast")
        _check_radius(self, "uncovered_radius")
        if self.min_area >= 1.0:
            raise InputError(
                f"min area must be below 1 (a fraction of the image), got {self.min_area}"
            )

    def min_pixels(self, width: int, height: int) -> float:
        """Components smaller than this many pixels never become paths (stages 1, 2 and 4)."""
        return max(4.0, self.min_area * height * width)


@dataclass(frozen=True)
class TraceOptions:
    """Stage 2: mask components to closed cubic paths."""

    segments: int | None = None
    """Cubic segments per path (the paper: 5); None: as few as fit within ``tolerance``."""
    tolerance: float = 2.0
    """Largest distance (working pixels) between a mask's outline and its traced path, when the
    segment count is chosen per path (like potrace's opttolerance)."""
    max_segments: int = 32
    reshape: bool = True
    """Between fitting phases, untangle each path and choose its segments again within the
    tolerance (split where the outline grew detail, merge where it became simple)."""

    def __post_init__(self) -> None:
        if self.segments is not None:
            _check_integer(self, "segments", 1)
        _check_integer(self, "max_segments", 1)
        _check_non_negative(self, "tolerance")
        if self.tolerance <= 0:
            raise InputError(f"tolerance must be a positive number, got {self.tolerance!r}")

    @property
    def adaptive(self) -> bool:
        return self.segments is None


@dataclass(frozen=True)
class FitOptions:
    """Stages 3 and 4: Adam through the rasterizer on MSE + Xing + LPIPS."""

    iterations: int = 500
    """Adam steps per optimization phase (after tracing, and again after each stage-4 round)."""
    draft_iterations: int = 200
    """Steps of the draft fits when stage 4 fits the whole scene once at its end (``refit_scene``
    off, the default): stage 3's fit and each round's fit of its new paths run this many steps
    (at most ``iterations``) on MSE + Xing, half of them at half size; they only have to place
    the paths for the next error map. The fit at the end has ``iterations`` steps."""
    point_learning_rate: float = 1.0
    colour_learning_rate: float = 0.01
    xing_weight: float = 0.01
    use_lpips: bool = True
    lpips_weight: float = 0.05
    lpips_size: int = 128
    """LPIPS is computed on the render resized to this longest side (cost, not quality)."""
    lpips_weights: str | None = None
    lpips_every: int = 1
    """Evaluate LPIPS every this many steps; the steps between reuse its last gradient with
    respect to the render (1: every step, the paper and the default)."""
    lpips_colours: bool = True
    """Whether LPIPS moves fill colours as well as shapes (the paper); off, colours follow MSE
    alone (LPIPS then cannot tint a path a colour the image does not have)."""
    coarse_fraction: float = 0.6
    """The share of each phase's steps fitted first at half size, coarse to fine (0: none, the
    paper)."""
    coarse_lpips: bool = False
    """Whether the half-size steps include LPIPS. Off by default: LPIPS costs as much per step
    at half size as at full size, and with 60 % of the steps at half size on MSE + Xing only the
    last whole-scene fit took 0.66x the time of half the steps at half size with LPIPS, at MSE
    x0.95 and LPIPS x1.01 (``benchmarks/results/speed_knobs/final.log``)."""
    plateau_steps: int | None = 50
    """Stop a phase (each size of it) early once its loss improved by less than 0.1 % over this
    many steps (None: every phase runs all its steps, the paper). Draft fits run all theirs."""
    translucent: bool = False
    """Learn each fill's opacity (the paper does); off keeps every fill opaque, except on
    inputs with an alpha channel."""
    margin: float | None = 0.02
    """Keep control points within the canvas plus this fraction of its longer side (None: no
    bound, the paper's setting)."""
    gradients: bool = True
    """Offer each flat path a linear or radial gradient fill before each fitting phase (off: every
    fill flat, as in the paper)."""
    gradient_cost: float = 1e-6
    """MSE a gradient must remove per parameter it adds over a flat fill."""
    gradient_ramp: float = 0.25
    """The least share of its path's extent that a gradient's colour ramp spans (0: free, as
    Adam leaves it). Keeps gradients as shading: a narrow ramp is an edge drawn by the fill
    (`samvg.optimize.ramp`)."""

    def __post_init__(self) -> None:
        _check_integer(self, "iterations", 0)
        _check_integer(self, "draft_iterations", 0)
        if self.margin is not None:
            _check_non_negative(self, "margin")
        _check_integer(self, "lpips_size", 32)
        _check_integer(self, "lpips_every", 1)
        _check_non_negative(self, "coarse_fraction")
        if self.plateau_steps is not None:
            _check_integer(self, "plateau_steps", 1)
        if self.coarse_fraction > 1:
            raise InputError(f"coarse fraction must be from 0 to 1, got {self.coarse_fraction!r}")
        for name in (
            "point_learning_rate",
            "colour_learning_rate",
            "xing_weight",
            "lpips_weight",
            "gradient_cost",
            "gradient_ramp",
        ):
            _check_non_negative(self, name)
        if self.gradient_ramp > 1:
            raise InputError(f"gradient ramp must be from 0 to 1, got {self.gradient_ramp!r}")

    @property
    def wants_lpips(self) -> bool:
        return self.use_lpips and self.lpips_weight > 0 and self.iterations > 0


@dataclass(frozen=True)
class FinishOptions:
    """The finish pass: simple, bounded paths, hidden and idle paths removed, touching paths of
    near-equal colour merged, optionally a palette (see `samvg.finish`)."""

    finish_pass: bool = True
    """Run the finish pass (the paper has none)."""
    colors: int | None = None
    """Snap the fills to this many colours (k-means in CIELAB), like Illustrator's colours."""
    remove_hidden: bool = True
    remove_idle: bool = True
    """Remove the paths whose removal changes the picture by less than ``IDLE_COST`` (mean
    squared change; all together by at most 1 % of the MSE): a path painted over its own colour,
    a sliver under a neighbour's edge, bytes for nothing (``samvg.optimize.reduce``)."""
    flatten_idle_gradients: bool = True
    """Make flat the gradient fills (and background) whose best flat colour changes the picture
    by less than ``IDLE_COST`` (1 % of the MSE in all): some 200 bytes of SVG each for nothing
    (``samvg.optimize.reduce``)."""
    merge_paths: bool = True
    whole_pixels: bool = True
    """Save a path's control points as whole pixels where that changes the picture by less than
    ``IDLE_COST`` (2 % of the MSE in all): a quarter fewer bytes for the path
    (``samvg.finish.whole_pixels``)."""

    def __post_init__(self) -> None:
        if self.colors is not None:
            _check_integer(self, "colors", 1)


@dataclass(frozen=True)
class MissingOptions:
    """Stage 4: paths added where the optimized render still differs from the image."""

    missing_components: bool = True
    missing_rounds: int | None = None
    """Rounds of stage 4 (error map → SAM → trace → fit); the paper runs one. None: rounds until
    one lowers the error by less than the ``detail`` tolerance."""
    detail: float = 0.5
    """How much detail the automatic rounds chase, from 0 (a round must lower the error by 10 %)
    to 1 (by 0.1 %); 0.5 stops at rounds that gain less than 1 %."""
    paths: int | None = None
    """Exactly this many paths when the image holds that much detail: stage 4 grows the scene to
    a larger pool, then the paths of least impact are removed (None: as ``detail`` decides)."""
    refit_scene: bool = False
    """Fit the whole scene again after every stage-4 round (the paper). Off (the default), a
    round fits only the paths it adds (MSE + Xing), over a fixed render of the rest, and the
    whole scene is fitted once after the last round."""
    marks: bool = True
    """Also add the small marks of one colour on flat areas (a texture's dashes and dots) that
    no SAM prompt segments, each group of marks judged by impact as a whole."""
    filter_speckle: int = 4
    """Marks smaller than this many pixels squared (working pixels) are speckle and never become
    paths: VTracer's ``filter_speckle``, and its default."""
    texture_layers: bool = True
    """Lay texture layers over a textured image (photos, paintings, hatched line art): compound
    paths of the small islands of one colour that the render misses (`samvg.missing.texture`),
    at most 16. Under a path budget they are its last paths (an eighth of it); without one, each
    is kept only if it lowers the error by the ``detail`` tolerance, as a stage-4 round."""
    missing_threshold: float = 0.784
    """ω of the paper, on the disc-averaged sum over RGB of |I − I′| (values in [0, 3])."""
    missing_radius: float = 0.015
    missing_impact_threshold: float = 2e-5
    """Stage 4 filters by impact against the optimized render, where any gain is on top of a good
    fit: small parts (eyes) gain little as flat colour, so the bar is lower than in stage 1."""

    def __post_init__(self) -> None:
        if self.missing_rounds is not None:
            _check_integer(self, "missing_rounds", 0)
        if self.paths is not None:
            _check_integer(self, "paths", 1)
        if (
            isinstance(self.detail, bool)
            or not isinstance(self.detail, (int, float))
            or not (0.0 <= self.detail <= 1.0)
        ):
            raise InputError(f"detail must be a number from 0 to 1, got {self.detail!r}")
        _check_integer(self, "filter_speckle", 1)
        _check_non_negative(self, "missing_threshold")
        _check_non_negative(self, "missing_impact_threshold")
        _check_radius(self, "missing_radius")

    @property
    def rounds(self) -> int | None:
        """Rounds of stage 4 to run; None: as many as ``detail`` (or ``paths``) asks."""
        return self.missing_rounds if self.missing_components else 0

    @property
    def gain_tolerance(self) -> float:
        """The fraction of the error a round must remove for the automatic rounds to go on."""
        return 0.1 * 10.0 ** (-2.0 * self.detail)


_GROUPS = {
    "segment": SegmentOptions,
    "trace": TraceOptions,
    "fit": FitOptions,
    "missing": MissingOptions,
    "finish": FinishOptions,
}
_GROUP_OF: dict[str, str] = {
    option.name: group for group, kind in _GROUPS.items() for option in dataclasses.fields(kind)
}


@dataclass(frozen=True, init=False)
class Config:
    """Settings of :func:`samvg.vectorize`, one group per stage plus the run's own.

    ``Config()`` is the product default (segments chosen per outline, opaque fills, bounded
    points, a finish pass), ``Config.paper()`` the paper's exact procedure and ``Config.fast()``
    the quick version of the default. Any setting of a group can also be given by name:
    ``Config(iterations=300)`` is ``Config(fit=FitOptions(iterations=300))``; the same holds for
    the presets and `replace`.
    """

    segment: SegmentOptions
    trace: TraceOptions
    fit: FitOptions
    missing: MissingOptions
    finish: FinishOptions
    size: int = 512
    """Working resolution (longest side); the SVG keeps the input's pixel coordinates."""
    seed: int = 0
    device: str = "cpu"
    threads: int | None = None
    """Threads for SAM (torch's) and for the rasterizer's kernels (None: torch's setting, and
    the rasterizer's, by default every core). Fitting's torch work (LPIPS, losses) runs on one
    thread: its tensors are small, and torch's pool stalls whenever another process holds a
    core. The rasterizer draws the same image on any thread count; its colour gradients are
    summed per thread, so a long fit can end a little differently on another count (the same
    for a given count, every run)."""

    def __init__(
        self,
        segment: SegmentOptions | None = None,
        trace: TraceOptions | None = None,
        fit: FitOptions | None = None,
        missing: MissingOptions | None = None,
        finish: FinishOptions | None = None,
        *,
        size: int = 512,
        seed: int = 0,
        device: str = "cpu",
        threads: int | None = None,
        **settings: Any,
    ) -> None:
        groups: dict[str, Any] = {
            "segment": segment or SegmentOptions(),
            "trace": trace or TraceOptions(),
            "fit": fit or FitOptions(),
            "missing": missing or MissingOptions(),
            "finish": finish or FinishOptions(),
        }
        for name, value in settings.items():
            group = _GROUP_OF.get(name)
            if group is None:
                raise InputError(f"unknown setting {name!r}")
            groups[group] = dataclasses.replace(groups[group], **{name: value})
        for group, value in groups.items():
            if not isinstance(value, _GROUPS[group]):
                raise InputError(f"{group} settings must be {_GROUPS[group].__name__}")
            object.__setattr__(self, group, value)
        object.__setattr__(self, "size", size)
        object.__setattr__(self, "seed", seed)
        object.__setattr__(self, "device", device)
        object.__setattr__(self, "threads", threads)
        self._check()

    def _check(self) -> None:
        _check_integer(self, "size", 8)
        if self.threads is not None:
            _check_integer(self, "threads", 1)
        _check_integer(self, "seed", 0)
        if self.seed > MAX_SEED:
            raise InputError(
                f"seed must be an integer from 0 to {MAX_SEED} (2**32 - 1, a seed numpy and torch "
                f"both accept), got {self.seed}"
            )
        if not isinstance(self.device, str) or not _DEVICE.fullmatch(self.device):
            raise InputError(f"device must be cpu, cuda, cuda:N or mps, got {self.device!r}")

    @classmethod
    def paper(cls, **overrides: Any) -> Config:
        """The paper's procedure: 32x32 grid with one layer of crops, 5 segments a path,
        learned opacity, no bounds, 500 + 500 steps with LPIPS, one stage-4 round, no finish
        pass."""
        return cls(**{**PAPER, **overrides})

    @classmethod
    def fast(cls, **overrides: Any) -> Config:
        """The quick preset: the default with an 8x8 grid, 384-px working size, 120 steps a
        phase (60 for the drafts) and MSE only."""
        return cls(**{**FAST, **overrides})

    def replace(self, **changes: Any) -> Config:
        """A copy with some settings changed, by group or by name (checked again)."""
        current: dict[str, Any] = {name: getattr(self, name) for name in (*_GROUPS, *_RUN)}
        for name, value in changes.items():
            if name in current:
                current[name] = value
        flat = {name: value for name, value in changes.items() if name not in current}
        return Config(**current, **flat)

    def as_dict(self) -> dict[str, Any]:
        """Every setting by name, flat (for reports and JSON)."""
        flat: dict[str, Any] = {}
        for group in _GROUPS:
            flat.update(dataclasses.asdict(getattr(self, group)))
        flat.update({name: getattr(self, name) for name in _RUN})
        return flat


_RUN = ("size", "seed", "device", "threads")

#: How `Config.paper` differs from the default.
PAPER: dict[str, Any] = {
    "points_per_side": 32,
    "crop_n_layers": 1,
    "segments": 5,
    "reshape": False,
    "translucent": True,
    "margin": None,
    "finish_pass": False,
    "colour_split": False,
    "marks": False,
    "missing_rounds": 1,
    "refit_scene": True,
    "gradients": False,
    "gradient_ramp": 0.0,
    "coarse_fraction": 0.0,
    "plateau_steps": None,
    "texture_layers": False,
}
#: How `Config.fast` differs from the default.
FAST: dict[str, Any] = {
    "points_per_side": 8,
    "size": 384,
    "iterations": 120,
    "draft_iterations": 60,
    "use_lpips": False,
    "texture_layers": False,
}
#: The presets by name, as ``--preset`` knows them: each builds a `Config` from overrides.
PRESETS: dict[str, Callable[..., Config]] = {
    "default": Config,
    "paper": Config.paper,
    "fast": Config.fast,
}
