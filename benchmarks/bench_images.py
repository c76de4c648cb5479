"""What the benchmark scripts share: where the bench is, which of its images to take, and one
timed samvg run on an image with its working-size target."""

from __future__ import annotations

import csv
import io
import json
import os
import time
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image

import samvg
from samvg.imaging import resize_longest, to_float_rgb
from samvg.io import read_image
from samvg.pipeline import PipelineResult

REPO = Path(__file__).resolve().parents[1]
BENCH = Path(os.environ.get("SAMVG_BENCH", REPO.parent / "shared" / "bench"))


def bench_entries(
    per_category: int | None = None, categories: list[str] | None = None
) -> list[dict[str, str]]:
    """Manifest rows: all, or the first ``per_category`` of each category (of ``categories``)."""
    with open(BENCH / "manifest.csv", newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if not categories or r["category"] in categories]
    if per_category is None:
        return rows
    picked: dict[str, list[dict[str, str]]] = defaultdict(list)
    for row in rows:
        if len(picked[row["category"]]) < per_category:
            picked[row["category"]].append(row)
    order = categories or sorted(picked)
    return [row for category in order for row in picked[category]]


@dataclass
class BenchRun:
    """One samvg run on a bench image: its result, the working-size target, the scale from
    input to working pixels, seconds, and the working image (uint8)."""

    result: PipelineResult
    target: np.ndarray
    scale: float
    seconds: float
    working: np.ndarray

    def render(self) -> np.ndarray:
        """The SVG rendered at the working size, clipped to [0, 1]."""
        return render_at_working_size(self.result.image, self.scale, self.target.shape)


def working_image(entry: dict[str, str], size: int = 512) -> tuple[np.ndarray, float]:
    """A bench image at the working size (uint8, longer side at most ``size``) and its scale."""
    return resize_longest(read_image(BENCH / entry["png"]), size)


def render_at_working_size(
    image: samvg.VectorImage, scale: float, shape: tuple[int, ...]
) -> np.ndarray:
    """An SVG in input pixels rendered at ``scale``, cropped (or, where the working size rounded
    up and the render's down, edge-padded by that pixel) to the working image's (H, W) and
    clipped to [0, 1]."""
    height, width = shape[:2]
    picture = image.render(scale=scale)[:height, :width]
    short = ((0, height - picture.shape[0]), (0, width - picture.shape[1]), (0, 0))
    return np.clip(np.pad(picture, short, mode="edge"), 0, 1)


def setting_value(text: str) -> Any:
    """A setting's value from the command line: JSON where it parses (numbers, true, null),
    else the text."""
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def run_samvg(entry: dict[str, str], config: samvg.Config) -> BenchRun:
    original = read_image(BENCH / entry["png"])
    working, scale = resize_longest(original, config.size)
    started = time.perf_counter()
    result = samvg.run(original, config)
    seconds = time.perf_counter() - started
    return BenchRun(result, to_float_rgb(working), scale, seconds, working)


def vtracer_default(image: np.ndarray) -> str:
    """VTracer's SVG of a uint8 image with its default settings."""
    import vtracer  # the bench extra

    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    return vtracer.convert_raw_image_to_svg(buffer.getvalue(), img_format="png")
