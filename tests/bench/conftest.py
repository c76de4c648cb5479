"""Fixtures of the benchmark tests: a tiny manifest of real images and the metric weights."""

import csv
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def lpips_file(lpips_weights: Path) -> Path:
    return lpips_weights


@pytest.fixture(scope="session")
def fid_file(fid_weights: Path) -> Path:
    return fid_weights


@pytest.fixture
def tiny_manifest(tmp_path: Path, bench_dir: Path) -> Path:
    """Two real images from two categories and one whose PNG is not an image."""
    folder = tmp_path / "set"
    folder.mkdir()
    (folder / "broken.png").write_bytes(b"not a png")
    rows = [
        ("cactus", "emoji", str(bench_dir / "emoji" / "noto_cactus.png")),
        ("folder", "icon", str(bench_dir / "icon" / "tango_folder_open.png")),
        ("broken", "icon", "broken.png"),
    ]
    manifest = folder / "manifest.csv"
    with manifest.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["id", "category", "png", "svg", "width", "height"])
        for image_id, category, png in rows:
            writer.writerow([image_id, category, png, "", 512, 512])
    return manifest
