"""The rasterizer's threads: how many, and the pool that runs its kernels' parts.

The numba kernels release the GIL, so plain Python threads run them side by side: one band of
canvas rows per thread for the forward pass and the pixel part of the backward pass, one run of
paths per thread for the edge part. Every pixel and every vertex gradient is computed by the
same arithmetic whichever thread does it; colour gradients are summed per band and then over
the bands, so they match a single thread's to the last bits only (and exactly on one thread).
A given thread count gives the same bits on every run.
(numba's own parallel layers were not used: their worker pools spin and fight torch's.)
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor

from samvg.errors import InputError

#: More threads than this gain nothing on a 512-px canvas (the parts get too small).
MAX_THREADS = 8

_state = threading.local()
_pool_lock = threading.Lock()
_pool: ThreadPoolExecutor | None = None


def available_cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def default_threads() -> int:
    """The rasterizer's thread count when none is set: every core, at most `MAX_THREADS`."""
    return max(1, min(MAX_THREADS, available_cores()))


def render_threads() -> int:
    """The thread count this thread's rasterizer calls use."""
    threads = getattr(_state, "threads", None)
    return default_threads() if threads is None else threads


@contextlib.contextmanager
def using_render_threads(threads: int | None) -> Iterator[None]:
    """Run the rasterizer on ``threads`` threads inside the block (None: the default)."""
    if threads is not None and (
        isinstance(threads, bool) or int(threads) != threads or threads < 1
    ):
        raise InputError(f"threads must be a positive integer, got {threads!r}")
    previous = getattr(_state, "threads", None)
    _state.threads = None if threads is None else min(int(threads), MAX_THREADS)
    try:
        yield
    finally:
        _state.threads = previous


def _executor() -> ThreadPoolExecutor:
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = ThreadPoolExecutor(MAX_THREADS - 1, thread_name_prefix="samvg-render")
        return _pool


def run_parts(job: Callable[[int], object], parts: int) -> None:
    """Run ``job(0)`` to ``job(parts - 1)``, the first on this thread and the others on the
    pool, and wait for all of them (the first error is raised)."""
    if parts <= 1:
        job(0)
        return
    futures = [_executor().submit(job, part) for part in range(1, parts)]
    error: BaseException | None = None
    try:
        job(0)
    except BaseException as exc:
        error = exc
    for future in futures:
        try:
            future.result()
        except BaseException as exc:
            error = error or exc
    if error is not None:
        raise error
