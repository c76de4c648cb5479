"""Tests of samvg.trace and the synthetic masks they (and benchmarks/bench_trace.py) use."""
