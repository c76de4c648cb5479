"""Running the benchmark: every image × method once, each result written to the output folder as
it finishes (a rerun skips what is there), a failure recorded without stopping the run.

Layout of the output folder::

    run.json                   settings of the run (a rerun must use the same)
    records/<method>/<id>.json one result: metrics, paths, time, or the error
    svg/<method>/<id>.svg      each method's SVG
    renders/<method>/<id>.png  its render at the working size (FID, contact sheet)
    targets/<id>.png           the target at the working size
    fid/targets/<id>.npy       InceptionV3 features of the target (FID; see samvg.bench.features)
    fid/renders/<method>/<id>.npy   the same of each render
    results.csv, summary.md, *.png   see :mod:`samvg.bench.report`
"""

from __future__ import annotations

import csv
import dataclasses
import io
import itertools
import json
import os
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple, Protocol

import numpy as np

from samvg.baselines import Vectorized, parameter_count, path_count
from samvg.bench.features import FeatureStore
from samvg.bench.layout import Layout
from samvg.bench.manifest import BenchImage, read_manifest
from samvg.bench.measure import IMAGE_METRICS, Scorer
from samvg.bench.methods import DEFAULT_METHODS, METHODS, Method, MethodRun
from samvg.bench.report import write_report
from samvg.config import Config, FinishOptions
from samvg.errors import InputError, WeightsError
from samvg.imaging import resize_longest, to_float_rgb
from samvg.io import atomic_write_text, read_image, write_png

#: Columns of results.csv, in order (``details`` is JSON text).
RECORD_FIELDS = (
    "id",
    "category",
    "method",
    "status",
    "error",
    "width",
    "height",
    "paths",
    "parameters",
    "svg_bytes",
    "time_s",
    *IMAGE_METRICS,
    "target_complexity",
    "details",
)
#: Config fields added after a run may have started, with the value that behaves as samvg did
#: before they existed: a run file without them holds that value. (The finish pass's options
#: need no entry: they are compared only where the finish pass runs.)
_ADDED_SETTINGS: dict[str, Any] = {"lpips_colours": True, "gradient_ramp": 0.0}
#: Config fields that do not change results (paths, device) and so may differ on a rerun.
_FREE_SETTINGS = ("checkpoint", "lpips_weights", "device")


class BenchProgress(Protocol):
    """What the runner reports while it works (the CLI draws it as progress bars)."""

    def start(self, total: int) -> None: ...
    def begin(self, image_id: str, method: str) -> None: ...
    def stage(self, stage: str, done: int, total: int) -> None: ...
    def end(self, record: dict[str, Any]) -> None: ...


class _Silent:
    def start(self, total: int) -> None:
        pass

    def begin(self, image_id: str, method: str) -> None:
        pass

    def stage(self, stage: str, done: int, total: int) -> None:
        pass

    def end(self, record: dict[str, Any]) -> None:
        pass


@dataclass
class BenchOutcome:
    """How a run went: results made now, found from an earlier run, and failed now."""

    out: Path
    done: int = 0
    skipped: int = 0
    failed: int = 0


def load_target(path: Path, size: int) -> np.ndarray:
    """The image at ``path`` as float32 (H, W, 3) in [0, 1], longer side at most ``size``."""
    resized, _scale = resize_longest(read_image(path), size)
    return to_float_rgb(resized, str(path))


def plan_methods(names: Sequence[str], table: dict[str, Method] | None = None) -> list[Method]:
    """The methods to run, in order: samvg first whenever a method needs its path count
    (added if not asked for). Unknown or repeated names raise :class:`InputError`."""
    table = METHODS if table is None else table
    names = [name.strip() for name in names if name.strip()]
    if not names:
        raise InputError("no methods given")
    unknown = [name for name in names if name not in table]
    if unknown:
        raise InputError(f"unknown method(s) {', '.join(unknown)}; choose from {', '.join(table)}")
    if len(set(names)) != len(names):
        raise InputError(f"methods repeated: {', '.join(names)}")
    if any(table[name].needs_path_count for name in names) and "samvg" not in names:
        names = ["samvg", *names]
    ordered = sorted(names, key=lambda name: (name != "samvg", names.index(name)))
    return [table[name] for name in ordered]


def _settings(config: Config) -> dict[str, Any]:
    """The config as run.json keeps it (JSON values, so a reloaded copy compares equal)."""
    settings = config.as_dict()
    for name in _FREE_SETTINGS:
        settings.pop(name, None)
    return json.loads(json.dumps(settings, default=str))


