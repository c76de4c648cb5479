"""Clean geometry on the bench (issue 12): self-intersecting paths, control points outside the
canvas, translucent fills, parameters per path, SVG bytes, MSE and LPIPS; the default settings
against fixed 5 segments per path at the same path count.

    python benchmarks/bench_geometry.py --settings default             # all 75 images, resumes
    python benchmarks/bench_geometry.py --per-category 4 --settings default,fixed5
    python benchmarks/bench_geometry.py --report-only

Each image's result is a JSON file in ``--out`` (a rerun skips what is there), and the report
goes to ``benchmarks/results/geometry.md``. The checks are independent of the finish pass: every
output path is flattened and tested with shapely in the SVG's own (input) pixels.
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from bench_images import REPO, bench_entries, run_samvg, setting_value, vtracer_default

import samvg
from samvg.baselines import count_paths, render_svg
from samvg.finish import flatten_paths
from samvg.io import atomic_write_text
from samvg.metrics import load_lpips, lpips_distance
from samvg.scene import Scene

OUTSIDE_FRACTION = 0.05


def geometry_checks(scene: Scene, opaque_input: bool) -> dict[str, Any]:
    """Counts of self-intersecting paths, points far outside the canvas, translucent fills."""
    margin = OUTSIDE_FRACTION * max(scene.width, scene.height)
    low, high = -margin, np.array([scene.width + margin, scene.height + margin])
    crossing = outside_points = outside_paths = 0
    vertices, vertex_offsets = flatten_paths(scene.points, scene.offsets)
    for index, (points, _paint) in enumerate(scene.paths()):
        ring = vertices[vertex_offsets[index] : vertex_offsets[index + 1]]
        if (
            len(np.unique(np.round(ring, 6), axis=0)) >= 3
            and not shapely.LinearRing(ring).is_simple
        ):
            crossing += 1
        far = np.any((points < low) | (points > high), axis=1)
        outside_points += int(far.sum())
        outside_paths += int(far.any())
    translucent = sum(paint.rgba[3] < 1.0 for paint in scene.paints)
    counts = scene.segment_counts()
    return {
        "paths": scene.path_count,
        "self_intersecting": crossing,
        "outside_points": outside_points,
        "outside_paths": outside_paths,
        "translucent": int(translucent) if opaque_input else None,
        "segments_mean": float(counts.mean()) if len(counts) else 0.0,
        "parameters": scene.parameter_count,
    }


def run_one(
    entry: dict[str, str],
    config: samvg.Config,
    lpips: Any,
    with_vtracer: bool = False,
    keep_svg: Path | None = None,
) -> dict[str, Any]:
    """One image's record; with ``keep_svg``, samvg's SVG is also written there as
    ``<id>.svg`` (for a contact sheet without reruns)."""
    run = run_samvg(entry, config)
    render = run.render()
    svg_text = run.result.image.to_svg()
    if keep_svg is not None:
        keep_svg.mkdir(parents=True, exist_ok=True)
        atomic_write_text(keep_svg / f"{entry['id']}.svg", svg_text)
    written = samvg.VectorImage.from_svg(svg_text)  # what the SVG file holds
    record = geometry_checks(written.scene, opaque_input=True)
    record.update(
        id=entry["id"],
        category=entry["category"],
        svg_bytes=len(svg_text.encode()),
        mse=float(np.mean((render - run.target) ** 2)),
        lpips=lpips_distance(lpips, render, run.target),
        seconds=run.seconds,
        idle_removed=run.result.counts.get("idle_removed", 0),
        whole_pixel_paths=run.result.counts.get("whole_pixel_paths", 0),
        gradients_flattened=run.result.counts.get("gradients_flattened", 0),
    )
    if with_vtracer:  # VTracer's default settings on the same working image
        svg = vtracer_default(run.working)
        theirs = np.clip(render_svg(svg, render.shape[1], render.shape[0]), 0, 1)
        record.update(
            vtracer_paths=count_paths(svg),
            vtracer_bytes=len(svg.encode()),
            vtracer_mse=float(np.mean((theirs - run.target) ** 2)),
            vtracer_lpips=lpips_distance(lpips, theirs, run.target),
        )
    return record


def configs(name: str, paths: int | None, overrides: dict[str, Any] | None = None) -> samvg.Config:
    overrides = overrides or {}
    if name == "default":
        return samvg.Config(**overrides)
    if name == "fixed5":
        return samvg.Config(segments=5, max_paths=paths, **overrides)
    raise SystemExit(f"unknown setting {name!r}")


def run_all(
    entries: list[dict[str, str]],
    out: Path,
    names: list[str],
    keep_svg: Path | None = None,
    overrides: dict[str, Any] | None = None,
) -> None:
    out.mkdir(parents=True, exist_ok=True)
    lpips = load_lpips()
    for entry in entries:
        for name in names:
            record_file = out / f"{entry['id']}.{name}.json"
            if record_file.exists():
                continue
            paths = None
            if name != "default":
                reference = out / f"{entry['id']}.default.json"
                if not reference.exists():
                    continue
                paths = json.loads(reference.read_text())["paths"]
            config = configs(name, paths, overrides)
            kept = keep_svg / name if keep_svg is not None else None
            record = run_one(entry, config, lpips, with_vtracer=name == "default", keep_svg=kept)
            record["setting"] = name
            if overrides:
                record["overrides"] = overrides
            atomic_write_text(record_file, json.dumps(record, indent=1))
            print(json.dumps(record), flush=True)


def _table(records: list[dict[str, Any]], names: list[str]) -> list[str]:
    lines = [
        "| category | setting | images | paths | segments/path | parameters/path | SVG bytes | "
        "MSE ×1e-3 | LPIPS | self-intersecting | points >5% outside | translucent | s/image |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    groups: dict[tuple[str, str], list[dict[str, Any]]] = defaultdict(list)
    for record in records:
        groups[(record["category"], record["setting"])].append(record)
        groups[("all", record["setting"])].append(record)
    categories = sorted({category for category, _ in groups} - {"all"}) + ["all"]
    for category in categories:
        for name in names:
            rows = groups.get((category, name))
            if not rows:
                continue
            per_path = sum(r["parameters"] for r in rows) / max(sum(r["paths"] for r in rows), 1)

            def mean(key: str, rows: list[dict[str, Any]] = rows) -> float:
                return float(np.mean([r[key] for r in rows]))

            lines.append(
                f"| {category} | {name} | {len(rows)} | {mean('paths'):.1f} | "
                f"{mean('segments_mean'):.2f} | {per_path:.1f} | "
                f"{mean('svg_bytes'):.0f} | {1e3 * mean('mse'):.2f} | {mean('lpips'):.3f} | "
                f"{sum(r['self_intersecting'] for r in rows)} | "
                f"{sum(r['outside_points'] for r in rows)} | "
                f"{sum(r['translucent'] or 0 for r in rows)} | {mean('seconds'):.1f} |"
            )
    return lines


def write_report(out: Path, names: list[str], report: Path) -> None:
    records = [json.loads(p.read_text()) for p in sorted(out.glob("*.json"))]
    records = [r for r in records if r["setting"] in names]
    settings_of: dict[str, set[str]] = defaultdict(set)
    for record in records:
        settings_of[record["id"]].add(record["setting"])
    paired = [r for r in records if settings_of[r["id"]] >= set(names)]
    defaults = [r for r in records if r["setting"] == "default"]
    lines = [
        "# Clean geometry (issue 12)",
        "",
        "`python benchmarks/bench_geometry.py --settings default` (two workers: `--shard 0/2` "
        "and `--shard 1/2`) on all of `../shared/bench` at 512 px; records in "
        "`benchmarks/results/geometry/`, each with VTracer's default settings measured on the "
        "same working image (used by `detail.md`). "
        "*default*: the product default (colour-coherent parts, stage-4 rounds until the "
        "`--detail` tolerance, adaptive segments, opaque fills, bounded points, finish pass). "
        "*fixed5*: the same with 5 segments per path when traced and `--max-paths` set to "
        "the default's path count (an upper bound: it ends with fewer paths on its own; the "
        "finish pass then redraws repaired outlines, so its segment counts drift from 5). "
        "Counts are totals over the images; other columns are means. "
        "Self-intersection is tested with shapely on each path of the written SVG (read back, "
        "coordinates rounded as saved), flattened to 0.1 px; outside = more than "
        f"{OUTSIDE_FRACTION:.0%} of the longer side beyond the canvas.",
        "",
        f"## The default on {len(defaults)} of the 75 images",
        "",
        *_table(defaults, ["default"]),
    ]
    if len(names) > 1:
        lines += [
            "",
            f"## Default against fixed5 on the {len(paired) // len(names)} images with both",
            "",
            *_table(paired, names),
        ]
    else:
        lines += [
            "",
            "The comparison with fixed 5 segments per path at equal path counts was measured "
            "on 24 images at commit 955dc51 (the default before colour parts and stage-4 "
            "rounds): `geometry_955dc51.md`, records in `geometry/955dc51/`.",
        ]
    wins: defaultdict[str, int] = defaultdict(int)
    by_id: dict[str, dict[str, dict[str, Any]]] = defaultdict(dict)
    for record in paired:
        by_id[record["id"]][record["setting"]] = record
    both = [v for v in by_id.values() if "default" in v and "fixed5" in v]
    for pair in both:
        wins["mse"] += pair["default"]["mse"] <= pair["fixed5"]["mse"]
        wins["lpips"] += pair["default"]["lpips"] <= pair["fixed5"]["lpips"]
    if both:
        lines += [
            "",
            f"Default against fixed5 on {len(both)} images: MSE lower or equal on "
            f"{wins['mse']}, LPIPS lower or equal on {wins['lpips']}.",
        ]
    atomic_write_text(report, "\n".join(lines) + "\n")
    print(f"wrote {report}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks/results/geometry")
    parser.add_argument("--per-category", type=int)
    parser.add_argument("--categories", help="comma-separated (default: all six)")
    parser.add_argument("--settings", default="default,fixed5")
    parser.add_argument("--report", type=Path, default=REPO / "benchmarks/results/geometry.md")
    parser.add_argument("--report-only", action="store_true")
    parser.add_argument(
        "--shard", default="0/1", help="i/n: run only every n-th image from the i-th (workers)"
    )
    parser.add_argument(
        "--keep-svg", type=Path, help="also write samvg's SVGs to <this folder>/<setting>/"
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a samvg setting for every run (kept in each record), e.g. lpips_colours=false",
    )
    arguments = parser.parse_args()
    overrides = {}
    for text in arguments.set:
        name, _, value = text.partition("=")
        overrides[name] = setting_value(value)
    names = arguments.settings.split(",")
    shard, shards = (int(part) for part in arguments.shard.split("/"))
    if not arguments.report_only:
        categories = arguments.categories.split(",") if arguments.categories else None
        entries = bench_entries(arguments.per_category, categories)[shard::shards]
        run_all(entries, arguments.out, names, arguments.keep_svg, overrides)
    write_report(arguments.out, names, arguments.report)


if __name__ == "__main__":
    main()
