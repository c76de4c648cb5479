"""Xing loss: zero for well-formed segments, positive for crossing handles, differentiable."""

import numpy as np
import pytest
import torch

from samvg.optimize.losses import xing_loss


def circle_path(segments=4, radius=10.0):
    points = []
    k = 4 / 3 * np.tan(np.pi / (2 * segments))
    for i in range(segments):
        a0, a1 = 2 * np.pi * i / segments, 2 * np.pi * (i + 1) / segments
        p0 = radius * np.array([np.cos(a0), np.sin(a0)])
        p3 = radius * np.array([np.cos(a1), np.sin(a1)])
        t0 = radius * k * np.array([-np.sin(a0), np.cos(a0)])
        t1 = radius * k * np.array([-np.sin(a1), np.cos(a1)])
        points += [p0, p0 + t0, p3 - t1]
    return torch.tensor(np.array(points)[None], dtype=torch.float32)


def test_circle_has_no_xing_loss_either_orientation():
    assert float(xing_loss(circle_path())) == 0.0
    assert float(xing_loss(circle_path().flip(1).roll(1, 1))) == 0.0


def test_crossing_handles_are_penalised_with_gradient():
    points = circle_path().clone()
    points[0, 1], points[0, 2] = points[0, 2].clone(), points[0, 1].clone()  # swap handles
    points.requires_grad_(True)
    loss = xing_loss(points)
    assert loss.item() > 0.05
    loss.backward()
    assert torch.isfinite(points.grad).all() and points.grad.abs().sum() > 0


def test_empty_scene():
    assert float(xing_loss(torch.zeros((0, 12, 2)))) == 0.0


def test_packed_paths_of_different_lengths_match_the_equal_length_form():
    from samvg.optimize.losses import segment_indices

    circle = circle_path(4).clone()
    circle[0, 1], circle[0, 2] = circle[0, 2].clone(), circle[0, 1].clone()
    triangle = circle_path(3)
    packed = torch.cat([circle[0], triangle[0]])
    offsets = np.array([0, 12, 21])
    start, first, second, end = segment_indices(offsets)
    assert end.tolist() == [3, 6, 9, 0, 15, 18, 12]
    expected = (xing_loss(circle) * 4 + xing_loss(triangle) * 3) / 7
    assert float(xing_loss(packed, offsets)) == pytest.approx(float(expected), rel=1e-6)
