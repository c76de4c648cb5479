"""The ``samvg`` command line: vectorize images (one, or a folder/glob in a batch), show SAM's
masks, render SVG; with progress, a closing summary and one-line errors.
"""

from __future__ import annotations

import argparse
import contextlib
import glob
import math
import signal
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any, NoReturn

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from samvg.config import PRESETS, Config
from samvg.errors import InputError, OutputError, SamvgError
from samvg.io import read_image, write_png
from samvg.output_paths import batch_outputs, check_output_file, check_output_folder
from samvg.svg.writer import DEFAULT_PRECISION, check_precision
from samvg.vector_image import VectorImage

if TYPE_CHECKING:  # the pipeline loads torch and numba: imported when a command needs it
    from samvg.pipeline import PipelineResult

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tif", ".tiff", ".webp")
SUBCOMMANDS = ("vectorize", "segment", "render")
MAX_RENDER_PIXELS = 2 * 89_478_485
"""The largest PNG `samvg render` writes: Pillow's decompression-bomb limit, which refuses to
read anything larger back."""


def _say(console: Console, text: str) -> None:
    """Print plain text (no markup, no wrapping: paths stay on one line)."""
    console.print(text, markup=False, highlight=False, soft_wrap=True)


class _StageProgress:
    """Rich progress bars, one per pipeline stage, with ETA; silent when ``quiet``."""

    def __init__(self, console: Console, quiet: bool) -> None:
        self.progress = Progress(
            TextColumn("{task.description:<14}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("eta"),
            TimeRemainingColumn(),
            console=console,
            transient=True,
            disable=quiet or not console.is_terminal,  # bars in a log are noise
        )
        self.tasks: dict[str, Any] = {}
        self.prefix = ""

    def report(self, stage: str, done: int, total: int) -> None:
        key = self.prefix + stage
        if key not in self.tasks:
            self.tasks[key] = self.progress.add_task(key, total=total)
        self.progress.update(self.tasks[key], completed=done, total=total)

    def clear(self) -> None:
        for task in self.tasks.values():
            self.progress.remove_task(task)
        self.tasks = {}


def one_line(message: str) -> str:
    """A message of several lines (a list of what was tried) joined into one line."""
    text = ""
    for line in (line.strip() for line in message.splitlines()):
        if line:
            text += ("" if not text else " " if text.endswith(":") else "; ") + line
    return text


class Interrupted(KeyboardInterrupt):
    """A termination signal (SIGTERM) raised as an exception, as Ctrl-C raises
    KeyboardInterrupt, so that cleanup (an atomic write's temporary file) runs."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def _terminate_as_interrupt() -> Iterator[None]:
    def interrupt(signum: int, _frame: FrameType | None) -> None:
        raise Interrupted(signum)

    try:
        previous = signal.signal(signal.SIGTERM, interrupt)
    except ValueError:  # not the main thread (an embedding program): leave signals alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


class _Parser(argparse.ArgumentParser):
    """argparse with each error on one line (the usage is what --help is for)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")


def _check_resources(config: Config) -> None:
    """Device, SAM and LPIPS weights, checked before any work (see `pipeline.check_resources`)."""
    from samvg.pipeline import check_resources  # lazy: loads torch (slow for --help)

    check_resources(config)


def _config(arguments: argparse.Namespace) -> Config:
    settings: dict[str, Any] = {
        "model": arguments.model,
        "checkpoint": arguments.checkpoint,
        "seed": arguments.seed,
        "device": arguments.device,
    }
    optional = {
        "max_paths": arguments.max_paths,
        "segments": arguments.segments,
        "iterations": arguments.iterations,
        "size": arguments.size,
        "crop_n_layers": arguments.crops,
        "threads": arguments.threads,
        "lpips_weights": arguments.lpips_weights,
        "missing_rounds": arguments.missing_rounds,
        "paths": arguments.paths,
        "detail": arguments.detail,
        "tolerance": arguments.tolerance,
        "colors": arguments.colors,
        "filter_speckle": arguments.filter_speckle,
    }
    settings.update({key: value for key, value in optional.items() if value is not None})
    if arguments.no_lpips:
        settings["use_lpips"] = False
    if arguments.no_filter:
        settings["filter_by_impact"] = False
    if arguments.translucent:
        settings["translucent"] = True
    if arguments.gradients is not None:
        settings["gradients"] = arguments.gradients
    if arguments.no_finish:
        settings["finish_pass"] = False
    if arguments.no_texture:
        settings["texture_layers"] = False
    preset = "fast" if arguments.fast else arguments.preset
    return PRESETS[preset](**settings)


def _expand_inputs(inputs: list[str]) -> tuple[list[Path], bool]:
    """Image files named by the arguments (files, folders, glob patterns); True if a batch."""
    found: list[Path] = []
    batch = len(inputs) > 1
    for text in inputs:
        path = Path(text)
        if path.is_dir():
            batch = True
            found.extend(sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES))
        elif path.exists() or not glob.has_magic(text):
            found.append(path)
        else:
            batch = True
            found.extend(
                sorted(Path(p) for p in glob.glob(text) if Path(p).suffix.lower() in IMAGE_SUFFIXES)
            )
    if not found:
        raise SamvgError(f"no images found in {' '.join(inputs)}")
    return found, batch


