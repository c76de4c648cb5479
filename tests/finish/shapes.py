"""Closed cubic paths and scenes for the finish tests."""

import numpy as np
import shapely

from samvg.finish import flatten_path
from samvg.scene import FlatPaint, Scene
from tests.paths import polygon, square

RED = (0.9, 0.1, 0.1, 1.0)
BLUE = (0.1, 0.2, 0.9, 1.0)
KAPPA = 0.5522847498  # handle length of a quarter circle as one cubic, per unit radius


def ellipse(cx: float, cy: float, rx: float, ry: float) -> np.ndarray:
    """Four cubics around an ellipse, starting at its rightmost point."""
    c = np.array([cx, cy])
    points = []
    for quarter in range(4):
        a, b = quarter * np.pi / 2, (quarter + 1) * np.pi / 2
        start = np.array([np.cos(a), np.sin(a)])
        end = np.array([np.cos(b), np.sin(b)])
        tangent_start = np.array([-np.sin(a), np.cos(a)])
        tangent_end = np.array([-np.sin(b), np.cos(b)])
        scale = np.array([rx, ry])
        points += [
            c + scale * start,
            c + scale * (start + KAPPA * tangent_start),
            c + scale * (end - KAPPA * tangent_end),
        ]
    return np.array(points)


def figure_eight(cx: float = 256.0, cy: float = 256.0) -> np.ndarray:
    """One closed path of four cubics through (cx, cy) twice: a right lobe, then a left lobe
    drawn so that the outline crosses itself at the centre."""
    return np.array(
        [
            [cx, cy], [cx + 44, cy - 80], [cx + 144, cy - 80],
            [cx + 144, cy], [cx + 144, cy + 80], [cx + 44, cy + 80],
            [cx, cy], [cx - 44, cy - 80], [cx - 144, cy - 80],
            [cx - 144, cy], [cx - 144, cy + 80], [cx - 44, cy + 80],
        ]
    )  # fmt: skip


def bow_tie() -> np.ndarray:
    """A straight-sided path whose two sides cross in the middle of a segment."""
    return polygon([[100, 100], [300, 300], [300, 100], [100, 300]])


def scene_of(*paths: tuple[np.ndarray, tuple[float, ...]], size: int = 512) -> Scene:
    return Scene.from_paths(size, size, [(points, FlatPaint(rgba)) for points, rgba in paths])


def is_simple(points: np.ndarray) -> bool:
    return bool(shapely.LinearRing(flatten_path(points)).is_simple)


def mean_abs_diff(a: Scene, b: Scene) -> float:
    return float(np.abs(a.render() - b.render()).mean())


__all__ = ["polygon", "square"]
