"""Our Adam takes the same steps as torch.optim.Adam."""

import torch

from samvg.optimize.adam import Adam


def _quadratic_steps(make_optimizer, steps: int = 25) -> list[torch.Tensor]:
    torch.manual_seed(3)
    points = torch.randn(7, 2, requires_grad=True)
    colours = torch.rand(4, 4, requires_grad=True)
    unused = torch.zeros(3, requires_grad=True)  # no gradient: left alone
    goal_points, goal_colours = torch.randn(7, 2), torch.rand(4, 4)
    optimizer = make_optimizer(points, colours, unused)
    for _ in range(steps):
        optimizer.zero_grad()
        loss = ((points - goal_points) ** 4).sum() + ((colours - goal_colours) ** 2).sum()
        loss.backward()
        optimizer.step()
    return [points.detach(), colours.detach(), unused.detach()]


def test_adam_matches_torch_step_for_step():
    ours = _quadratic_steps(lambda p, c, u: Adam([([p, u], 0.5), ([c], 0.01)]))
    theirs = _quadratic_steps(
        lambda p, c, u: torch.optim.Adam(
            [{"params": [p, u], "lr": 0.5}, {"params": [c], "lr": 0.01}]
        )
    )
    for mine, reference in zip(ours, theirs, strict=True):
        assert torch.equal(mine, reference)
    assert torch.equal(ours[2], torch.zeros(3))
    assert not torch.equal(ours[0], _quadratic_steps(lambda p, c, u: Adam([([p], 0.5)]), 0)[0])


def test_a_rate_per_element_matches_the_number_and_zero_freezes():
    ones = torch.ones(7, 1)
    by_number = _quadratic_steps(lambda p, c, u: Adam([([p, u], 0.5), ([c], 0.01)]))
    by_tensor = _quadratic_steps(lambda p, c, u: Adam([([p], 0.5 * ones), ([c], 0.01)]))
    assert torch.allclose(by_number[0], by_tensor[0], atol=1e-6)
    frozen = torch.ones(7, 1)
    frozen[2:4] = 0.0
    moved = _quadratic_steps(lambda p, c, u: Adam([([p], 0.5 * frozen), ([c], 0.01)]))
    torch.manual_seed(3)
    start = torch.randn(7, 2)
    assert torch.equal(moved[0][2:4], start[2:4])
    assert not torch.equal(moved[0][:2], start[:2])
