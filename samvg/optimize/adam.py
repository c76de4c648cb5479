"""Adam for the fitting loops, step for step the update of ``torch.optim.Adam`` on CPU.

Why our own: constructing any ``torch.optim`` optimizer imports ``torch._dynamo`` (about a
second on two cores), which is a fifth of the ``--fast`` preset's budget; the fits need nothing
of it but the plain update on a handful of tensors.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import torch


class Adam:
    """Adam (Kingma & Ba) over groups of tensors, one learning rate per group: a number, or a
    tensor that broadcasts against each of the group's tensors (a rate per element).

    With numbers the arithmetic is that of ``torch.optim.Adam``'s single-tensor path (the CPU
    default), so a fit gives the same numbers with either.
    """

    def __init__(
        self,
        groups: Sequence[tuple[Sequence[torch.Tensor], float | torch.Tensor]],
        betas: tuple[float, float] = (0.9, 0.999),
        eps: float = 1e-8,
    ) -> None:
        self.groups = [
            (list(tensors), rate if isinstance(rate, torch.Tensor) else float(rate))
            for tensors, rate in groups
        ]
        self.betas = betas
        self.eps = eps
        self.steps = 0
        self._moments: dict[int, tuple[torch.Tensor, torch.Tensor]] = {}

    def zero_grad(self) -> None:
        for tensors, _ in self.groups:
            for tensor in tensors:
                tensor.grad = None

    @torch.no_grad()
    def step(self) -> None:
        beta1, beta2 = self.betas
        self.steps += 1
        correction1 = 1 - beta1**self.steps
        correction2_root = math.sqrt(1 - beta2**self.steps)
        for tensors, rate in self.groups:
            for tensor in tensors:
                if tensor.grad is None:
                    continue
                mean, square = self._moments.setdefault(
                    id(tensor), (torch.zeros_like(tensor), torch.zeros_like(tensor))
                )
                mean.lerp_(tensor.grad, 1 - beta1)
                square.mul_(beta2).addcmul_(tensor.grad, tensor.grad, value=1 - beta2)
                denominator = (square.sqrt() / correction2_root).add_(self.eps)
                if isinstance(rate, torch.Tensor):
                    tensor.sub_(mean / denominator * (rate / correction1))
                else:
                    tensor.addcdiv_(mean, denominator, value=-rate / correction1)
