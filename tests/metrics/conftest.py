"""Metric test fixtures: a local HTTP file server, the FID network, the LPIPS calibration pairs."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

SHARED = Path(__file__).resolve().parents[3] / "shared"


class _Files(http.server.BaseHTTPRequestHandler):
    files: dict[str, bytes] = {}

    def do_GET(self):  # noqa: N802
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


class FileServer:
    """Serves ``files[path]`` (bytes) at ``url + path`` on 127.0.0.1."""

    def __init__(self, url: str, files: dict[str, bytes]) -> None:
        self.url = url
        self.files = files


@pytest.fixture
def file_server() -> Iterator[FileServer]:
    files: dict[str, bytes] = {}
    handler = type("Handler", (_Files,), {"files": files})
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield FileServer(f"http://127.0.0.1:{httpd.server_address[1]}", files)
    finally:
        httpd.shutdown()
        httpd.server_close()


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    """An empty weight cache; the LPIPS / FID environment variables unset."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("SAMVG_CACHE", str(folder))
    monkeypatch.delenv("SAMVG_LPIPS_WEIGHTS", raising=False)
    monkeypatch.delenv("SAMVG_FID_WEIGHTS", raising=False)
    return folder


@pytest.fixture(scope="session")
def lpips_calibration() -> Path:
    folder = SHARED / "data" / "lpips_calibration"
    if not (folder / "ref_dir").is_dir():
        pytest.skip("../shared/data/lpips_calibration not found")
    return folder
