"""SamPredictor: encode an image once, then prompt it with points, boxes or masks."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import torch
from PIL import Image

from samvg.errors import InputError
from samvg.sam.fast_decoder import FastDecoder
from samvg.sam.image import resize_longest_side, resized_shape, to_rgb_uint8
from samvg.sam.model import Sam


def resize_logits(
    logits: torch.Tensor,
    input_size: tuple[int, int],
    original_size: tuple[int, int],
    grid: int = 256,
) -> torch.Tensor:
    """Bilinearly resample low-res logits (..., h, w) straight to ``original_size``.

    The logits are the top-left part (h, w <= ``grid``) of SAM's ``grid`` x ``grid`` low-res
    output, which covers the padded 1024 x 1024 model input whose top-left ``input_size`` is
    the resized image. One separable bilinear resampling (half-pixel centres, like
    ``align_corners=False``) replaces upstream SAM's upscale-crop-resize; the logits must cover
    rows/cols up to ``ceil(input_size / 4)`` inclusive (see `needed_lowres`).
    """
    img_size = 4 * grid
    h_av, w_av = logits.shape[-2:]

    def axis(n_out: int, n_in: int, avail: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        pos = (torch.arange(n_out, dtype=torch.float32, device=logits.device) + 0.5) * (
            n_in / n_out
        ) * (grid / img_size) - 0.5
        pos = pos.clamp(min=0.0, max=grid - 1)
        i0 = pos.floor().long()
        i1 = (i0 + 1).clamp(max=grid - 1)
        if int(i1.max()) >= avail:
            raise ValueError("low-res logits do not cover the image region")
        return i0, i1, pos - i0

    y0, y1, wy = axis(original_size[0], input_size[0], h_av)
    x0, x1, wx = axis(original_size[1], input_size[1], w_av)
    rows = logits[..., y0, :] * (1 - wy)[:, None] + logits[..., y1, :] * wy[:, None]
    return rows[..., x0] * (1 - wx) + rows[..., x1] * wx


def needed_lowres(input_size: tuple[int, int], grid: int = 256) -> tuple[int, int]:
    """Rows/cols of the low-res logits that `resize_logits` reads for this input size."""
    return (
        min(grid, math.ceil(input_size[0] / 4) + 1),
        min(grid, math.ceil(input_size[1] / 4) + 1),
    )


def decoder_grids(input_size: tuple[int, int]) -> tuple[tuple[int, int], tuple[int, int]]:
    """The 64x64 token grid's part that `FastDecoder.masks_and_counts` lays out for this input
    size (enough 4x4 cells for `needed_lowres`), and the part whose cells cover the image (the
    rest is padding): its ``grid_hw`` and ``valid_hw``."""
    low_h, low_w = needed_lowres(input_size)
    grid_hw = (math.ceil(low_h / 4), math.ceil(low_w / 4))
    valid_hw = (math.ceil(input_size[0] / 4), math.ceil(input_size[1] / 4))
    return grid_hw, valid_hw


def _as_float_array(x: npt.ArrayLike, shape_tail: tuple[int, ...], what: str) -> np.ndarray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.ndim != len(shape_tail) + 1 or arr.shape[1:] != shape_tail:
        raise InputError(
            f"{what} must have shape (N, {', '.join(map(str, shape_tail))}), got {arr.shape}"
        )
    if not np.isfinite(arr).all():
        raise InputError(f"{what} contains NaN or infinite values")
    return arr


class SamPredictor:
    """Upstream-compatible predictor: ``set_image`` then ``predict`` / ``predict_points``.

    ``fast=True`` (default) decodes with `FastDecoder` (exact low-rank reformulation of the
    mask decoder, shared work computed once per image); ``fast=False`` uses the plain
    per-prompt decoder (the reference path).
    """

    def __init__(self, model: Sam, fast: bool = True) -> None:
        self.model = model.eval()
        self.fast = fast
        self.reset_image()

    def reset_image(self) -> None:
        self.features: torch.Tensor | None = None
        self.original_size: tuple[int, int] | None = None
        self.input_size: tuple[int, int] | None = None
        self._fast: FastDecoder | None = None

    @property
    def is_image_set(self) -> bool:
        return self.features is not None

    @torch.inference_mode()
    def set_image(self, image: np.ndarray | Image.Image, image_format: str = "RGB") -> None:
        """Encode an image: (H, W, 3) uint8 RGB (others are converted, see `to_rgb_uint8`)."""
        img = to_rgb_uint8(image, min_side=2)
        if image_format.upper() == "BGR":
            img = img[:, :, ::-1]
        elif image_format.upper() != "RGB":
            raise InputError(f"image_format must be 'RGB' or 'BGR', got {image_format!r}")
        self.reset_image()
        resized = resize_longest_side(np.ascontiguousarray(img), self.model.img_size)
        x = torch.from_numpy(np.array(resized, dtype=np.float32)).to(self.model.device)
        x = x.permute(2, 0, 1)[None]
        self.original_size = (img.shape[0], img.shape[1])
        self.input_size = (resized.shape[0], resized.shape[1])
        self.features = self.model.image_encoder(self.model.preprocess(x))

    def set_features(self, features: torch.Tensor, original_size: tuple[int, int]) -> None:
        """Reuse an image embedding (1, 256, 64, 64) computed earlier for an image of this size."""
        self.reset_image()
        self.features = features
        self.original_size = (int(original_size[0]), int(original_size[1]))
        self.input_size = resized_shape(*self.original_size, self.model.img_size)

    def get_image_embedding(self) -> torch.Tensor:
        self._require_image()
        assert self.features is not None
        return self.features

    def _require_image(self) -> None:
        if self.features is None:
            raise RuntimeError("call set_image() before predicting")

    def fast_decoder(self) -> FastDecoder:
        """The per-image `FastDecoder` (built on first use, shared across calls)."""
        self._require_image()
        if self._fast is None:
            self._fast = FastDecoder(self.model, self.get_image_embedding())
        return self._fast

    def transform_coords(self, coords: np.ndarray | torch.Tensor) -> torch.Tensor:
        """Map (..., 2) pixel (x, y) coords of the original image to model input coords."""
        assert self.original_size is not None and self.input_size is not None
        c = torch.as_tensor(coords, dtype=torch.float32, device=self.model.device).clone()
        c[..., 0] = c[..., 0] * (self.input_size[1] / self.original_size[1])
        c[..., 1] = c[..., 1] * (self.input_size[0] / self.original_size[0])
        return c

    @torch.inference_mode()
    def predict(
        self,
        point_coords: np.ndarray | None = None,
        point_labels: np.ndarray | None = None,
        box: np.ndarray | None = None,
        mask_input: np.ndarray | None = None,
        multimask_output: bool = True,
        return_logits: bool = False,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One prompt (points in (x, y) pixels, labels 1 fg / 0 bg, box x0 y0 x1 y1, mask logits).

        Returns (masks (C, H, W) bool or float logits, scores (C,), low-res logits (C, 256, 256)).
        """
        self._require_image()
        points = None
        if point_coords is not None:
            pc = _as_float_array(point_coords, (2,), "point_coords")
            if point_labels is None:
                raise InputError("point_labels must be given with point_coords")
            pl = np.asarray(point_labels, dtype=np.float64).reshape(-1)
            if pl.shape[0] != pc.shape[0]:
                raise InputError("point_coords and point_labels have different lengths")
            points = (
                self.transform_coords(pc)[None],
                torch.as_tensor(pl, dtype=torch.float32)[None],
            )
        boxes = None
        if box is not None:
            b = _as_float_array(np.asarray(box).reshape(1, 4), (4,), "box")
            boxes = self.transform_coords(b.reshape(-1, 2, 2)).reshape(1, 4)
        masks = None
        if mask_input is not None:
            masks = torch.as_tensor(np.asarray(mask_input), dtype=torch.float32).reshape(
                1, 1, 256, 256
            )
        logits, scores, low = self.predict_torch(
            points, boxes, masks, multimask_output, return_logits=True
        )
        out = logits[0] if return_logits else logits[0] > self.model.mask_threshold
        return out.cpu().numpy(), scores[0].cpu().numpy(), low[0].cpu().numpy()

    @torch.inference_mode()
    def predict_torch(
        self,
        points: tuple[torch.Tensor, torch.Tensor] | None,
        boxes: torch.Tensor | None = None,
        mask_input: torch.Tensor | None = None,
        multimask_output: bool = True,
        return_logits: bool = False,
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Batched prompts in model-input coords: points ((B, N, 2), (B, N)), boxes (B, 4).

        Returns (masks (B, C, H, W), iou (B, C), low-res logits (B, C, 256, 256)).
        """
        self._require_image()
        sparse, dense = self.model.prompt_encoder(points, boxes, mask_input)
        if self.fast and mask_input is None:
            low, iou = self.fast_decoder().decode(sparse, multimask_output)
        else:
            low, iou = self.model.mask_decoder(
                self.get_image_embedding(),
                self.model.prompt_encoder.get_dense_pe(),
                sparse,
                dense,
                multimask_output,
            )
        assert self.input_size is not None and self.original_size is not None
        masks = resize_logits(low, self.input_size, self.original_size)
        if not return_logits:
            masks = masks > self.model.mask_threshold
        return masks, iou, low

    @torch.inference_mode()
    def predict_points(
        self,
        points: np.ndarray,
        labels: np.ndarray | None = None,
        multimask_output: bool = True,
        batch_size: int = 64,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Many single-point prompts at once (e.g. SAMVG's re-prompts), one prompt per point.

        points (N, 2) pixel (x, y); labels (N,) default all foreground. Returns masks
        (N, C, H, W) bool, scores (N, C), low-res logits (N, C, 256, 256).
        """
        self._require_image()
        pts = _as_float_array(points, (2,), "points")
        lab = np.ones(len(pts)) if labels is None else np.asarray(labels, dtype=np.float64)
        if lab.shape != (len(pts),):
            raise InputError("labels must have shape (N,)")
        out_m, out_s, out_l = [], [], []
        for i in range(0, len(pts), batch_size):
            p = self.transform_coords(pts[i : i + batch_size])[:, None, :]
            lb = torch.as_tensor(lab[i : i + batch_size], dtype=torch.float32)[:, None]
            m, s, low = self.predict_torch((p, lb), None, None, multimask_output)
            out_m.append(m.cpu().numpy())
            out_s.append(s.cpu().numpy())
            out_l.append(low.cpu().numpy())
        c = 3 if multimask_output else 1
        assert self.original_size is not None
        if not out_m:
            return (
                np.zeros((0, c, *self.original_size), bool),
                np.zeros((0, c), np.float32),
                np.zeros((0, c, 256, 256), np.float32),
            )
        return np.concatenate(out_m), np.concatenate(out_s), np.concatenate(out_l)
