"""Filter by impact: paths kept and error against the threshold, on ../shared/bench.

For each image SAM's automatic masks are computed once; then for each threshold the mask
components are filtered (samvg.segment), traced, and the traced SVG rendered. Reports components
kept, the filter canvas error e (samvg/segment/impact.py's normalization: 1 = blank canvas) and
the MSE of the traced, not yet optimized, SVG. Threshold "off" keeps every component (the
paper's ablation).

Usage: python benchmarks/bench_impact.py [--per-category 1] [--output benchmarks/results/impact.md]
"""

from __future__ import annotations

import argparse
import csv
import os
from collections import defaultdict
from pathlib import Path

import numpy as np

import samvg
from samvg.imaging import filled_components, resize_longest, to_float_rgb
from samvg.io import read_image
from samvg.segment import Segmenter, filter_by_impact, keep_all
from samvg.trace.stage import TraceSettings, trace_scene, uncovered_background

REPO = Path(__file__).resolve().parents[1]
BENCH = Path(os.environ.get("SAMVG_BENCH", REPO.parent / "shared" / "bench"))
THRESHOLDS = [None, 0.0, 2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--per-category", type=int, default=1)
    parser.add_argument("--output", type=Path, default=REPO / "benchmarks/results/impact.md")
    arguments = parser.parse_args()
    with open(BENCH / "manifest.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    chosen: dict[str, list[dict[str, str]]] = defaultdict(list)
    for row in rows:
        if len(chosen[row["category"]]) < arguments.per_category:
            chosen[row["category"]].append(row)
    config = samvg.Config()
    segmenter = Segmenter(config.segment)
    results: dict[str, list[tuple[int, float, float]]] = defaultdict(list)
    for category in sorted(chosen):
        for row in chosen[category]:
            image, _ = resize_longest(read_image(BENCH / row["png"]), config.size)
            target = to_float_rgb(image)
            height, width = target.shape[:2]
            trace_settings = TraceSettings.from_config(config, width, height)
            min_pixels = trace_settings.min_pixels
            candidates = [
                part
                for mask in segmenter.automatic(image)
                for part in filled_components(mask, min_pixels)
            ]
            for threshold in THRESHOLDS:
                if threshold is None:
                    kept, canvas = keep_all(candidates, target)
                else:
                    kept, canvas = filter_by_impact(candidates, target, threshold)
                masks = sorted((candidates[i] for i in kept), key=lambda m: -int(m.sum()))
                traced = trace_scene(masks, target, trace_settings)
                traced = traced.with_background(uncovered_background(masks, target))
                mse = float(np.mean((traced.render() - target) ** 2))
                paths = traced.path_count
                results[str(threshold)].append((paths, canvas.mean_error, mse))
                print(row["id"], threshold, paths, canvas.mean_error, mse, flush=True)
    count = sum(len(v) for v in chosen.values())
    grid = config.segment.points_per_side
    lines = [
        "# Filter by impact: threshold against paths and error",
        "",
        f"`python benchmarks/bench_impact.py --per-category {arguments.per_category}`: "
        f"{count} images of ../shared/bench (the first of each category), 512 px, MobileSAM "
        f"AMG {grid}x{grid}. Means over the images. *e*: the filter's canvas error (mean over "
        "pixels of the mean squared RGB error, uncovered = 1). *traced MSE*: the traced SVG "
        "before any optimization. Default threshold: 2e-4.",
        "",
        "| threshold | paths | canvas error e | traced MSE x1e-3 |",
        "|---|---:|---:|---:|",
    ]
    for threshold in THRESHOLDS:
        values = np.array(results[str(threshold)])
        label = "off (keep all)" if threshold is None else f"{threshold:g}"
        lines.append(
            f"| {label} | {values[:, 0].mean():.1f} | {values[:, 1].mean():.4f} | "
            f"{1e3 * values[:, 2].mean():.2f} |"
        )
    arguments.output.write_text("\n".join(lines) + "\n")
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main()
