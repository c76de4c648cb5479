"""Speed knobs of the fit (issue 14) against their cost in quality, at two levels.

    python benchmarks/bench_speed_knobs.py fit  base= lp2=lpips_every:2 plat=plateau_steps:50
    python benchmarks/bench_speed_knobs.py pipeline --per-category 4 g32=points_per_side:32 g16=
    python benchmarks/bench_speed_knobs.py final base= lp2=perceptual_every:2 threads2=threads:2

``fit``: stage 3 alone. Each of 12 bench images (2 per category) is segmented and traced once
at the default (no stage 4, no finish pass; cached under ``benchmarks/results/speed_knobs/
scenes/``, which git ignores), then fitted with each variant of `FitOptions`; MSE and LPIPS of the
fitted scene, seconds, and the geometric mean of each variant's MSE and LPIPS ratios to the
first variant's.

``pipeline``: the whole pipeline with `Config` overrides (``preset:fast`` starts from
`Config.fast`) on 2 (``--per-category``) images per category; one JSON record per variant and
image under ``benchmarks/results/speed_knobs/pipeline/<variant>/`` (a rerun skips what is there,
so a long run resumes); ratios against the first variant.

``final``: the default's last whole-scene fit alone (LPIPS, gradient fills), the one fit whose
knobs leave stage 4's rounds as they are (the rounds draft-fit their new paths without LPIPS).
Stages 1–4 run once per image at the default and the scene handed to that fit is cached under
``benchmarks/results/speed_knobs/final_scenes/`` (git ignores it); each variant replaces fields of
its `FitSettings` (``threads:N`` runs torch on N threads in the fit) and is scored
on its render (no finish pass).

A variant is ``name=setting:value,setting:value`` (``name=`` alone: the default). Lines go to
stdout and to ``benchmarks/results/speed_knobs/<study>.log``.
"""

from __future__ import annotations

import contextlib
import json
import pickle
import sys
import time
from collections.abc import Iterator
from dataclasses import replace
from typing import Any
from unittest.mock import patch

import numpy as np
import torch
from bench_images import BENCH, REPO, bench_entries, run_samvg, setting_value

import samvg
import samvg.missing.stage as missing_stage
import samvg.optimize.fit as fit_module
from samvg.config import FitOptions
from samvg.io import atomic_write_text
from samvg.metrics import load_lpips, lpips_distance
from samvg.optimize import FitResult, FitSettings, fit_scene
from samvg.optimize.losses import lpips_loss
from samvg.scene import FlatPaint

RESULTS = REPO / "benchmarks/results/speed_knobs"


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
    assert result.scene is not None and result.target is not None
    return result.scene, result.target


def final_scene(entry: dict[str, str]) -> tuple[samvg.Scene, np.ndarray, FitSettings]:
    """The scene the default pipeline hands its last whole-scene fit, the target and the
    settings of that fit (cached; the LPIPS loss is bound again on loading)."""
    cache = RESULTS / "final_scenes" / f"{entry['id']}.pkl"
    if not cache.exists():
        calls: list[tuple[samvg.Scene, FitSettings]] = []
        original = missing_stage.fit_scene

        def recording(
            scene: samvg.Scene, target: np.ndarray, settings: FitSettings, *rest: Any
        ) -> FitResult:
            if settings.perceptual is not None:
                calls.append((scene, settings))
            return original(scene, target, settings, *rest)

        with patch.object(missing_stage, "fit_scene", recording):
            result = samvg.run(BENCH / entry["png"], samvg.Config())
        scene, settings = calls[-1]
        cache.parent.mkdir(parents=True, exist_ok=True)
        with cache.open("wb") as written:
            pickle.dump((scene, result.target, replace(settings, perceptual=None)), written)
    with cache.open("rb") as stored:
        scene, target, settings = pickle.load(stored)
    perceptual = lpips_loss(target, FitOptions().lpips_size)
    return scene, target, replace(settings, perceptual=perceptual)


