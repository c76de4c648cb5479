"""Benchmark of samvg.trace: accuracy (IoU of the rendered paths vs the mask) and speed.

1. Synthetic shapes on a 128x128 canvas (tests/trace/synthetic.py) x segments per path
   (3, 4, 5, 6, 8): IoU of the traced path rendered by the project's rasterizer (coverage >
   0.5) against the mask, the fitting error (max distance contour -> curve) and the median
   time of one ``trace_components`` call.
2. Real SAM masks: MobileSAM automatic masks (``--points`` per side) of bench photos at
   ``--side`` px, traced with ``trace_masks_with_info`` at 4 and 5 segments; mean, median and
   worst IoU per mask against the mask as the tracer models it (components of at least
   ``min_area`` pixels, holes filled) and against the raw mask.
3. Speed: ``trace_masks`` of 100 random wavy blobs (radius 8-150 px) over a 512x512 image.

Usage: python benchmarks/bench_trace.py [--repeats N] [--points P] [--side S] [--out FILE]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage

from samvg.trace import DEFAULT_MIN_AREA, trace_components, trace_masks, trace_masks_with_info

REPO = Path(__file__).resolve().parents[1]
# The synthetic masks live with the tests (tests/trace/synthetic.py), not in the package: put
# the repository root first on the path so `tests` imports when this script is run directly.
sys.path.insert(0, str(REPO))
from tests.trace.synthetic import (  # noqa: E402
    SHAPES,
    iou,
    random_blobs,
    render_coverage,
    rounded_rectangle,
)

SHARED = REPO.parent / "shared"
SEGMENTS = (3, 4, 5, 6, 8)
PHOTOS = ("kodim04", "kodim05", "kodim23")


def median_seconds(function: Callable[[], object], repeats: int) -> float:
    function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def filled(mask: np.ndarray, min_area: float = DEFAULT_MIN_AREA) -> np.ndarray:
    """Components of at least min_area pixels with their holes filled (what the tracer traces)."""
    labels, count = ndimage.label(mask)
    result = np.zeros_like(mask)
    for label in range(1, count + 1):
        component = labels == label
        if component.sum() >= min_area:
            result |= ndimage.binary_fill_holes(component)
    return result


def shape_table(repeats: int) -> str:
    shapes = {name: make() for name, make in SHAPES.items()}
    shapes["rounded_rectangle_45deg"] = rounded_rectangle(128, 45.0)
    header = "| shape | " + " | ".join(f"K={k}" for k in SEGMENTS) + " |"
    lines = [
        "IoU / max fitting error (px) / ms per `trace_components` call:\n",
        header,
        "|---|" + "---:|" * len(SEGMENTS),
    ]
    for name, mask in shapes.items():
        cells = []
        for segments in SEGMENTS:
            paths = trace_components(mask, segments)
            coverage = render_coverage([p.points for p in paths], 128, 128)
            seconds = median_seconds(partial(trace_components, mask, segments), repeats)
            error = max(p.max_error for p in paths)
            cells.append(f"{iou(coverage, mask):.4f} / {error:.1f} / {1000 * seconds:.2f}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
        print(lines[-1], flush=True)
    return "\n".join(lines)


def sam_masks(points: int, side: int) -> list[tuple[str, np.ndarray, list[np.ndarray]]]:
    import torch

    from samvg.sam import SamAutomaticMaskGenerator, load_sam

    torch.set_num_threads(1)  # two threads stall each other on a small shared machine
    model = load_sam("mobile_sam", checkpoint=SHARED / "models" / "mobile_sam.pt")
    generator = SamAutomaticMaskGenerator(model, points_per_side=points)
    result = []
    for name in PHOTOS:
        photo = Image.open(SHARED / "bench" / "photo" / f"{name}.png").convert("RGB")
        photo.thumbnail((side, side))
        image = np.asarray(photo)
        records = generator.generate(image)
        masks = sorted((r["segmentation"] for r in records), key=lambda m: -int(m.sum()))
        print(f"{name}: {image.shape[1]}x{image.shape[0]}, {len(masks)} masks", flush=True)
        result.append((name, image, masks))
    return result


def sam_table(photos: list[tuple[str, np.ndarray, list[np.ndarray]]], repeats: int) -> str:
    lines = [
        "| photo | size | masks | K | paths | mean IoU | median IoU | worst IoU "
        "| mean IoU vs raw mask | trace ms |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    summary: dict[int, list[float]] = {4: [], 5: []}
    for name, image, masks in photos:
        height, width = image.shape[:2]
        targets = [filled(mask) for mask in masks]
        for segments in summary:
            _, info = trace_masks_with_info(masks, image, segments)
            seconds = median_seconds(partial(trace_masks, masks, image, segments), 3)
            scores, raw = [], []
            for index, (mask, target) in enumerate(zip(masks, targets, strict=True)):
                points = [p.points for p in info if p.mask_index == index]
                coverage = render_coverage(points, width, height)
                scores.append(iou(coverage, target))
                raw.append(iou(coverage, mask))
            summary[segments].extend(scores)
            lines.append(
                f"| {name} | {width}x{height} | {len(masks)} | {segments} | {len(info)} | "
                f"{np.mean(scores):.4f} | {np.median(scores):.4f} | {np.min(scores):.4f} | "
                f"{np.mean(raw):.4f} | {1000 * seconds:.1f} |"
            )
            print(lines[-1], flush=True)
    for segments, scores in summary.items():
        lines.append(
            f"| **all** | | {len(scores)} | {segments} | | **{np.mean(scores):.4f}** | "
            f"{np.median(scores):.4f} | {np.min(scores):.4f} | | |"
        )
    return "\n".join(lines)


def speed_line(repeats: int) -> str:
    masks = random_blobs(100, 512)
    image = np.random.default_rng(0).integers(0, 256, (512, 512, 3), dtype=np.uint8)
    times = []
    trace_masks(masks, image)
    for _ in range(repeats):
        start = time.perf_counter()
        result = trace_masks(masks, image)
        times.append(time.perf_counter() - start)
    return (
        f"`trace_masks` of 100 random wavy blobs (radius 8-150 px) at 512x512, K=4: "
        f"{result.path_count} paths, median {1000 * statistics.median(times):.0f} ms, "
        f"min {1000 * min(times):.0f} ms over {repeats} runs."
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--points", type=int, default=16, help="SAM points per side")
    parser.add_argument("--side", type=int, default=512, help="longest photo side for SAM")
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent / "results" / "trace.md"
    )
    args = parser.parse_args()

    start = time.perf_counter()
    trace_components(np.ones((4, 4), bool), 4)
    warm = time.perf_counter() - start
    speed = speed_line(args.repeats)
    print(speed, flush=True)
    shapes = shape_table(args.repeats)
    photos = sam_masks(args.points, args.side)
    sam = sam_table(photos, args.repeats)
    machine = f"{platform.machine()}, {os.cpu_count()} cores, numpy {np.__version__}"
    text = (
        "# Tracing benchmark\n\n"
        f"Command: `python benchmarks/bench_trace.py --points {args.points} --side {args.side}` "
        f"({machine}; the machine is shared, so times are noisy; times are medians of "
        f"{args.repeats} runs unless stated). Numba kernel warm-up in this process (cache load "
        f"or compile): {warm:.2f} s. Defaults: min_area {DEFAULT_MIN_AREA} px, "
        "16 Newton reparameterization rounds, at most 64 fitted points per segment.\n\n"
        "## Speed\n\n"
        f"{speed}\n\n"
        "## Synthetic shapes (128x128)\n\n"
        "IoU: traced path rendered by `samvg.render` (coverage > 0.5) vs the mask.\n\n"
        f"{shapes}\n\n"
        "## Real SAM masks\n\n"
        f"MobileSAM automatic masks (points_per_side={args.points}, default thresholds) of bench "
        f"photos resized to {args.side} px on the longest side. IoU per mask of its traced "
        "paths vs the mask as traced (components >= min_area, holes filled); 'vs raw mask' "
        "compares with the mask itself. 'trace ms' is one `trace_masks` call for all the "
        "photo's masks.\n\n"
        f"{sam}\n"
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
