"""The ``samvg`` command line: vectorize, segment and render, with progress and plain errors."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from samvg.errors import SamvgError


def _say(console, text: str) -> None:  # type: ignore[no-untyped-def]
    """Print plain text (no markup, no wrapping: paths stay on one line)."""
    console.print(text, markup=False, highlight=False, soft_wrap=True)


def _progress_reporter(console):  # type: ignore[no-untyped-def]
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    progress = Progress(
        TextColumn("{task.description:<10}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=console,
        transient=False,
    )
    tasks: dict[str, int] = {}

    def report(stage: str, done: int, total: int) -> None:
        if stage not in tasks:
            tasks[stage] = progress.add_task(stage, total=total)
        progress.update(tasks[stage], completed=done, total=total)

    return progress, report


def _check_output(path: Path, suffixes: tuple[str, ...]) -> None:
    if path.suffix.lower() not in suffixes:
        raise SamvgError(f"output {path} should end in {' or '.join(suffixes)}")
    if not path.parent.resolve().is_dir():
        raise SamvgError(f"output folder {path.parent} does not exist")


def _vectorize(arguments: argparse.Namespace, console) -> None:  # type: ignore[no-untyped-def]
    from samvg.io import read_image, write_png
    from samvg.pipeline import VectorizeConfig, vectorize

    _check_output(arguments.output, (".svg",))
    if arguments.preview is not None:
        _check_output(arguments.preview, (".png",))
    config = VectorizeConfig(
        checkpoint=arguments.checkpoint,
        model=arguments.model,
        steps=arguments.steps,
        max_paths=arguments.max_paths,
        num_segments=arguments.segments,
    )
    image = read_image(arguments.input)
    progress, report = _progress_reporter(console)
    with progress:
        result = vectorize(image, config, progress=report)
    result.save(arguments.output, precision=arguments.precision)
    _say(console, f"wrote {arguments.output} ({len(result.paths)} paths)")
    if arguments.preview is not None:
        write_png(arguments.preview, result.render())
        _say(console, f"wrote {arguments.preview}")


def _segment(arguments: argparse.Namespace, console) -> None:  # type: ignore[no-untyped-def]
    import numpy as np

    from samvg.io import read_image, write_png
    from samvg.pipeline import VectorizeConfig, segment

    _check_output(arguments.output, (".png",))
    image = read_image(arguments.input)
    with console.status("segmenting"):
        masks = segment(image, VectorizeConfig(checkpoint=arguments.checkpoint, max_paths=10**9))
    rng = np.random.default_rng(0)
    overlay = image.astype(np.float32) / 255.0
    for mask in masks:
        overlay[mask] = 0.45 * overlay[mask] + 0.55 * rng.uniform(0, 1, 3)
    write_png(arguments.output, overlay)
    _say(console, f"wrote {arguments.output} ({len(masks)} masks)")


def _render(arguments: argparse.Namespace, console) -> None:  # type: ignore[no-untyped-def]
    from samvg.io import write_png
    from samvg.vector_image import VectorImage

    _check_output(arguments.output, (".png",))
    image = VectorImage.load(arguments.input)
    write_png(arguments.output, image.render(scale=arguments.scale))
    _say(console, f"wrote {arguments.output}")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``samvg`` command."""
    parser = argparse.ArgumentParser(prog="samvg", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)

    vectorize = commands.add_parser("vectorize", help="raster image to SVG")
    vectorize.add_argument("input", type=Path)
    vectorize.add_argument("-o", "--output", type=Path, required=True, help="SVG file to write")
    vectorize.add_argument("--preview", type=Path, help="also write a PNG render of the result")
    vectorize.add_argument("--model", default="mobile_sam", help="SAM variant (default mobile_sam)")
    vectorize.add_argument("--checkpoint", help="SAM checkpoint file")
    vectorize.add_argument("--steps", type=int, default=300, help="optimisation steps")
    vectorize.add_argument("--max-paths", type=int, default=64)
    vectorize.add_argument("--segments", type=int, default=5, help="cubic segments per path")
    vectorize.add_argument("--precision", type=int, default=2, help="decimals in SVG output")
    vectorize.set_defaults(handler=_vectorize)

    segment = commands.add_parser("segment", help="SAM automatic masks as a colour overlay PNG")
    segment.add_argument("input", type=Path)
    segment.add_argument("-o", "--output", type=Path, required=True)
    segment.add_argument("--checkpoint", help="SAM checkpoint file")
    segment.set_defaults(handler=_segment)

    render = commands.add_parser("render", help="render an SVG of filled paths to PNG")
    render.add_argument("input", type=Path)
    render.add_argument("-o", "--output", type=Path, required=True)
    render.add_argument("--scale", type=float, default=1.0)
    render.set_defaults(handler=_render)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 error, 130 interrupted)."""
    from rich.console import Console
    from rich.markup import escape

    arguments = build_parser().parse_args(argv)
    console = Console(stderr=True)
    try:
        arguments.handler(arguments, console)
    except SamvgError as error:
        console.print(f"[bold red]error:[/] {escape(str(error))}", highlight=False, soft_wrap=True)
        return 1
    except KeyboardInterrupt:
        console.print("interrupted")
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
