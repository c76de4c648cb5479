"""The benchmark's report from the records in an output folder: summary.md in the paper's layout
(rows = metrics, columns = methods) with a per-category breakdown and the failures, plots of time
and MSE against path count, and a contact sheet of targets next to each method's render."""

from __future__ import annotations

import io
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from samvg.bench.features import FeatureStore, fid_over_stored
from samvg.bench.layout import Layout
from samvg.bench.methods import DEFAULT_METHODS
from samvg.errors import InputError
from samvg.io import atomic_write_bytes, atomic_write_text, read_image


@dataclass(frozen=True)
class Row:
    """One metric row of the summary: label, record field, scale, format, lower is better."""

    label: str
    field: str
    scale: float = 1.0
    fmt: str = "{:.3f}"
    lower_is_better: bool = True


ROWS = (
    Row("MSE ×10⁻³ ↓", "mse", 1e3, "{:.2f}"),
    Row("PSNR (dB) ↑", "psnr", 1.0, "{:.2f}", lower_is_better=False),
    Row("SSIM ↑", "ssim", 1.0, "{:.3f}", lower_is_better=False),
    Row("LPIPS ↓", "lpips", 1.0, "{:.3f}"),
    Row("FID ↓", "fid", 1.0, "{:.2f}"),
    Row("Complexity ↓", "complexity", 1.0, "{:.2f}"),
    Row("Paths ↓", "paths", 1.0, "{:.2f}"),
    Row("Num of parameters ↓", "parameters", 1.0, "{:.0f}"),
    Row("SVG bytes ↓", "svg_bytes", 1.0, "{:.0f}"),
    Row("Time (s) ↓", "time_s", 1.0, "{:.2f}"),
)
#: Images shown on the contact sheet (the first common image of each category, in turn).
CONTACT_IMAGES = 6
#: Categories left off the contact sheet: the sheet is committed with the results, and copies of
#: the bench's photos and paintings (or renders traced from them) do not go into the repository.
CONTACT_SKIP_CATEGORIES = ("photo", "painting")

NOTES = """\
- Means over the images on which every method succeeded ("images" row); failures are listed
  below and left out of every mean.
- MSE is on RGB in [0, 1] (reported ×10⁻³); PSNR, SSIM and LPIPS (AlexNet) compare each render
  with the target at the working size. Complexity is the JPEG-based image complexity of
  Machado & Cardoso (see `samvg.metrics.complexity`) of the render; lower means simpler.
- FID (InceptionV3, pytorch-fid's weights) is over the whole set per method. On a few dozen
  images it is very noisy (the Inception feature covariance is rank-deficient): compare it only
  between methods on the same images, and not with FID values from other papers.
- Num of parameters: all coordinates and colour values, 6K + 4 per path of K cubic segments
  (34 for K = 5, the paper's count); a background colour is not counted. VTracer's count is
  every number in its path data and transforms plus 3 per fill colour.
- diffvg (random blobs) and live (layer-wise) use samvg's optimiser, losses and total iteration
  budget (both phases), the same path count as samvg on each image and a white background;
  LIVE's UDF-weighted loss is not used. VTracer's settings are searched per image to match
  samvg's path count and its time includes that search.
"""


def _method_order(records: list[dict[str, Any]]) -> list[str]:
    seen = list(dict.fromkeys(r["method"] for r in records))
    return [m for m in DEFAULT_METHODS if m in seen] + [m for m in seen if m not in DEFAULT_METHODS]


def _common_ids(records: list[dict[str, Any]], methods: list[str]) -> list[str]:
    ok: dict[str, set[str]] = {}
    for record in records:
        if record.get("status") == "ok":
            ok.setdefault(record["id"], set()).add(record["method"])
    return sorted(image for image, done in ok.items() if set(methods) <= done)


def _means(
    records: list[dict[str, Any]], methods: list[str], ids: set[str]
) -> dict[str, dict[str, float]]:
    table: dict[str, dict[str, float]] = {}
    for method in methods:
        chosen = [r for r in records if r["method"] == method and r["id"] in ids]
        table[method] = {}
        for row in ROWS:
            values = [r.get(row.field) for r in chosen]
            numbers = [float(v) for v in values if isinstance(v, (int, float))]
            finite = [v for v in numbers if math.isfinite(v)]
            table[method][row.field] = float(np.mean(finite)) if finite else float("nan")
    return table