def _vectorize(arguments: argparse.Namespace, console: Console) -> int:
    config = _config(arguments)
    check_precision(arguments.precision)
    if arguments.batch_mode:
        return _vectorize_batch(arguments, config, console)
    source = arguments.inputs[0]
    if not source.is_file():
        raise InputError(f"image file not found: {source}")
    output = check_output_file(arguments.output, (".svg",), [source])
    preview = None
    if arguments.preview is not None:
        preview = check_output_file(arguments.preview, (".png",), [source], "preview")
    stages = None
    if arguments.save_stages is not None:
        stages = check_output_folder(arguments.save_stages, "--save-stages folder")
    _check_resources(config)
    progress = _StageProgress(console, arguments.quiet)
    with progress.progress:
        _vectorize_one(source, output, preview, stages, config, arguments, progress, console)
    return 0


def _vectorize_batch(arguments: argparse.Namespace, config: Config, console: Console) -> int:
    if Path(arguments.output).suffix.lower() == ".svg":
        raise SamvgError(f"several inputs: -o must be a folder, not {arguments.output}")
    if arguments.preview is not None:
        raise SamvgError("--preview takes one input; in a batch use --save-stages DIR")
    folder = check_output_folder(arguments.output)
    if arguments.save_stages is not None:
        check_output_folder(arguments.save_stages, "--save-stages folder")
    pairs = batch_outputs(arguments.inputs, folder)
    _check_resources(config)
    _make_folder(folder)
    failures: list[tuple[Path, str]] = []
    done = skipped = 0
    progress = _StageProgress(console, arguments.quiet)
    with progress.progress:
        overall = progress.progress.add_task("images", total=len(pairs))
        for source, target in pairs:
            if target.exists() and not arguments.overwrite:
                skipped += 1
                progress.progress.advance(overall)
                continue
            progress.prefix = f"{source.stem[:8]} "
            stages = None
            if arguments.save_stages is not None:
                stages = Path(arguments.save_stages) / target.name[: -len(".svg")]
            try:
                _vectorize_one(source, target, None, stages, config, arguments, progress, console)
                done += 1
            except OutputError:
                raise  # a full disk or a vanished folder fails every image after it: stop
            except SamvgError as error:
                failures.append((source, one_line(str(error))))
                _say(console, f"failed {source}: {failures[-1][1]}")
            except Exception as error:  # noqa: BLE001 - one bad image must not stop a batch
                failures.append((source, f"internal error {type(error).__name__}: {error}"))
                _say(console, f"failed {source}: {failures[-1][1]}")
            progress.clear()
            progress.progress.advance(overall)
    _say(
        console,
        f"batch: {done} vectorized, {skipped} skipped (already done), {len(failures)} failed",
    )
    for source, reason in failures:
        _say(console, f"  {source}: {reason}")
    return 1 if failures else 0


def _make_folder(folder: Path) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"cannot create folder {folder}: {error.strerror or error}") from None


