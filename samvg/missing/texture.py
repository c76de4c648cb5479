"""Texture layers: under a path budget, a textured image's last paths are compound paths of many
small islands of one colour each, laid over the fitted scene where the render misses the
image's texture (the stones of a wall, a painting's strokes, the glints on water). This is how
VTracer's layered output keeps a photo's texture with few ``<path>`` elements. Paths that SAM's
masks give are smooth regions; at 64 paths kodim01's stone wall was a smooth smear, LPIPS 0.58
against VTracer's 0.47; with 8 texture layers it is 0.32.

One layer at a time: the image's colours, sampled where the render is wrong (weighted by the
squared error), are clustered by k-means (scikit-learn ``KMeans``); of the cluster colours, the
one that paints its pixels better than the render with the most gain in all wins. Those pixels,
cleared of single-pixel noise (a 3 × 3 median) and of islands under ``min_pixels``, are the
layer: its islands of most gain are traced (stage 2's tracer) and joined into one compound path
(`Scene.joined`) filled with their mean colour. Where the budget is full, a layer takes the
place of the element of least removal cost beneath the layers (`removal_costs`, summed over an
element's pieces, measured once), and is kept only if the whole render's MSE drops: on hatched
line art (arctic_greyling at 16 paths) the two paths that the layers replaced mattered more
(MSE 35.2 -> 57.6e-3 when room for all the layers was made first and they then found no gain).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage
from sklearn.cluster import KMeans

from samvg.optimize.reduce import removal_costs
from samvg.scene import FlatPaint, Scene
from samvg.trace import trace_masks

#: Pixels sampled for the k-means fit of the colours the render misses.
SAMPLE_PIXELS = 20000


@dataclass(frozen=True)
class TextureSettings:
    """Texture layers in working pixels."""

    share: float = 0.125
    """The share of a path budget given to texture layers (at least one layer)."""
    max_layers: int = 16
    """The most texture layers (keeps the SVG small at large budgets)."""
    islands: int = 150
    """The most islands one layer holds (those of most gain)."""
    colours: int = 8
    """k-means clusters of the missed colours, each a candidate layer colour."""
    min_pixels: float = 4.0
    """Smaller islands are left out: 2 × 2 pixels, a finer grain than the marks' speckle filter
    (`MissingOptions.filter_speckle`, 4 × 4 as VTracer's): at 16 pixels, kodim01 at 64 paths
    kept 237 shapes in place of 1282 (LPIPS 0.31 -> 0.48), great_wave's LPIPS went 0.29 -> 0.31
    and kodim04's 0.30 -> 0.33."""
    tolerance: float = 1.0
    """The tracer's tolerance (pixels) for an island's outline."""
    min_lpips: float = 0.05
    """Without a path budget, an image that is not textured (flat art) gets layers where its
    fitted render's LPIPS against it is at least this: it still looks unlike it. Below, layers
    cost bytes for differences hardly seen (see `benchmarks/results/detail.md`)."""
    seed: int = 0

    def layers(self, budget: int) -> int:
        """Texture layers under a budget of ``budget`` paths (none under a budget of one)."""
        if budget < 2:
            return 0
        return min(self.max_layers, max(1, round(budget * self.share)), budget - 1)


def add_texture_layers(
    scene: Scene,
    target: np.ndarray,
    budget: int,
    settings: TextureSettings,
    opaque: np.ndarray | None = None,
    min_gain: float = 0.0,
) -> tuple[Scene, int]:
    """``scene`` (within ``budget`` SVG elements) with texture layers laid on top, each one in
    exchange for the element of least removal cost beneath them where the budget is full, and
    kept only if the exchange lowers the MSE against ``target`` (H, W, 3 float in [0, 1]);
    returns the scene and how many layers it gained. With ``opaque`` ((H, W) bool, an input with
    transparency), islands lie only where it is True; with ``min_gain``, a layer must lower the
    MSE by that fraction."""
    generator = np.random.default_rng(settings.seed)
    runs = scene.joined_runs()
    cheapest: list[int] = []
    removed: list[int] = []
    base, layers = scene, scene.subset([])
    error = _mse(scene, target)
    for _ in range(settings.layers(budget)):
        current = base.stacked(layers)
        room, out = base, removed
        if current.element_count >= budget:
            if not cheapest:  # measured once, on the scene as it came
                costs = np.bincount(runs, weights=removal_costs(scene, target))
                cheapest = np.argsort(costs, kind="stable").tolist()
            out = [*removed, cheapest[len(removed)]]
            room = scene.subset(np.flatnonzero(~np.isin(runs, out)))
        under = room.stacked(layers)
        found = _best_exchange(current, under, target, settings, generator, opaque)
        if found is None or found[1] >= error * (1.0 - min_gain):
            break
        layer, error = found
        base, layers, removed = room, layers.stacked(layer), out
    return base.stacked(layers), layers.element_count


def _best_exchange(
    current: Scene,
    under: Scene,
    target: np.ndarray,
    settings: TextureSettings,
    generator: np.random.Generator,
    opaque: np.ndarray | None,
) -> tuple[Scene, float] | None:
    """The next layer laid over ``under`` (``current`` less the element the layer replaces, or
    ``current`` itself) and the MSE it leaves. Where an element goes, the layer is drawn both
    over ``under``'s render (to fill in for the element too) and over ``current``'s (where
    filling in painted over more than it mended: kodim01 at 64 paths kept 1 layer of 8), and
    the one that leaves less error is taken."""
    drawn_over = [under] if under.path_count == current.path_count else [under, current]
    best: tuple[Scene, float] | None = None
    for scene in drawn_over:
        layer = texture_layer(scene, target, settings, generator, opaque)
        if layer is None:
            continue
        error = _mse(under.stacked(layer), target)
        if best is None or error < best[1]:
            best = (layer, error)
    return best


def texture_layer(
    scene: Scene,
    target: np.ndarray,
    settings: TextureSettings,
    generator: np.random.Generator,
    opaque: np.ndarray | None = None,
) -> Scene | None:
    """The next texture layer over ``scene``'s render: a scene of islands of one flat colour,
    each joined to the one below into one compound path (None: nothing worth a layer), only
    where ``opaque`` is True when given."""
    squared = ((target - scene.render()) ** 2).sum(axis=2)
    if opaque is not None:  # no gain where the input is transparent: no island there
        squared = np.where(opaque, squared, 0.0)
    mask = _best_colour_mask(squared, target, settings, generator)
    if mask is None:
        return None
    labels, count = ndimage.label(mask)
    indices = np.arange(1, count + 1)
    areas = ndimage.sum_labels(mask, labels, indices)
    gains = ndimage.sum_labels(
        squared - _squared_to(target, target[mask].mean(axis=0)), labels, indices
    )
    wanted = indices[(areas >= settings.min_pixels) & (gains > 0)]
    wanted = wanted[np.argsort(-gains[wanted - 1], kind="stable")[: settings.islands]]
    if len(wanted) == 0:
        return None
    islands = np.isin(labels, wanted)
    colour = target[islands].mean(axis=0)
    traced = trace_masks(
        [islands], target, min_area=settings.min_pixels, tolerance=settings.tolerance
    )
    if traced.path_count == 0:
        return None
    paint = FlatPaint((float(colour[0]), float(colour[1]), float(colour[2]), 1.0))
    inside = np.clip(traced.points, 0.0, [traced.width, traced.height])  # handles past the edge
    layer = replace(traced.with_geometry(inside), paints=(paint,) * traced.path_count)
    joined = np.ones(layer.path_count, dtype=bool)
    joined[0] = False
    return replace(layer, joined=joined)


def _best_colour_mask(
    squared: np.ndarray,
    target: np.ndarray,
    settings: TextureSettings,
    generator: np.random.Generator,
) -> np.ndarray | None:
    """The pixels that the candidate colour of most total gain paints better than the render,
    single-pixel noise removed (None when the render is exact)."""
    weights = squared.reshape(-1).astype(np.float64)
    if weights.sum() <= 0:
        return None
    pixels = target.reshape(-1, 3)
    picked = generator.choice(
        len(pixels), min(SAMPLE_PIXELS, len(pixels)), p=weights / weights.sum()
    )
    sample = pixels[picked]
    clusters = min(settings.colours, len(np.unique(sample, axis=0)))
    centres = KMeans(clusters, n_init=1, random_state=settings.seed).fit(sample).cluster_centers_
    best, best_gain = None, 0.0
    for centre in centres:
        gain = squared - _squared_to(target, centre)
        mask = ndimage.median_filter(gain > 0, size=3)
        total = float(gain[mask].sum())
        if total > best_gain:
            best, best_gain = mask, total
    return best


def _squared_to(target: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """Per pixel, the squared distance (summed over RGB) from ``target`` to one colour."""
    return ((target - colour) ** 2).sum(axis=2)


def _mse(scene: Scene, target: np.ndarray) -> float:
    return float(np.mean((scene.render() - target) ** 2))
