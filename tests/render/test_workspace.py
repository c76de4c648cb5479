"""The rasterizer's reused scratch buffers: never shared while in use, reused once free."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from samvg.render import rasterize, workspace


def _address(array: np.ndarray) -> int:
    """Where the array's data starts (an id that holds no reference to the buffer)."""
    return int(array.__array_interface__["data"][0])


def test_an_array_in_use_keeps_its_buffer_and_a_freed_one_is_reused() -> None:
    workspace.clear()
    first = workspace.scratch((1000, 3), np.float32)
    first[...] = 7.0
    second = workspace.scratch((1000, 3), np.float32)
    assert _address(first) != _address(second)
    assert np.all(first == 7.0)
    held = _address(second)
    del second
    third = workspace.scratch(1500, np.float64)  # 12 KB: fits the freed 15 KB buffer
    assert _address(third) == held
    assert third.shape == (1500,) and third.dtype == np.float64 and third.flags.c_contiguous


def test_a_slightly_larger_request_reuses_a_buffer_made_with_room() -> None:
    workspace.clear()
    first = workspace.scratch(10_000, np.float64)
    held = _address(first)
    del first
    again = workspace.scratch(11_000, np.float64)
    assert _address(again) == held


def test_free_buffers_beyond_the_limit_are_let_go(monkeypatch: pytest.MonkeyPatch) -> None:
    workspace.clear()
    monkeypatch.setattr(workspace, "MAX_KEPT_BYTES", 100_000)
    arrays = [workspace.scratch(10_000, np.float64) for _ in range(4)]  # 100 KB each, with room
    assert len(workspace._buffers) == 4
    del arrays
    workspace.scratch(8, np.uint8)
    assert sum(buffer.nbytes for buffer in workspace._buffers) <= 200_000


def test_draws_on_reused_buffers_match_draws_on_fresh_ones() -> None:
    """Forward and backward passes on buffers that held another scene give the same bits."""
    rng = np.random.default_rng(3)
    points = torch.tensor(rng.uniform(2, 46, (6, 12, 2)), requires_grad=True)
    colours = torch.tensor(rng.uniform(0.1, 0.9, (6, 4)), requires_grad=True)
    runs = []
    for run in range(3):
        if run == 0:
            workspace.clear()
        else:  # leave other numbers in the free buffers
            for _ in range(4):
                workspace.scratch(50_000, np.float64)[...] = np.nan
        image = rasterize(points, colours, 48, 40)
        (image**2).sum().backward()
        runs.append((image.detach().clone(), points.grad.clone(), colours.grad.clone()))
        points.grad = colours.grad = None
    for image, point_grad, colour_grad in runs[1:]:
        assert torch.equal(image, runs[0][0])
        assert torch.equal(point_grad, runs[0][1])
        assert torch.equal(colour_grad, runs[0][2])
