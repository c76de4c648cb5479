"""Scoring renders against their targets with :mod:`samvg.metrics`: per image, and FID per set."""

from __future__ import annotations

import os

import numpy as np

from samvg import metrics
from samvg.errors import SamvgError

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


def fid_scores(
    renders: dict[str, list[np.ndarray]],
    targets: list[np.ndarray],
    weights: str | os.PathLike[str] | None = None,
) -> tuple[dict[str, float], list[str]]:
    """FID of each method's renders against the targets (each list: the same images in the
    same order).

    The Inception network is loaded and the targets' features computed once. The trace term
    is computed exactly from the features (``method="nuclear"``): with fewer images than
    feature dimensions the covariances are singular and pytorch-fid's sqrtm would need an
    offset. Returns the values (NaN where FID could not be computed) and what went wrong.
    """
    values = {method: float("nan") for method in renders}
    if len(targets) < 2:
        return values, ["FID needs at least two images with results from every method"]
    methods = list(renders)
    everything = list(targets) + [image for method in methods for image in renders[method]]
    try:
        model = metrics.load_fid_inception(weights, progress=False)
        features = metrics.fid_features(model, everything)  # one pass: same batches throughout
    except SamvgError as error:
        return values, [f"FID: {str(error).splitlines()[0]}"]
    count = len(targets)
    target_features = features[:count]
    problems = []
    for index, method in enumerate(methods):
        own = features[count * (index + 1) : count * (index + 2)]
        try:
            values[method] = metrics.frechet_distance(own, target_features, method="nuclear")
        except SamvgError as error:
            problems.append(f"FID of {method}: {str(error).splitlines()[0]}")
    return values, problems
