"""Detail at any path budget (issue 11): samvg at N paths against VTracer tuned to N paths, the
LIVE-style baseline and random init (diffvg) at N, and samvg with gradient fills at N (issue
13); VTracer's settings swept on photos and paintings for the rate-distortion plot (beside samvg
at the budgets of the budget study); and the report, which also holds the default against
VTracer's default settings (from the records of ``bench_geometry.py --settings default``).

    python benchmarks/bench_detail.py budget --per-category 4 --paths 16,64,256 \
        --methods samvg-gradients,vtracer,live,diffvg --records benchmarks/results/detail/budget-X
    python benchmarks/bench_detail.py rate --per-category 4
    python benchmarks/bench_detail.py report --records benchmarks/results/detail/budget-X

Every run is one JSON record in ``benchmarks/results/detail/`` (a rerun skips what is there, so
a long run resumes); the report goes to ``benchmarks/results/detail.md`` and the
rate-distortion plot to ``benchmarks/results/detail_rate.png``. All images are vectorized at
512 px; MSE and LPIPS are measured at that working size.
"""

from __future__ import annotations

import argparse
import io
import json
import time
from pathlib import Path
from typing import Any

import numpy as np
from bench_images import REPO, bench_entries, run_samvg, setting_value, working_image
from PIL import Image

import samvg
from samvg.baselines import count_paths, count_shapes, render_svg, run_baseline
from samvg.baselines.vtracer_baseline import trace_once
from samvg.imaging import to_float_rgb
from samvg.io import atomic_write_text
from samvg.metrics import load_lpips, lpips_distance
from samvg.optimize import FitSettings

RECORDS = REPO / "benchmarks/results/detail"
GEOMETRY = REPO / "benchmarks/results/geometry"
FLAT_ART = ("emoji", "icon", "clipart", "digital_art")
#: Baselines that optimize get samvg's losses and the paper's two phases of steps.
BASELINE_STEPS = 2 * samvg.Config().fit.iterations
#: VTracer settings for the rate-distortion sweep: (filter_speckle, color_precision,
#: layer_difference), from finest to coarsest; (4, 6, 16) is VTracer's default.
VTRACER_SWEEP = ((2, 7, 8), (4, 6, 16), (8, 5, 24), (16, 4, 32), (32, 3, 48))


def measured(picture: np.ndarray, target: np.ndarray, lpips: Any) -> dict[str, float]:
    picture = np.clip(picture, 0.0, 1.0)
    return {
        "mse": float(np.mean((picture - target) ** 2)),
        "lpips": lpips_distance(lpips, picture, target),
    }


def samvg_record(
    entry: dict[str, str], config: samvg.Config, lpips: Any, keep_svg: Path | None = None
) -> dict[str, Any]:
    """samvg's record at ``config``; with ``keep_svg``, its SVG is also written there (for a
    contact sheet without reruns)."""
    run = run_samvg(entry, config)
    svg = run.result.image.to_svg()
    if keep_svg is not None:
        keep_svg.mkdir(parents=True, exist_ok=True)
        tag = f"{config.missing.paths}.{'gradients' if config.fit.gradients else 'flat'}"
        atomic_write_text(keep_svg / f"{entry['id']}.{tag}.svg", svg)
    return {
        "paths": run.result.counts.get("paths", 0),
        "shapes": count_shapes(svg),
        "gradient_fills": run.result.counts.get("gradient_fills", 0),
        "svg_bytes": len(svg.encode()),
        "seconds": run.seconds,
        **measured(run.render(), run.target, lpips),
    }


def baseline_record(entry: dict[str, str], method: str, paths: int, lpips: Any) -> dict[str, Any]:
    working = working_image(entry)[0]
    target = to_float_rgb(working)
    fit = FitSettings.from_options(samvg.Config().fit, target)
    started = time.perf_counter()
    result = run_baseline(method, target, paths, fit, steps=BASELINE_STEPS)
    seconds = time.perf_counter() - started
    svg = result.to_svg()
    height, width = target.shape[:2]
    return {
        "paths": count_paths(svg),
        "shapes": count_shapes(svg),
        "svg_bytes": len(svg.encode()),
        "seconds": seconds,
        **measured(render_svg(svg, width, height), target, lpips),
    }


def vtracer_record(entry: dict[str, str], setting: tuple[int, int, int], lpips: Any) -> dict:
    working = working_image(entry)[0]
    target = to_float_rgb(working)
    buffer = io.BytesIO()
    Image.fromarray(working).save(buffer, format="PNG")
    started = time.perf_counter()
    svg = trace_once(buffer.getvalue(), *setting)
    seconds = time.perf_counter() - started
    height, width = target.shape[:2]
    return {
        "paths": count_paths(svg),
        "shapes": count_shapes(svg),
        "svg_bytes": len(svg.encode()),
        "seconds": seconds,
        **measured(render_svg(svg, width, height), target, lpips),
    }


