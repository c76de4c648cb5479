"""The report of ``bench_detail.py``: the default against VTracer's default settings, samvg at
fixed budgets against the baselines, and the rate-distortion plot for photos and paintings."""

from __future__ import annotations

import json
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from bench_images import REPO

from samvg.io import atomic_write_text

REPORT = REPO / "benchmarks/results/detail.md"
PLOT = REPO / "benchmarks/results/detail_rate.png"
FLAT_ART = ("emoji", "icon", "clipart", "digital_art")
CATEGORIES = (*FLAT_ART, "photo", "painting")
LPIPS_SLACK = 0.01
BYTES_SHARE = 1 / 3


def _records(folder: Path, pattern: str) -> list[dict[str, Any]]:
    return [json.loads(path.read_text()) for path in sorted(folder.glob(pattern))]


def _mean(rows: list[dict[str, Any]], key: str) -> float:
    return float(np.mean([row[key] for row in rows]))


def default_table(geometry: Path) -> list[str]:
    """samvg's default against VTracer's default settings, per category."""
    rows = [r for r in _records(geometry, "*.default.json") if "vtracer_mse" in r]
    lines = [
        f"## The default against VTracer's default settings ({len(rows)} of 75 images)",
        "",
        f"Records in `{_shown(geometry)}` from `python benchmarks/bench_geometry.py --settings "
        "default` (which also counts "
        "the geometry of issue 12, see `geometry.md`). A *win* is MSE ≤ VTracer's, LPIPS ≤ "
        f"VTracer's + {LPIPS_SLACK} and SVG bytes ≤ {BYTES_SHARE:.2f} × VTracer's (the issue's "
        "goal: wins on ≥ 80 % of the emoji, icon, clipart and digital-art images).",
        "",
        "| category | images | samvg paths | VTracer paths | samvg bytes | VTracer bytes | "
        "samvg MSE ×1e-3 | VTracer MSE ×1e-3 | samvg LPIPS | VTracer LPIPS | MSE ≤ | "
        "LPIPS ≤ +0.01 | bytes ≤ 1/3 | wins | samvg s/image |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        groups[row["category"]].append(row)
        if row["category"] in FLAT_ART:
            groups["flat art (4 categories)"].append(row)
        groups["all"].append(row)
    for name in (*CATEGORIES, "flat art (4 categories)", "all"):
        group = groups.get(name)
        if not group:
            continue
        mse = sum(r["mse"] <= r["vtracer_mse"] for r in group)
        lpips = sum(r["lpips"] <= r["vtracer_lpips"] + LPIPS_SLACK for r in group)
        small = sum(r["svg_bytes"] <= BYTES_SHARE * r["vtracer_bytes"] for r in group)
        wins = sum(
            r["mse"] <= r["vtracer_mse"]
            and r["lpips"] <= r["vtracer_lpips"] + LPIPS_SLACK
            and r["svg_bytes"] <= BYTES_SHARE * r["vtracer_bytes"]
            for r in group
        )
        count = len(group)
        lines.append(
            f"| {name} | {count} | {_mean(group, 'paths'):.1f} | "
            f"{_mean(group, 'vtracer_paths'):.1f} | {_mean(group, 'svg_bytes'):.0f} | "
            f"{_mean(group, 'vtracer_bytes'):.0f} | {1e3 * _mean(group, 'mse'):.2f} | "
            f"{1e3 * _mean(group, 'vtracer_mse'):.2f} | {_mean(group, 'lpips'):.3f} | "
            f"{_mean(group, 'vtracer_lpips'):.3f} | {mse}/{count} | {lpips}/{count} | "
            f"{small}/{count} | **{wins}/{count}** ({wins / count:.0%}) | "
            f"{_mean(group, 'seconds'):.1f} |"
        )
    return lines


def budget_tables(
    records: list[dict[str, Any]], folder: Path, fallback: Sequence[Path] = ()
) -> list[str]:
    """Per budget and category: each method's means, and samvg's wins against each baseline
    (lower MSE and lower LPIPS on the same image). samvg is its default (gradient fills) where
    those records exist, else flat fills."""
    rows = [r for r in records if r.get("study") == "budget"]
    subject = _subject(rows)
    by_key: dict[tuple[int, str], dict[str, dict[str, Any]]] = defaultdict(dict)
    for row in rows:
        by_key[(row["budget"], row["id"])][row["method"]] = row
    lines = [
        "## Equal budgets",
        "",
        "`python benchmarks/bench_detail.py budget --per-category 4 --paths 16,64,256 --methods "
        f"samvg-gradients,vtracer,live,diffvg --records {_shown(folder)}`: samvg "
        f"(`{subject}`: "
        + ("the default, gradient fills" if subject != "samvg" else "flat fills")
        + ") with `--paths N`; VTracer with its settings searched for the most paths not over N "
        "(`samvg.baselines.vtracer_trace`); *paths* counts `<path>` elements and *shapes* "
        "their subpaths: a compound path (VTracer's with holes or several islands, samvg's "
        "pieces of a crossing path that the finish pass repaired) is one path but several "
        "closed shapes, where every LIVE and DiffVG path is one closed shape; the LIVE-style "
        "baseline and random init (diffvg) "
        f"fitted with samvg's losses for {2 * 500} steps. Means over the images that have every "
        "method's record; *wins* = images where samvg has lower MSE **and** lower LPIPS than "
        "that method (the goal: ≥ 90 % in every category)."
        + (
            " Records that folder lacks come from "
            + ", then ".join(f"`{_shown(folder)}`" for folder in fallback)
            + " (`--fallback`)."
            if fallback
            else ""
        ),
    ]
    lines += _wins_summary(by_key, subject)
    for budget in sorted({b for b, _ in by_key}):
        complete = {i: m for (b, i), m in by_key.items() if b == budget and subject in m}
        methods = sorted({name for m in complete.values() for name in m} - {"samvg", subject})
        lines += [
            "",
            f"### N = {budget}",
            "",
            "| category | images | method | paths | shapes | MSE ×1e-3 | LPIPS | bytes | s "
            "| samvg wins |",
            "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|",
        ]
        by_category: dict[str, list[dict[str, dict[str, Any]]]] = defaultdict(list)
        for found in complete.values():
            by_category[found[subject]["category"]].append(found)
            by_category["all"].append(found)
        for category in (*CATEGORIES, "all"):
            for method in [subject, *methods]:
                lines += _budget_row(category, by_category.get(category, []), subject, method)
    return lines


def _wins_summary(
    by_key: dict[tuple[int, str], dict[str, dict[str, Any]]], subject: str
) -> list[str]:
    """One table of samvg's wins: a row per category, a column per budget and baseline."""
    columns = sorted(
        {(b, name) for (b, _), found in by_key.items() if subject in found for name in found}
        - {(b, name) for b, _ in by_key for name in ("samvg", subject)}
    )
    header = " | ".join(f"N={b} vs {name}" for b, name in columns)
    lines = ["", "samvg's wins, per category and budget:", ""]
    lines += [f"| category | {header} |", "|---|" + "---:|" * len(columns)]
    for category in (*CATEGORIES, "all"):
        cells = []
        for budget, method in columns:
            pairs = [
                found
                for (b, _), found in by_key.items()
                if b == budget and subject in found and method in found
                and category in ("all", found[subject]["category"])
            ]  # fmt: skip
            won = sum(
                m[subject]["mse"] < m[method]["mse"] and m[subject]["lpips"] < m[method]["lpips"]
                for m in pairs
            )
            cells.append(f"{won}/{len(pairs)}" if pairs else "")
        if any(cells):
            lines.append(f"| {category} | " + " | ".join(cells) + " |")
    return lines


def _shown(folder: Path) -> str:
    """``folder`` relative to the repository where it lies inside it."""
    return str(folder.relative_to(REPO)) if folder.is_relative_to(REPO) else str(folder)


def _budget_row(
    category: str, found: list[dict[str, dict[str, Any]]], subject: str, method: str
) -> list[str]:
    """One table row: ``method``'s means over the images of ``found`` that have its record,
    and samvg's wins against it there."""
    images = [m for m in found if method in m]
    if not images:
        return []
    group = [m[method] for m in images]
    wins = ""
    if method != subject:
        won = sum(
            m[subject]["mse"] < m[method]["mse"] and m[subject]["lpips"] < m[method]["lpips"]
            for m in images
        )
        wins = f"{won}/{len(images)} ({won / len(images):.0%})"
    shapes = f"{_mean(group, 'shapes'):.1f}" if all("shapes" in r for r in group) else ""
    return [
        f"| {category} | {len(images)} | {method} | {_mean(group, 'paths'):.1f} | {shapes} | "
        f"{1e3 * _mean(group, 'mse'):.2f} | {_mean(group, 'lpips'):.3f} | "
        f"{_mean(group, 'svg_bytes'):.0f} | {_mean(group, 'seconds'):.1f} | {wins} |"
    ]


def gradient_table(records: list[dict[str, Any]]) -> list[str]:
    """samvg with gradient fills against flat fills at the same budget (issue 13)."""
    pairs: dict[tuple[int, str], dict[str, dict[str, Any]]] = defaultdict(dict)
    for row in records:
        if row.get("study") == "budget" and row["method"] in ("samvg", "samvg-gradients"):
            pairs[(row["budget"], row["id"])][row["method"]] = row
    complete = [(b, p) for (b, _), p in pairs.items() if len(p) == 2]
    if not complete:
        return []
    lines = [
        "",
        "## Gradient fills against flat fills at equal budgets (issue 13)",
        "",
        "`samvg --paths N --gradients` against `samvg --paths N` (flat fills), same images. "
        "*better* = "
        "images where gradients give lower MSE **and** lower LPIPS. "
        + _settings_note([r for _, p in complete for r in p.values()]),
        "",
        "| N | category | images | flat paths | gradients paths (gradient fills) | flat MSE ×1e-3 "
        "| gradients MSE ×1e-3 | flat LPIPS | gradients LPIPS | flat bytes | gradients bytes "
        "| better |",
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for budget in sorted({b for b, _ in complete}):
        for category in (*CATEGORIES, "all"):
            group = [
                p
                for b, p in complete
                if b == budget and category in ("all", p["samvg"]["category"])
            ]
            if not group:
                continue
            flat = [p["samvg"] for p in group]
            shaded = [p["samvg-gradients"] for p in group]
            better = sum(
                s["mse"] < f["mse"] and s["lpips"] < f["lpips"]
                for f, s in zip(flat, shaded, strict=True)
            )
            fills = (
                _mean(shaded, "gradient_fills")
                if all("gradient_fills" in r for r in shaded)
                else float("nan")
            )
            lines.append(
                f"| {budget} | {category} | {len(group)} | {_mean(flat, 'paths'):.1f} | "
                f"{_mean(shaded, 'paths'):.1f} ({fills:.1f}) | {1e3 * _mean(flat, 'mse'):.2f} | "
                f"{1e3 * _mean(shaded, 'mse'):.2f} | {_mean(flat, 'lpips'):.3f} | "
                f"{_mean(shaded, 'lpips'):.3f} | {_mean(flat, 'svg_bytes'):.0f} | "
                f"{_mean(shaded, 'svg_bytes'):.0f} | {better}/{len(group)} |"
            )
    return lines


def _settings_note(rows: list[dict[str, Any]]) -> str:
    """Which samvg settings the runs used besides the default (``bench_detail.py --set``)."""
    found = sorted({json.dumps(row.get("overrides") or {}, sort_keys=True) for row in rows})
    if found == ["{}"]:
        return "Default settings."
    return (
        "Settings besides the default, the same for both: "
        + "; ".join(f"`{text}`" for text in found)
        + "."
    )


def rate_plot(records: list[dict[str, Any]], budget_records: list[dict[str, Any]]) -> list[str]:
    """Mean MSE and LPIPS against mean SVG bytes for photos and paintings: samvg at each
    budget of the equal-budget study, VTracer at each setting of its sweep (``bench_detail.py
    rate``), over the images that have every point."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves: dict[str, dict[str, dict[str, dict[str, Any]]]] = defaultdict(lambda: defaultdict(dict))
    for row in records:
        if row.get("study") == "rate" and row["method"] == "vtracer":
            curves["vtracer (settings)"][row["setting"]][row["id"]] = row
    budget_rows = [r for r in budget_records if r.get("study") == "budget"]
    subject = _subject(budget_rows)
    for row in budget_rows:
        if row["method"] == subject and row["category"] in ("photo", "painting"):
            curves[f"{subject} (--paths N)"][str(row["budget"])][row["id"]] = row
    if len(curves) < 2:
        return []
    common = set.intersection(*(set(g) for s in curves.values() for g in s.values()))
    if not common:
        return []
    figure, axes = plt.subplots(1, 2, figsize=(10, 4))
    lines = [
        "",
        "## Rate-distortion, photos and paintings",
        "",
        f"{len(common)} images: samvg at each budget of the equal-budget study above (default "
        "settings), VTracer at five settings (filter_speckle, color_precision, layer_difference; "
        "`python benchmarks/bench_detail.py rate --per-category 4`, 4-6-16 is its default). "
        "Means over the same images at every point; lower is better on both axes.",
        "",
        f"![rate]({PLOT.name})",
        "",
        "| method | setting | images | paths | bytes | MSE ×1e-3 | LPIPS |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for method, settings in sorted(curves.items()):
        points = []
        for setting, by_id in settings.items():
            group = [by_id[i] for i in sorted(common)]
            points.append(
                (_mean(group, "svg_bytes"), _mean(group, "mse"), _mean(group, "lpips"), setting,
                 _mean(group, "paths"))
            )  # fmt: skip
        points.sort()
        for size, mse, lpips, setting, paths in points:
            lines.append(
                f"| {method} | {setting} | {len(common)} | {paths:.0f} | {size:.0f} | "
                f"{1e3 * mse:.2f} | {lpips:.3f} |"
            )
        sizes = [p[0] for p in points]
        axes[0].plot(sizes, [p[1] for p in points], "o-", label=method)
        axes[1].plot(sizes, [p[2] for p in points], "o-", label=method)
    for axis, name in zip(axes, ("MSE", "LPIPS"), strict=True):
        axis.set_xscale("log")
        axis.set_xlabel("SVG bytes (mean)")
        axis.set_ylabel(name)
        axis.legend()
    figure.tight_layout()
    figure.savefig(PLOT, dpi=100)
    return lines


def _subject(rows: list[dict[str, Any]]) -> str:
    """samvg's method in budget records: its default (gradient fills) where those records
    exist, else flat fills."""
    return "samvg-gradients" if any(r["method"] == "samvg-gradients" for r in rows) else "samvg"


def with_fallback(records: list[dict[str, Any]], fallback: Sequence[Path]) -> list[dict[str, Any]]:
    """``records`` and the budget records of the ``fallback`` folders, in order, for the
    (image, method, budget) they lack (an older commit's baselines, or budgets not rerun)."""
    records = list(records)
    for folder in fallback:
        have = {(r["id"], r["method"], r.get("budget")) for r in records}
        records += [
            r
            for r in _records(folder, "*.json")
            if (r["id"], r["method"], r.get("budget")) not in have
        ]
    return records


def write_report(
    records_folder: Path,
    geometry: list[Path],
    budget_folder: Path | None = None,
    fallback: Sequence[Path] = (),
) -> None:
    """detail.md from the records: the default against VTracer (a table per folder of
    ``geometry``), the equal-budget
    tables (``budget_folder``, else the budget records of ``records_folder``), the gradient
    table (``records_folder``) and the rate-distortion plot (samvg from the budget records,
    VTracer's sweep from ``records_folder``)."""
    records = _records(records_folder, "*.json")
    budget_folder = budget_folder or records_folder
    budget_records = with_fallback(_records(budget_folder, "*.json"), fallback)
    lines = [
        "# Detail at any path budget (issue 11)",
        "",
        "All images at 512 px on this machine (2 cores, shared); MSE and LPIPS (AlexNet) at the "
        "working size; SVG bytes as written.",
        "",
        *[line for folder in geometry for line in (*default_table(folder), "")],
        "",
        *budget_tables(budget_records, budget_folder, fallback),
        *gradient_table(records),
        *rate_plot(records, budget_records),
    ]
    atomic_write_text(REPORT, "\n".join(lines) + "\n")
    print(f"wrote {REPORT}")
