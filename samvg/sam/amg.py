"""SamAutomaticMaskGenerator: grid-prompted masks for a whole image, CPU-fast."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import torch
from PIL import Image

from samvg.sam.amg_utils import (
    batched_mask_to_box,
    box_area,
    build_all_layer_point_grids,
    generate_crop_boxes,
    is_box_near_crop_edge,
    nms,
    remove_small_regions,
    stability_from_counts,
    uncrop_boxes_xyxy,
    uncrop_masks,
    uncrop_points,
)
from samvg.sam.image import to_rgb_uint8
from samvg.sam.model import Sam
from samvg.sam.predictor import SamPredictor, decoder_grids, needed_lowres, resize_logits

#: RGB distance (0-255) within which a grid point has the colour of the mask that covers it
#: (24 in the 24-image run of `benchmarks/results/speed.md`; 12 kept all of debian_emerald's
#: paths in a check of four of the images that lost quality, and changed nothing on the others).
COVERED_COLOUR_TOLERANCE = 12.0


class SamAutomaticMaskGenerator:
    """Segment everything: prompt SAM with a point grid (and optional zoomed crops).

    Same parameters and output as upstream SAM's generator (binary-mask output). Speed: per
    crop the image is encoded once, prompts run in batches through `FastDecoder`; masks whose
    predicted IoU is below ``pred_iou_thresh`` are never computed, the stability score is
    taken on the 256x256 low-res logits (the part covering the image; counted while the logits
    are laid out, `FastDecoder.masks_and_counts`), and only survivors are upsampled, straight
    to the crop's own resolution. NMS runs in torch.

    Differences from upstream (documented, deliberate): stability is measured on low-res
    logits rather than on logits upsampled to the image size, and masks are resampled from
    256x256 to the image size in one bilinear step.

    ``skip_covered`` (off by default, and then the masks are upstream's): prompt every other
    row and column of the grid first, then the rest, and skip any grid point that lies inside
    the smallest kept mask of an earlier prompt and has that mask's mean colour (within
    `COVERED_COLOUR_TOLERANCE`): it would find that part again. Fewer prompts run through the
    decoder; parts that only such a point would find are lost.
    """

    def __init__(
        self,
        model: Sam,
        points_per_side: int | None = 32,
        points_per_batch: int = 8,
        pred_iou_thresh: float = 0.88,
        stability_score_thresh: float = 0.95,
        stability_score_offset: float = 1.0,
        box_nms_thresh: float = 0.7,
        crop_n_layers: int = 0,
        crop_nms_thresh: float = 0.7,
        crop_overlap_ratio: float = 512 / 1500,
        crop_n_points_downscale_factor: int = 1,
        point_grids: list[np.ndarray] | None = None,
        min_mask_region_area: int = 0,
        mask_batch: int = 2,
        skip_covered: bool = False,
    ) -> None:
        if (points_per_side is None) == (point_grids is None):
            raise ValueError("give exactly one of points_per_side and point_grids")
        if point_grids is None:
            assert points_per_side is not None
            if points_per_side < 1:
                raise ValueError("points_per_side must be >= 1")
            point_grids = build_all_layer_point_grids(
                points_per_side, crop_n_layers, crop_n_points_downscale_factor
            )
        elif len(point_grids) != crop_n_layers + 1:
            raise ValueError("point_grids needs one grid per crop layer")
        self.predictor = SamPredictor(model, fast=True)
        self.model = model
        self.point_grids = point_grids
        self.points_per_batch = max(1, int(points_per_batch))
        self.pred_iou_thresh = pred_iou_thresh
        self.stability_score_thresh = stability_score_thresh
        self.stability_score_offset = stability_score_offset
        self.box_nms_thresh = box_nms_thresh
        self.crop_n_layers = crop_n_layers
        self.crop_nms_thresh = crop_nms_thresh
        self.crop_overlap_ratio = crop_overlap_ratio
        self.min_mask_region_area = min_mask_region_area
        self.mask_batch = max(1, int(mask_batch))
        self.skip_covered = skip_covered
        self.timings: dict[str, float] = {}
        self.prompted = 0
        """How many grid points the last `generate` ran through the decoder."""
        self.image_embedding: torch.Tensor | None = None
        """The whole image's embedding from the last `generate` (reuse it to prompt again)."""

    @torch.inference_mode()
    def generate(self, image: np.ndarray | Image.Image) -> list[dict[str, Any]]:
        """Masks for an image (H, W, 3) uint8 RGB (other inputs converted, see `to_rgb_uint8`).

        Returns a list of dicts with ``segmentation`` (bool H x W), ``area``, ``bbox`` (XYWH),
        ``predicted_iou``, ``point_coords`` ([[x, y]]), ``stability_score``, ``crop_box`` (XYWH).
        """
        img = to_rgb_uint8(image, min_side=2)
        self.timings = {"encoder": 0.0, "decoder": 0.0, "masks": 0.0, "post": 0.0}
        self.image_embedding = None
        self.prompted = 0
        orig_size = (img.shape[0], img.shape[1])
        crop_boxes, layer_idxs = generate_crop_boxes(
            orig_size, self.crop_n_layers, self.crop_overlap_ratio
        )
        parts = []
        for crop_box, layer in zip(crop_boxes, layer_idxs, strict=True):
            parts.append(self._process_crop(img, crop_box, layer, orig_size))
        t0 = time.perf_counter()
        data = _cat(parts)
        if len(crop_boxes) > 1 and len(data["iou"]):
            scores = 1.0 / box_area(data["crop_boxes"]).float().clamp(min=1)
            keep = nms(data["boxes"].float(), scores, self.crop_nms_thresh)
            data = _filter(data, keep)
        if self.min_mask_region_area > 0 and len(data["iou"]):
            data = self._postprocess_small_regions(
                data, self.min_mask_region_area, max(self.box_nms_thresh, self.crop_nms_thresh)
            )
        out = []
        masks = data["masks"].cpu().numpy()
        areas = masks.reshape(len(masks), -1).sum(1) if len(masks) else []
        for i in range(len(masks)):
            x0, y0, x1, y1 = (int(v) for v in data["boxes"][i])
            cx0, cy0, cx1, cy1 = (int(v) for v in data["crop_boxes"][i])
            out.append(
                {
                    "segmentation": masks[i],
                    "area": int(areas[i]),
                    "bbox": [x0, y0, x1 - x0, y1 - y0],
                    "predicted_iou": float(data["iou"][i]),
                    "point_coords": [[float(v) for v in data["points"][i]]],
                    "stability_score": float(data["stability"][i]),
                    "crop_box": [cx0, cy0, cx1 - cx0, cy1 - cy0],
                }
            )
        self.timings["post"] += time.perf_counter() - t0
        return out

    def _process_crop(
        self, img: np.ndarray, crop_box: list[int], layer: int, orig_size: tuple[int, int]
    ) -> dict[str, torch.Tensor]:
        x0, y0, x1, y1 = crop_box
        crop = img[y0:y1, x0:x1]
        ch, cw = crop.shape[:2]
        pred = self.predictor
        t0 = time.perf_counter()
        pred.set_image(crop)
        fd = pred.fast_decoder()
        self.timings["encoder"] += time.perf_counter() - t0
        assert pred.input_size is not None
        in_h, in_w = pred.input_size
        lh, lw = needed_lowres(pred.input_size)
        grid_hw, valid_hw = decoder_grids(pred.input_size)
        points = self.point_grids[layer] * np.array([[cw, ch]])
        mask_ids = [1, 2, 3]
        thr = self.model.mask_threshold
        orig_h, orig_w = orig_size
        collected: list[dict[str, torch.Tensor]] = []
        covered = _Coverage(crop) if self.skip_covered else None
        if covered is not None:
            points = points[coarse_first(self.point_grids[layer])]
        for i in range(0, len(points), self.points_per_batch):
            t0 = time.perf_counter()
            batch = points[i : i + self.points_per_batch]
            if covered is not None:
                batch = batch[~covered.covered(batch)]
                if len(batch) == 0:
                    continue
            pts = torch.as_tensor(batch, dtype=torch.float32)
            self.prompted += len(pts)
            tp = pred.transform_coords(pts)[:, None, :]
            sparse, _ = self.model.prompt_encoder((tp, torch.ones(len(pts), 1)), None, None)
            st = fd.transformer(sparse)
            iou = st.iou[:, mask_ids]
            ok = (iou > self.pred_iou_thresh) | (self.pred_iou_thresh <= 0)
            prompt_idx = torch.nonzero(ok.any(1)).flatten()
            self.timings["decoder"] += time.perf_counter() - t0
            t0 = time.perf_counter()
            for j in range(0, len(prompt_idx), self.mask_batch):
                sel = prompt_idx[j : j + self.mask_batch]
                off = self.stability_score_offset
                low, cnt = fd.masks_and_counts(  # (b, 3, 4gh, 4gw) logits, (b, 3, 2) counts
                    st.select(sel), mask_ids, grid_hw, valid_hw, thr + off, thr - off
                )
                stab = stability_from_counts(cnt[..., 0], cnt[..., 1])
                keep = ok[sel]
                if self.stability_score_thresh > 0:
                    keep = keep & (stab >= self.stability_score_thresh)
                kb, km = torch.nonzero(keep, as_tuple=True)
                if len(kb) == 0:
                    continue
                logits = resize_logits(low[kb, km][:, :lh, :lw], (in_h, in_w), (ch, cw))
                masks = logits > thr
                if covered is not None:
                    covered.add_finest(masks, kb)
                boxes = batched_mask_to_box(masks)
                part = {
                    "masks": masks,
                    "iou": iou[sel[kb], km],
                    "stability": stab[kb, km],
                    "points": pts[sel[kb]].double(),
                    "boxes": boxes,
                }
                if crop_box != [0, 0, orig_w, orig_h]:
                    near = is_box_near_crop_edge(boxes, crop_box, [0, 0, orig_w, orig_h])
                    part = _filter(part, torch.nonzero(~near).flatten())
                collected.append(part)
            self.timings["masks"] += time.perf_counter() - t0
        t0 = time.perf_counter()
        data = self._crop_result(_cat(collected, (ch, cw)), crop_box, orig_size)
        if crop_box == [0, 0, orig_w, orig_h]:
            self.image_embedding = pred.get_image_embedding()
        pred.reset_image()
        self.timings["post"] += time.perf_counter() - t0
        return data

    def _crop_result(
        self, data: dict[str, torch.Tensor], crop_box: list[int], orig_size: tuple[int, int]
    ) -> dict[str, torch.Tensor]:
        """One crop's masks after NMS, moved from the crop into the whole image."""
        data = _filter(data, nms(data["boxes"].float(), data["iou"], self.box_nms_thresh))
        data["boxes"] = uncrop_boxes_xyxy(data["boxes"], crop_box)
        data["points"] = uncrop_points(data["points"], crop_box)
        data["masks"] = uncrop_masks(data["masks"], crop_box, *orig_size)
        boxes = torch.tensor([crop_box] * len(data["iou"]), dtype=torch.long)
        data["crop_boxes"] = boxes.view(-1, 4)
        return data

    @staticmethod
    def _postprocess_small_regions(
        data: dict[str, torch.Tensor], min_area: int, nms_thresh: float
    ) -> dict[str, torch.Tensor]:
        """Fill small holes and drop small islands; re-run NMS preferring unchanged masks."""
        new_masks, scores = [], []
        for m in data["masks"].cpu().numpy():
            m, changed_h = remove_small_regions(m, min_area, "holes")
            m, changed_i = remove_small_regions(m, min_area, "islands")
            new_masks.append(torch.as_tensor(m))
            scores.append(0.0 if (changed_h or changed_i) else 1.0)
        masks = torch.stack(new_masks)
        boxes = batched_mask_to_box(masks)
        keep = nms(boxes.float(), torch.as_tensor(scores), nms_thresh)
        data = dict(data)
        data["masks"] = masks
        data["boxes"] = boxes
        return _filter(data, keep)


