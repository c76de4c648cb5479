"""The paper's evaluation as one command (``samvg-bench``): samvg, its ablation and the baselines
on a manifest of images, scored with :mod:`samvg.metrics`, resumable, with a markdown report."""

from samvg.bench.manifest import BenchImage, read_manifest
from samvg.bench.methods import DEFAULT_METHODS, METHODS, Method, MethodRun
from samvg.bench.report import write_report
from samvg.bench.runner import BenchOutcome, run_bench

__all__ = [
    "DEFAULT_METHODS",
    "METHODS",
    "BenchImage",
    "BenchOutcome",
    "Method",
    "MethodRun",
    "read_manifest",
    "run_bench",
    "write_report",
]
