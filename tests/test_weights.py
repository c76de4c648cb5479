"""Weight resolution: explicit path, env var, cache, verified downloads from a local server."""

from __future__ import annotations

import hashlib
import http.server
import io
import tarfile
import threading
from pathlib import Path

import pytest

from samvg.errors import WeightsError
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
