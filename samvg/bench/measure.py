"""Scoring renders against their targets with :mod:`samvg.metrics`: per image, and FID per set."""

from __future__ import annotations

import os

import numpy as np

from samvg import metrics

#: Per-image metrics, in the order the CSV and the summary list them.
IMAGE_METRICS = ("mse", "psnr", "ssim", "lpips", "complexity")


class Scorer:
    """Computes :data:`IMAGE_METRICS` for (render, target) pairs; LPIPS is loaded once, on
    creation, so missing weights stop a run before any work (``WeightsError``)."""

    def __init__(self, lpips_weights: str | os.PathLike[str] | None = None) -> None:
        self._lpips = metrics.load_lpips(lpips_weights, progress=False)

    def score(self, render: np.ndarray, target: np.ndarray) -> dict[str, float]:
        """All per-image metrics of ``render`` against ``target`` (both (H, W, 3) in [0, 1])."""
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
        """The JPEG complexity of the target itself (float32 (H, W, 3) in [0, 1])."""
        return float(metrics.complexity(np.asarray(target, dtype=np.float32)))
