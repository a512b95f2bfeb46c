"""Recycled output blocks for large solves.

A solve of a million samples writes a hundred megabytes or more into new
arrays.  New memory from the operating system arrives one page fault at a
time, each page zeroed first: on this project's 2-core machine that costs
about a third of a Jansen leg's whole solve (measured: 48 ms into new arrays,
33 ms into the same arrays again, one thread).  A solve called again and again
(a benchmark, an optimiser, an animation) can write into the block of an
earlier result instead, once nothing holds that result any more.

:func:`block` hands out an array whose memory is a *pool* block, and the pool
keeps a reference to the block.  Every view numpy makes of the array (the
result's per-part rows, a user's slice of them) references the block itself
(numpy collapses the chain of bases), so the block's reference count is the
pool's own references exactly when no view of it is alive anywhere: only then
is it handed out again (a released block up to twice the size of a request
serves it).  When a request finds no released block of its size, released
blocks are dropped, oldest first, until they are no more than the blocks in
use (:func:`held_bytes`) and they and the new block stay within
:data:`MAX_BYTES`: the pool follows what its caller holds, so a long-running
caller that asks for many sizes (a render solving motion after motion) keeps
at most as much memory in released blocks as in results it holds, without
calling :func:`release` (which drops them all, and asks the allocator to
return free memory to the system).  A loop that asks for the same sizes again
and again finds its released blocks every time and drops none.  Set
``PLANAR_RECYCLE=0`` to turn recycling off (every block is new).

The reference count test needs CPython's reference counting; where it does
not behave as measured at import (another interpreter, a free-threaded
build) recycling is off.
"""

from __future__ import annotations

import os
import sys
from threading import Lock
from typing import Any

import numpy as np

__all__ = ["MAX_BYTES", "MIN_BYTES", "block", "held_bytes", "pooled_bytes", "release"]

#: smallest block worth recycling (below it new memory costs little; above it glibc maps new pages, a fault
#: each: a 1e5-sample solve's driver copy, validity and codes, 1.1 MB, cost Jansen's leg 0.1-0.3 ms of 2.4)
MIN_BYTES = 1 << 16
#: most bytes the pool keeps in blocks nothing else holds
MAX_BYTES = 1 << 29

_LOCK = Lock()
_POOL: list[np.ndarray[Any, Any]] = []  # oldest first


def _count(pool: list[np.ndarray[Any, Any]], i: int) -> int:
    """``sys.getrefcount`` of ``pool[i]``, always taken the same way (so it compares with :data:`_FREE`)."""
    return sys.getrefcount(pool[i])


def _measure() -> int:
    """What :func:`_count` gives for a block nothing but its pool holds, or -1 when reference
    counts do not tell (a view of a view must add exactly one, and dropping it take it back)."""
    pool = [np.empty(1)]
    free = _count(pool, 0)
    v = pool[0].view(np.uint8).reshape(8)[2:]  # a view of a view: its base is the block itself
    held = _count(pool, 0)
    del v
    gil = getattr(sys, "_is_gil_enabled", lambda: True)()
    return free if gil and held == free + 1 and _count(pool, 0) == free else -1


#: what :func:`_count` gives for a block only the pool holds
_FREE = _measure()


def _enabled() -> bool:
    text = os.environ.get("PLANAR_RECYCLE", "").strip().lower()
    if text in ("", "1", "true", "yes", "on"):
        return _FREE > 0
    if text in ("0", "false", "no", "off"):
        return False
    from planar.errors import InputError

    raise InputError("PLANAR_RECYCLE", os.environ["PLANAR_RECYCLE"], "0 (off) or 1 (on: the default)")


def block(shape: tuple[int, ...], dtype: Any = float) -> np.ndarray[Any, Any]:
    """An uninitialised C-contiguous array of ``shape`` (``np.empty``), recycled from the pool when it can be."""
    dt = np.dtype(dtype)
    nbytes = int(np.prod(shape, dtype=np.int64)) * dt.itemsize
    if nbytes < MIN_BYTES or not _enabled():
        return np.empty(shape, dt)
    with _LOCK:
        # the smallest released block that holds the request and wastes at most half of itself
        best = -1
        for i in range(len(_POOL)):
            size = _POOL[i].nbytes
            if nbytes <= size <= 2 * nbytes and _count(_POOL, i) == _FREE and (best < 0 or size < _POOL[best].nbytes):
                best = i
        if best >= 0:
            b = _POOL.pop(best)
            _POOL.append(b)  # most recently used last
            return b[:nbytes].view(dt).reshape(shape)  # a view: the pool's block stays referenced while it lives
        # released blocks that serve no request of this size are dropped, oldest first, until they are no
        # more than the blocks in use (and within the cap with the new block): the pool follows what
        # the caller holds, however many sizes it asks for
        _trim(min(MAX_BYTES - nbytes, _held()))
        new = np.empty(nbytes, np.uint8)
        _POOL.append(new)
        return new.view(dt).reshape(shape)


def _trim(keep: int = MAX_BYTES) -> None:
    """Drop the oldest released blocks beyond ``keep`` bytes (blocks in use are never counted or dropped)."""
    free = _free_indices()
    total = sum(_POOL[i].nbytes for i in free)
    drop = []
    for i in free:
        if total <= keep:
            break
        total -= _POOL[i].nbytes
        drop.append(i)
    for i in reversed(drop):
        del _POOL[i]


def _held() -> int:
    """Bytes of the pool's blocks that something else holds (call with the lock held)."""
    return sum(_POOL[i].nbytes for i in range(len(_POOL)) if _count(_POOL, i) != _FREE)


def held_bytes() -> int:
    """Bytes of the pool's blocks in use (held by results, or views of them, alive now)."""
    with _LOCK:
        return _held()


def _free_indices() -> list[int]:
    """Indices of the pool's blocks that nothing else holds (call with the lock held)."""
    return [i for i in range(len(_POOL)) if _count(_POOL, i) == _FREE]


def pooled_bytes() -> int:
    """Bytes held by the pool in blocks no result uses (memory planar keeps for the next large solve)."""
    with _LOCK:
        return sum(_POOL[i].nbytes for i in _free_indices())


def release() -> None:
    """Forget every released block, blocks in use unaffected; their memory goes back to the allocator, and on
    glibc the allocator is asked to return its free memory to the system (``malloc_trim``)."""
    with _LOCK:
        for i in reversed(_free_indices()):
            del _POOL[i]
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):  # not glibc: the allocator keeps what it keeps
        pass
