"""Filter by impact (SAMVG stage 1): keep a mask only if painting it lowers the canvas error enough.

The paper paints masks, largest first, each in the mean colour of the image under it, onto a
canvas whose uncovered pixels count as maximum error, and drops masks whose change of the
"normalized error" is below a threshold. It leaves the normalization open; samvg uses

    error(p) = mean over R, G, B of (I(p) − C(p))²  ∈ [0, 1]   (1 for uncovered pixels)
    e        = mean of error(p) over all pixels of the image  ∈ [0, 1]
    impact   = e_before − e_after                              (> 0 when the mask helps)

so the impact of a mask is the fraction of the image's worst-case error it removes: a mask that
covers 1% of a blank canvas exactly has impact 0.01, and a mask that refines a region of 1% of the
image from error 0.02 to 0.005 has impact 0.00015. Normalizing by the image rather than by the
mask's own area makes the threshold a budget of visible error, independent of resolution; small
masks survive only where they fix a large error (eyes on a face), which is what the paper wants.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from samvg.errors import InputError
from samvg.imaging import filled_components


@dataclass
class ImpactDecision:
    """What the filter decided for one mask."""

    kept: bool
    impact: float
    colour: np.ndarray


@dataclass
class ImpactCanvas:
    """A canvas that masks are painted onto one at a time; reverts masks with too little impact.

    ``target`` (H, W, 3) float in [0, 1]. ``start`` is the initial canvas (None = blank, every
    pixel at maximum error); a start canvas counts as covered everywhere (stage 4 starts from the
    render I′). Kept masks are painted in the order :meth:`offer` receives them, except that a
    mask offered ``below=True`` only changes pixels not covered by a kept mask of smaller area
    (it will be painted beneath them, in area order).
    """

    target: np.ndarray
    threshold: float
    start: np.ndarray | None = None
    canvas: np.ndarray = field(init=False)
    covered: np.ndarray = field(init=False)
    error: np.ndarray = field(init=False)
    kept_masks: list[np.ndarray] = field(init=False, default_factory=list)
    kept_areas: list[int] = field(init=False, default_factory=list)
    kept_colours: list[np.ndarray] = field(init=False, default_factory=list)
    impacts: list[float] = field(init=False, default_factory=list)

    def __post_init__(self) -> None:
        target = np.asarray(self.target, dtype=np.float32)
        if target.ndim != 3 or target.shape[2] != 3:
            raise InputError(f"target must be an (H, W, 3) image, got shape {target.shape}")
        self.target = target
        if self.start is None:
            self.canvas = np.zeros_like(target)
            self.covered = np.zeros(target.shape[:2], dtype=bool)
            self.error = np.ones(target.shape[:2], dtype=np.float32)
        else:
            start = np.asarray(self.start, dtype=np.float32)
            if start.shape != target.shape:
                raise InputError(f"start canvas {start.shape} does not match target {target.shape}")
            self.canvas = start.copy()
            self.covered = np.ones(target.shape[:2], dtype=bool)
            self.error = np.mean((target - start) ** 2, axis=2)

    @property
    def mean_error(self) -> float:
        """e: the canvas error averaged over the image (1 = blank canvas)."""
        return float(self.error.mean())

    def impact_of(self, mask: np.ndarray, below: bool = False) -> tuple[float, np.ndarray]:
        """(impact, colour) that painting ``mask`` would have; the canvas is not changed."""
        impact, colour, _ = self._evaluate(mask, below)
        return impact, colour

    def offer(
        self, mask: np.ndarray, below: bool = False, keep: bool | None = None
    ) -> ImpactDecision:
        """Paint ``mask`` if its impact reaches the threshold (or if ``keep`` forces a decision).

        Returns the decision; a rejected mask leaves the canvas unchanged.
        """
        impact, colour, visible = self._evaluate(mask, below)
        if visible is None:
            return ImpactDecision(False, 0.0, colour)
        accept = impact >= self.threshold if keep is None else keep
        if accept:
            rows, cols, new_error = visible
            self.canvas[rows, cols] = colour
            self.error[rows, cols] = new_error
            self.covered[rows, cols] = True
            self.kept_masks.append(np.asarray(mask, dtype=bool))
            self.kept_areas.append(int(np.count_nonzero(mask)))
            self.kept_colours.append(colour)
            self.impacts.append(impact)
        return ImpactDecision(accept, impact, colour)

    def _evaluate(
        self, mask: np.ndarray, below: bool
    ) -> tuple[float, np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray] | None]:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != self.error.shape:
            raise InputError(f"mask shape {mask.shape} does not match image {self.error.shape}")
        area = int(np.count_nonzero(mask))
        if area == 0:
            return 0.0, np.zeros(3, np.float32), None
        colour = self.target[mask].mean(axis=0)
        visible = mask
        if below:
            for other, other_area in zip(self.kept_masks, self.kept_areas, strict=True):
                if other_area < area:
                    visible = visible & ~other
        rows, cols = np.nonzero(visible)
        new_error = np.mean((self.target[rows, cols] - colour) ** 2, axis=1)
        impact = float((self.error[rows, cols].sum() - new_error.sum()) / self.error.size)
        return impact, colour, (rows, cols, new_error)


def filter_by_impact(
    masks: list[np.ndarray],
    target: np.ndarray,
    threshold: float,
    start: np.ndarray | None = None,
) -> tuple[list[int], ImpactCanvas]:
    """Indices of the masks kept by the filter (masks taken largest first) and the canvas.

    ``threshold=0`` keeps every mask that does not make the canvas worse; to switch the filter off
    entirely (the paper's ablation) use :func:`keep_all`.
    """
    canvas = ImpactCanvas(target, threshold, start)
    order = sorted(range(len(masks)), key=lambda i: -int(np.count_nonzero(masks[i])))
    kept = [i for i in order if canvas.offer(masks[i]).kept]
    return kept, canvas


def keep_all(
    masks: list[np.ndarray], target: np.ndarray, start: np.ndarray | None = None
) -> tuple[list[int], ImpactCanvas]:
    """No filtering (ablation): every non-empty mask is painted, largest first."""
    canvas = ImpactCanvas(target, 0.0, start)
    order = sorted(range(len(masks)), key=lambda i: -int(np.count_nonzero(masks[i])))
    kept = [i for i in order if canvas.offer(masks[i], keep=bool(masks[i].any())).kept]
    return kept, canvas


def offer_best(
    canvas: ImpactCanvas,
    candidates: list[list[np.ndarray]],
    min_pixels: float,
    use_filter: bool = True,
    below: bool = False,
) -> int:
    """Per prompt, take SAM's candidate mask with the largest impact (with the filter off: SAM's
    first candidate) and offer its components to ``canvas``, prompts in the order given
    (largest region first). Returns how many components were kept."""
    kept = 0
    for options in candidates:
        if not options:
            continue
        if use_filter:
            impacts = [canvas.impact_of(mask, below)[0] for mask in options]
            best = options[int(np.argmax(impacts))]
        else:
            best = options[0]
        for part in filled_components(best, min_pixels):
            forced = None if use_filter else True
            kept += canvas.offer(part, below=below, keep=forced).kept
    return kept
