"""The finish stage: the last pass over a scene before it is saved.

``finish_scene`` runs, in order: bounded geometry (``bounds``), simple paths (``simplicity``),
hidden paths and a path that hides the background (``hidden``), merging (``merge``) and the
palette (``palette``), each switchable in :class:`FinishSettings` (bounds always runs), and
gathers their counts. Every path a step redraws keeps its control points inside the canvas plus
the margin.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from samvg.errors import InputError
from samvg.finish.bounds import bound_paths, default_margin, margin_box
from samvg.finish.hidden import HIDDEN_TOLERANCE, background_from_cover, remove_hidden
from samvg.finish.merge import merge_paths
from samvg.finish.palette import check_colour_count, snap_colours
from samvg.finish.simplicity import MIN_PART_AREA, simplify_paths
from samvg.scene import Scene


def _check_number(value: object, name: str, positive: bool = False) -> float:
    real = (int, float, np.integer, np.floating)
    if isinstance(value, bool) or not isinstance(value, real) or not math.isfinite(value):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    if value < 0 or (positive and value == 0):
        raise InputError(f"{name} must be {'> 0' if positive else '>= 0'}, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class FinishSettings:
    """What the finish stage does, in working pixels.

    ``margin``: how far (px) control points may lie outside the canvas; None: 2 % of the longer
    side. ``tolerance``: largest distance (px) of an outline fitted afresh from the area it
    redraws (outlines cut from existing paths keep those paths' cubics and need no fit).
    ``background_from_path``: an opaque lowest path over the whole canvas becomes the background
    (with ``remove_hidden``). ``merge_delta_e``: largest CIELAB ΔE of two fills that merge.
    ``colours``: snap the fills to this many colours (None: keep them). ``min_part_area``:
    smallest part (px²) split off a crossing or clipped path kept as its own path.
    ``hidden_tolerance``: uncovered area (px²) a hidden path may keep.
    """

    simplify: bool = True
    margin: float | None = None
    remove_hidden: bool = True
    background_from_path: bool = True
    merge: bool = True
    merge_delta_e: float = 2.0
    colours: int | None = None
    tolerance: float = 0.5
    min_part_area: float = MIN_PART_AREA
    hidden_tolerance: float = HIDDEN_TOLERANCE

    def __post_init__(self) -> None:
        for name in ("simplify", "remove_hidden", "background_from_path", "merge"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if self.margin is not None:
            object.__setattr__(self, "margin", _check_number(self.margin, "margin"))
        object.__setattr__(
            self, "merge_delta_e", _check_number(self.merge_delta_e, "merge_delta_e")
        )
        if self.colours is not None:
            object.__setattr__(self, "colours", check_colour_count(self.colours))
        object.__setattr__(
            self, "tolerance", _check_number(self.tolerance, "tolerance", positive=True)
        )
        object.__setattr__(
            self, "min_part_area", _check_number(self.min_part_area, "min_part_area")
        )
        object.__setattr__(
            self, "hidden_tolerance", _check_number(self.hidden_tolerance, "hidden_tolerance")
        )


@dataclass(frozen=True)
class FinishResult:
    """The finished scene and what each step did (``counts``, see the step functions)."""

    scene: Scene
    counts: dict[str, int] = field(default_factory=dict)


def finish_scene(scene: Scene, settings: FinishSettings | None = None) -> FinishResult:
    """Run the finish steps on ``scene`` (working pixels) with ``settings`` (default: all on,
    no palette)."""
    settings = settings if settings is not None else FinishSettings()
    margin = settings.margin
    if margin is None:
        margin = default_margin(scene.width, scene.height)
    box = margin_box(scene.width, scene.height, margin)
    tolerance, min_area = settings.tolerance, settings.min_part_area
    counts: dict[str, int] = {"finish_paths_in": scene.path_count}
    scene, step = bound_paths(scene, margin, tolerance, min_area)
    counts.update(step)
    if settings.simplify:
        scene, step = simplify_paths(scene, tolerance, min_area, box)
        counts.update(step)
    if settings.remove_hidden:
        scene, step = remove_hidden(scene, settings.hidden_tolerance)
        counts.update(step)
        if settings.background_from_path:
            scene, step = background_from_cover(scene, settings.hidden_tolerance)
            counts.update(step)
    if settings.merge:
        scene, step = merge_paths(scene, settings.merge_delta_e, tolerance, box)
        counts.update(step)
    if settings.colours is not None:
        scene, step = snap_colours(scene, settings.colours)
        counts.update(step)
    counts["finish_paths_out"] = scene.path_count
    return FinishResult(scene, counts)
