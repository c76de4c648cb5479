"""A/B benchmark of SAM's fast mask decoder: an older source tree's `FastDecoder` against this
tree's, in one process on one image embedding, timed alternately (this machine is noisy).

For each image: the 32x32 grid's 1024 prompts run through the two-way transformer
(`FastDecoder.transformer`, batches of 8 as in the generator), then through mask decoding as
well (`masks_and_counts` for every prompt, pairs as in the generator); each timed ``--repeat``
times per decoder, old and new in turn, and the fastest run kept. Then the whole automatic mask
generator runs once with each decoder, and the masks are compared pixel for pixel.

Usage:
    git worktree add /tmp/old <commit>
    python benchmarks/bench_decoder.py --old-tree /tmp/old --images kodim04 kodim05 ...
Writes benchmarks/results/decoder.md (``--out`` to change).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import torch
from bench_images import BENCH, REPO, bench_entries

import samvg.sam.predictor as predictor_module
from samvg.io import read_image
from samvg.sam import SamAutomaticMaskGenerator, SamPredictor, load_sam
from samvg.sam.fast_decoder import FastDecoder
from samvg.sam.predictor import decoder_grids

GRID_SIDE = 32


def load_old_decoder(tree: Path) -> type:
    """`FastDecoder` from another checkout's ``samvg/sam/fast_decoder.py``."""
    spec = importlib.util.spec_from_file_location(
        "old_fast_decoder", tree / "samvg/sam/fast_decoder.py"
    )
    if spec is None or spec.loader is None:
        raise SystemExit(f"no samvg/sam/fast_decoder.py under {tree}")
    module: ModuleType = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.FastDecoder


def bench_image(image_id: str) -> np.ndarray:
    """A bench image by id, as uint8 RGB, the way the product reads it."""
    for entry in bench_entries():
        if entry["id"] == image_id:
            return read_image(BENCH / entry["png"])
    raise SystemExit(f"no bench image {image_id!r} in {BENCH / 'manifest.csv'}")


def prompt_batches(
    generator: SamAutomaticMaskGenerator, predictor: SamPredictor, height: int, width: int
) -> list[torch.Tensor]:
    """Sparse prompt embeddings of the generator's whole-image grid, in its batches."""
    points = generator.point_grids[0] * np.array([[width, height]])
    step = generator.points_per_batch
    batches = []
    with torch.inference_mode():
        for start in range(0, len(points), step):
            chunk = torch.as_tensor(points[start : start + step], dtype=torch.float32)
            coords = predictor.transform_coords(chunk)[:, None, :]
            sparse, _ = generator.model.prompt_encoder(
                (coords, torch.ones(len(chunk), 1)), None, None
            )
            batches.append(sparse)
    return batches


def time_decoder(
    decoder: Any,
    batches: list[torch.Tensor],
    with_masks: bool,
    generator: SamAutomaticMaskGenerator,
    input_size: tuple[int, int],
) -> float:
    """Seconds for all ``batches`` through the transformer (and, ``with_masks``, every prompt's
    three masks and stability counts, in the generator's mask batches and thresholds)."""
    grid_hw, valid_hw = decoder_grids(input_size)
    threshold, offset = generator.model.mask_threshold, generator.stability_score_offset
    step = generator.mask_batch
    start = time.perf_counter()
    with torch.inference_mode():
        for sparse in batches:
            state = decoder.transformer(sparse)
            if not with_masks:
                continue
            for first in range(0, len(sparse), step):
                chosen = torch.arange(first, min(first + step, len(sparse)))
                decoder.masks_and_counts(
                    state.select(chosen),
                    [1, 2, 3],
                    grid_hw,
                    valid_hw,
                    threshold + offset,
                    threshold - offset,
                )
    return time.perf_counter() - start


def amg_masks(model: Any, image: np.ndarray, decoder_class: type) -> np.ndarray:
    """The 32x32 generator's masks with ``decoder_class`` as the predictor's decoder."""
    saved = predictor_module.FastDecoder
    predictor_module.FastDecoder = decoder_class  # type: ignore[assignment,misc]
    try:
        found = SamAutomaticMaskGenerator(model, points_per_side=GRID_SIDE).generate(image)
    finally:
        predictor_module.FastDecoder = saved  # type: ignore[misc]
    return (
        np.stack([m["segmentation"] for m in found])
        if found
        else np.zeros((0, *image.shape[:2]), bool)
    )


