"""End-to-end vectorization benchmark on ../shared/bench: time per stage, paths, MSE and LPIPS of
samvg's default and --fast presets, against VTracer and random-init optimization (the paper's
DiffVG baseline) at the same path count.

Usage: python benchmarks/bench_vectorize.py [--per-category 1] [--presets default,fast]
       [--baselines vtracer,diffvg] [--output benchmarks/results/vectorize.md]
Needs ../shared (or SAMVG_BENCH) and the SAM and LPIPS weights (SAMVG_* variables or cache).
All images are worked at 512 px (the bench images already are); metrics are on that grid.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import statistics
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
import torch

import samvg
from samvg.baselines import path_count, run_baseline
from samvg.imaging import resize_longest, to_float_rgb
from samvg.io import read_image
from samvg.metrics import load_lpips, lpips_distance
from samvg.optimize import FitSettings

REPO = Path(__file__).resolve().parents[1]
BENCH = Path(os.environ.get("SAMVG_BENCH", REPO.parent / "shared" / "bench"))
PRESETS = {"default": samvg.Config(), "fast": samvg.Config.fast()}


def choose(rows: list[dict[str, str]], per_category: int) -> list[dict[str, str]]:
    chosen: dict[str, list[dict[str, str]]] = defaultdict(list)
    for row in rows:
        if len(chosen[row["category"]]) < per_category:
            chosen[row["category"]].append(row)
    return [row for category in sorted(chosen) for row in chosen[category]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--per-category", type=int, default=1)
    parser.add_argument("--presets", default="default,fast")
    parser.add_argument("--baselines", default="vtracer,diffvg")
    parser.add_argument("--output", type=Path, default=REPO / "benchmarks/results/vectorize.md")
    arguments = parser.parse_args()
    presets = [p for p in arguments.presets.split(",") if p]
    baselines = [b for b in arguments.baselines.split(",") if b]

    with open(BENCH / "manifest.csv", newline="") as handle:
        rows = choose(list(csv.DictReader(handle)), arguments.per_category)
    lpips_model = load_lpips()
    table: list[dict[str, object]] = []
    for row in rows:
        original = read_image(BENCH / row["png"])
        target_u8, target_scale = resize_longest(original, 512)
        target = to_float_rgb(target_u8)
        counts: dict[str, int] = {}
        for preset in presets:
            config = PRESETS[preset]
            result = samvg.run(original, config)
            render = result.image.render(scale=target_scale)[: target.shape[0], : target.shape[1]]
            counts[preset] = path_count(result.image)
            table.append(
                {
                    "image": row["id"],
                    "category": row["category"],
                    "method": f"samvg-{preset}",
                    "paths": counts[preset],
                    "mse": float(np.mean((render - target) ** 2)),
                    "lpips": lpips_distance(lpips_model, np.clip(render, 0, 1), target),
                    **{f"t_{k}": v for k, v in result.timings.items()},
                }
            )
            print(table[-1], flush=True)
        reference = counts.get("default", next(iter(counts.values())))
        options = FitSettings.from_options(PRESETS["default"].fit, target)
        for baseline in baselines:
            started = time.perf_counter()
            output = run_baseline(baseline, target, reference, options, seed=0)
            elapsed = time.perf_counter() - started
            render = output.render()
            table.append(
                {
                    "image": row["id"],
                    "category": row["category"],
                    "method": baseline,
                    "paths": path_count(output),
                    "mse": float(np.mean((render - target) ** 2)),
                    "lpips": lpips_distance(lpips_model, np.clip(render, 0, 1), target),
                    "t_total": elapsed,
                }
            )
            print(table[-1], flush=True)
    write_report(table, arguments, presets, baselines)


def write_report(table, arguments, presets, baselines) -> None:  # type: ignore[no-untyped-def]
    methods = [f"samvg-{p}" for p in presets] + baselines
    by_method = {m: [r for r in table if r["method"] == m] for m in methods}
    lines = [
        "# End-to-end vectorization benchmark",
        "",
        f"`python benchmarks/bench_vectorize.py --per-category {arguments.per_category} "
        f"--presets {arguments.presets} --baselines {arguments.baselines}`; "
        f"{platform.machine()}, {os.cpu_count()} cores, torch {torch.__version__} "
        f"({torch.get_num_threads()} threads). Images from ../shared/bench at 512 px (longest "
        "side). MSE on RGB in [0, 1]; LPIPS AlexNet v0.1. Baselines get samvg-default's path "
        "count, its losses (MSE + Xing + LPIPS) and its total iterations (2 x 500).",
        "",
        "## Summary",
        "",
        "| method | images | median time s | mean paths | mean MSE x1e-3 | mean LPIPS |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for method, rows in by_method.items():
        if not rows:
            continue
        lines.append(
            f"| {method} | {len(rows)} | {statistics.median(r['t_total'] for r in rows):.1f} | "
            f"{np.mean([r['paths'] for r in rows]):.1f} | "
            f"{1e3 * np.mean([r['mse'] for r in rows]):.2f} | "
            f"{np.mean([r['lpips'] for r in rows]):.3f} |"
        )
    if "samvg-default" in by_method:
        lines += ["", "Images where samvg-default has the lower value:", ""]
        ours = {r["image"]: r for r in by_method["samvg-default"]}
        for baseline in baselines:
            rows = by_method[baseline]
            mse_wins = sum(ours[r["image"]]["mse"] < r["mse"] for r in rows)
            lpips_wins = sum(ours[r["image"]]["lpips"] < r["lpips"] for r in rows)
            lines.append(
                f"- vs {baseline}: MSE {mse_wins}/{len(rows)}, LPIPS {lpips_wins}/{len(rows)}"
            )
    stages = ["segment", "trace", "optimize", "missing", "refine", "total"]
    lines += [
        "",
        "## Per image",
        "",
        "| image | category | method | paths | MSE x1e-3 | LPIPS | "
        + " | ".join(f"{s} s" for s in stages)
        + " |",
        "|---|---|---|---:|---:|---:|" + "---:|" * len(stages),
    ]
    for r in table:
        times = " | ".join(f"{r[f't_{s}']:.1f}" if f"t_{s}" in r else "" for s in stages)
        lines.append(
            f"| {r['image']} | {r['category']} | {r['method']} | {r['paths']} | "
            f"{1e3 * r['mse']:.2f} | {r['lpips']:.3f} | {times} |"
        )
    arguments.output.parent.mkdir(parents=True, exist_ok=True)
    arguments.output.write_text("\n".join(lines) + "\n")
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main()
