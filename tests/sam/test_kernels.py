"""Fused mask-output kernels (`samvg.sam._kernels`) against plain torch references."""

from __future__ import annotations

import numpy as np
import torch

from samvg.sam._kernels import scatter_logits_counts
from samvg.sam.amg_utils import stability_score
from samvg.sam.fast_decoder import FastDecoder


def test_scatter_logits_counts_matches_torch():
    rng = np.random.default_rng(1)
    b, gh, gw, nm = 2, 5, 3, 3
    cells = torch.as_tensor(rng.normal(0, 2, (b, gh, gw, 2, 2, 2, 2, nm)), dtype=torch.float32)
    cells[0, 0, 0, 0, 0, 0, 0, 0] = 1.0  # exactly at the threshold: not counted
    ref = cells.permute(0, 7, 1, 3, 5, 2, 4, 6).reshape(b, nm, 4 * gh, 4 * gw)
    vh, vw = 17, 10
    out = torch.empty_like(ref)
    counts = torch.empty((b, nm, 2), dtype=torch.int64)
    scatter_logits_counts(cells.numpy(), vh, vw, 1.0, -1.0, out.numpy(), counts.numpy())
    assert torch.equal(out, ref)
    crop = ref[..., :vh, :vw]
    assert torch.equal(counts[..., 0], (crop > 1.0).sum((-1, -2)))
    assert torch.equal(counts[..., 1], (crop > -1.0).sum((-1, -2)))


def test_masks_and_counts_match_masks(sam_model, portrait_predictor):
    fd = FastDecoder(sam_model, portrait_predictor.get_image_embedding())
    pts = torch.tensor([[[180.0, 300.0]], [[600.0, 100.0]], [[50.0, 900.0]]])
    with torch.inference_mode():
        sparse, _ = sam_model.prompt_encoder((pts, torch.ones(3, 1)), None, None)
        st = fd.transformer(sparse)
        ref = fd.masks(st, [1, 2, 3], (64, 43))
        low, counts = fd.masks_and_counts(st, [1, 2, 3], (64, 43), (256, 171), 1.0, -1.0)
    diff = (low - ref).abs().max().item()
    print(f"masks_and_counts vs masks: max logit diff {diff:.2e}")
    assert diff < 1e-5
    stab = stability_score(ref[..., :256, :171], 0.0, 1.0)
    mine = counts[..., 0].float() / counts[..., 1].clamp(min=1).float()
    # identical logits give identical counts, except where a logit sits within float noise
    # of a threshold; allow a few pixels of slack
    assert (mine - stab).abs().max().item() < 1e-3
