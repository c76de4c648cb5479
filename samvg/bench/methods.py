"""The benchmark's method table: each method vectorizes one target image under a shared config.

``samvg`` and ``samvg-nofilter`` (Table 2's ablation) run the product; ``diffvg``, ``live`` and
``vtracer`` are the baselines of :mod:`samvg.baselines`, given samvg's path count on the same
image, samvg's losses and its iteration budget (both phases).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from samvg import pipeline
from samvg.baselines import TracedSvg, Vectorized, run_baseline
from samvg.config import Config
from samvg.optimize import FitSettings


@dataclass
class MethodRun:
    """What a method gets for one image: the target (float32 (H, W, 3) in [0, 1]) at the
    working size, the config, samvg's path count on this image (for the baselines), the
    image's id and a progress callback ``progress(stage, done, total)``."""

    target: np.ndarray
    config: Config
    path_count: int | None = None
    image_id: str = ""
    progress: Callable[[str, int, int], None] = lambda _stage, _done, _total: None
    details: dict[str, Any] = field(default_factory=dict)
    """Filled by the method: anything worth keeping in the image's record."""


@dataclass(frozen=True)
class Method:
    """A named way to vectorize; ``needs_path_count`` methods run after samvg on each image."""

    name: str
    run: Callable[[MethodRun], Vectorized]
    needs_path_count: bool = False
    description: str = ""


def _samvg(config_change: dict[str, Any]) -> Callable[[MethodRun], Vectorized]:
    def vectorize_with_samvg(job: MethodRun) -> Vectorized:
        config = job.config.replace(**config_change) if config_change else job.config
        uint8 = np.round(job.target * 255.0).astype(np.uint8)
        result = pipeline.run(uint8, config, progress=job.progress)
        job.details.update(counts=dict(result.counts), notes=list(result.notes))
        job.details["timings"] = {k: round(v, 3) for k, v in result.timings.items()}
        return result.image

    return vectorize_with_samvg


def baseline_fit_settings(job: MethodRun) -> FitSettings:
    """samvg's fit settings for ``job``'s target; when LPIPS weights are nowhere to be found,
    samvg's own fallback (MSE + Xing), noted in the record."""
    settings, note = pipeline.fit_settings(job.config.fit, job.target)
    if note is not None:
        job.details.setdefault("notes", []).append(note)
    return settings


def _baseline(name: str) -> Callable[[MethodRun], Vectorized]:
    def vectorize_with_baseline(job: MethodRun) -> Vectorized:
        if job.path_count is None:
            raise ValueError(f"{name} needs samvg's path count on this image")
        if name == "vtracer":
            result = run_baseline(name, job.target, max(1, job.path_count))
            assert isinstance(result, TracedSvg)
            job.details.update(
                settings=result.settings,
                evaluations=result.evaluations,
                single_run_s=round(result.run_seconds, 3),
            )
            return result
        rounds = job.config.missing.rounds
        phases = 1 + (1 if rounds is None else rounds)  # automatic rounds: as the paper's one
        steps = phases * job.config.fit.iterations
        job.details["steps"] = steps
        return run_baseline(
            name,
            job.target,
            max(1, job.path_count),
            baseline_fit_settings(job),
            seed=job.config.seed,
            steps=steps,
            segments=job.config.trace.segments or 5,
            progress=lambda done, total: job.progress(name, done, total),
        )

    return vectorize_with_baseline


METHODS: dict[str, Method] = {
    method.name: method
    for method in (
        Method("samvg", _samvg({}), description="samvg with the given config"),
        Method(
            "samvg-nofilter",
            _samvg({"filter_by_impact": False}),
            description="samvg without filter by impact in all stages (the paper's Table 2)",
        ),
        Method(
            "diffvg",
            _baseline("diffvg"),
            needs_path_count=True,
            description="random blobs, fitted like samvg (the paper's DiffVG)",
        ),
        Method(
            "live",
            _baseline("live"),
            needs_path_count=True,
            description="LIVE-style layer-wise initialization, fitted like samvg",
        ),
        Method(
            "vtracer",
            _baseline("vtracer"),
            needs_path_count=True,
            description="VTracer with settings searched to samvg's path count",
        ),
    )
}
DEFAULT_METHODS = ("samvg", "samvg-nofilter", "diffvg", "live", "vtracer")
