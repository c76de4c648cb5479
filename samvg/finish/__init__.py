"""The finish stage: clean, editable geometry before saving (see ``finish``).

Bounded control points (``bounds``), simple paths (``simplicity``), no hidden paths
(``hidden``, which also turns a path over the whole canvas into the background), merged paths
of near-equal colour (``merge``), an optional palette (``palette``) and, when the scene is
saved, paths in whole pixels where that changes nothing visible (``whole_pixels``). They share one
flattener (``flatten``), the painted area of a path as shapely geometry (``outline``),
outlines redrawn from the cubics they were cut from (``trim``) or fitted afresh (``refit``),
cubic-segment operations (``cubics``) and per-path scene edits (``edits``).
"""

from samvg.finish.bounds import bound_paths, default_margin, margin_box
from samvg.finish.finish import FinishResult, FinishSettings, finish_scene
from samvg.finish.flatten import flatten_path, flatten_paths
from samvg.finish.hidden import background_from_cover, remove_hidden
from samvg.finish.merge import merge_paths
from samvg.finish.palette import snap_colours
from samvg.finish.refit import refit_ring
from samvg.finish.simplicity import crossing_paths, simplify_paths
from samvg.finish.trim import redraw_ring

__all__ = [
    "FinishResult",
    "background_from_cover",
    "FinishSettings",
    "bound_paths",
    "crossing_paths",
    "default_margin",
    "finish_scene",
    "flatten_path",
    "flatten_paths",
    "margin_box",
    "merge_paths",
    "redraw_ring",
    "refit_ring",
    "remove_hidden",
    "simplify_paths",
    "snap_colours",
]
