"""Speed knobs of the fit (issue 14) against their cost in quality, at two levels.

    python benchmarks/bench_speed_knobs.py fit  base= lp2=lpips_every:2 plat=plateau_steps:50
    python benchmarks/bench_speed_knobs.py pipeline v6=refit_scene:true,plateau_steps:50

``fit``: stage 3 alone. Each of 12 bench images (2 per category) is segmented and traced once
at the default (no stage 4, no finish pass; cached under ``benchmarks/results/speed_knobs/
scenes/``, which git ignores), then fitted with each variant of `FitOptions`; MSE and LPIPS of the
fitted scene, seconds, and the geometric mean of each variant's MSE and LPIPS ratios to the
first variant's.

``pipeline``: the whole default pipeline with `Config` overrides on the same 12 images, against
the default's records of ``bench_geometry.py --settings default`` (same code path, so the old
default reproduces them exactly).

A variant is ``name=setting:value,setting:value`` (``name=`` alone: the default). Lines go to
stdout and to ``benchmarks/results/speed_knobs/<study>.log``.
"""

from __future__ import annotations

import json
import pickle
import sys
import time
from typing import Any

import numpy as np
from bench_images import BENCH, REPO, bench_entries, run_samvg, setting_value

import samvg
from samvg.config import FitOptions
from samvg.metrics import load_lpips, lpips_distance
from samvg.optimize import FitSettings, fit_scene
from samvg.scene import FlatPaint

RESULTS = REPO / "benchmarks/results/speed_knobs"
GEOMETRY = REPO / "benchmarks/results/geometry"


def variants(arguments: list[str]) -> dict[str, dict[str, Any]]:
    parsed = {}
    for argument in arguments:
        name, _, settings = argument.partition("=")
        pairs = (item.split(":", 1) for item in settings.split(",") if item)
        parsed[name] = {key: setting_value(value) for key, value in pairs}
    return parsed


class Log:
    def __init__(self, study: str) -> None:
        RESULTS.mkdir(parents=True, exist_ok=True)
        self.file = (RESULTS / f"{study}.log").open("a")

    def __call__(self, line: str) -> None:
        print(line, flush=True)
        self.file.write(line + "\n")
        self.file.flush()


def traced_scene(entry: dict[str, str]) -> tuple[samvg.Scene, np.ndarray]:
    cache = RESULTS / "scenes" / f"{entry['id']}.pkl"
    if cache.exists():
        with cache.open("rb") as handle:
            return pickle.load(handle)
    config = samvg.Config(missing_rounds=0, finish_pass=False, iterations=0, gradients=False)
    result = samvg.run(BENCH / entry["png"], config)
    cache.parent.mkdir(parents=True, exist_ok=True)
    with cache.open("wb") as handle:
        pickle.dump((result.scene, result.target), handle)
    return result.scene, result.target


def summary(rows: dict[str, list[tuple[float, ...]]], log: Log) -> None:
    names = list(rows)
    first = np.array(rows[names[0]])
    for name in names:
        values = np.array(rows[name])
        ratio = np.exp(np.mean(np.log(values[:, :2] / first[:, :2]), axis=0))
        log(
            f"SUMMARY {name}: mean MSE {values[:, 0].mean() * 1e3:.3f}e-3, mean LPIPS "
            f"{values[:, 1].mean():.4f}, seconds {values[:, 2].sum():.1f}; geometric-mean ratio "
            f"to {names[0]}: MSE {ratio[0]:.3f}, LPIPS {ratio[1]:.3f}"
            + (f"; mean parameters {values[:, 3].mean():.0f}" if values.shape[1] > 3 else "")
        )


def fit_study(chosen: dict[str, dict[str, Any]], log: Log) -> None:
    lpips = load_lpips()
    rows: dict[str, list[tuple[float, ...]]] = {name: [] for name in chosen}
    for entry in bench_entries(2):
        scene, target = traced_scene(entry)
        for name, overrides in chosen.items():
            options = FitOptions(**overrides)
            settings = FitSettings.from_options(options, target, (scene.width, scene.height))
            started = time.perf_counter()
            fitted = fit_scene(scene, target, settings).scene
            seconds = time.perf_counter() - started
            picture = np.clip(fitted.render(), 0, 1)
            mse = float(np.mean((picture - target) ** 2))
            shaded = sum(not isinstance(paint, FlatPaint) for paint in fitted.paints)
            shaded += fitted.background_gradient is not None
            distance = lpips_distance(lpips, picture, target)
            rows[name].append((mse, distance, seconds, fitted.parameter_count))
            log(f"{entry['id'][:28]:28} {name:10} MSE {mse * 1e3:7.3f}e-3 LPIPS {distance:.4f} "
                f"{seconds:5.1f} s, {fitted.parameter_count} parameters, "
                f"{shaded} gradients")  # fmt: skip
    summary(rows, log)


def pipeline_study(chosen: dict[str, dict[str, Any]], log: Log) -> None:
    lpips = load_lpips()
    for name, overrides in chosen.items():
        rows: dict[str, list[tuple[float, ...]]] = {"default records": [], name: []}
        for entry in bench_entries(2):
            run = run_samvg(entry, samvg.Config(**overrides))
            picture = run.render()
            mse = float(np.mean((picture - run.target) ** 2))
            measured = (mse, lpips_distance(lpips, picture, run.target), run.seconds)
            old = json.loads((GEOMETRY / f"{entry['id']}.default.json").read_text())
            rows["default records"].append((old["mse"], old["lpips"], old["seconds"]))
            rows[name].append(measured)
            paths = run.result.counts.get("paths")
            log(f"{name} {entry['id'][:26]:26} MSE {mse * 1e3:.3f}e-3 (default "
                f"{old['mse'] * 1e3:.3f}) LPIPS {measured[1]:.4f} (default {old['lpips']:.4f}) "
                f"paths {paths} ({old['paths']}) {run.seconds:.1f} s")  # fmt: skip
        summary(rows, log)


def main() -> None:
    if len(sys.argv) < 3 or sys.argv[1] not in ("fit", "pipeline"):
        raise SystemExit(__doc__)
    study, chosen = sys.argv[1], variants(sys.argv[2:])
    log = Log(study)
    log(f"# {time.strftime('%Y-%m-%d %H:%M')} {study}: {' '.join(sys.argv[2:])}")
    (fit_study if study == "fit" else pipeline_study)(chosen, log)


if __name__ == "__main__":
    main()
