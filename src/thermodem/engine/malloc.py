"""Return freed array memory to the system (glibc only).

glibc serves an allocation above its mmap threshold (128 KiB) with its own memory mapping,
which ``free`` unmaps at once. But after freeing such a block glibc raises the threshold to the
block's size (up to 32 MiB), so later arrays of that size come from the heap, where freed
blocks stay resident between live ones. Every neighbour rebuild replaces the index arrays and
the particle arrays (sort), so a long run's resident memory crept up by ~60 B per particle over
ten rebuilds (50,000 spheres). Fixing the threshold at glibc's default keeps large arrays in
their own mappings: measured, the resident size stays at the live arrays plus one rebuild's
temporaries. Setting ``MALLOC_MMAP_THRESHOLD_`` in the environment takes precedence.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

M_MMAP_THRESHOLD = -3  # mallopt parameter (malloc.h)
THRESHOLD = 128 * 1024

_done = False


def fix_mmap_threshold() -> None:
    """Once per process: mallopt(M_MMAP_THRESHOLD, 128 KiB) where glibc is the allocator."""
    global _done
    if _done:
        return
    _done = True
    if "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return
    name = ctypes.util.find_library("c")
    if not name:
        return
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (musl, macOS, Windows)
        return
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    mallopt(M_MMAP_THRESHOLD, THRESHOLD)
