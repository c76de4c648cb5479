"""Point prompting with the real MobileSAM checkpoint on a Kodak portrait, fast vs reference."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from samvg.errors import InputError
from samvg.sam import SamPredictor
from samvg.sam.fast_decoder import FastDecoder

# kodim04 (341 x 512): hand-checked regions, (x0, y0, x1, y1) inclusive
FACE_POINT = (180, 300)  # cheek, beside the nose
FACE_BOX = (90, 150, 280, 350)  # forehead to chin, ear to ear


def test_point_on_face_gives_face_head_person(portrait_predictor):
    masks, scores, low = portrait_predictor.predict(
        np.array([FACE_POINT]), np.array([1]), multimask_output=True
    )
    assert masks.shape == (3, 512, 341) and masks.dtype == bool
    assert scores.shape == (3,) and low.shape == (3, 256, 256)
    x, y = FACE_POINT
    assert masks[:, y, x].all(), "every output contains the prompted pixel"
    areas = masks.reshape(3, -1).sum(1)
    # at least one output is "the face": mostly inside the face box and covering much of it
    x0, y0, x1, y1 = FACE_BOX
    box = np.zeros_like(masks[0])
    box[y0 : y1 + 1, x0 : x1 + 1] = True
    inside = (masks & box).reshape(3, -1).sum(1) / np.maximum(areas, 1)
    covered = (masks & box).reshape(3, -1).sum(1) / box.sum()
    assert ((inside > 0.8) & (covered > 0.4)).any(), (inside, covered)
    # outputs grow from part to whole: the last covers most of the person / image
    assert areas[2] > areas[0]
    assert areas[2] > 0.5 * masks[0].size
    assert (scores > 0.8).all()


def test_background_point_excludes_face(portrait_predictor):
    # pink curtain to the right of the face
    masks, scores, _ = portrait_predictor.predict(np.array([[325, 250]]), np.array([1]))
    x, y = FACE_POINT
    assert masks[:, 250, 325].all()
    assert not masks[0, y, x] and not masks[1, y, x]
    assert masks[0].mean() < 0.3


def test_single_mask_and_box_and_negative_point(portrait_predictor):
    m, s, low = portrait_predictor.predict(
        np.array([FACE_POINT]), np.array([1]), multimask_output=False
    )
    assert m.shape == (1, 512, 341) and s.shape == (1,)
    mb, sb, _ = portrait_predictor.predict(box=np.array(FACE_BOX), multimask_output=False)
    x0, y0, x1, y1 = FACE_BOX
    assert mb[0, y0 : y1 + 1, x0 : x1 + 1].mean() > 0.5
    assert mb[0].sum() < 1.3 * (x1 - x0 + 1) * (y1 - y0 + 1)
    # a negative point on the face removes it from the box mask
    mn, _, _ = portrait_predictor.predict(
        np.array([[185, 320]]), np.array([0]), box=np.array(FACE_BOX), multimask_output=False
    )
    assert not mn[0, 320, 185]
    # mask prompt: feeding back the low-res logits keeps the mask
    mm, _, _ = portrait_predictor.predict(
        np.array([FACE_POINT]), np.array([1]), mask_input=low, multimask_output=False
    )
    assert mm.shape == (1, 512, 341) and mm[0, FACE_POINT[1], FACE_POINT[0]]
    inter = (mm[0] & m[0]).sum() / max((mm[0] | m[0]).sum(), 1)
    assert inter > 0.5


def test_fast_decoder_matches_reference(sam_model, portrait_predictor):
    emb = portrait_predictor.get_image_embedding()
    fd = FastDecoder(sam_model, emb)
    rng = np.random.default_rng(0)
    n = 12
    pts = torch.as_tensor(rng.uniform(0, [683, 1024], size=(n, 2)), dtype=torch.float32)
    labels = torch.ones(n, 1)
    with torch.inference_mode():
        for points in [(pts[:, None], labels), (pts.view(n // 2, 2, 2), labels.view(n // 2, 2))]:
            sparse, dense = sam_model.prompt_encoder(points, None, None)
            ref_m, ref_i = sam_model.mask_decoder(
                emb, sam_model.prompt_encoder.get_dense_pe(), sparse, dense, True
            )
            fast_m, fast_i = fd.decode(sparse, True)
            diff = (fast_m - ref_m).abs().max().item()
            print(f"fast vs reference: max logit diff {diff:.2e}")
            assert diff < 2e-3
            assert (fast_i - ref_i).abs().max().item() < 1e-4
        # cropped upscaling equals the same region of the full grid
        st = fd.transformer(sparse)
        part = fd.masks(st, [1, 2, 3], (64, 43))
        torch.testing.assert_close(part, fast_m[..., :, :172], atol=1e-4, rtol=0)


def test_reference_path_predictor_agrees(sam_model, portrait_predictor):
    ref = SamPredictor(sam_model, fast=False)
    ref.set_features(portrait_predictor.get_image_embedding(), (512, 341))
    a = portrait_predictor.predict(np.array([FACE_POINT]), np.array([1]), return_logits=True)
    b = ref.predict(np.array([FACE_POINT]), np.array([1]), return_logits=True)
    assert np.abs(a[0] - b[0]).max() < 2e-3
    assert np.abs(a[2] - b[2]).max() < 2e-3


def test_predict_points_batched(portrait_predictor):
    pts = np.array([FACE_POINT, (325, 250), (60, 470), (200, 100)], dtype=float)
    masks, scores, low = portrait_predictor.predict_points(pts, batch_size=3)
    assert masks.shape == (4, 3, 512, 341) and scores.shape == (4, 3)
    assert low.shape == (4, 3, 256, 256)
    for i, (x, y) in enumerate(pts.astype(int)):
        single, s, _ = portrait_predictor.predict(pts[i : i + 1], np.array([1]))
        np.testing.assert_allclose(scores[i], s, atol=1e-5)
        assert (masks[i] != single).mean() < 1e-4
        assert masks[i, :, y, x].any()
    empty = portrait_predictor.predict_points(np.zeros((0, 2)))
    assert empty[0].shape == (0, 3, 512, 341)


def test_bad_prompts(portrait_predictor, sam_model):
    with pytest.raises(InputError):
        portrait_predictor.predict(np.array([[np.nan, 3.0]]), np.array([1]))
    with pytest.raises(InputError):
        portrait_predictor.predict(np.array([[1.0, 2.0, 3.0]]), np.array([1]))
    with pytest.raises(InputError):
        portrait_predictor.predict(np.array([[1.0, 2.0]]), None)
    with pytest.raises(RuntimeError):
        SamPredictor(sam_model).predict(np.array([[1.0, 2.0]]), np.array([1]))
