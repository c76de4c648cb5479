"""Benchmark of samvg.render.rasterize against resvg-py on the same scenes.

Random scenes of P star-shaped closed paths (K = 4 cubic segments, radius 5-60 px, random
translucent colours) at 256x256 and 512x512. For each: forward ms (no grad), forward+backward ms
(MSE loss against a random target image, gradients w.r.t. points and colours) and resvg-py's time
to render the same SVG text (what ``VectorImage.to_svg`` writes) to PNG; medians of repeats. The
same scenes with every fill a gradient (linear and radial alternately, 3 stops; gradients also
w.r.t. their parameters) give the gradient columns. The rasterizer's own times are measured on
one thread and on ``--render-threads`` (default: every core).

Usage: python benchmarks/bench_render.py [--repeats N] [--torch-threads T] [--render-threads R]
[--out FILE]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import resvg_py
import torch

from samvg.render import rasterize, warmup
from samvg.render._paint_kernels import LINEAR, PARAMS, RADIAL
from samvg.render.rasterizer import GradientPaints
from samvg.render.threads import default_threads, using_render_threads
from samvg.vector_image import VectorImage, VectorPath

SIZES = (256, 512)
PATH_COUNTS = (16, 64, 256)
SEGMENTS = 4


def star_path(rng: np.random.Generator, cx: float, cy: float, radius: float) -> np.ndarray:
    angles = np.sort(rng.uniform(0, 2 * np.pi, 3 * SEGMENTS))
    radii = radius * (1 + 0.3 * rng.uniform(-1, 1, 3 * SEGMENTS))
    return np.stack([cx + radii * np.cos(angles), cy + radii * np.sin(angles)], 1)


def _centre(rng: np.random.Generator, size: int) -> tuple[float, float]:
    cx, cy = rng.uniform(0, size, 2)
    return float(cx), float(cy)


def scene(rng: np.random.Generator, n_paths: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    points = np.stack(
        [star_path(rng, *_centre(rng, size), rng.uniform(5, 60)) for _ in range(n_paths)]
    )
    colors = rng.uniform(0, 1, (n_paths, 4))
    colors[:, 3] = rng.uniform(0.3, 1.0, n_paths)
    return points, colors


def gradient_paints(rng: np.random.Generator, n_paths: int, size: int) -> GradientPaints:
    """Every path a 3-stop gradient: linear for even paths, radial for odd ones."""
    params = np.zeros((n_paths, PARAMS))
    kinds = np.where(np.arange(n_paths) % 2 == 0, LINEAR, RADIAL)
    params[:, :4] = rng.uniform(0, size, (n_paths, 4))
    params[kinds == RADIAL, 2] = rng.uniform(10, size / 2, int(np.sum(kinds == RADIAL)))
    params[:, 4:7] = np.sort(rng.uniform(0, 1, (n_paths, 3)), axis=1)
    params[:, 8:17] = rng.uniform(0, 1, (n_paths, 9))
    tensor = torch.tensor(params, dtype=torch.float32, requires_grad=True)
    return GradientPaints(kinds.astype(np.int64), np.full(n_paths, 3, np.int64), tensor)


def median_ms(function: Callable[[], None], repeats: int) -> float:
    function()  # warm caches
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return 1000 * statistics.median(times)


def run(repeats: int, threads: int) -> list[dict[str, float]]:
    rng = np.random.default_rng(0)
    rows = []
    for size in SIZES:
        for n_paths in PATH_COUNTS:
            points, colors = scene(rng, n_paths, size)
            svg = VectorImage(
                size,
                size,
                [VectorPath(p, tuple(c)) for p, c in zip(points, colors, strict=True)],
                (1.0, 1.0, 1.0),
            ).to_svg()
            target = torch.rand(size, size, 3)
            pts = torch.tensor(points, dtype=torch.float32, requires_grad=True)
            cols = torch.tensor(colors, dtype=torch.float32, requires_grad=True)

            def forward(
                pts: torch.Tensor = pts, cols: torch.Tensor = cols, size: int = size
            ) -> None:
                with torch.no_grad():
                    rasterize(pts, cols, size, size)

            def forward_backward(
                pts: torch.Tensor = pts,
                cols: torch.Tensor = cols,
                size: int = size,
                target: torch.Tensor = target,
            ) -> None:
                pts.grad = cols.grad = None
                loss = ((rasterize(pts, cols, size, size) - target) ** 2).mean()
                loss.backward()

            def resvg(svg: str = svg) -> None:
                resvg_py.svg_to_bytes(svg_string=svg, background="#ffffff")

            paints = gradient_paints(rng, n_paths, size)

            def gradient_forward(
                pts: torch.Tensor = pts,
                cols: torch.Tensor = cols,
                size: int = size,
                paints: GradientPaints = paints,
            ) -> None:
                with torch.no_grad():
                    rasterize(pts, cols, size, size, gradients=paints)

            def gradient_forward_backward(
                pts: torch.Tensor = pts,
                cols: torch.Tensor = cols,
                size: int = size,
                target: torch.Tensor = target,
                paints: GradientPaints = paints,
            ) -> None:
                pts.grad = cols.grad = paints.params.grad = None
                image = rasterize(pts, cols, size, size, gradients=paints)
                ((image - target) ** 2).mean().backward()

            with using_render_threads(1):
                row = {
                    "size": size,
                    "paths": n_paths,
                    "forward": median_ms(forward, repeats),
                    "forward_backward": median_ms(forward_backward, repeats),
                    "resvg": median_ms(resvg, repeats),
                    "gradient_forward": median_ms(gradient_forward, repeats),
                    "gradient_forward_backward": median_ms(gradient_forward_backward, repeats),
                }
            with using_render_threads(threads):
                row["threaded_forward"] = median_ms(forward, repeats)
                row["threaded_forward_backward"] = median_ms(forward_backward, repeats)
            row["ratio"] = row["forward_backward"] / row["resvg"]
            rows.append(row)
            print(
                f"{size}x{size} P={n_paths}: fwd {row['forward']:.2f} ms, "
                f"fwd+bwd {row['forward_backward']:.2f} ms, resvg {row['resvg']:.2f} ms; "
                f"{threads} threads: fwd {row['threaded_forward']:.2f} ms, "
                f"fwd+bwd {row['threaded_forward_backward']:.2f} ms",
                flush=True,
            )
    return rows


def table(rows: list[dict[str, float]], threads: int) -> str:
    lines = [
        "| canvas | paths (K=4) | forward ms | forward+backward ms | resvg-py ms "
        "| fwd+bwd / resvg | gradient fills: forward ms | gradient fills: fwd+bwd ms "
        f"| {threads} threads: forward ms | {threads} threads: fwd+bwd ms |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['size']}x{r['size']} | {r['paths']} | {r['forward']:.2f} | "
            f"{r['forward_backward']:.2f} | {r['resvg']:.2f} | {r['ratio']:.2f} | "
            f"{r['gradient_forward']:.2f} | {r['gradient_forward_backward']:.2f} | "
            f"{r['threaded_forward']:.2f} | {r['threaded_forward_backward']:.2f} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument(
        "--torch-threads",
        type=int,
        default=1,
        help="torch intra-op threads for the loss and autograd glue (0: torch's default). The "
        "rasterizer kernels are single-threaded either way, as is resvg; on a small shared "
        "machine torch's thread pool adds large, erratic wake-up delays to tiny tensor ops.",
    )
    parser.add_argument(
        "--render-threads",
        type=int,
        default=default_threads(),
        help="the rasterizer's threads for the threaded columns (default: every core)",
    )
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent / "results" / "render.md"
    )
    args = parser.parse_args()

    if args.torch_threads > 0:
        torch.set_num_threads(args.torch_threads)
    start = time.perf_counter()
    warmup()
    warm = time.perf_counter() - start
    rows = run(args.repeats, args.render_threads)
    body = table(rows, args.render_threads)
    machine = (
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"torch {torch.__version__} (intra-op threads: {torch.get_num_threads()}), "
        f"resvg-py {getattr(resvg_py, '__version__', '?')}"
    )
    text = (
        "# Rasterizer benchmark\n\n"
        "`python benchmarks/bench_render.py` - median of "
        f"{args.repeats} repeats; {machine}.\n"
        "Scenes: P random star-shaped paths (K = 4 cubics, radius 5-60 px, translucent). "
        "forward+backward = rasterize, MSE against a random target, backward to points and "
        "colours. resvg-py renders the same SVG text (2 decimals) to PNG over white.\n"
        "The first columns run the rasterizer on one thread, as resvg runs; the last two on "
        f"{args.render_threads} (row bands and runs of paths, the same bits). torch threads "
        f"(`--torch-threads`, 0 = torch default): {args.torch_threads}; with torch's default "
        "pool on a 2-core machine where another process keeps one core busy, the MSE loss "
        "and its backward alone take ~40 ms instead of ~0.6 ms (thread wake-up stalls).\n"
        f"Kernel warm-up in this process (cache load or compile): {warm:.2f} s.\n\n"
        f"{body}\n"
    )
    print()
    print(body)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