def _vectorize_one(
    source: Path,
    output: Path,
    preview: Path | None,
    stages: Path | None,
    config: Config,
    arguments: argparse.Namespace,
    progress: _StageProgress,
    console: Console,
) -> None:
    from samvg.pipeline import run  # lazy: loads torch and numba (slow for --help)

    started = time.perf_counter()
    result = run(source, config, progress=progress.report, log=lambda text: _say(console, text))
    result.image.save(output, precision=arguments.precision)
    if preview is not None:
        write_png(preview, result.image.render())
    if stages is not None:
        _save_stages(result, stages, arguments.precision)
    if not arguments.quiet:
        for note in result.notes:
            _say(console, f"note: {note}")
        timings = ", ".join(
            f"{stage} {seconds:.1f}s"
            for stage, seconds in result.timings.items()
            if stage != "total"
        )
        scene = result.image.scene
        shapes = f" ({scene.path_count} shapes)" if scene.path_count != scene.element_count else ""
        _say(
            console,
            f"wrote {output}: {scene.element_count} path{'' if scene.element_count == 1 else 's'}"
            f"{shapes}, MSE {result.mse:.5f}, "
            f"{time.perf_counter() - started:.1f}s ({timings})",
        )
        if preview is not None:
            _say(console, f"wrote {preview}")


def _save_stages(result: PipelineResult, folder: Path, precision: int) -> None:
    """Intermediate results: masks, initial SVG, SVG after stage 3, stage-4 map, final SVG, and
    target | initial | optimized | final side by side."""
    _make_folder(folder)
    target = result.target
    if target is None:
        return
    if result.masks:
        write_png(folder / "1_masks.png", mask_overlay(target, result.masks))
    renders = [target]
    for name, image in (("2_initial", result.initial), ("3_optimized", result.optimized)):
        if image is not None:
            image.save(folder / f"{name}.svg", precision=precision)
            renders.append(image.render(scale=result.scale))
    if result.missing_map is not None:
        heat = np.clip(result.missing_map / 3.0, 0.0, 1.0)
        picture = np.stack([heat, heat * 0.3, 1.0 - heat], axis=2)
        for x, y in result.missing_prompts:
            picture[max(0, int(y) - 2) : int(y) + 3, max(0, int(x) - 2) : int(x) + 3] = (1, 1, 1)
        write_png(folder / "4_missing.png", picture)
    result.image.save(folder / "5_final.svg", precision=precision)
    renders.append(result.image.render(scale=result.scale))
    height = min(r.shape[0] for r in renders)
    width = min(r.shape[1] for r in renders)
    write_png(folder / "comparison.png", np.concatenate([r[:height, :width] for r in renders], 1))


def mask_overlay(image: np.ndarray, masks: list[np.ndarray], seed: int = 0) -> np.ndarray:
    """The image dimmed, each mask tinted with its own random colour (paint order)."""
    rng = np.random.default_rng(seed)
    pixels = np.asarray(image)
    overlay = pixels.astype(np.float32)
    if pixels.dtype == np.uint8:
        overlay /= 255.0
    for mask in masks:
        overlay[mask] = 0.45 * overlay[mask] + 0.55 * rng.uniform(0, 1, 3)
    return overlay


def _segment(arguments: argparse.Namespace, console: Console) -> int:
    source = arguments.input
    if not source.is_file():
        raise InputError(f"image file not found: {source}")
    output = check_output_file(arguments.output, (".png",), [source])
    config = Config(checkpoint=arguments.checkpoint, model=arguments.model, use_lpips=False)
    image = read_image(source)
    _check_resources(config)
    from samvg.segment import Segmenter  # lazy: loads torch

    with console.status("segmenting"):
        masks = Segmenter(config.segment, config.device).automatic(image)
    masks.sort(key=lambda m: -int(m.sum()))
    write_png(output, mask_overlay(image, masks))
    _say(console, f"wrote {output} ({len(masks)} masks)")
    return 0


