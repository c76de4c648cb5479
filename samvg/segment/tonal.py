"""Tonal regions: the large areas of one tone of a blurred image, as VTracer's hierarchical
clustering finds them at a coarse setting. SAM finds objects; in a textured picture (a brick
wall, a painting's strokes) its masks are the texture's small patches, or nothing, and a small
path budget spent on those leaves the picture's light and dark areas out. A tonal region is a
candidate beneath the masks and their colour parts, kept only if the filter by impact finds it
lowers the error.

Only a textured image gets them: one whose JPEG complexity (Machado & Cardoso, as the bench
measures it) is at least ``min_complexity``. On flat art and smooth wallpapers they crowded out
the small marks that stage 4 finds (debian_spacefun at 256 paths: LPIPS 0.093 -> 0.237, its
stars gone); on photos, paintings and hatched line art they were the better paths
(composition_vii at 16 paths: MSE 31.9 -> 26.3e-3, openclipart_bowsaw 3.8 -> 1.0e-3).

The image (CIELAB) is blurred with a Gaussian of ``blur`` pixels, its colours are
clustered by k-means (scikit-learn ``KMeans``) into ``tones`` clusters, and each connected area of
one cluster, holes filled, is a region.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from sklearn.cluster import KMeans

from samvg.imaging import filled_components
from samvg.metrics.image_metrics import complexity

#: k-means is fitted on at most this many pixels (every pixel is then labelled).
SAMPLE_PIXELS = 20000
#: The least JPEG complexity of a textured image: the bench's photos and paintings measure 0.20
#: to 1.33, its hatched clipart 0.21 to 0.30, its emoji, icons and wallpapers 0.02 to 0.10.
TEXTURED = 0.15


@dataclass(frozen=True)
class TonalSettings:
    """Tonal regions in working pixels."""

    blur: float
    """Pixels: the Gaussian's sigma."""
    tones: int
    """k-means clusters."""
    min_pixels: float
    """Smaller regions are left out."""
    seed: int = 0
    min_complexity: float = TEXTURED
    """The least JPEG complexity of an image that gets tonal regions."""


def textured(image: np.ndarray, min_complexity: float = TEXTURED) -> bool:
    """Whether an (H, W, 3) float image in [0, 1] is textured: its JPEG complexity is at least
    ``min_complexity`` (also the gate of `samvg.missing.texture`)."""
    return complexity(image) >= min_complexity


def tonal_regions(lab: np.ndarray, settings: TonalSettings) -> list[np.ndarray]:
    """The tonal regions of an (H, W, 3) CIELAB image as full-size masks, largest first."""
    height, width = lab.shape[:2]
    blurred = np.stack(
        [ndimage.gaussian_filter(lab[..., channel], settings.blur) for channel in range(3)],
        axis=-1,
    ).reshape(-1, 3)
    generator = np.random.default_rng(settings.seed)
    sample = blurred[generator.choice(len(blurred), min(SAMPLE_PIXELS, len(blurred)), False)]
    tones = min(settings.tones, len(np.unique(sample, axis=0)))
    if tones < 2:
        return []
    clusters = KMeans(tones, n_init=2, random_state=settings.seed).fit(sample)
    labels = clusters.predict(blurred).reshape(height, width)
    regions = [
        region
        for tone in range(tones)
        for region in filled_components(labels == tone, settings.min_pixels)
    ]
    return sorted(regions, key=lambda region: -int(np.count_nonzero(region)))
