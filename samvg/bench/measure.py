"""Scoring one output render against its target with the metrics of :mod:`samvg.metrics`."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

#: Per-image metrics, in the order the CSV and the summary list them.
IMAGE_METRICS = ("mse", "psnr", "ssim", "lpips", "complexity")


class Scorer:
    """Computes :data:`IMAGE_METRICS` for (render, target) pairs; LPIPS is loaded once, on
    creation, so missing weights stop a run before any work (``WeightsError``)."""

    def __init__(self, lpips_weights: str | os.PathLike[str] | None = None) -> None:
        from samvg.metrics import load_lpips

        self._lpips = load_lpips(lpips_weights, progress=False)

    def score(self, render: np.ndarray, target: np.ndarray) -> dict[str, float]:
        """All per-image metrics of ``render`` against ``target`` (both (H, W, 3) in [0, 1])."""
        from samvg import metrics

        a = np.clip(np.asarray(render, dtype=np.float32), 0.0, 1.0)
        b = np.asarray(target, dtype=np.float32)
        return {
            "mse": float(metrics.mse(a, b)),
            "psnr": float(metrics.psnr(a, b)),
            "ssim": float(metrics.ssim(a, b)),
            "lpips": float(metrics.lpips_distance(self._lpips, a, b)),
            "complexity": float(metrics.complexity(a)),
        }

    @staticmethod
    def target_complexity(target: np.ndarray) -> float:
        from samvg import metrics

        return float(metrics.complexity(np.asarray(target, dtype=np.float32)))


def fid_score(
    renders: list[np.ndarray],
    targets: list[np.ndarray],
    weights: str | os.PathLike[str] | None = None,
) -> dict[str, Any]:
    """FID between a method's renders and the targets: ``{"fid": value}``, or ``{"fid": nan,
    "error": why}`` when it cannot be computed (fewer than two images, no weights ...)."""
    from samvg import metrics
    from samvg.errors import SamvgError

    if len(renders) < 2:
        return {"fid": float("nan"), "error": "FID needs at least two images"}
    try:
        return {"fid": float(metrics.fid(renders, targets, weights=weights))}
    except SamvgError as error:
        return {"fid": float("nan"), "error": str(error).splitlines()[0]}
