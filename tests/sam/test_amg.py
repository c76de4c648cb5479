"""Automatic mask generation on real photos (downscaled for test speed)."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from PIL import Image

from samvg.sam import SamAutomaticMaskGenerator
from samvg.sam.amg import coarse_first
from samvg.sam.amg_utils import (
    batched_mask_to_box,
    box_iou,
    build_point_grid,
    generate_crop_boxes,
    nms,
    remove_small_regions,
)


def _check_annotations(anns, h, w):
    for a in anns:
        seg = a["segmentation"]
        assert seg.shape == (h, w) and seg.dtype == bool
        assert a["area"] == int(seg.sum()) > 0
        ys, xs = np.nonzero(seg)
        assert a["bbox"] == [xs.min(), ys.min(), xs.max() - xs.min(), ys.max() - ys.min()]
        assert 0.0 <= a["stability_score"] <= 1.0
        x, y = a["point_coords"][0]
        assert 0 <= x <= w and 0 <= y <= h
        assert len(a["crop_box"]) == 4


def test_amg_photo_plausible_masks(sam_model, photo):
    img = photo("kodim04", 256)
    h, w = img.shape[:2]
    gen = SamAutomaticMaskGenerator(sam_model, points_per_side=12)
    anns = gen.generate(img)
    _check_annotations(anns, h, w)
    assert len(anns) >= 5
    areas = np.array([a["area"] for a in anns]) / (h * w)
    assert areas.max() > 0.05, "some object-sized masks"
    assert (areas < 0.95).all()
    assert all(a["predicted_iou"] > 0.88 and a["stability_score"] >= 0.95 for a in anns)
    # NMS: no two kept masks have near-identical boxes
    boxes = torch.tensor(
        [[*a["bbox"][:2], a["bbox"][0] + a["bbox"][2], a["bbox"][1] + a["bbox"][3]] for a in anns],
        dtype=torch.float32,
    )
    iou = box_iou(boxes, boxes) - torch.eye(len(anns))
    assert iou.max() <= 0.7 + 1e-6
    # union of masks covers a good part of the image
    cover = np.any([a["segmentation"] for a in anns], axis=0).mean()
    assert cover > 0.5


@pytest.mark.slow
def test_amg_crop_layers_and_small_regions(sam_model, photo):
    img = photo("kodim23", 200)  # parrots
    h, w = img.shape[:2]
    gen = SamAutomaticMaskGenerator(
        sam_model, points_per_side=8, crop_n_layers=1, min_mask_region_area=30
    )
    anns = gen.generate(img)
    _check_annotations(anns, h, w)
    assert len(anns) >= 3
    crops = {tuple(a["crop_box"]) for a in anns}
    assert len(crops) >= 2, "masks from zoomed crops survive"
    for a in anns:
        seg = a["segmentation"]
        _, changed = remove_small_regions(seg, 30, "islands")
        assert not changed


def test_skipping_covered_points_prompts_fewer_and_finds_the_same_parts(sam_model, bench_dir):
    image = Image.open(bench_dir / "emoji" / "fluentflat_crab.png").convert("RGB")
    crab = np.asarray(image.resize((256, 256), Image.BILINEAR)).copy()
    every = SamAutomaticMaskGenerator(sam_model, points_per_side=16)
    skipping = SamAutomaticMaskGenerator(sam_model, points_per_side=16, skip_covered=True)
    full = [a["segmentation"] for a in every.generate(crab)]
    annotations = skipping.generate(crab)
    found = [a["segmentation"] for a in annotations]
    assert every.prompted == 256 and skipping.prompted <= 128
    _check_annotations(annotations, 256, 256)
    union, union_found = np.any(full, axis=0), np.any(found, axis=0)
    assert (union & union_found).sum() >= 0.98 * union.sum()
    for mask in full:
        best = max((mask & other).sum() / (mask | other).sum() for other in found)
        assert best >= 0.75, "every part the whole grid finds is found again"


def test_coarse_first_visits_every_other_row_and_column_first():
    order = coarse_first(build_point_grid(4))
    assert order[:4].tolist() == [0, 2, 8, 10]
    assert sorted(order.tolist()) == list(range(16))


def test_grid_and_crops_match_upstream_conventions():
    g = build_point_grid(2)
    np.testing.assert_allclose(g, [[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]])
    boxes, layers = generate_crop_boxes((300, 400), 1, 512 / 1500)
    assert boxes[0] == [0, 0, 400, 300] and layers == [0, 1, 1, 1, 1]
    for x0, y0, x1, y1 in boxes[1:]:
        assert 0 <= x0 < x1 <= 400 and 0 <= y0 < y1 <= 300
        assert (x1 - x0) > 200 and (y1 - y0) > 150


def test_box_utils():
    m = torch.zeros(3, 10, 12, dtype=torch.bool)
    m[0, 2:5, 3:7] = True
    m[1, 9, 11] = True
    boxes = batched_mask_to_box(m)
    assert boxes.tolist() == [[3, 2, 6, 4], [11, 9, 11, 9], [0, 0, 0, 0]]
    b = torch.tensor([[0, 0, 10, 10], [1, 1, 10, 10], [20, 20, 30, 30.0]])
    keep = nms(b, torch.tensor([0.5, 0.9, 0.1]), 0.7)
    assert keep.tolist() == [1, 2]


def test_remove_small_regions():
    m = np.zeros((20, 20), bool)
    m[2:15, 2:15] = True
    m[6, 6] = False  # 1-pixel hole
    m[18, 18] = True  # 1-pixel island
    filled, ch = remove_small_regions(m, 5, "holes")
    assert ch and filled[6, 6]
    cleaned, ch = remove_small_regions(filled, 5, "islands")
    assert ch and not cleaned[18, 18] and cleaned[2:15, 2:15].all()
    same, ch = remove_small_regions(cleaned, 5, "islands")
    assert not ch and (same == cleaned).all()
