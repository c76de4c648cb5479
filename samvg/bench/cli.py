"""The ``samvg-bench`` command line: run the paper's evaluation on a manifest of images."""

from __future__ import annotations

import argparse
import importlib.util
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from samvg.bench.layout import Layout
from samvg.bench.methods import DEFAULT_METHODS, METHODS
from samvg.bench.report import write_report
from samvg.bench.runner import run_bench, write_results_csv
from samvg.config import PRESETS
from samvg.errors import SamvgError

BENCH_EXTRA = "pip install 'samvg[bench]'"
#: Optional modules (the ``bench`` extra): what needs each, and the methods that need it (None:
#: every run, for the report's plots).
OPTIONAL_MODULES: dict[str, tuple[str, tuple[str, ...] | None]] = {
    "matplotlib": ("the report's plots", None),
    "vtracer": ("the vtracer baseline", ("vtracer",)),
    "resvg_py": ("rendering the vtracer baseline", ("vtracer",)),
}


def _installed(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):  # a broken or blocked install counts as missing
        return False


def check_optional_modules(methods: list[str]) -> None:
    """Raise `SamvgError` with a one-line install hint if a module this run needs is missing."""
    for module, (purpose, users) in OPTIONAL_MODULES.items():
        if (users is None or set(users) & set(methods)) and not _installed(module):
            raise SamvgError(
                f"samvg-bench needs {module} for {purpose}, and it is not installed: {BENCH_EXTRA}"
            )


def _names(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="samvg-bench",
        description=(
            "Vectorize every image of a manifest with each method, score the results and write "
            "results.csv, summary.md, plots and a contact sheet into --out. Finished results "
            "are kept: rerunning the same command resumes."
        ),
        epilog="methods: "
        + "; ".join(f"{name}: {method.description}" for name, method in METHODS.items()),
    )
    parser.add_argument("--manifest", type=Path, help="CSV with id, category, png columns")
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument(
        "--methods",
        type=_names,
        default=list(DEFAULT_METHODS),
        help=f"comma-separated (default {','.join(DEFAULT_METHODS)})",
    )
    parser.add_argument("--limit", type=int, help="only the first N images")
    parser.add_argument("--categories", type=_names, help="comma-separated categories only")
    parser.add_argument("--size", type=int, default=512, help="working size, longest side")
    parser.add_argument("--iterations", type=int, help="optimization steps per phase")
    parser.add_argument("--seed", type=int, help="random seed (samvg and the baselines)")
    parser.add_argument(
        "--preset",
        choices=tuple(PRESETS),
        default="default",
        help="samvg's settings to start from: default, paper (the paper's exact procedure, for "
        "its Tables 1 and 2) or fast",
    )
    parser.add_argument("--fast", action="store_true", help="same as --preset fast")
    parser.add_argument("--checkpoint", help="SAM checkpoint file")
    parser.add_argument("--lpips-weights", help="LPIPS weights file (else the usual lookup)")
    parser.add_argument("--fid-weights", help="FID Inception weights (else the usual lookup)")
    parser.add_argument("--no-fid", action="store_true", help="leave FID out of the report")
    parser.add_argument(
        "--retry-failed", action="store_true", help="run again what failed in an earlier run"
    )
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="only rewrite the report and results.csv from --out's records",
    )
    return parser


class _RichProgress:
    """Two bars: image × method results, and the steps of the method now running."""

    def __init__(self, console: Any) -> None:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
        )

        self.console = console
        self.progress = Progress(
            TextColumn("{task.description}", markup=False),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            console=console,
        )
        self.overall = self.progress.add_task("results", total=None)
        self.current: Any = None
        self.label = ""

    def start(self, total: int) -> None:
        self.progress.update(self.overall, total=total)

    def begin(self, image_id: str, method: str) -> None:
        self.label = f"{image_id} · {method}"
        if self.current is not None:
            self.progress.remove_task(self.current)  # a fresh bar: no total until told one
        self.current = self.progress.add_task(self.label, total=None)

    def stage(self, stage: str, done: int, total: int) -> None:
        self.progress.update(
            self.current, description=f"{self.label} · {stage}", completed=done, total=total
        )

    def end(self, record: dict[str, Any]) -> None:
        self.progress.advance(self.overall)
        if record.get("status") != "ok":
            error = str(record.get("error", "")).splitlines()[0]
            self.console.print(
                f"failed: {record['id']} · {record['method']}: {error}",
                markup=False,
                highlight=False,
                soft_wrap=True,
            )


def _run(arguments: argparse.Namespace, console: Any, command: str) -> None:
    check_optional_modules([] if arguments.report_only else arguments.methods)
    if arguments.report_only:
        summary = write_report(
            arguments.out, fid_weights=arguments.fid_weights, fid=not arguments.no_fid
        )
        write_results_csv(Layout(arguments.out))  # a run stopped part way wrote none yet
        console.print(f"wrote {summary}", markup=False, highlight=False, soft_wrap=True)
        return
    if arguments.manifest is None:
        raise SamvgError("--manifest is required (except with --report-only)")
    config = PRESETS["fast" if arguments.fast else arguments.preset]()
    if arguments.checkpoint:
        config = config.replace(checkpoint=arguments.checkpoint)
    if arguments.lpips_weights:
        config = config.replace(lpips_weights=arguments.lpips_weights)
    reporter = _RichProgress(console)
    with reporter.progress:
        outcome = run_bench(
            arguments.manifest,
            arguments.out,
            arguments.methods,
            size=arguments.size,
            iterations=arguments.iterations,
            seed=arguments.seed,
            limit=arguments.limit,
            categories=arguments.categories,
            retry_failed=arguments.retry_failed,
            config=config,
            lpips_weights=arguments.lpips_weights,
            fid_weights=arguments.fid_weights,
            fid=not arguments.no_fid,
            progress=reporter,
            command=command,
        )
    console.print(
        f"{outcome.done} results made, {outcome.skipped} already there, {outcome.failed} failed; "
        f"see {outcome.out / 'summary.md'}",
        markup=False,
        highlight=False,
        soft_wrap=True,
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 error, 130 interrupted)."""
    from rich.console import Console
    from rich.markup import escape

    words = list(sys.argv[1:] if argv is None else argv)
    arguments = build_parser().parse_args(words)
    console = Console(stderr=True)
    try:
        _run(arguments, console, shlex.join(["samvg-bench", *words]))
    except SamvgError as error:
        console.print(f"[bold red]error:[/] {escape(str(error))}", highlight=False, soft_wrap=True)
        return 1
    except ModuleNotFoundError as error:  # an optional module the checks above did not name
        hint = f"samvg-bench needs {error.name}, and it is not installed: {BENCH_EXTRA}"
        console.print(f"[bold red]error:[/] {escape(hint)}", highlight=False, soft_wrap=True)
        return 1
    except KeyboardInterrupt:
        console.print("interrupted")
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
