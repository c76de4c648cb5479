"""Colour-coherent parts: a mask whose pixels hold two or more distinct colours (a striped sail,
a suit symbol on a card) gets one part per extra colour, to be painted on top of it, so that no
path is filled with the blur of two colours.

The colours are found by k-means in CIELAB (scikit-learn ``KMeans``) on a sample of the mask's
pixels; k grows while each step still removes a large share of the colour variance and the
centres stay distinct: ``contrast`` apart (in ΔE), or, for two flat colours, only
``fine_contrast`` apart (a folder's grey stripes, ΔE 7: distinct to the eye, but a smooth ramp
of that range must stay one colour for a gradient fill; the two are told apart by how rare the
colours between them are, `MAX_DIP`). The mask keeps its most common colour; each
connected region of another colour (opened with a 3 × 3 square, so that the one- or two-pixel
anti-aliased seams between colours do not become parts of their own) becomes a part with its
holes filled. A filled part can again hold other colours (a ring's inside), so parts are split
the same way, ``depth`` levels deep.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from skimage.color import rgb2lab
from sklearn.cluster import KMeans

from samvg.imaging import filled_components

#: k-means runs on at most this many of a mask's pixels (labels are then given to all).
SAMPLE_PIXELS = 4000
#: k grows while the next centre removes at least this share of the remaining colour variance.
MIN_VARIANCE_DROP = 0.4
#: Two clusters closer than ``contrast`` are two colours only when the colours halfway between
#: their centres are at most this share as common as those at the centres (counted in bands a
#: quarter of the gap wide): a folder's shaded stripes give 0.26, an even ramp 1, a gradient
#: wallpaper 1.2 to 1.5, a photo's texture 0.9 at such small gaps.
MAX_DIP = 0.35
_OPENING = np.ones((3, 3), dtype=bool)


@dataclass(frozen=True)
class ColourSplitSettings:
    """How masks are split into colour-coherent parts (working pixels)."""

    min_pixels: float
    """Parts smaller than this (after opening) are dropped."""
    contrast: float = 10.0
    """Smallest ΔE (CIELAB) between two colours for them to become separate parts."""
    fine_contrast: float = 4.0
    """Smallest ΔE between two colours with few colours between them (see `MAX_DIP`)."""
    max_colours: int = 4
    depth: int = 3
    seed: int = 0


def lab_image(target: np.ndarray) -> np.ndarray:
    """``target`` (H, W, 3) RGB in [0, 1] in CIELAB, float32."""
    return rgb2lab(np.clip(target, 0.0, 1.0)).astype(np.float32)


def colour_clusters(pixels: np.ndarray, settings: ColourSplitSettings) -> np.ndarray | None:
    """The distinct colour centres (k, 3) of ``pixels`` (n, 3) in CIELAB, most common first, or
    None when they are one colour (see `_distinct`)."""
    if len(pixels) < 2 * settings.min_pixels:
        return None
    rng = np.random.default_rng(settings.seed)
    sample = pixels if len(pixels) <= SAMPLE_PIXELS else rng.choice(pixels, SAMPLE_PIXELS, False)
    spread = float(((sample - sample.mean(axis=0)) ** 2).sum(axis=1).mean())
    if spread < (min(settings.contrast, settings.fine_contrast) / 2) ** 2:
        return None
    best: np.ndarray | None = None
    inertia = spread * len(sample)
    distinct = len(np.unique(np.round(sample, 1), axis=0))
    for k in range(2, min(settings.max_colours, distinct) + 1):
        kmeans = KMeans(n_clusters=k, n_init=2, random_state=settings.seed).fit(sample)
        centres = kmeans.cluster_centers_
        if (
            not _distinct(sample, centres, settings)
            or kmeans.inertia_ > (1 - MIN_VARIANCE_DROP) * inertia
        ):
            break
        counts = np.bincount(kmeans.labels_, minlength=k)
        best, inertia = centres[np.argsort(-counts, kind="stable")], kmeans.inertia_
    return best


def _distinct(sample: np.ndarray, centres: np.ndarray, settings: ColourSplitSettings) -> bool:
    """Whether every two of ``centres`` are distinct colours: ``settings.contrast`` apart, or
    ``settings.fine_contrast`` apart with few of ``sample``'s colours between them (`MAX_DIP`)."""
    for first in range(len(centres)):
        for second in range(first + 1, len(centres)):
            axis = centres[second] - centres[first]
            gap = float(np.linalg.norm(axis))
            if gap >= settings.contrast:
                continue
            if gap < settings.fine_contrast:
                return False
            along = (sample - centres[first]) @ axis / gap**2  # 0 at the first, 1 at the second
            near = np.count_nonzero(np.abs(along) < 0.125) + np.count_nonzero(
                np.abs(along - 1) < 0.125
            )
            between = np.count_nonzero(np.abs(along - 0.5) < 0.125)
            if between > MAX_DIP * near / 2:
                return False
    return True


