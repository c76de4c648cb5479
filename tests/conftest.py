"""Shared fixtures: model weights and benchmark images from ../shared (or the SAMVG_* variables)."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared"


def shared_file(variable: str, relative: str) -> Path:
    """A file named by environment variable, else under ../shared; skip if neither exists."""
    candidate = Path(os.environ.get(variable) or SHARED / relative)
    if not candidate.is_file():
        pytest.skip(f"{relative} not found (set {variable} or place ../shared beside the repo)")
    return candidate


@pytest.fixture(scope="session")
def sam_checkpoint() -> Path:
    return shared_file("SAMVG_SAM_CHECKPOINT", "models/mobile_sam.pt")


@pytest.fixture(scope="session")
def bench_dir() -> Path:
    folder = SHARED / "bench"
    if not (folder / "manifest.csv").is_file():
        pytest.skip("../shared/bench not found")
    return folder


@pytest.fixture(scope="session")
def lpips_weights() -> Path:
    return shared_file("SAMVG_LPIPS_WEIGHTS", "models/lpips_alex.pt")


@pytest.fixture(scope="session")
def fid_weights() -> Path:
    return shared_file("SAMVG_FID_WEIGHTS", "models/fid_inception_v3.torchscript.pt")