def coarse_first(grid: np.ndarray) -> np.ndarray:
    """An order of a square point grid (N, 2) that visits every other row and column first
    (a grid of half the density), then the rest, each part in the grid's own order."""
    side = max(1, round(math.sqrt(len(grid))))
    index = np.arange(len(grid))
    coarse = (index // side % 2 == 0) & (index % side % 2 == 0)
    return np.concatenate([index[coarse], index[~coarse]])


class _Coverage:
    """The finest kept mask of each prompt so far, as an owner map and the owners' mean
    colours: a grid point inside one, of its colour, would find that part again."""

    def __init__(self, image: np.ndarray, tolerance: float = COVERED_COLOUR_TOLERANCE) -> None:
        self.image = torch.tensor(np.asarray(image), dtype=torch.float32)
        self.owner = torch.full(image.shape[:2], -1, dtype=torch.long)
        self.colours: list[torch.Tensor] = []
        self.tolerance = tolerance

    def covered(self, points: np.ndarray) -> np.ndarray:
        """Which (x, y) points lie in a mask of their own pixel's colour."""
        height, width = self.owner.shape
        cols = torch.as_tensor(np.clip(points[:, 0].astype(np.int64), 0, width - 1))
        rows = torch.as_tensor(np.clip(points[:, 1].astype(np.int64), 0, height - 1))
        owners = self.owner[rows, cols]
        if bool((owners < 0).all()):
            return np.zeros(len(points), dtype=bool)
        means = torch.stack(self.colours)[owners.clamp(min=0)]
        near = torch.linalg.vector_norm(self.image[rows, cols] - means, dim=1) <= self.tolerance
        return ((owners >= 0) & near).numpy()

    def add_finest(self, masks: torch.Tensor, prompts: torch.Tensor) -> None:
        """Record the smallest of the kept ``masks`` of each prompt."""
        areas = masks.flatten(1).sum(1)
        for prompt in torch.unique(prompts):
            mine = torch.nonzero(prompts == prompt).flatten()
            finest = masks[mine[torch.argmin(areas[mine])]]
            self.owner[finest] = len(self.colours)
            self.colours.append(self.image[finest].mean(dim=0))


def _filter(data: dict[str, torch.Tensor], idx: torch.Tensor) -> dict[str, torch.Tensor]:
    return {k: v[idx] for k, v in data.items()}


def _cat(
    parts: list[dict[str, torch.Tensor]], mask_hw: tuple[int, int] | None = None
) -> dict[str, torch.Tensor]:
    if parts:
        return {k: torch.cat([p[k] for p in parts]) for k in parts[0]}
    assert mask_hw is not None
    return {
        "masks": torch.zeros((0, *mask_hw), dtype=torch.bool),
        "iou": torch.zeros(0),
        "stability": torch.zeros(0),
        "points": torch.zeros((0, 2), dtype=torch.float64),
        "boxes": torch.zeros((0, 4), dtype=torch.long),
    }