def _check_settings(layout: Layout, settings: dict[str, Any]) -> None:
    if layout.run_file.is_file():
        try:
            earlier = json.loads(layout.run_file.read_text(encoding="utf-8"))["settings"]
        except (OSError, json.JSONDecodeError, KeyError, TypeError):
            raise InputError(f"{layout.run_file} is not a samvg-bench run file") from None
        earlier = {**_ADDED_SETTINGS, **earlier}
        inert = set()
        if not earlier.get("finish_pass", True) and not settings.get("finish_pass", True):
            inert = {field.name for field in dataclasses.fields(FinishOptions)} - {"finish_pass"}
        changed = sorted(
            key
            for key in set(earlier) | set(settings)
            if key not in inert and earlier.get(key) != settings.get(key)
        )
        if changed:
            detail = ", ".join(f"{k}: {earlier.get(k)!r} -> {settings.get(k)!r}" for k in changed)
            raise InputError(
                f"{layout.out} holds results made with other settings ({detail}); "
                "use another --out folder to run with these"
            )
    else:
        text = json.dumps({"settings": settings}, indent=2, sort_keys=True, default=str)
        atomic_write_text(layout.run_file, text + "\n")


def _add_command(layout: Layout, command: str) -> None:
    info = json.loads(layout.run_file.read_text(encoding="utf-8"))
    info["commands"] = [*info.get("commands", []), command]
    atomic_write_text(layout.run_file, json.dumps(info, indent=2, sort_keys=True) + "\n")


def _write_json(path: Path, data: dict[str, Any]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, json.dumps(data, indent=2, default=_json_default) + "\n")


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def write_results_csv(layout: Layout) -> None:
    """results.csv: one row per record (all images and methods in the folder), atomically."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=RECORD_FIELDS, extrasaction="ignore")
    writer.writeheader()
    for record in layout.records():
        row = dict(record)
        row["details"] = json.dumps(record.get("details", {}), sort_keys=True)
        writer.writerow({key: "" if row.get(key) is None else row[key] for key in RECORD_FIELDS})
    atomic_write_text(layout.results_csv, buffer.getvalue())


def _existing(layout: Layout, method: str, image_id: str) -> dict[str, Any] | None:
    path = layout.record(method, image_id)
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None


def _error_text(error: BaseException) -> str:
    text = str(error).strip() or "(no message)"
    return f"{type(error).__name__}: {text}"


def categories_in_turn(images: Sequence[BenchImage]) -> list[BenchImage]:
    """``images`` taking their categories in turn (the first of each, then the second ...), so
    that a run stopped part way has results in every category."""
    by_category: dict[str, list[BenchImage]] = {}
    for image in images:
        by_category.setdefault(image.category, []).append(image)
    rounds = itertools.zip_longest(*by_category.values())
    return [image for round_ in rounds for image in round_ if image is not None]


def run_bench(
    manifest: str | os.PathLike[str],
    out: str | os.PathLike[str],
    methods: Sequence[str] = DEFAULT_METHODS,
    *,
    size: int = 512,
    iterations: int | None = None,
    seed: int | None = None,
    limit: int | None = None,
    categories: Sequence[str] | None = None,
    retry_failed: bool = False,
    config: Config | None = None,
    lpips_weights: str | os.PathLike[str] | None = None,
    fid_weights: str | os.PathLike[str] | None = None,
    fid: bool = True,
    progress: BenchProgress | None = None,
    method_table: dict[str, Method] | None = None,
    report: bool = True,
    command: str | None = None,
) -> BenchOutcome:
    """Run ``methods`` on the manifest's images into ``out``, then write the report.

    Images take their categories in turn (`categories_in_turn`). ``config`` (default
    :class:`samvg.Config`) is used with ``size`` and, if given,
    ``iterations`` and ``seed``. Results already in ``out`` are kept and skipped (failed ones
    too unless ``retry_failed``); ``out`` must have been made with the same settings.
    ``command`` (the command line) is kept in run.json and shown in the summary; ``fid=False``
    leaves FID out of the report.
    """
    planned = plan_methods(methods, method_table)
    images = read_manifest(manifest, list(categories) if categories else None, limit)
    changes: dict[str, Any] = {"size": size}
    if iterations is not None:
        changes["iterations"] = iterations
    if seed is not None:
        changes["seed"] = seed
    config = (config or Config()).replace(**changes)
    layout = _open_layout(Path(out), config, command)
    reporter = progress or _Silent()
    outcome = BenchOutcome(out=layout.out)

    def pending(image: BenchImage, method: Method) -> bool:
        record = _existing(layout, method.name, image.id)
        return record is None or (retry_failed and record.get("status") != "ok")

    total = sum(pending(image, method) for image in images for method in planned)
    outcome.skipped = len(images) * len(planned) - total
    scorer = Scorer(lpips_weights) if total else None
    features = _feature_store(layout, fid_weights) if total and fid else None
    reporter.start(total)
    for image in categories_in_turn(images):
        todo = [method for method in planned if pending(image, method)]
        if todo:
            assert scorer is not None
            _run_image(image, todo, config, Scoring(scorer, features), layout, reporter, outcome)
    if report:
        write_results_csv(layout)
        write_report(layout.out, fid_weights=fid_weights, fid=fid)
    return outcome


def _open_layout(out: Path, config: Config, command: str | None) -> Layout:
    """The output folder, created, its run.json checked against ``config`` (or written)."""
    layout = Layout(out)
    try:
        layout.out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(f"cannot create output folder {layout.out}: {error}") from None
    _check_settings(layout, _settings(config))
    if command:
        _add_command(layout, command)
    return layout


def _feature_store(layout: Layout, weights: str | os.PathLike[str] | None) -> FeatureStore:
    """The run's FID feature store, its network loaded now: missing weights stop the run here."""
    try:
        return FeatureStore(layout, weights, load_now=True)
    except WeightsError as error:
        first = str(error).splitlines()[0]
        raise WeightsError(f"{first} (or pass --no-fid to run without FID)") from None