def measure(image_id: str, model: Any, old_class: type, repeat: int) -> dict[str, Any]:
    image = bench_image(image_id)
    generator = SamAutomaticMaskGenerator(model, points_per_side=GRID_SIDE)
    predictor = SamPredictor(model, fast=True)
    start = time.perf_counter()
    predictor.set_image(image)
    encoder_s = time.perf_counter() - start
    embedding = predictor.get_image_embedding()
    decoders = {"old": old_class(model, embedding), "new": FastDecoder(model, embedding)}
    input_size = predictor.input_size
    assert input_size is not None
    batches = prompt_batches(generator, predictor, *image.shape[:2])
    runs: dict[tuple[str, str], list[float]] = {}
    for _ in range(repeat):
        for part, with_masks in (("transformer", False), ("transformer+masks", True)):
            for name, decoder in decoders.items():
                runs.setdefault((name, part), []).append(
                    time_decoder(decoder, batches, with_masks, generator, input_size)
                )
    old_masks, new_masks = amg_masks(model, image, old_class), amg_masks(model, image, FastDecoder)
    same = old_masks.shape == new_masks.shape and bool((old_masks == new_masks).all())
    best = {key: min(values) for key, values in runs.items()}
    return {
        "id": image_id,
        "encoder": encoder_s,
        "best": best,
        "masks": len(new_masks),
        "same": same,
    }


def write_report(rows: list[dict[str, Any]], old_tree: Path, out: Path, repeat: int) -> None:
    lines = [
        "# Fast mask decoder, A/B (issue 14)",
        "",
        f"Command: `python benchmarks/bench_decoder.py --old-tree {old_tree} --images "
        f"{' '.join(r['id'] for r in rows)} --repeat {repeat}`; torch {torch.__version__}, "
        f"{torch.get_num_threads()} threads. 1024 prompts (32x32 grid); fastest of {repeat} "
        "alternating runs per decoder. `masks` = the generator's masks with each decoder, "
        "compared pixel for pixel.",
        "",
        "| image | encoder s | transformer old s | new s | speed-up "
        "| +masks old s | new s | speed-up | AMG masks | same |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        b = r["best"]
        t_old, t_new = b[("old", "transformer")], b[("new", "transformer")]
        m_old, m_new = b[("old", "transformer+masks")], b[("new", "transformer+masks")]
        same = "yes" if r["same"] else "NO"
        lines.append(
            f"| {r['id']} | {r['encoder']:.2f} | {t_old:.2f} | {t_new:.2f} | {t_old / t_new:.2f}x "
            f"| {m_old:.2f} | {m_new:.2f} | {m_old / m_new:.2f}x | {r['masks']} | {same} |"
        )
    ratios = [r["best"][("old", "transformer")] / r["best"][("new", "transformer")] for r in rows]
    lines += ["", f"Median transformer speed-up: {statistics.median(ratios):.2f}x.", ""]
    out.write_text("\n".join(lines), encoding="utf-8")
    print("\n".join(lines))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--old-tree", type=Path, required=True, help="checkout holding the old decoder"
    )
    parser.add_argument(
        "--images", nargs="+", default=["kodim04", "kodim05", "fluentflat_hamburger"]
    )
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", type=Path, default=REPO / "benchmarks" / "results" / "decoder.md")
    args = parser.parse_args()
    torch.set_num_threads(max(1, min(2, torch.get_num_threads())))
    old_class = load_old_decoder(args.old_tree)
    model = load_sam()
    rows = []
    for image_id in args.images:
        rows.append(measure(image_id, model, old_class, args.repeat))
        print(
            image_id,
            {f"{k[0]} {k[1]}": round(v, 2) for k, v in rows[-1]["best"].items()},
            flush=True,
        )
    write_report(rows, args.old_tree, args.out, args.repeat)


if __name__ == "__main__":
    main()
