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
    parts = _cluster_parts(_Region.of(mask), lab, settings, depth, with_main=False)
    return [part.full(mask.shape) for part in parts]


def colour_regions(
    region: np.ndarray, lab: np.ndarray, settings: ColourSplitSettings
) -> list[np.ndarray]:
    """Every colour-coherent part of ``region`` (the main colour's too), each followed by its own
    parts: the candidate shapes of an area the current paths get wrong."""
    parts = _cluster_parts(_Region.of(region), lab, settings, settings.depth, with_main=True)
    return [part.full(region.shape) for part in parts]


def _cluster_parts(
    region: _Region, lab: np.ndarray, settings: ColourSplitSettings, depth: int, with_main: bool
) -> list[_Region]:
    rows, cols = np.nonzero(region.window)
    if depth <= 0 or len(rows) == 0:
        return []
    pixels = lab[rows + region.top, cols + region.left]
    centres = colour_clusters(pixels, settings)
    if centres is None:
        if not with_main:
            return []
        centres = pixels.mean(axis=0, keepdims=True)
    nearest = np.argmin(((pixels[:, None, :] - centres[None]) ** 2).sum(axis=2), axis=1)
    labels = np.full(region.window.shape, -1, dtype=np.int16)  # each pixel's nearest centre
    labels[rows, cols] = nearest
    parts: list[_Region] = []

    def add(found: _Region) -> None:
        if not any(found.same_as(other) for other in parts):
            parts.append(found)

    for cluster in range(0 if with_main else 1, len(centres)):
        opened = ndimage.binary_opening(labels == cluster, _OPENING)
        for part in filled_components(opened, settings.min_pixels):
            found = _Region.of(part, region.top, region.left)
            for each in (found, *_cluster_parts(found, lab, settings, depth - 1, False)):
                add(each)
    if not with_main and len(centres) > 1:
        # the main colour's own area may hold colours the first clustering had no room for
        # (a folder's stripes beside its blue front and dark border)
        opened = ndimage.binary_opening(labels == 0, _OPENING)
        main = _Region.of(opened, region.top, region.left)
        for found in _cluster_parts(main, lab, settings, depth - 1, False):
            add(found)
    return parts


@dataclass(frozen=True)
class _Region:
    """A mask as the window of its bounding box and that window's corner in the image: the
    recursion works on windows, so that a small part costs as little as its size."""

    window: np.ndarray
    top: int
    left: int
    count: int

    @classmethod
    def of(cls, mask: np.ndarray, top: int = 0, left: int = 0) -> _Region:
        """The pixels of ``mask``, a window whose corner is at (``top``, ``left``)."""
        rows = np.flatnonzero(mask.any(axis=1))
        cols = np.flatnonzero(mask.any(axis=0))
        if len(rows) == 0:
            return cls(np.zeros((0, 0), dtype=bool), top, left, 0)
        window = mask[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
        count = int(np.count_nonzero(window))
        return cls(window, top + int(rows[0]), left + int(cols[0]), count)

    @property
    def bottom(self) -> int:
        return self.top + self.window.shape[0]

    @property
    def right(self) -> int:
        return self.left + self.window.shape[1]

    def full(self, shape: tuple[int, ...]) -> np.ndarray:
        """The region as a mask of ``shape``."""
        mask = np.zeros(shape, dtype=bool)
        mask[self.top : self.bottom, self.left : self.right] = self.window
        return mask

    def same_as(self, other: _Region, overlap: float = 0.9) -> bool:
        """Whether the two regions cover nearly the same pixels (a disc found inside a ring's
        filled part and again as a region of its own colour): at least ``overlap`` of the
        larger one's pixels shared."""
        larger = max(self.count, other.count)
        if min(self.count, other.count) < overlap * larger:
            return False
        top, bottom = max(self.top, other.top), min(self.bottom, other.bottom)
        left, right = max(self.left, other.left), min(self.right, other.right)
        if top >= bottom or left >= right:
            return larger == 0
        mine = self.window[top - self.top : bottom - self.top, left - self.left : right - self.left]
        theirs = other.window[
            top - other.top : bottom - other.top, left - other.left : right - other.left
        ]
        return bool(np.count_nonzero(mine & theirs) >= overlap * larger)