def final_study(chosen: dict[str, dict[str, Any]], log: Log) -> None:
    lpips = load_lpips()
    rows: dict[str, list[tuple[float, ...]]] = {name: [] for name in chosen}
    for entry in bench_entries(2):
        scene, target, base = final_scene(entry)
        for name, overrides in chosen.items():
            changes = dict(overrides)
            threads = int(changes.pop("threads", 1))
            settings = replace(base, **changes)
            started = time.perf_counter()
            with torch_threads_in_fit(threads):
                fitted = fit_scene(scene, target, settings).scene
            seconds = time.perf_counter() - started
            picture = np.clip(fitted.render(), 0, 1)
            mse = float(np.mean((picture - target) ** 2))
            distance = lpips_distance(lpips, picture, target)
            rows[name].append((mse, distance, seconds))
            log(f"{entry['id'][:28]:28} {name:10} MSE {mse * 1e3:7.3f}e-3 LPIPS {distance:.4f} "
                f"{seconds:5.1f} s, {scene.path_count} paths")  # fmt: skip
    summary(rows, log)


@contextlib.contextmanager
def torch_threads_in_fit(threads: int) -> Iterator[None]:
    """The fit's torch thread count set to ``threads`` inside the block."""
    original = fit_module.fit_torch_threads

    @contextlib.contextmanager
    def chosen(perceptual: bool) -> Iterator[None]:
        before = torch.get_num_threads()
        torch.set_num_threads(threads if perceptual else 1)
        try:
            yield
        finally:
            torch.set_num_threads(before)

    fit_module.fit_torch_threads = chosen
    try:
        yield
    finally:
        fit_module.fit_torch_threads = original


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


def pipeline_study(chosen: dict[str, dict[str, Any]], log: Log, per_category: int = 2) -> None:
    """Each variant on the same images (``preset:fast`` starts from `Config.fast`); records under
    ``pipeline/<variant>/`` (a rerun skips them); ratios against the first variant."""
    lpips = load_lpips()
    rows: dict[str, list[tuple[float, ...]]] = {name: [] for name in chosen}
    for entry in bench_entries(per_category):
        for name, overrides in chosen.items():
            path = RESULTS / "pipeline" / name / f"{entry['id']}.json"
            if not path.exists():
                settings = dict(overrides)
                preset = samvg.Config.fast if settings.pop("preset", None) == "fast" else None
                run = run_samvg(entry, (preset or samvg.Config)(**settings))
                picture = run.render()
                record = {
                    "id": entry["id"],
                    "mse": float(np.mean((picture - run.target) ** 2)),
                    "lpips": lpips_distance(lpips, picture, run.target),
                    "seconds": run.seconds,
                    "paths": run.result.counts.get("paths"),
                    "timings": run.result.timings,
                }
                path.parent.mkdir(parents=True, exist_ok=True)
                atomic_write_text(path, json.dumps(record, indent=1))
            record = json.loads(path.read_text())
            rows[name].append((record["mse"], record["lpips"], record["seconds"]))
            log(f"{name} {entry['id'][:26]:26} MSE {record['mse'] * 1e3:.3f}e-3 LPIPS "
                f"{record['lpips']:.4f} paths {record['paths']} "
                f"{record['seconds']:.1f} s")  # fmt: skip
    summary(rows, log)


def main() -> None:
    arguments = sys.argv[1:]
    per_category = 2
    if "--per-category" in arguments:
        at = arguments.index("--per-category")
        per_category = int(arguments[at + 1])
        del arguments[at : at + 2]
    if len(arguments) < 2 or arguments[0] not in ("fit", "pipeline", "final"):
        raise SystemExit(__doc__)
    study, chosen = arguments[0], variants(arguments[1:])
    log = Log(study)
    log(f"# {time.strftime('%Y-%m-%d %H:%M')} {study}: {' '.join(arguments[1:])}")
    if study == "fit":
        fit_study(chosen, log)
    elif study == "final":
        final_study(chosen, log)
    else:
        pipeline_study(chosen, log, per_category)


if __name__ == "__main__":
    main()
