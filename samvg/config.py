"""`Config`: every setting of the vectorization pipeline, checked once, with the paper's defaults.

Where the paper gives a value it is the default (32x32 AMG grid, 5 cubic segments per path, i.e.
34 numbers per path with RGBA; Adam with learning rates 1 for points and 0.01 for colours; the
missing-component threshold 0.784). Where it does not (impact threshold, kernel radii, loss
weights) the value was chosen on ``../shared/bench`` with ``benchmarks/bench_vectorize.py``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from samvg.errors import InputError

SAM_MODELS = ("mobile_sam", "vit_b", "vit_l", "vit_h")


@dataclass(frozen=True)
class Config:
    """Settings of :func:`samvg.vectorize`. ``Config.fast()`` is the quick preset."""

    # segmentation (stage 1)
    model: str = "mobile_sam"
    checkpoint: str | None = None
    points_per_side: int = 32
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

    # tracing (stage 2)
    segments: int = 5

    # optimization (stage 3 and 4)
    iterations: int = 500
    """Adam steps per optimization phase (after tracing, and again after stage 4)."""
    point_learning_rate: float = 1.0
    colour_learning_rate: float = 0.01
    xing_weight: float = 0.01
    use_lpips: bool = True
    lpips_weight: float = 0.05
    lpips_size: int = 128
    """LPIPS is computed on the render resized to this longest side (cost, not quality)."""
    lpips_weights: str | None = None

    # missing components (stage 4)
    missing_components: bool = True
    missing_threshold: float = 0.784
    """ω of the paper, on the disc-averaged sum over RGB of |I − I′| (values in [0, 3])."""
    missing_radius: float = 0.015
    missing_impact_threshold: float = 2e-5
    """Stage 4 filters by impact against the optimized render, where any gain is on top of a good
    fit: small parts (eyes) gain little as flat colour, so the bar is lower than in stage 1."""

    # product
    size: int = 512
    """Working resolution (longest side); the SVG keeps the input's pixel coordinates."""
    seed: int = 0
    device: str = "cpu"
    threads: int | None = None
    """torch threads for SAM (None = torch's default). Fitting always runs on one thread: its
    tensors are small, and a thread pool stalls whenever another process holds a core."""

    def __post_init__(self) -> None:
        if self.model not in SAM_MODELS:
            raise InputError(
                f"unknown SAM model {self.model!r}; choose one of {', '.join(SAM_MODELS)}"
            )
        at_least = {
            "points_per_side": 1,
            "crop_n_layers": 0,
            "segments": 1,
            "iterations": 0,
            "size": 8,
            "lpips_size": 32,
        }
        for name, smallest in at_least.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < smallest:
                raise InputError(f"{_label(name)} must be an integer >= {smallest}, got {value!r}")
        if self.max_paths is not None and (
            isinstance(self.max_paths, bool)
            or not isinstance(self.max_paths, int)
            or self.max_paths < 1
        ):
            raise InputError(f"max paths must be a positive integer, got {self.max_paths!r}")
        non_negative = (
            "impact_threshold",
            "missing_impact_threshold",
            "min_area",
            "point_learning_rate",
            "colour_learning_rate",
            "xing_weight",
            "lpips_weight",
            "missing_threshold",
        )
        for name in non_negative:
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not 0.0 <= float(value) < float("inf"):
                raise InputError(f"{_label(name)} must be a finite number >= 0, got {value!r}")
        for name in ("uncovered_radius", "missing_radius"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not 0.0 < float(value) <= 0.5:
                raise InputError(f"{_label(name)} must be in (0, 0.5], got {value!r}")
        if self.min_area >= 1.0:
            raise InputError(
                f"min area must be below 1 (a fraction of the image), got {self.min_area}"
            )
        if self.threads is not None and (
            isinstance(self.threads, bool) or not isinstance(self.threads, int) or self.threads < 1
        ):
            raise InputError(f"threads must be a positive integer, got {self.threads!r}")
        if not isinstance(self.seed, int) or isinstance(self.seed, bool) or self.seed < 0:
            raise InputError(f"seed must be a non-negative integer, got {self.seed!r}")
        if self.device != "cpu" and not self.device.startswith(("cuda", "mps")):
            raise InputError(f"device must be cpu, cuda[:N] or mps, got {self.device!r}")

    @classmethod
    def fast(cls, **overrides: Any) -> Config:
        """The quick preset: a 16x16 grid, 384-px working size, 120 steps a phase, MSE only."""
        settings: dict[str, Any] = {
            "points_per_side": 16,
            "size": 384,
            "iterations": 120,
            "use_lpips": False,
        }
        settings.update(overrides)
        return cls(**settings)

    def replace(self, **changes: Any) -> Config:
        """A copy with some settings changed (checked again)."""
        return dataclasses.replace(self, **changes)


def _label(name: str) -> str:
    return name.replace("_", " ")