def save(
    records: Path, name: str, entry: dict[str, str], extra: dict[str, Any], make: Any, *args: Any
) -> None:
    """Run ``make(entry, *args)`` and keep its record in the folder ``records``, unless the
    record is there already."""
    record_file = records / f"{entry['id']}.{name}.json"
    if record_file.exists():
        return
    record = {"id": entry["id"], "category": entry["category"], **extra, **make(entry, *args)}
    records.mkdir(parents=True, exist_ok=True)
    atomic_write_text(record_file, json.dumps(record, indent=1))
    print(json.dumps(record), flush=True)


def run_budget(
    entries: list[dict[str, str]],
    budgets: list[int],
    methods: list[str],
    overrides: dict[str, Any],
    keep_svg: Path | None = None,
    records: Path = RECORDS,
) -> None:
    lpips = load_lpips()
    for budget in budgets:
        for entry in entries:
            for method in methods:
                extra = {"study": "budget", "method": method, "budget": budget}
                if method in ("samvg", "samvg-gradients"):
                    gradients = method == "samvg-gradients"
                    config = samvg.Config(paths=budget, gradients=gradients, **overrides)
                    extra["overrides"] = overrides
                    record = samvg_record
                    name = f"{method}.{budget}"
                    save(records, name, entry, extra, record, config, lpips, keep_svg)
                else:
                    name = f"{method}.{budget}"
                    save(records, name, entry, extra, baseline_record, method, budget, lpips)


def run_rate(entries: list[dict[str, str]]) -> None:
    """VTracer at every setting of `VTRACER_SWEEP` (samvg's points of the rate-distortion plot
    are its runs at each budget of the ``budget`` study)."""
    lpips = load_lpips()
    for entry in entries:
        for setting in VTRACER_SWEEP:
            tag = "-".join(map(str, setting))
            extra = {"study": "rate", "method": "vtracer", "setting": tag}
            save(RECORDS, f"rate.vtracer.{tag}", entry, extra, vtracer_record, setting, lpips)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", choices=("budget", "rate", "report"))
    parser.add_argument("--per-category", type=int, default=4)
    parser.add_argument("--categories", help="comma-separated (default: all six)")
    parser.add_argument("--paths", default="16,64", help="budgets, comma-separated")
    parser.add_argument("--methods", default="samvg,samvg-gradients,vtracer,live,diffvg")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a samvg setting for every samvg run (kept in each record), e.g. plateau_steps=50",
    )
    parser.add_argument("--keep-svg", type=Path, help="also write samvg's SVGs to this folder")
    parser.add_argument(
        "--records",
        type=Path,
        default=RECORDS,
        help="budget records' folder, written by budget and read by report (bench_speed.py's "
        "time-against-paths plot reads benchmarks/results/speed/paths)",
    )
    parser.add_argument(
        "--fallback",
        type=Path,
        action="append",
        default=[],
        help="report: budget records missing from --records are taken from this folder (an "
        "older commit's baselines); repeat it to look in several, in order",
    )
    parser.add_argument(
        "--geometry",
        type=Path,
        action="append",
        help="report: a folder of bench_geometry.py's default records, samvg against VTracer, "
        "one table each (default: benchmarks/results/geometry)",
    )
    arguments = parser.parse_args()
    overrides = dict(_setting(text) for text in arguments.set)
    if arguments.study == "report":
        from detail_report import write_report

        budget = arguments.records if arguments.records != RECORDS else None
        write_report(RECORDS, arguments.geometry or [GEOMETRY], budget, arguments.fallback)
        return
    categories = arguments.categories.split(",") if arguments.categories else None
    if arguments.study == "rate" and categories is None:
        categories = ["photo", "painting"]
    entries = bench_entries(arguments.per_category, categories)
    budgets = [int(text) for text in arguments.paths.split(",")]
    if arguments.study == "budget":
        methods = arguments.methods.split(",")
        run_budget(entries, budgets, methods, overrides, arguments.keep_svg, arguments.records)
    else:
        run_rate(entries)


def _setting(text: str) -> tuple[str, Any]:
    """``name=value`` with the value read as JSON where it parses (numbers, true, null)."""
    name, _, value = text.partition("=")
    return name, setting_value(value)


if __name__ == "__main__":
    main()
