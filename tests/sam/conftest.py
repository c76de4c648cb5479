"""SAM test fixtures: the real MobileSAM model and Kodak photos, encoded once per session."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from samvg.sam import SamPredictor, load_sam


@pytest.fixture(scope="session")
def sam_model(sam_checkpoint: Path):
    return load_sam("mobile_sam", checkpoint=sam_checkpoint)


def load_photo(bench_dir: Path, name: str, long_side: int | None = None) -> np.ndarray:
    img = Image.open(bench_dir / "photo" / f"{name}.png").convert("RGB")
    if long_side is not None:
        scale = long_side / max(img.size)
        img = img.resize((round(img.width * scale), round(img.height * scale)), Image.BILINEAR)
    return np.asarray(img).copy()


@pytest.fixture(scope="session")
def photo(bench_dir: Path):
    """``photo(name, long_side=None)``: a Kodak photo as RGB uint8, optionally downscaled."""
    return lambda name, long_side=None: load_photo(bench_dir, name, long_side)


@pytest.fixture(scope="session")
def portrait(bench_dir: Path) -> np.ndarray:
    """kodim04: a girl in a red hat, 341 x 512."""
    return load_photo(bench_dir, "kodim04")


@pytest.fixture(scope="session")
def portrait_predictor(sam_model, portrait) -> SamPredictor:
    pred = SamPredictor(sam_model)
    pred.set_image(portrait)
    return pred
