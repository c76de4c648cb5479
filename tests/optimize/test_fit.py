"""Tests of path fitting: the optimiser moves a misplaced shape onto its target and fixes colour."""

import numpy as np
import pytest

from samvg import InputError, VectorImage, VectorPath
from samvg.optimize import fit_paths


def square(x0: float, y0: float, size: float) -> np.ndarray:
    corners = np.array([[x0, y0], [x0 + size, y0], [x0 + size, y0 + size], [x0, y0 + size]])
    points = []
    for i in range(4):
        start, end = corners[i], corners[(i + 1) % 4]
        points += [start, start + (end - start) / 3, start + 2 * (end - start) / 3]
    return np.array(points)


def test_fit_moves_shape_and_colour_onto_target():
    truth = VectorImage(64, 64, [VectorPath(square(20, 24, 24), (0.9, 0.2, 0.1, 1.0))])
    target = truth.render()
    start_points = square(14, 18, 20)[None]
    result = fit_paths(start_points, np.array([[0.5, 0.5, 0.5, 1.0]]), target, steps=150)
    assert result.losses[-1] < result.losses[0] / 20
    np.testing.assert_allclose(result.colours[0, :3], (0.9, 0.2, 0.1), atol=0.05)
    fitted = VectorImage(64, 64, [VectorPath(result.points[0], tuple(result.colours[0]))])
    assert np.abs(fitted.render() - target).mean() < 0.01
    assert np.abs(result.points[0, 6] - (44, 48)).max() < 1.0  # the far corner found its place


def test_fit_rejects_bad_target_and_accepts_no_paths():
    with pytest.raises(InputError, match="target"):
        fit_paths(np.zeros((1, 3, 2)), np.ones((1, 4)), np.zeros((8, 8)))
    empty = fit_paths(np.zeros((0, 3, 2)), np.zeros((0, 4)), np.zeros((8, 8, 3)), steps=5)
    assert empty.points.shape == (0, 3, 2) and empty.losses == []