def _markdown_table(
    table: dict[str, dict[str, float]], methods: list[str], count: int, skip: tuple[str, ...] = ()
) -> list[str]:
    lines = [
        "| Metrics | " + " | ".join(methods) + " |",
        "|---|" + "---:|" * len(methods),
    ]
    for row in ROWS:
        if row.field in skip:
            continue
        values = [table[m][row.field] * row.scale for m in methods]
        finite = [v for v in values if math.isfinite(v)]
        best = (min(finite) if row.lower_is_better else max(finite)) if finite else None
        cells = []
        for value in values:
            if not math.isfinite(value):
                cells.append("n/a")
                continue
            text = row.fmt.format(value)
            cells.append(f"**{text}**" if len(methods) > 1 and value == best else text)
        lines.append(f"| {row.label} | " + " | ".join(cells) + " |")
    lines.append("| images | " + " | ".join(str(count) for _ in methods) + " |")
    return lines


def _save_figure(figure: Any, path: Path) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: optional (bench extra)

    FigureCanvasAgg(figure)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=120, bbox_inches="tight")
    atomic_write_bytes(path, buffer.getvalue())


def _scatter(
    records: list[dict[str, Any]],
    methods: list[str],
    y_field: str,
    y_label: str,
    title: str,
    path: Path,
    scale: float = 1.0,
) -> None:
    from matplotlib.figure import Figure  # lazy: matplotlib is optional (bench extra)

    figure = Figure(figsize=(6.4, 4.4))
    axes = figure.add_subplot()
    markers = "os^Dvx*P"
    for index, method in enumerate(methods):
        points = [
            (r["paths"], r[y_field] * scale)
            for r in records
            if r["method"] == method and r.get("status") == "ok" and r.get(y_field) is not None
        ]
        if points:
            x, y = zip(*points, strict=True)
            axes.scatter(x, y, label=method, marker=markers[index % len(markers)], alpha=0.75)
    positive = [
        float(r[y_field]) * scale
        for r in records
        if r.get("status") == "ok" and isinstance(r.get(y_field), (int, float)) and r[y_field] > 0
    ]
    if positive and max(positive) > 100 * min(positive):
        axes.set_yscale("log")  # times of VTracer and the optimisers differ by orders
    axes.set_xlabel("paths")
    axes.set_ylabel(y_label)
    axes.set_title(title)
    if any(r.get("status") == "ok" for r in records):
        axes.legend()
    axes.grid(alpha=0.3)
    _save_figure(figure, path)


def _pictures(layout: Layout, methods: list[str], image: str) -> list[Path]:
    """The target's PNG, then each method's render of ``image``: one row of the contact sheet."""
    return [layout.target(image)] + [layout.render(method, image) for method in methods]


def _contact_sheet(
    layout: Layout, records: list[dict[str, Any]], methods: list[str], ids: list[str], path: Path
) -> None:
    from matplotlib.figure import Figure  # lazy: matplotlib is optional (bench extra)

    category = {r["id"]: r.get("category", "") for r in records}
    chosen: list[str] = []
    by_category: dict[str, list[str]] = {}
    for image in ids:
        if not all(picture.is_file() for picture in _pictures(layout, methods, image)):
            continue  # renders gone (not kept with committed results) or a run stopped part way
        if category[image] not in CONTACT_SKIP_CATEGORIES:
            by_category.setdefault(category[image], []).append(image)
    while len(chosen) < CONTACT_IMAGES and any(by_category.values()):
        for queue in by_category.values():
            if queue and len(chosen) < CONTACT_IMAGES:
                chosen.append(queue.pop(0))
    if not chosen:
        return
    columns = ["target", *methods]
    figure = Figure(figsize=(2.2 * len(columns), 2.3 * len(chosen)))
    for row, image in enumerate(chosen):
        pictures = _pictures(layout, methods, image)
        by_id = {r["method"]: r for r in records if r["id"] == image}
        for column, (name, picture) in enumerate(zip(columns, pictures, strict=True)):
            axes = figure.add_subplot(len(chosen), len(columns), row * len(columns) + column + 1)
            axes.imshow(read_image(picture))
            axes.set_xticks([])
            axes.set_yticks([])
            if column == 0:
                axes.set_ylabel(image, fontsize=7)
                axes.set_title("target" if row == 0 else "", fontsize=9)
            else:
                record = by_id[name]
                top = f"{name}\n" if row == 0 else ""
                axes.set_title(
                    f"{top}{record['paths']} paths, MSE {1e3 * record['mse']:.1f}e-3", fontsize=7
                )
    _save_figure(figure, path)


