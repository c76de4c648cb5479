"""Benchmark of adaptive segment counts in samvg.trace: a tolerance (px) against fixed K.

For one bench image per category (the first of each in ../shared/bench/manifest.csv, at most
512 px a side), SAM's automatic masks (``Segmenter(Config().segment).automatic``) are traced
with a fixed K in (3, 4, 5, 8) segments per path and with a tolerance in (0.5, 1, 2, 3) px
(``trace_masks_with_info(..., tolerance=t)``). Per setting: segments per path (mean, median,
max), parameters per path (6K + 4: 3K control points and a colour with alpha), IoU of each path
rendered by ``samvg.render`` (coverage > 0.5) against its mask component (holes filled, as the
tracer models it; mean, pooled over all pixels, worst), the share of paths within the
tolerance, and the time of one ``trace_masks_with_info`` call per image (median, summed).

Also: synthetic shapes (segments per shape at each tolerance), and the alternative design the
tracer does not use, "re-select": trace every mask at K = 1, 2, ... with the fixed-K tracer
(global corner selection) and keep each component's first K within the tolerance.

Usage: python benchmarks/bench_trace_tolerance.py [--points P] [--repeats N] [--out FILE]
(SAMVG_SAM_CHECKPOINT names the MobileSAM weights if they are not in the cache.)
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage

from samvg import Config
from samvg.trace import (
    DEFAULT_MAX_SEGMENTS,
    DEFAULT_MIN_AREA,
    TracedPath,
    find_components,
    trace_components,
    trace_masks_with_info,
)

REPO = Path(__file__).resolve().parents[1]
# The synthetic masks and the coverage renderer live with the tests (tests/trace/synthetic.py).
sys.path.insert(0, str(REPO))
from tests.trace.synthetic import SHAPES, render_coverage  # noqa: E402

BENCH = REPO.parent / "shared" / "bench"
FIXED = (3, 4, 5, 8)
TOLERANCES = (0.5, 1.0, 2.0, 3.0)
SIDE = 512


@dataclass
class Picture:
    category: str
    name: str
    image: np.ndarray
    masks: list[np.ndarray]
    targets: list[list[tuple[np.ndarray, tuple[slice, slice]]]]  # per mask, per component


@dataclass
class Row:
    label: str
    tolerance: float | None
    counts: list[int]
    errors: list[float]
    ious: list[float]
    inter: int
    union: int
    seconds: float
    per_category: dict[str, tuple[float, float]]


def component_targets(mask: np.ndarray) -> list[tuple[np.ndarray, tuple[slice, slice]]]:
    """Each traced component of the mask, holes filled, with its box in the canvas."""
    found = find_components(mask, DEFAULT_MIN_AREA)
    top, left = found.origin
    targets = []
    for label, (rows, cols) in zip(found.ids, found.boxes, strict=True):
        filled = ndimage.binary_fill_holes(found.labels[rows, cols] == label)
        box = (
            slice(top + rows.start, top + rows.stop),
            slice(left + cols.start, left + cols.stop),
        )
        targets.append((filled, box))
    return targets


def path_iou(
    points: np.ndarray, target: np.ndarray, box: tuple[slice, slice], shape: tuple[int, ...]
) -> tuple[int, int]:
    """(intersection, union) of the rendered path and its component, on a crop that holds both
    (the curve lies in its control points' hull)."""
    height, width = shape
    top = max(0, min(box[0].start, int(np.floor(points[:, 1].min()))))
    left = max(0, min(box[1].start, int(np.floor(points[:, 0].min()))))
    bottom = min(height, max(box[0].stop, int(np.ceil(points[:, 1].max()))))
    right = min(width, max(box[1].stop, int(np.ceil(points[:, 0].max()))))
    inside = render_coverage([points - [left, top]], right - left, bottom - top) > 0.5
    mask = np.zeros_like(inside)
    mask[box[0].start - top : box[0].stop - top, box[1].start - left : box[1].stop - left] = target
    return int((inside & mask).sum()), int((inside | mask).sum())


def load_pictures(points: int) -> list[Picture]:
    import torch

    from samvg.segment import Segmenter

    torch.set_num_threads(1)  # two threads stall each other on a small shared machine
    with (BENCH / "manifest.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    first: dict[str, dict[str, str]] = {}
    for row in rows:
        first.setdefault(row["category"], row)
    segmenter = Segmenter(Config(points_per_side=points).segment)
    pictures = []
    for category, row in sorted(first.items()):
        photo = Image.open(BENCH / row["png"]).convert("RGB")
        photo.thumbnail((SIDE, SIDE))
        image = np.asarray(photo)
        start = time.perf_counter()
        masks = segmenter.automatic(image)
        seconds = time.perf_counter() - start
        targets = [component_targets(mask) for mask in masks]
        print(
            f"{category}/{row['id']}: {image.shape[1]}x{image.shape[0]}, {len(masks)} masks, "
            f"{sum(map(len, targets))} components, SAM {seconds:.1f} s",
            flush=True,
        )
        pictures.append(Picture(category, row["id"], image, masks, targets))
    return pictures


def traced(
    picture: Picture, segments: int, tolerance: float | None, repeats: int
) -> tuple[list[list[TracedPath]], float]:
    """The traced paths (per mask, per component) and the median seconds of one call."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        _, info = trace_masks_with_info(picture.masks, picture.image, segments, tolerance=tolerance)
        times.append(time.perf_counter() - start)
    by_mask: list[list[TracedPath]] = [[] for _ in picture.masks]
    for path in info:
        by_mask[path.mask_index].append(path)
    return by_mask, statistics.median(times)


def measure(
    pictures: list[Picture],
    label: str,
    by_picture: list[tuple[list[list[TracedPath]], float]],
    tolerance: float | None,
) -> Row:
    row = Row(label, tolerance, [], [], [], 0, 0, 0.0, {})
    for picture, (by_mask, seconds) in zip(pictures, by_picture, strict=True):
        row.seconds += seconds
        counts, ious = [], []
        for paths, targets in zip(by_mask, picture.targets, strict=True):
            for path, (target, box) in zip(paths, targets, strict=True):
                inter, union = path_iou(path.points, target, box, picture.image.shape[:2])
                row.inter += inter
                row.union += union
                counts.append(len(path.points) // 3)
                ious.append(inter / union)
                row.errors.append(path.max_error)
        row.counts += counts
        row.ious += ious
        row.per_category[picture.category] = (float(np.mean(counts)), float(np.mean(ious)))
    return row


def reselect(picture: Picture, tolerance: float) -> tuple[list[list[TracedPath]], float]:
    """The alternative design: fixed-K traces at K = 1, 2, ... for the masks still over the
    tolerance; each component keeps its first K within it (or the cap)."""
    start = time.perf_counter()
    chosen: list[list[TracedPath | None]] = [[None] * len(t) for t in picture.targets]
    pending = [index for index, targets in enumerate(picture.targets) if targets]
    for segments in range(1, DEFAULT_MAX_SEGMENTS + 1):
        if not pending:
            break
        masks = [picture.masks[index] for index in pending]
        _, info = trace_masks_with_info(masks, picture.image, segments)
        seen = [0] * len(pending)
        for path in info:
            index = pending[path.mask_index]
            slot = seen[path.mask_index]
            seen[path.mask_index] += 1
            done = path.max_error <= tolerance or segments == DEFAULT_MAX_SEGMENTS
            if chosen[index][slot] is None and done:
                chosen[index][slot] = path
        pending = [index for index in pending if any(p is None for p in chosen[index])]
    seconds = time.perf_counter() - start
    return [[p for p in paths if p is not None] for paths in chosen], seconds


def summary_table(rows: list[Row]) -> str:
    lines = [
        "| setting | mean K | median K | max K | params / path | mean IoU | pooled IoU "
        "| worst IoU | within tol | trace ms |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        counts = np.array(row.counts)
        within = ""
        if row.tolerance is not None:
            ok = (np.array(row.errors) <= row.tolerance) | (counts == DEFAULT_MAX_SEGMENTS)
            within = f"{100 * ok.mean():.0f} %"
        lines.append(
            f"| {row.label} | {counts.mean():.2f} | {np.median(counts):.0f} | {counts.max()} | "
            f"{6 * counts.mean() + 4:.1f} | {np.mean(row.ious):.4f} | "
            f"{row.inter / row.union:.4f} | {np.min(row.ious):.3f} | {within} | "
            f"{1000 * row.seconds:.0f} |"
        )
    return "\n".join(lines)


def category_table(rows: list[Row], pictures: list[Picture]) -> str:
    lines = [
        "| image | paths | " + " | ".join(row.label for row in rows) + " |",
        "|---|---:|" + "---:|" * len(rows),
    ]
    for picture in pictures:
        cells = []
        for row in rows:
            segments, score = row.per_category[picture.category]
            cells.append(f"{segments:.1f} / {score:.3f}")
        paths = sum(map(len, picture.targets))
        lines.append(f"| {picture.category}/{picture.name} | {paths} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def shape_table() -> str:
    yy, xx = np.mgrid[:96, :128]
    shapes = {name: make() for name, make in SHAPES.items()}
    shapes["disc r=30"] = (xx - 60.5) ** 2 + (yy - 50.5) ** 2 < 30**2
    lines = [
        "| shape | " + " | ".join(f"tol {t:g}" for t in TOLERANCES) + " |",
        "|---|" + "---:|" * len(TOLERANCES),
    ]
    for name, mask in shapes.items():
        cells = []
        for tolerance in TOLERANCES:
            (path,) = trace_components(mask, tolerance=tolerance)
            cells.append(f"{len(path.points) // 3} ({path.max_error:.2f})")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=Config().segment.points_per_side)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--out",
        type=Path,
        default=Path(__file__).resolve().parent / "results" / "trace_tolerance.md",
    )
    args = parser.parse_args()
    started = time.perf_counter()
    trace_components(np.ones((8, 8), bool), tolerance=1.0)  # numba kernels: load or compile
    shapes = shape_table()
    pictures = load_pictures(args.points)
    rows = []
    settings: list[tuple[str, int, float | None]] = [(f"K={k}", k, None) for k in FIXED]
    settings += [(f"tol {t:g}", 4, t) for t in TOLERANCES]
    for label, segments, tolerance in settings:
        results = [traced(p, segments, tolerance, args.repeats) for p in pictures]
        rows.append(measure(pictures, label, results, tolerance))
        print(summary_table(rows[-1:]).splitlines()[-1], flush=True)
    alternative = measure(pictures, "re-select, tol 1", [reselect(p, 1.0) for p in pictures], 1.0)
    print(summary_table([alternative]).splitlines()[-1], flush=True)
    write_report(args, rows, alternative, pictures, shapes, time.perf_counter() - started)


def reading(rows: list[Row], alternative: Row) -> str:
    """What the tables say, with this run's numbers."""
    by = {row.label: row for row in rows}

    def stats(label: str) -> str:
        row = by[label]
        return (
            f"{np.mean(row.counts):.1f} segments, {6 * np.mean(row.counts) + 4:.0f} parameters "
            f"a path, mean IoU {np.mean(row.ious):.3f}, pooled {row.inter / row.union:.4f}"
        )

    def beaten(label: str) -> str:
        """The fixed-K settings the tolerance beats on pooled IoU."""
        pooled = by[label].inter / by[label].union
        fixed = [f"K={k}" for k in FIXED if by[f"K={k}"].inter / by[f"K={k}"].union < pooled]
        return ", ".join(fixed) or "none"

    tol1, alt = by["tol 1"], alternative
    return (
        f"* tol 1: {stats('tol 1')}; K=5: {stats('K=5')}; K=8: {stats('K=8')}. On pooled IoU "
        f"(pixels) 1 px beats {beaten('tol 1')} at about the parameters of K=5-6: the segments "
        "go to the long, complex outlines. Per path (mean IoU) it is close to K=5: small masks "
        "get 2-3 segments, and 1 px is a lot for a mask 15 px across (a boundary pixel's "
        "centre lies within 0.5 px of the contour, so a 0.5 px shift flips it).\n"
        f"* tol 0.5: {stats('tol 0.5')}: about twice the parameters of 1 px for the last "
        "half-percent; at 0.5 px and below the fit starts to follow the pixel staircase (the "
        "disk in the synthetic table).\n"
        f"* tol 2: {stats('tol 2')} (beats {beaten('tol 2')} on pooled IoU); tol 3: "
        f"{stats('tol 3')} (beats {beaten('tol 3')}). Coarse tolerances lose the small shapes "
        "first (mean IoU).\n"
        f"* Re-selecting corners at each K needs {np.mean(alt.counts):.2f} segments a path for "
        f"the same tolerance (tol 1: {np.mean(tol1.counts):.2f}) and "
        f"{alt.seconds / max(tol1.seconds, 1e-9):.0f}x the time: growing by splits keeps joins "
        "that already fit, and the merge pass removes the ones the greedy splits did not "
        "need.\n"
        "* Measured while developing (not rerun here): splitting at the worst point or at the "
        "arclength middle gives the same counts within 2 %; the merge pass saves about 5 % of "
        "the segments; sliding joins to lower the error changed IoU by < 0.001 for 2x the "
        "time, so the tracer does not do it."
    )


def write_report(
    args: argparse.Namespace,
    rows: list[Row],
    alternative: Row,
    pictures: list[Picture],
    shapes: str,
    seconds: float,
) -> None:
    machine = f"{platform.machine()}, {os.cpu_count()} cores, numpy {np.__version__}"
    text = (
        "# Tracing with a tolerance: adaptive segment counts against fixed K\n\n"
        f"Command: `python benchmarks/bench_trace_tolerance.py --points {args.points}` "
        f"({machine}; shared machine, times are noisy; whole run {seconds / 60:.1f} min, most "
        f"of it SAM). Masks: MobileSAM automatic masks (`Segmenter(Config().segment)`, "
        f"points_per_side={args.points}) of the first bench image of each category at "
        f"<= {SIDE} px; min_area {DEFAULT_MIN_AREA} px; max_segments {DEFAULT_MAX_SEGMENTS}.\n\n"
        "One row per setting over all paths of all images. *params / path*: 6K + 4 (3K "
        "control points and an RGBA colour). *IoU*: each path rendered alone by `samvg.render` "
        "(coverage > 0.5) against its mask component with holes filled; *mean* weighs every "
        "path alike, *pooled* is total intersection / total union (weighs paths by size). "
        "*within tol*: paths with `max_error` <= tolerance or at max_segments. *trace ms*: "
        f"one `trace_masks_with_info` call per image (median of {args.repeats}), summed.\n\n"
        f"{summary_table(rows)}\n\n"
        "## Per image (mean K / mean IoU)\n\n"
        f"{category_table(rows, pictures)}\n\n"
        "## The alternative: re-selecting corners at each K\n\n"
        "Fixed-K traces at K = 1, 2, ... (global corner selection, every join re-chosen) for "
        "the masks with a component still over 1 px; each component keeps its first K within "
        "it. Compare with the `tol 1` row above (split at the worst point, merge, corners "
        "kept).\n\n"
        f"{summary_table([alternative])}\n\n"
        "## Reading\n\n"
        f"{reading(rows, alternative)}\n\n"
        "## Synthetic shapes: segments (max error px) at each tolerance\n\n"
        "128x128 masks from `tests/trace/synthetic.py`; the disc is 128x96.\n\n"
        f"{shapes}\n"
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
