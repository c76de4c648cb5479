"""Contact sheet for the visual check: target | samvg | VTracer (default settings) [| samvg at
N paths], one row per bench image, with path counts, MSE and SVG bytes under each picture.

    python benchmarks/contact_sheet.py --per-category 2 --preset fast --output sheet.png
    python benchmarks/contact_sheet.py --per-category 2 --preset default --budget 64 --output s.png
    python benchmarks/contact_sheet.py --svg-dir svgs/ --categories digital_art --output g.png
    python benchmarks/contact_sheet.py --ids gnome_field_l,noto_cactus --preset default -o f.png

``--svg-dir`` draws SVGs written earlier (``bench_detail.py --keep-svg``) instead of running
samvg: one column per ``<id>.<tag>.svg`` file of the image, in name order, with VTracer's after
the first (name them ``<id>.1-default.svg``, ``<id>.2-64.svg`` for target | samvg default |
VTracer default | samvg at 64 paths).

Photos and paintings may be drawn for a local look (``--categories photo,painting``), but their
sheets must not be committed (the bench's licences forbid copies of them in the repository).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from bench_images import (
    REPO,
    bench_entries,
    render_at_working_size,
    run_samvg,
    vtracer_default,
    working_image,
)
from PIL import Image, ImageDraw

import samvg
from samvg.baselines import count_paths, render_svg
from samvg.config import PRESETS
from samvg.imaging import to_float_rgb

CELL = 256
CAPTION = 30


def cell(picture: np.ndarray, caption: str) -> Image.Image:
    """A picture scaled into a CELL square with a caption strip below."""
    canvas = Image.new("RGB", (CELL, CELL + CAPTION), "white")
    image = Image.fromarray(np.round(np.clip(picture, 0, 1) * 255).astype(np.uint8))
    image.thumbnail((CELL, CELL), Image.Resampling.LANCZOS)
    canvas.paste(image, ((CELL - image.width) // 2, (CELL - image.height) // 2))
    ImageDraw.Draw(canvas).text((4, CELL + 4), caption, fill="black")
    return canvas


def row_for(
    entry: dict[str, str], config: samvg.Config, budget: int | None = None
) -> list[Image.Image]:
    run = run_samvg(entry, config)
    target, result = run.target, run.result
    ours = run.render()
    svg = vtracer_default(run.working)
    theirs = render_svg(svg, target.shape[1], target.shape[0])
    paths_theirs = count_paths(svg)

    def mse(picture: np.ndarray) -> float:
        return float(np.mean((picture - target) ** 2))

    ours_bytes = len(result.image.to_svg().encode())
    paths = result.counts.get("paths", 0)
    print(
        f"{entry['id']}: samvg {paths} paths, mse {mse(ours):.4f}, {ours_bytes} B, "
        f"{run.seconds:.1f} s | vtracer {paths_theirs} paths, mse {mse(theirs):.4f}, "
        f"{len(svg)} B",
        flush=True,
    )
    row = [
        cell(target, f"{entry['id'][:36]}"),
        cell(ours, f"samvg {paths}p {mse(ours) * 1e3:.1f}e-3 {ours_bytes / 1e3:.1f}kB"),
        cell(theirs, f"vtracer {paths_theirs}p {mse(theirs) * 1e3:.1f}e-3 {len(svg) / 1e3:.0f}kB"),
    ]
    if budget is not None:
        fixed = run_samvg(entry, config.replace(paths=budget))
        picture, count = fixed.render(), fixed.result.counts.get("paths", 0)
        size = len(fixed.result.image.to_svg().encode())
        row.append(cell(picture, f"samvg --paths {budget}: {count}p {mse(picture) * 1e3:.1f}e-3 "
                                 f"{size / 1e3:.1f}kB"))  # fmt: skip
    return row


def saved_svgs(folder: Path, image_id: str) -> list[Path]:
    """An image's saved SVGs: ``<id>.svg`` (bench_geometry.py's) and ``<id>.<tag>.svg``."""
    return sorted(folder.glob(f"{image_id}.svg")) + sorted(folder.glob(f"{image_id}.*.svg"))


def row_from_svgs(entry: dict[str, str], folder: Path) -> list[Image.Image]:
    """Target | the image's first saved SVG | VTracer's default | its other saved SVGs, with
    paths, MSE and bytes."""
    from samvg import VectorImage

    working, scale = working_image(entry)
    target = to_float_rgb(working)
    height, width = target.shape[:2]
    row = [cell(target, entry["id"][:36])]
    for path in saved_svgs(folder, entry["id"]):
        svg = path.read_text()
        image = VectorImage.from_svg(svg)
        picture = render_at_working_size(image, scale, target.shape)
        error = float(np.mean((picture - target) ** 2))
        tag = path.name[len(entry["id"]) + 1 : -4] or "samvg"
        row.append(cell(picture, f"{tag}: {len(image.paths)}p {error * 1e3:.2f}e-3 "
                                 f"{len(svg.encode()) / 1e3:.1f}kB"))  # fmt: skip
    svg = vtracer_default(working)
    theirs = render_svg(svg, width, height)
    error = float(np.mean((theirs - target) ** 2))
    row.insert(2, cell(theirs, f"vtracer {svg.count('<path')}p {error * 1e3:.2f}e-3 "
                               f"{len(svg) / 1e3:.0f}kB"))  # fmt: skip
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-category", type=int, default=2)
    parser.add_argument("--categories", default="emoji,icon,clipart,digital_art")
    parser.add_argument("--preset", choices=sorted(PRESETS), default="fast")
    parser.add_argument("-o", "--output", type=Path, required=True)
    parser.add_argument("--budget", type=int, help="add a column: samvg with --paths N")
    parser.add_argument("--svg-dir", type=Path, help="draw saved SVGs instead of running samvg")
    parser.add_argument("--ids", help="comma-separated bench ids instead of --per-category")
    arguments = parser.parse_args()
    wanted = arguments.categories.split(",")
    if arguments.output.resolve().is_relative_to(REPO) and {"photo", "painting"} & set(wanted):
        sys.exit("photo and painting sheets stay out of the repository: write them elsewhere")
    config = PRESETS[arguments.preset]()
    if arguments.ids:
        ids = arguments.ids.split(",")
        by_id = {entry["id"]: entry for entry in bench_entries(None, wanted)}
        missing = [name for name in ids if name not in by_id]
        if missing:
            sys.exit(f"not in the bench (or not in --categories): {', '.join(missing)}")
        entries = [by_id[name] for name in ids]
    else:
        entries = bench_entries(arguments.per_category, wanted)
    if arguments.svg_dir is not None:
        entries = [e for e in entries if saved_svgs(arguments.svg_dir, e["id"])]
        rows = [row_from_svgs(entry, arguments.svg_dir) for entry in entries]
    else:
        rows = [row_for(entry, config, arguments.budget) for entry in entries]
    width = max(len(row) for row in rows)
    sheet = Image.new("RGB", (width * CELL, len(rows) * (CELL + CAPTION)), "white")
    for index, row in enumerate(rows):
        for column, picture in enumerate(row):
            sheet.paste(picture, (column * CELL, index * (CELL + CAPTION)))
    sheet.save(arguments.output)
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main()
