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
