"""Model building and strict checkpoint loading (real MobileSAM, tiny random ViT variants)."""

from __future__ import annotations

import pytest
import torch

from samvg.errors import WeightsError
from samvg.sam import build_sam, load_sam
from samvg.sam.build import read_checkpoint
from samvg.sam.tiny_vit import Conv2dBN, TinyViT


def test_real_checkpoint_strict(sam_checkpoint, sam_model):
    state = read_checkpoint(sam_checkpoint)
    own = sam_model.state_dict()
    assert set(state) == set(own)
    for k, v in state.items():
        assert torch.equal(own[k], v), k
    assert not sam_model.training


def test_wrong_model_name_is_clear(sam_checkpoint):
    with pytest.raises(WeightsError, match="looks like a mobile_sam checkpoint"):
        load_sam("vit_b", checkpoint=sam_checkpoint)


def test_corrupt_and_foreign_files(tmp_path, sam_checkpoint):
    truncated = tmp_path / "trunc.pt"
    truncated.write_bytes(sam_checkpoint.read_bytes()[:1_000_000])
    with pytest.raises(WeightsError, match="cannot read SAM checkpoint"):
        load_sam(checkpoint=truncated)
    garbage = tmp_path / "garbage.pt"
    garbage.write_bytes(b"not a checkpoint at all" * 100)
    with pytest.raises(WeightsError):
        load_sam(checkpoint=garbage)
    partial = tmp_path / "partial.pt"
    state = read_checkpoint(sam_checkpoint)
    del state["mask_decoder.iou_token.weight"]
    state["extra.weight"] = torch.zeros(3)
    torch.save(state, partial)
    with pytest.raises(WeightsError, match="missing keys: mask_decoder.iou_token.weight"):
        load_sam(checkpoint=partial)
    state = read_checkpoint(sam_checkpoint)
    state["mask_decoder.iou_token.weight"] = torch.zeros(1, 128)
    torch.save(state, partial)
    with pytest.raises(WeightsError, match="shape mismatch mask_decoder.iou_token.weight"):
        load_sam(checkpoint=partial)
    with pytest.raises(WeightsError, match="does not exist"):
        load_sam(checkpoint=tmp_path / "missing.pt")
    with pytest.raises(ValueError):
        load_sam("vit_xxl", checkpoint=sam_checkpoint)


def test_eval_before_load_has_no_stale_cache(sam_checkpoint):
    """TinyViT attention biases: switching to eval before loading must not freeze old biases."""
    state = {
        k[len("image_encoder.") :]: v
        for k, v in read_checkpoint(sam_checkpoint).items()
        if k.startswith("image_encoder.")
    }
    x = torch.randn(1, 3, 256, 256, generator=torch.Generator().manual_seed(0))
    early = TinyViT(img_size=256).eval()
    with torch.inference_mode():
        early(x)  # run once with random weights, in eval mode
    early.load_state_dict(state, strict=True)
    late = TinyViT(img_size=256)
    late.load_state_dict(state, strict=True)
    late.eval()
    with torch.inference_mode():
        a, b = early(x), late(x)
    assert torch.equal(a, b)
    early.train()
    early.eval()
    with torch.inference_mode():
        assert torch.equal(early(x), b)


@pytest.mark.parametrize("name", ["vit_b", "vit_l", "vit_h"])
def test_vit_configs_have_official_layout(name):
    depth = {"vit_b": 12, "vit_l": 24, "vit_h": 32}[name]
    with torch.device("meta"):
        model = build_sam(name)
    keys = model.state_dict().keys()
    assert f"image_encoder.blocks.{depth - 1}.attn.rel_pos_h" in keys
    assert "image_encoder.pos_embed" in keys and "image_encoder.neck.3.bias" in keys
    glob = {"vit_b": 2, "vit_l": 5, "vit_h": 7}[name]
    sd = model.state_dict()
    assert sd[f"image_encoder.blocks.{glob}.attn.rel_pos_h"].shape[0] == 127
    assert sd["image_encoder.blocks.0.attn.rel_pos_h"].shape[0] == 27


def test_tiny_vit_roundtrip_strict(tmp_path):
    """A small random ViT-B-style model saves and loads strictly through load_sam's checks."""
    from samvg.sam.build import check_state_dict

    torch.manual_seed(0)
    cfg = dict(
        img_size=128, embed_dim=32, depth=2, num_heads=2, window_size=4, global_attn_indexes=(1,)
    )
    a = build_sam("vit_b", **cfg)
    for p in a.parameters():
        p.data.normal_(0, 0.1)
    path = tmp_path / "tiny.pth"
    torch.save(a.state_dict(), path)
    b = build_sam("vit_b", **cfg)
    state = read_checkpoint(path)
    check_state_dict(b, state, "vit_b", str(path))
    b.load_state_dict(state, strict=True)
    x = torch.randn(1, 3, 128, 128)
    with torch.inference_mode():
        assert torch.equal(a.image_encoder(x), b.image_encoder(x))
    other = build_sam("vit_b", **{**cfg, "depth": 3})
    with pytest.raises(WeightsError, match="missing keys"):
        check_state_dict(other, state, "vit_b", str(path))


def test_folded_conv_bn_equals_conv_then_batchnorm():
    torch.manual_seed(0)
    layer = Conv2dBN(8, 8, 3, 1, 1, groups=8)
    bn = layer.bn
    with torch.no_grad():
        bn.running_mean.uniform_(-1, 1)
        bn.running_var.uniform_(0.5, 2)
        bn.weight.uniform_(0.5, 1.5)
        bn.bias.uniform_(-0.5, 0.5)
    layer.eval()
    x = torch.randn(2, 8, 16, 16).contiguous(memory_format=torch.channels_last)
    with torch.no_grad():
        reference = bn(layer.c(x))
        folded = layer(x)
    torch.testing.assert_close(folded, reference, atol=1e-5, rtol=1e-5)
    assert layer.state_dict().keys() == {
        "c.weight",
        "bn.weight",
        "bn.bias",
        "bn.running_mean",
        "bn.running_var",
        "bn.num_batches_tracked",
    }
