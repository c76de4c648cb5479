"""Time of the removal costs that reduce a scene to a path budget (`samvg.optimize.reduce`):
each path's cost measured on its own window (now) against a whole-canvas render per path (before
fc773ec), on scenes of 16, 64 and 256 fitted random paths over bench images at 512 px; and the
largest difference between the two sets of costs.

    python benchmarks/bench_reduce.py --per-category 1 --paths 16,64,256

Prints a markdown table and writes it to ``benchmarks/results/reduce_costs.md``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
from bench_images import REPO, bench_entries, working_image

from samvg.baselines import random_init
from samvg.imaging import to_float_rgb
from samvg.io import atomic_write_text
from samvg.optimize.reduce import removal_costs
from samvg.scene import Scene


def whole_render_costs(scene: Scene, target: np.ndarray) -> np.ndarray:
    """The costs as computed before fc773ec: the whole canvas rendered once per path."""
    squared = np.sum((scene.render() - target) ** 2)
    costs = np.empty(scene.path_count)
    for index in range(scene.path_count):
        others = [other for other in range(scene.path_count) if other != index]
        costs[index] = np.sum((scene.subset(others).render() - target) ** 2) - squared
    return costs / target.size


def timed(
    compute: Callable[[Scene, np.ndarray], np.ndarray], scene: Scene, target: np.ndarray
) -> tuple[np.ndarray, float]:
    started = time.perf_counter()
    costs = compute(scene, target)
    return costs, time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-category", type=int, default=1)
    parser.add_argument("--paths", default="16,64,256")
    parser.add_argument("--output", default=str(REPO / "benchmarks/results/reduce_costs.md"))
    arguments = parser.parse_args()
    budgets = [int(value) for value in arguments.paths.split(",")]
    rows = []
    for count in budgets:
        before, after, worst = [], [], 0.0
        for entry in bench_entries(arguments.per_category):
            image, _scale = working_image(entry)
            target = to_float_rgb(image, entry["id"])
            scene = random_init(target, count, steps=20, seed=0)
            whole, seconds_before = timed(whole_render_costs, scene, target)
            windowed, seconds_after = timed(removal_costs, scene, target)
            before.append(seconds_before)
            after.append(seconds_after)
            worst = max(
                worst, float(np.abs(whole - windowed).max() / max(np.abs(whole).max(), 1e-12))
            )
            print(
                f"{entry['id']} {count}: {seconds_before:.2f} s -> {seconds_after:.2f} s",
                flush=True,
            )
        median_before, median_after = statistics.median(before), statistics.median(after)
        rows.append(
            f"| {count} | {len(before)} | {median_before:.2f} | {median_after:.2f} | "
            f"{median_before / median_after:.1f}x | {worst:.1e} |"
        )
    table = [
        "# Removal costs: whole renders against windows",
        "",
        "Made by `python benchmarks/bench_reduce.py "
        f"--per-category {arguments.per_category} --paths {arguments.paths}` (2 CPU cores); "
        "scenes of N random paths fitted 20 steps to each image at 512 px. Times are medians "
        "over the images, seconds for one set of costs (reduction to a budget computes one per "
        "batch). The last column is the largest difference of the two, relative to the largest "
        "cost.",
        "",
        "| paths | images | whole renders (s) | windows (s) | speed-up | largest difference |",
        "|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
    ]
    atomic_write_text(arguments.output, "\n".join(table))
    print("\n".join(table))


if __name__ == "__main__":
    main()
