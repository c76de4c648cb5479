"""Speed (issue 14): time per stage and quality of samvg's default and ``--fast`` presets, an
older commit against the working tree, run alternately image by image on one machine state.

    python benchmarks/bench_speed.py run --old 45a9978 --per-category 4
    python benchmarks/bench_speed.py report --old 45a9978
    python benchmarks/bench_speed.py paths --paths-records benchmarks/results/detail/budget-X

``--new REV`` measures a commit instead of the working tree (so the tree can change while it
runs), and ``--records DIR`` keeps a run's records apart from an earlier one's (another
machine's, say).

``run`` checks the old commit out in a temporary git worktree and, for each bench image and
preset, runs the old code and then the new code in fresh subprocesses (so neither warms the
other's caches), each on the machine as it is at that moment: the machine is noisy, so the
report gives medians and the median of the per-image ratios. Every run is one JSON record under
``benchmarks/results/speed/<label>/`` (a rerun skips what is there, so a long run resumes). MSE
and LPIPS are measured by the working tree's code on both SVGs, rendered at the 512-px working
size. The report goes to ``benchmarks/results/speed.md``, with a plot of time against path
count (``speed_paths.png``) for samvg, random init (diffvg) and the LIVE-style baseline at fixed
budgets, drawn from the records of ``bench_detail.py budget`` (which time every run) in
``--paths-records`` (default ``benchmarks/results/speed/paths``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
RECORDS = REPO / "benchmarks/results/speed"
REPORT = REPO / "benchmarks/results/speed.md"
PLOT = REPO / "benchmarks/results/speed_paths.png"
PATHS = REPO / "benchmarks/results/speed/paths"
PLOTTED = ("samvg", "samvg-gradients", "diffvg", "live")
PATHS_HEADING = "## Time against path count (median seconds per image)"
PRESETS = ("default", "fast")
STAGES = (
    "segment",
    "trace",
    "optimize",
    "reshape",
    "missing",
    "refine",
    "reduce",
    "finish",
    "texture",
)


def worker(image: str, preset: str) -> None:
    """In the tree under test (first on ``PYTHONPATH``): vectorize one image and print a JSON
    line with the timings, counts and SVG."""
    import samvg

    config = samvg.Config() if preset == "default" else samvg.Config.fast()
    started = time.perf_counter()
    result = samvg.run(image, config)
    seconds = time.perf_counter() - started
    record = {
        "samvg": str(Path(samvg.__file__).resolve().parent),
        "seconds": seconds,
        "timings": result.timings,
        "paths": result.counts.get("paths", 0),
        "svg": result.image.to_svg(),
    }
    print(json.dumps(record))


def run_tree(tree: Path, image: Path, preset: str) -> dict[str, Any]:
    """One worker run on the code in ``tree``."""
    environment = {**os.environ, "PYTHONPATH": str(tree)}
    command = [sys.executable, str(Path(__file__).resolve()), "worker", str(image), preset]
    done = subprocess.run(command, env=environment, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"worker failed on {image.name} in {tree}: {done.stderr[-2000:]}")
    record = json.loads(done.stdout.strip().splitlines()[-1])
    if Path(record["samvg"]) != (tree / "samvg").resolve():
        raise SystemExit(f"the worker imported {record['samvg']}, not {tree / 'samvg'}")
    return record


def measure(record: dict[str, Any], entry: dict[str, str], lpips: Any) -> dict[str, Any]:
    """MSE and LPIPS of the record's SVG against the image at the 512-px working size."""
    import numpy as np
    from bench_images import render_at_working_size, working_image

    from samvg import VectorImage
    from samvg.imaging import to_float_rgb
    from samvg.metrics import lpips_distance

    working, scale = working_image(entry)
    target = to_float_rgb(working)
    vector = VectorImage.from_svg(record.pop("svg"))
    picture = render_at_working_size(vector, scale, target.shape)
    record["mse"] = float(np.mean((picture - target) ** 2))
    record["lpips"] = lpips_distance(lpips, picture, target)
    return record


