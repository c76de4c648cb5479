"""InceptionV3 features of each target and render of a benchmark run, kept beside its records.

FID is a statistic of the whole set, so it needs every image's features at report time. The
renders are large and not kept with the committed results (nor may renders of the bench's photos
and paintings be), and a long run is resumed across sessions; storing each image's 2048 pool
features (8 KB, float32) as it finishes lets FID over the full set survive both. Features are
computed one image at a time; Inception runs in eval mode, so they match a batched pass up to
rounding.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import torch

from samvg import metrics
from samvg.bench.layout import Layout
from samvg.errors import InputError, SamvgError
from samvg.imaging import to_float_rgb
from samvg.io import atomic_write_bytes, read_image
from samvg.metrics.fid import FEATURES


class FeatureStore:
    """Reads and writes the features of one run's targets and renders.

    The Inception network is loaded on first need, or at once with ``load_now`` (so that missing
    weights stop a run before any work, as `WeightsError`)."""

    def __init__(
        self,
        layout: Layout,
        weights: str | os.PathLike[str] | None = None,
        *,
        load_now: bool = False,
    ) -> None:
        self._layout = layout
        self._weights = weights
        self._model: torch.jit.ScriptModule | None = None
        if load_now:
            self._network()

    def _network(self) -> torch.jit.ScriptModule:
        if self._model is None:
            self._model = metrics.load_fid_inception(self._weights, progress=False)
        return self._model

    def _compute(self, image: np.ndarray) -> np.ndarray:
        model = self._network()
        return metrics.fid_features(model, [image])[0].astype(np.float32)

    def save_target(self, image_id: str, image: np.ndarray) -> None:
        """Compute and store the target's features unless they are stored already."""
        path = self._layout.target_features(image_id)
        if not path.is_file():
            _save(path, self._compute(image))

    def save_render(self, method: str, image_id: str, image: np.ndarray) -> None:
        """Compute and store (or replace) the features of ``method``'s render of the image."""
        _save(self._layout.render_features(method, image_id), self._compute(image))

    def target(self, image_id: str) -> np.ndarray | None:
        """The target's features: stored, else computed from its PNG (and stored), else None."""
        return self._load(self._layout.target_features(image_id), self._layout.target(image_id))

    def render(self, method: str, image_id: str) -> np.ndarray | None:
        """The render's features: stored, else computed from its PNG (and stored), else None."""
        return self._load(
            self._layout.render_features(method, image_id), self._layout.render(method, image_id)
        )

    def _load(self, stored: Path, picture: Path) -> np.ndarray | None:
        if stored.is_file():
            try:
                features = np.load(stored, allow_pickle=False)
                if features.shape == (FEATURES,):
                    return features.astype(np.float64)
            except (OSError, ValueError):
                pass  # unreadable: computed again below if the picture is still there
        if not picture.is_file():
            return None
        try:
            image = to_float_rgb(read_image(picture), str(picture))
        except InputError:
            return None
        features = self._compute(image)
        _save(stored, features)
        return features.astype(np.float64)


def _save(path: Path, features: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    buffer = io.BytesIO()
    np.save(buffer, np.asarray(features, dtype=np.float32), allow_pickle=False)
    atomic_write_bytes(path, buffer.getvalue())


def fid_over_stored(
    store: FeatureStore, methods: list[str], ids: list[str]
) -> tuple[dict[str, float], list[str]]:
    """FID of each method over the images of ``ids`` whose target and renders (from every
    method) have features, stored or computable; returns the values (NaN where not computed)
    and the problems (including how many images were left out)."""
    values = {method: float("nan") for method in methods}
    targets: list[np.ndarray] = []
    renders: dict[str, list[np.ndarray]] = {method: [] for method in methods}
    try:
        for image_id in ids:
            target = store.target(image_id)
            found = [store.render(method, image_id) for method in methods]
            own = [features for features in found if features is not None]
            if target is None or len(own) < len(methods):
                continue
            targets.append(target)
            for method, features in zip(methods, own, strict=True):
                renders[method].append(features)
    except SamvgError as error:
        return values, [f"FID: {str(error).splitlines()[0]}"]
    problems = []
    if len(ids) > len(targets):
        problems.append(
            f"FID over {len(targets)} of {len(ids)} images: the others have neither stored "
            "features nor renders"
        )
    if len(targets) < 2:
        return values, [*problems, "FID needs at least two images with every method's features"]
    target_features = np.stack(targets)
    for method in methods:
        try:
            values[method] = metrics.frechet_distance(
                np.stack(renders[method]), target_features, method="nuclear"
            )
        except SamvgError as error:
            problems.append(f"FID of {method}: {str(error).splitlines()[0]}")
    return values, problems