def colour_parts(
    mask: np.ndarray, lab: np.ndarray, settings: ColourSplitSettings, depth: int | None = None
) -> list[np.ndarray]:
    """The parts of ``mask`` (H, W) bool whose colour differs from the mask's main colour, as
    filled full-size masks, each followed by its own parts (``depth`` levels)."""
    depth = settings.depth if depth is None else depth
    return _cluster_parts(mask, lab, settings, depth, with_main=False)


def colour_regions(
    region: np.ndarray, lab: np.ndarray, settings: ColourSplitSettings
) -> list[np.ndarray]:
    """Every colour-coherent part of ``region`` (the main colour's too), each followed by its own
    parts: the candidate shapes of an area the current paths get wrong."""
    return _cluster_parts(region, lab, settings, settings.depth, with_main=True)


def _cluster_parts(
    mask: np.ndarray, lab: np.ndarray, settings: ColourSplitSettings, depth: int, with_main: bool
) -> list[np.ndarray]:
    rows, cols = np.nonzero(mask)
    if depth <= 0 or len(rows) == 0:
        return []
    pixels = lab[rows, cols]
    centres = colour_clusters(pixels, settings)
    if centres is None:
        if not with_main:
            return []
        centres = pixels.mean(axis=0, keepdims=True)
    nearest = np.argmin(((pixels[:, None, :] - centres[None]) ** 2).sum(axis=2), axis=1)
    top, left = rows.min(), cols.min()
    window = np.full((rows.max() - top + 1, cols.max() - left + 1), -1, dtype=np.int16)
    window[rows - top, cols - left] = nearest
    parts: list[_Region] = []

    def add(found: np.ndarray) -> None:
        candidate = _Region.of(found)
        if not any(candidate.same_as(other) for other in parts):
            parts.append(candidate)

    for cluster in range(0 if with_main else 1, len(centres)):
        region = ndimage.binary_opening(window == cluster, _OPENING)
        for part in filled_components(region, settings.min_pixels):
            full = _full_size(part, mask.shape, top, left)
            for found in (full, *_cluster_parts(full, lab, settings, depth - 1, False)):
                add(found)
    if not with_main and len(centres) > 1:
        # the main colour's own area may hold colours the first clustering had no room for
        # (a folder's stripes beside its blue front and dark border)
        main = _full_size(ndimage.binary_opening(window == 0, _OPENING), mask.shape, top, left)
        for found in _cluster_parts(main, lab, settings, depth - 1, False):
            add(found)
    return [part.mask for part in parts]


def _full_size(part: np.ndarray, shape: tuple[int, ...], top: int, left: int) -> np.ndarray:
    """``part``, a window whose corner is at (``top``, ``left``), as a mask of ``shape``."""
    full = np.zeros(shape, dtype=bool)
    full[top : top + part.shape[0], left : left + part.shape[1]] = part
    return full


@dataclass(frozen=True)
class _Region:
    """A full-size mask with its pixel count and bounds, so that comparing two stays cheap."""

    mask: np.ndarray
    count: int
    rows: tuple[int, int]
    cols: tuple[int, int]

    @classmethod
    def of(cls, mask: np.ndarray) -> _Region:
        rows = np.flatnonzero(mask.any(axis=1))
        cols = np.flatnonzero(mask.any(axis=0))
        if len(rows) == 0:
            return cls(mask, 0, (0, 0), (0, 0))
        count = int(np.count_nonzero(mask))
        bounds = (int(rows[0]), int(rows[-1]) + 1), (int(cols[0]), int(cols[-1]) + 1)
        return cls(mask, count, *bounds)

    def same_as(self, other: _Region, overlap: float = 0.9) -> bool:
        """Whether the two masks cover nearly the same pixels (a disc found inside a ring's
        filled part and again as a region of its own colour): at least ``overlap`` of the
        larger one's pixels shared."""
        larger = max(self.count, other.count)
        if min(self.count, other.count) < overlap * larger:
            return False
        top, bottom = max(self.rows[0], other.rows[0]), min(self.rows[1], other.rows[1])
        left, right = max(self.cols[0], other.cols[0]), min(self.cols[1], other.cols[1])
        if top >= bottom or left >= right:
            return larger == 0
        window = (slice(top, bottom), slice(left, right))
        shared = np.count_nonzero(self.mask[window] & other.mask[window])
        return bool(shared >= overlap * larger)