def run_study(
    old: str,
    per_category: int,
    presets: list[str],
    keep_svg: Path | None = None,
    new: str | None = None,
    records: Path = RECORDS,
) -> None:
    sys.path.insert(0, str(REPO / "benchmarks"))
    from bench_images import BENCH, bench_entries

    from samvg.io import atomic_write_text
    from samvg.metrics import load_lpips

    lpips = load_lpips()
    with tempfile.TemporaryDirectory() as folder:
        trees = {old: Path(folder) / "old"}
        if new is not None:
            trees[new] = Path(folder) / "new"
        for revision, tree in trees.items():
            subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(tree),
                            revision], check=True, capture_output=True)  # fmt: skip
        new_tree = REPO if new is None else trees[new]
        entries = bench_entries(per_category)
        try:
            for tree in {trees[old], new_tree}:  # compile (and cache) every numba kernel first
                run_tree(tree, BENCH / entries[0]["png"], "fast")
            for entry in entries:
                for preset in presets:
                    for label, tree in ((f"old-{old}", trees[old]), ("new", new_tree)):
                        path = records / label / f"{entry['id']}.{preset}.json"
                        if path.exists():
                            continue
                        image = BENCH / entry["png"]
                        record = run_tree(tree, image, preset)
                        if keep_svg is not None:  # for contact_sheet.py --svg-dir
                            keep_svg.mkdir(parents=True, exist_ok=True)
                            tag = f"{label.split('-')[0]}-{preset}"
                            (keep_svg / f"{entry['id']}.{tag}.svg").write_text(record["svg"])
                        record = measure(record, entry, lpips)
                        record.update(id=entry["id"], category=entry["category"], preset=preset)
                        path.parent.mkdir(parents=True, exist_ok=True)
                        atomic_write_text(path, json.dumps(record, indent=1))
                        print(label, entry["id"], preset, f"{record['seconds']:.1f}s", flush=True)
        finally:
            for tree in trees.values():
                subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force",
                                str(tree)], check=False)  # fmt: skip


def _records(label: str, records: Path = RECORDS) -> dict[tuple[str, str], dict[str, Any]]:
    found = {}
    for path in sorted((records / label).glob("*.json")):
        record = json.loads(path.read_text())
        found[(record["id"], record["preset"])] = record
    return found


def _median(values: list[float]) -> str:
    return f"{statistics.median(values):.2f}" if values else "–"


def _stage_rows(old: dict, new: dict, keys: list, preset: str) -> list[str]:
    rows = []
    for stage in (*STAGES, "total"):
        before = [old[k]["timings"].get(stage, 0.0) for k in keys]
        after = [new[k]["timings"].get(stage, 0.0) for k in keys]
        if not any(before) and not any(after):
            continue
        ratios = [b / a for b, a in zip(before, after, strict=True) if a > 0 and b > 0]
        rows.append(f"| {preset} | {stage} | {_median(before)} | {_median(after)} | "
                    f"{_median(ratios)}× |")  # fmt: skip
    return rows


def _quality_rows(old: dict, new: dict, keys: list, preset: str) -> list[str]:
    rows = []
    categories = sorted({old[k]["category"] for k in keys})
    for category in [*categories, "all"]:
        chosen = [k for k in keys if category in ("all", old[k]["category"])]
        cells = []
        for metric in ("mse", "lpips", "paths"):
            before = statistics.mean(old[k][metric] for k in chosen)
            after = statistics.mean(new[k][metric] for k in chosen)
            scale = 1e3 if metric == "mse" else 1.0
            cells.append(f"{before * scale:.3f} → {after * scale:.3f} ({after / before - 1:+.1%})")
        rows.append(f"| {preset} | {category} | {len(chosen)} | " + " | ".join(cells) + " |")
    return rows


def write_report(
    old_label: str, records: Path = RECORDS, new_label: str | None = None, paths: Path = PATHS
) -> None:
    old, new = _records(f"old-{old_label}", records), _records("new", records)
    if not any(key in new for key in old):
        raise SystemExit(f"no paired records under {records} for {old_label}: run `run` first")
    shown = records.relative_to(REPO) if records.is_relative_to(REPO) else records
    new_text = (
        "the working tree when the records were made"
        if new_label is None
        else (f"commit `{new_label}`")
    )
    lines = [
        "# Speed: per-stage time and quality, before and after (issue 14)",
        "",
        f"Old: commit `{old_label}`; new: {new_text}. Both run alternately, image by image, in "
        "fresh processes on the same machine (2 cores), by `python benchmarks/bench_speed.py run "
        f"--old {old_label}"
        + ("" if new_label is None else f" --new {new_label}")
        + f" --records {shown}`. Seconds are medians over the images; the ratio is the median "
        "of the per-image old/new ratios.",
        "",
        "| preset | stage | old s | new s | speed-up |",
        "|---|---|---|---|---|",
    ]
    quality = [
        "",
        "## Quality (means; MSE ×1e-3 at 512 px, LPIPS-alex)",
        "",
        "| preset | category | images | MSE | LPIPS | paths |",
        "|---|---|---|---|---|---|",
    ]
    for preset in PRESETS:
        keys = sorted(k for k in old if k in new and k[1] == preset)
        if keys:
            lines += _stage_rows(old, new, keys, preset)
            quality += _quality_rows(old, new, keys, preset)
    REPORT.write_text("\n".join(lines + quality + _paths_section(paths)) + "\n")
    print(REPORT.read_text())


