"""Scratch arrays for the rasterizer's kernels, kept and handed out again.

A fit draws one canvas hundreds of times, and each step needs the same large buffers: the
per-path box accumulators (a float64 and three float32 numbers per path-box pixel, 10-30 MB on a
512-px canvas) and the backward pass's coverage gradients. As fresh allocations glibc maps them
from the kernel and unmaps them on free, so every step paid about a thousand page faults (4 ms of
a 27 ms step on the Tango folder icon, `benchmarks/results/speed.md`). A buffer here stays
allocated after use and is handed out again once nothing but the pool refers to it: an array a
forward pass saved for its backward pass keeps its buffer (numpy views hold their base), so no
buffer is ever handed out twice. No library offers this for numpy arrays; it is a few lines.
"""

from __future__ import annotations

import sys
import threading

import numpy as np

#: Free buffers beyond this many bytes in all are let go (the largest kept first).
MAX_KEPT_BYTES = 512 * 2**20

_lock = threading.Lock()
_buffers: list[np.ndarray] = []


def _in_use(index: int) -> bool:
    # The pool's list and getrefcount's argument are the two references of a free buffer (so
    # callers look buffers up by index, never holding one in a local name while asking).
    return sys.getrefcount(_buffers[index]) > 2


def scratch(shape: int | tuple[int, ...], dtype: type | np.dtype) -> np.ndarray:
    """An uninitialised C-contiguous array of ``shape`` and ``dtype`` on a reused buffer."""
    dims = (shape,) if isinstance(shape, int) else tuple(shape)
    kind = np.dtype(dtype)
    nbytes = int(np.prod(dims, dtype=np.int64)) * kind.itemsize
    with _lock:
        chosen = -1
        for index in range(len(_buffers)):  # no loop variable may hold a buffer: see _in_use
            size = _buffers[index].nbytes
            smaller = chosen < 0 or size < _buffers[chosen].nbytes
            if size >= nbytes and smaller and not _in_use(index):
                chosen = index
        if chosen < 0:  # with room to grow: a fit's boxes change size a little every step
            _buffers.append(np.empty(max(nbytes + nbytes // 4, 1), np.uint8))
            chosen = len(_buffers) - 1
        view = _buffers[chosen][:nbytes].view(kind).reshape(dims)
        _release_surplus()
    return view


def _release_surplus() -> None:
    """Drop free buffers, smallest first, while the free ones hold more than `MAX_KEPT_BYTES`."""
    free = sorted(
        (index for index in range(len(_buffers)) if not _in_use(index)),
        key=lambda index: _buffers[index].nbytes,
    )
    kept = sum(_buffers[index].nbytes for index in free)
    dropped = set()
    for index in free:
        if kept <= MAX_KEPT_BYTES:
            break
        kept -= _buffers[index].nbytes
        dropped.add(index)
    if dropped:
        _keep_only([index for index in range(len(_buffers)) if index not in dropped])


def clear() -> None:
    """Let go of every free buffer."""
    with _lock:
        _keep_only([index for index in range(len(_buffers)) if _in_use(index)])


def _keep_only(indices: list[int]) -> None:
    _buffers[:] = [_buffers[index] for index in indices]