class Scoring(NamedTuple):
    """What scores a result: the per-image metrics, and the FID feature store (None without
    FID)."""

    scorer: Scorer
    features: FeatureStore | None


def _run_image(
    image: BenchImage,
    todo: Sequence[Method],
    config: Config,
    scoring: Scoring,
    layout: Layout,
    reporter: BenchProgress,
    outcome: BenchOutcome,
) -> None:
    """Run the ``todo`` methods on one image, writing each record as it finishes."""
    target: np.ndarray | None = None
    target_error: str | None = None
    try:
        target = load_target(image.png, config.size)
        if not layout.target(image.id).is_file():
            layout.target(image.id).parent.mkdir(parents=True, exist_ok=True)
            write_png(layout.target(image.id), target)
        if scoring.features is not None:
            scoring.features.save_target(image.id, target)
    except Exception as error:  # one bad image must not stop the run
        target_error = _error_text(error)
    target_complexity = None if target is None else _safe(Scorer.target_complexity, target)
    for method in todo:
        reporter.begin(image.id, method.name)
        record: dict[str, Any] = {
            "id": image.id,
            "category": image.category,
            "method": method.name,
            "status": "error",
        }
        if target is None:
            record["error"] = target_error
        else:
            record["target_complexity"] = target_complexity
            samvg_record = _existing(layout, "samvg", image.id) or {}
            count = samvg_record.get("paths") if samvg_record.get("status") == "ok" else None
            if method.needs_path_count and count is None:
                record["error"] = "no samvg result on this image to take the path count from"
            else:
                record.update(
                    _run_one(method, image, target, config, count, scoring, layout, reporter)
                )
        _write_json(layout.record(method.name, image.id), record)
        write_results_csv(layout)
        if record["status"] == "ok":
            outcome.done += 1
        else:
            outcome.failed += 1
        reporter.end(record)


def _safe(compute: Callable[[np.ndarray], float], image: np.ndarray) -> float | None:
    try:
        return compute(image)
    except Exception:  # a metric that fails leaves an empty cell
        return None


def _run_one(
    method: Method,
    image: BenchImage,
    target: np.ndarray,
    config: Config,
    count: int | None,
    scoring: Scoring,
    layout: Layout,
    reporter: BenchProgress,
) -> dict[str, Any]:
    """Run one method on one image; the record's fields, with the error if it failed."""
    job = MethodRun(
        target=target,
        config=config,
        path_count=count,
        image_id=image.id,
        progress=reporter.stage,
    )
    try:
        started = time.perf_counter()
        result: Vectorized = method.run(job)
        elapsed = time.perf_counter() - started
        svg = result.to_svg()
        render = result.render()
        if render.shape != target.shape:
            raise InputError(
                f"{method.name} rendered {render.shape[1]}x{render.shape[0]} pixels, "
                f"the target is {target.shape[1]}x{target.shape[0]}"
            )
        for path in (layout.svg(method.name, image.id), layout.render(method.name, image.id)):
            path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(layout.svg(method.name, image.id), svg)
        write_png(layout.render(method.name, image.id), render)
        fields: dict[str, Any] = {
            "status": "ok",
            "width": int(target.shape[1]),
            "height": int(target.shape[0]),
            "paths": path_count(result),
            "parameters": parameter_count(result),
            "svg_bytes": len(svg.encode("utf-8")),
            "time_s": round(elapsed, 3),
        }
        fields.update(scoring.scorer.score(render, target))
    except Exception as error:  # one failure must not stop the run
        job.details["traceback"] = traceback.format_exc(limit=8)
        return {"status": "error", "error": _error_text(error), "details": job.details}
    if scoring.features is not None:
        try:
            scoring.features.save_render(method.name, image.id, render)
        except Exception as error:  # FID then leaves this image out; the result stands
            job.details["fid_features_error"] = _error_text(error)
    fields["details"] = job.details
    return fields
