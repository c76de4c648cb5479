"""End-to-end vectorization benchmark on ../shared/bench: seconds per stage, paths and pixel MSE.

Usage: python benchmarks/bench_vectorize.py [--per-category 1] [--steps 300]
Writes benchmarks/results/vectorize.md. Needs ../shared (or SAMVG_BENCH) and the SAM weights.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import torch

from samvg.io import read_image
from samvg.pipeline import VectorizeConfig, vectorize

REPO = Path(__file__).resolve().parents[1]
BENCH = Path(os.environ.get("SAMVG_BENCH", REPO.parent / "shared" / "bench"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--per-category", type=int, default=1)
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--output", type=Path, default=REPO / "benchmarks/results/vectorize.md")
    arguments = parser.parse_args()

    with open(BENCH / "manifest.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    chosen: dict[str, list[dict[str, str]]] = defaultdict(list)
    for row in rows:
        if len(chosen[row["category"]]) < arguments.per_category:
            chosen[row["category"]].append(row)

    lines = [
        "# End-to-end vectorization benchmark",
        "",
        f"`python benchmarks/bench_vectorize.py --per-category {arguments.per_category} "
        f"--steps {arguments.steps}`; {platform.machine()}, {os.cpu_count()} cores, "
        f"torch {torch.__version__}. Pipeline: MobileSAM AMG 32x32, trace (5 segments per path), "
        "MSE fit. Seconds are wall time per stage.",
        "",
        "| image | category | size | segment s | trace s | optimize s | total s | paths | MSE |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    totals = []
    for category in sorted(chosen):
        for row in chosen[category]:
            image = read_image(BENCH / row["png"])
            stamps: dict[str, float] = {}
            start = time.perf_counter()

            def progress(stage: str, _done: int, _total: int) -> None:
                stamps[stage] = time.perf_counter()  # noqa: B023

            result = vectorize(image, VectorizeConfig(steps=arguments.steps), progress=progress)
            end = time.perf_counter()
            target = image.astype(np.float32) / 255.0
            mse = float(np.mean((result.render() - target) ** 2))
            segment = stamps["segment"] - start
            trace = stamps.get("trace", stamps["segment"]) - stamps["segment"]
            optimize = end - stamps.get("trace", stamps["segment"])
            totals.append(end - start)
            lines.append(
                f"| {row['id']} | {category} | {image.shape[1]}x{image.shape[0]} | "
                f"{segment:.1f} | {trace:.2f} | {optimize:.1f} | {end - start:.1f} | "
                f"{len(result.paths)} | {mse:.4f} |"
            )
            print(lines[-1], flush=True)
    lines += ["", f"Mean total: {np.mean(totals):.1f} s per image."]
    arguments.output.parent.mkdir(parents=True, exist_ok=True)
    arguments.output.write_text("\n".join(lines) + "\n")
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main()
