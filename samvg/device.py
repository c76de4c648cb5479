"""Whether a torch device named by the user (``cpu``, ``cuda``, ``cuda:N``, ``mps``) exists on
this machine, asked of torch before any model is loaded."""

from __future__ import annotations

import torch

from samvg.errors import InputError


def check_device(device: str) -> None:
    """Raise `InputError` with one line unless ``device`` can be used on this machine."""
    if device == "cpu":
        return
    if device.startswith("cuda"):
        if not torch.cuda.is_available():
            why = "is built without CUDA" if torch.version.cuda is None else "finds no CUDA GPU"
            raise InputError(
                f"device {device} is not available: torch {torch.__version__} {why}; "
                "use --device cpu"
            )
        index = int(device.partition(":")[2] or 0)
        count = torch.cuda.device_count()
        if index >= count:
            raise InputError(
                f"device {device} is not available: this machine has {count} CUDA device"
                f"{'s' if count != 1 else ''} (cuda:0 to cuda:{count - 1})"
            )
        return
    if device == "mps":
        if not torch.backends.mps.is_available():
            raise InputError("device mps is not available: it needs Apple silicon and macOS 12.3+")
        return
    raise InputError(f"device must be cpu, cuda, cuda:N or mps, got {device!r}")