def _render(arguments: argparse.Namespace, console: Console) -> int:
    output = check_output_file(arguments.output, (".png",), [arguments.input])
    scale = arguments.scale
    if not (math.isfinite(scale) and scale > 0):
        raise InputError(f"--scale must be a positive number, got {scale}")
    image = VectorImage.load(arguments.input)
    width, height = max(1, round(image.width * scale)), max(1, round(image.height * scale))
    if width * height > MAX_RENDER_PIXELS:
        raise InputError(
            f"the render would be {width}x{height} pixels, over the {MAX_RENDER_PIXELS} a PNG "
            "may have; lower --scale"
        )
    write_png(output, image.render(scale=scale))
    _say(console, f"wrote {output}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``samvg`` command."""
    parser = _Parser(
        prog="samvg",
        description="Raster images to compact, editable SVG (SAMVG). "
        "`samvg INPUT -o OUT.svg` is short for `samvg vectorize INPUT -o OUT.svg`.",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    _add_vectorize_command(commands)

    segment = commands.add_parser("segment", help="SAM automatic masks as a colour overlay PNG")
    segment.add_argument("input", type=Path)
    segment.add_argument("-o", "--output", required=True)
    segment.add_argument("--model", default="mobile_sam")
    segment.add_argument("--checkpoint", help="SAM checkpoint file")
    segment.set_defaults(handler=_segment)

    render = commands.add_parser("render", help="render an SVG of filled paths to PNG")
    render.add_argument("input", type=Path)
    render.add_argument("-o", "--output", required=True)
    render.add_argument("--scale", type=float, default=1.0)
    render.set_defaults(handler=_render)
    return parser


def _add_tuning_options(vectorize: argparse.ArgumentParser) -> None:
    """The ``vectorize`` options that tune the method (paths, segments, fitting, SAM)."""
    vectorize.add_argument(
        "--paths",
        type=int,
        help="exactly this many paths (SVG <path> elements: the pieces of one shape may be one "
        "compound path, as in Illustrator), when the image holds that much detail (default: as "
        "--detail decides)",
    )
    vectorize.add_argument(
        "--detail",
        type=float,
        help="0 to 1: how much detail to chase when --paths is not given; stage 4 adds rounds "
        "until one lowers the error by less than 10%% (0), 1%% (0.5, the default), 0.1%% (1)",
    )
    vectorize.add_argument("--max-paths", type=int, help="at most this many paths")
    _add_shape_options(vectorize)
    vectorize.add_argument(
        "--iterations", type=int, help="optimization steps per phase (default 500, two phases)"
    )
    vectorize.add_argument(
        "--size",
        type=int,
        help="working resolution, longest side (default 512); the SVG keeps "
        "the input's pixel coordinates",
    )
    vectorize.add_argument("--seed", type=int, default=0, help="random seed, 0 to 2**32 - 1")
    vectorize.add_argument("--device", default="cpu", help="cpu (default), cuda, cuda:N or mps")
    vectorize.add_argument(
        "--threads",
        type=int,
        help="threads for SAM and the rasterizer (default: every core; 1 on a busy machine)",
    )
    vectorize.add_argument(
        "--model",
        default="mobile_sam",
        help="SAM variant: mobile_sam (default), vit_b, vit_l, vit_h",
    )
    vectorize.add_argument("--checkpoint", help="SAM checkpoint file")
    vectorize.add_argument("--crops", type=int, help="SAM crop layers (test-time augmentation)")
    vectorize.add_argument(
        "--missing-rounds",
        type=int,
        help="rounds of stage 4, adding missing parts (default: as --detail decides; paper: 1)",
    )
    vectorize.add_argument("--no-lpips", action="store_true", help="optimize MSE + Xing only")
    vectorize.add_argument("--lpips-weights", help="LPIPS weight file (flat state dict)")
    vectorize.add_argument(
        "--no-filter",
        action="store_true",
        help="keep every SAM mask (the paper's ablation of filter by impact)",
    )


def _add_shape_options(vectorize: argparse.ArgumentParser) -> None:
    """The ``vectorize`` options that shape the paths and their fills."""
    vectorize.add_argument(
        "--segments",
        type=int,
        help="cubic segments per path (default: as few as fit within --tolerance; paper: 5)",
    )
    vectorize.add_argument(
        "--tolerance",
        type=float,
        help="largest distance in working pixels between an outline and its path when the "
        "segments are chosen per path (default 2; like potrace's opttolerance)",
    )
    vectorize.add_argument(
        "--colors", type=int, help="snap the fills to this many colours (k-means in CIELAB)"
    )
    vectorize.add_argument(
        "--filter-speckle",
        type=int,
        help="small marks on flat areas (a texture's dashes) smaller than N x N working pixels "
        "are left out (default 4, as VTracer)",
    )
    vectorize.add_argument(
        "--translucent",
        action="store_true",
        help="learn each fill's opacity (default: opaque fills, unless the input has alpha)",
    )
    vectorize.add_argument(
        "--gradients",
        action=argparse.BooleanOptionalAction,
        help="let paths and the background take linear or radial gradient fills where they pay "
        "for their parameters (the default; --no-gradients keeps every fill flat, as the paper)",
    )
    vectorize.add_argument(
        "--no-texture",
        action="store_true",
        help="no texture layers over a photo or painting (compound paths of many small islands "
        "of one colour; with --paths they are its last paths)",
    )
    vectorize.add_argument(
        "--no-finish",
        action="store_true",
        help="skip the finish pass (untangling, bounds, hidden and idle paths, merges)",
    )


def _add_vectorize_command(commands: Any) -> None:
    """The ``vectorize`` sub-command and its options."""
    vectorize = commands.add_parser(
        "vectorize",
        help="raster image(s) to SVG",
        description="Vectorize an image, or a batch (folder, glob or several files) into a folder.",
    )
    vectorize.add_argument("input", nargs="+", help="image file(s), folder or glob pattern")
    vectorize.add_argument(
        "-o", "--output", required=True, help="SVG file (one input) or output folder"
    )
    vectorize.add_argument("--preview", help="also write a PNG render of the result")
    vectorize.add_argument(
        "--save-stages",
        metavar="DIR",
        help="write every stage's result (masks, SVGs, maps) into DIR",
    )
    vectorize.add_argument(
        "--preset",
        choices=tuple(PRESETS),
        default="default",
        help="default: segments per outline, opaque fills, finish pass; paper: the paper's "
        "exact procedure (32x32 grid with crops, 5 segments, learned opacity, no finish pass); "
        "fast: the default with an 8x8 grid, at 384 px, 120 steps a phase (60 a draft), no LPIPS",
    )
    vectorize.add_argument("--fast", action="store_true", help="same as --preset fast")
    _add_tuning_options(vectorize)
    vectorize.add_argument(
        "--precision",
        type=int,
        default=DEFAULT_PRECISION,
        help=f"decimals in SVG output, 0 to 10 (default {DEFAULT_PRECISION})",
    )
    vectorize.add_argument(
        "--overwrite", action="store_true", help="in a batch, redo images whose SVG already exists"
    )
    vectorize.add_argument("-q", "--quiet", action="store_true", help="no progress, no summary")
    vectorize.set_defaults(handler=_vectorize)


def _error(console: Console, message: str) -> int:
    """Print ``error: message`` as one line (never wrapped) and return the exit status 1."""
    console.print(
        f"[bold red]error:[/] {escape(one_line(message))}", highlight=False, soft_wrap=True
    )
    return 1


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (0 ok, 1 error, 2 bad arguments, 130
    interrupted by Ctrl-C, 143 terminated by SIGTERM). Every error is one line on stderr."""

    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] not in SUBCOMMANDS and args[0] not in ("-h", "--help"):
        args.insert(0, "vectorize")
    arguments = build_parser().parse_args(args)
    console = Console(stderr=True)
    with _terminate_as_interrupt():
        try:
            if arguments.command == "vectorize":
                arguments.inputs, arguments.batch_mode = _expand_inputs(arguments.input)
            return int(arguments.handler(arguments, console) or 0)
        except SamvgError as error:
            return _error(console, str(error))
        except MemoryError:
            return _error(console, "out of memory; try a smaller --size")
        except KeyboardInterrupt as interrupt:
            console.print("interrupted", highlight=False)
            return 128 + (interrupt.signum if isinstance(interrupt, Interrupted) else signal.SIGINT)


if __name__ == "__main__":
    sys.exit(main())