def write_report(
    out: str | os.PathLike[str],
    fid_weights: str | os.PathLike[str] | None = None,
    progress: Callable[[str], None] | None = None,
    fid: bool = True,
) -> Path:
    """Write summary.md, time_vs_paths.png, mse_vs_paths.png and contact_sheet.png into
    ``out`` from its records; returns the summary's path."""
    layout = Layout(Path(out))
    say = progress or (lambda _text: None)
    records = layout.records()
    if not records:
        raise InputError(f"{layout.out} holds no benchmark records")
    methods = _method_order(records)
    common = _common_ids(records, methods)
    say("FID")
    if fid:
        fid_values, problems = fid_over_stored(FeatureStore(layout, fid_weights), methods, common)
    else:
        fid_values, problems = {m: float("nan") for m in methods}, ["FID not computed (--no-fid)"]
    overall = _means(records, methods, set(common))
    for method in methods:
        overall[method]["fid"] = fid_values[method]
    lines = [
        *_header_lines(layout, records, common),
        *_markdown_table(overall, methods, len(common)),
        "",
        *_category_lines(records, methods, common),
        *_failure_lines(records),
        "## Notes",
        "",
        NOTES.rstrip(),
    ]
    if problems:
        lines += ["", *[f"- {problem}" for problem in problems]]
    lines += [
        "",
        "Plots: `time_vs_paths.png`, `mse_vs_paths.png`; renders: `contact_sheet.png`;",
        "per-image values: `results.csv`.",
        "",
    ]
    summary = layout.out / "summary.md"
    atomic_write_text(summary, "\n".join(lines))
    say("plots")
    _scatter(
        records,
        methods,
        "time_s",
        "time (s)",
        "Time vs number of paths",
        layout.out / "time_vs_paths.png",
    )
    _scatter(
        records,
        methods,
        "mse",
        "MSE ×10⁻³",
        "MSE vs number of paths",
        layout.out / "mse_vs_paths.png",
        scale=1e3,
    )
    _contact_sheet(layout, records, methods, common, layout.out / "contact_sheet.png")
    return summary


def _header_lines(layout: Layout, records: list[dict[str, Any]], common: list[str]) -> list[str]:
    """The summary's title, command, settings and count, up to the overall table."""
    all_ids = sorted({r["id"] for r in records})
    lines = ["# samvg-bench summary", ""]
    run_info = _run_info(layout)
    if run_info.get("commands"):
        lines += ["Made by:", "", "```", run_info["commands"][-1], "```", ""]
    settings = run_info.get("settings", {})
    if settings:
        keys = ("size", "iterations", "segments", "use_lpips", "seed")
        shown = ", ".join(f"{k}={settings[k]}" for k in keys if k in settings)
        lines += [f"Settings: {shown}.", ""]
    return [
        *lines,
        f"{len(common)} of {len(all_ids)} images have results from every method.",
        "",
        "## All images",
        "",
    ]


def _category_lines(
    records: list[dict[str, Any]], methods: list[str], common: list[str]
) -> list[str]:
    """One table per category (without FID), over its images with every method's result."""
    lines = ["## By category (FID left out: too few images per category)", ""]
    categories = sorted({r.get("category", "") for r in records})
    for name in categories:
        ids = {r["id"] for r in records if r.get("category", "") == name} & set(common)
        lines += [f"### {name}", ""]
        if not ids:
            lines += ["No image with results from every method.", ""]
            continue
        table = _means(records, methods, ids)
        lines += [*_markdown_table(table, methods, len(ids), skip=("fid",)), ""]
    return lines


def _failure_lines(records: list[dict[str, Any]]) -> list[str]:
    """The failures section: one table row per failed record (its error's first line)."""
    failures = [r for r in records if r.get("status") != "ok"]
    lines = ["## Failures", ""]
    if failures:
        lines += ["| image | method | error |", "|---|---|---|"]
        for record in failures:
            error = str(record.get("error", "")).splitlines()[0].replace("|", "\\|")
            lines.append(f"| {record['id']} | {record['method']} | {error} |")
    else:
        lines.append("None.")
    return [*lines, ""]


def _run_info(layout: Layout) -> dict[str, Any]:
    try:
        return json.loads(layout.run_file.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return {}