def _budget_runs(
    folder: Path,
) -> tuple[dict[str, dict[int, list[tuple[float, int]]]], dict[str, str]]:
    """(seconds, paths written) of the budget runs of ``bench_detail.py budget --records
    <folder>``, by method and path budget, and the category of each image they ran on."""
    runs: dict[str, dict[int, list[tuple[float, int]]]] = {}
    categories: dict[str, str] = {}
    for path in sorted(folder.glob("*.json")):
        record = json.loads(path.read_text())
        if record.get("study") == "budget" and record["method"] in PLOTTED:
            by_budget = runs.setdefault(record["method"], {})
            run = (float(record["seconds"]), int(record["paths"]))
            by_budget.setdefault(int(record["budget"]), []).append(run)
            categories[record["id"]] = record["category"]
    return runs, categories


def _paths_section(folder: Path) -> list[str]:
    """The time-against-paths table and plot (medians over the images run at each budget)."""
    runs, categories = _budget_runs(folder)
    if not runs:
        return []
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = folder.resolve().relative_to(REPO) if folder.resolve().is_relative_to(REPO) else folder
    lines = [
        "",
        PATHS_HEADING,
        "",
        f"The runs of `python benchmarks/bench_detail.py budget --records {shown}` on "
        f"{len(categories)} images ({', '.join(sorted(set(categories.values())))}; "
        "samvg-gradients is the default, gradient fills on; random init (diffvg) and the "
        "LIVE-style baseline: 1000 steps with samvg's losses). Each record times its own run. "
        "samvg writes fewer paths than the budget where no further path lowers the error "
        "measurably (a simple emoji stops near 15), so its time follows the paths it writes.",
        "",
        "| method | path budget | images | mean paths written | median s |",
        "|---|---|---|---|---|",
    ]
    figure, axes = plt.subplots(figsize=(6, 4))
    for method, by_budget in sorted(runs.items()):
        budgets = sorted(by_budget)
        medians = [statistics.median(s for s, _ in by_budget[n]) for n in budgets]
        axes.plot(budgets, medians, marker="o", label=method)
        for n, median in zip(budgets, medians, strict=True):
            written = statistics.mean(p for _, p in by_budget[n])
            lines.append(f"| {method} | {n} | {len(by_budget[n])} | {written:.0f} | {median:.1f} |")
    axes.set(xscale="log", xlabel="path budget", ylabel="seconds per image (median)")
    axes.set_ylim(bottom=0)
    budgets = sorted({n for by_budget in runs.values() for n in by_budget})
    axes.set_xticks(budgets, [str(n) for n in budgets])
    axes.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes.legend()
    figure.tight_layout()
    figure.savefig(PLOT, dpi=100)
    return [*lines, "", f"![time against paths]({PLOT.name})"]


def replace_paths_section(paths: Path) -> None:
    """Redraw only the time-against-paths section of ``speed.md`` (and its plot), keeping the
    rest of the report as it stands."""
    text = REPORT.read_text() if REPORT.exists() else ""
    kept = text.split(PATHS_HEADING)[0].rstrip("\n")
    section = _paths_section(paths)
    if not section:
        raise SystemExit(f"no budget records of {', '.join(PLOTTED)} under {paths}")
    REPORT.write_text("\n".join([kept, *section]) + "\n")
    print(f"wrote {REPORT} and {PLOT}")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "worker":
        worker(sys.argv[2], sys.argv[3])
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", choices=("run", "report", "paths"))
    parser.add_argument("--old", help="the commit to compare with (run, report)")
    parser.add_argument("--per-category", type=int, default=4)
    parser.add_argument("--presets", default="default,fast")
    parser.add_argument("--keep-svg", type=Path, help="also write every run's SVG to this folder")
    parser.add_argument("--new", help="the commit to measure (default: the working tree)")
    parser.add_argument("--records", type=Path, default=RECORDS, help="the records' folder")
    parser.add_argument(
        "--paths-records",
        type=Path,
        default=PATHS,
        help="the folder of bench_detail.py budget records to plot time against paths from",
    )
    arguments = parser.parse_args()
    if arguments.study == "paths":
        replace_paths_section(arguments.paths_records)
        return
    if arguments.old is None:
        parser.error(f"{arguments.study} needs --old")
    records = arguments.records.resolve()
    if arguments.study == "run":
        presets = arguments.presets.split(",")
        run_study(
            arguments.old, arguments.per_category, presets, arguments.keep_svg, arguments.new,
            records,
        )  # fmt: skip
    write_report(arguments.old, records, arguments.new, arguments.paths_records)


if __name__ == "__main__":
    main()
