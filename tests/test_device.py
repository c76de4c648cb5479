"""Devices named by the user are checked against torch before anything loads."""

import pytest
import torch

from samvg.device import check_device
from samvg.errors import InputError


def test_cpu_is_always_there():
    check_device("cpu")


def test_devices_a_machine_lacks(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    monkeypatch.setattr(torch.backends.mps, "is_available", lambda: False)
    for device in ("cuda", "cuda:0", "cuda:3", "mps"):
        with pytest.raises(InputError, match=f"device {device} is not available"):
            check_device(device)


def test_a_cuda_index_beyond_the_gpus(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    monkeypatch.setattr(torch.cuda, "device_count", lambda: 2)
    check_device("cuda:1")
    with pytest.raises(InputError, match="has 2 CUDA devices"):
        check_device("cuda:2")


def test_names_that_are_no_device():
    with pytest.raises(InputError, match="device must be cpu, cuda, cuda:N or mps"):
        check_device("tpu")
