"""Fixtures of the trace tests: real SAM masks of a bench photo, made once per session."""

import numpy as np
import pytest
from PIL import Image


@pytest.fixture(scope="session")
def photo_sam_masks(sam_checkpoint, bench_dir) -> tuple[np.ndarray, list[np.ndarray]]:
    """kodim04 at 256 px and its MobileSAM automatic masks (12 points per side), largest first.

    SAM runs on one thread: on a small shared machine two threads stall each other (~3x)."""
    import torch

    from samvg.sam import SamAutomaticMaskGenerator, load_sam

    photo = Image.open(bench_dir / "photo" / "kodim04.png").convert("RGB")
    photo.thumbnail((256, 256))
    image = np.asarray(photo)
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        model = load_sam("mobile_sam", checkpoint=sam_checkpoint)
        records = SamAutomaticMaskGenerator(model, points_per_side=12).generate(image)
    finally:
        torch.set_num_threads(threads)
    masks = sorted((r["segmentation"] for r in records), key=lambda m: -int(m.sum()))
    return image, masks
