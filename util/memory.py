"""Give freed heap memory back to the OS after a burst (e.g. a dropped client's buffers).

glibc keeps freed memory in its heap (and raises its mmap threshold after large frees), so a server's RSS stays
high after a burst of big buffers is freed; ``malloc_trim(0)`` returns the free pages. Elsewhere a no-op.
"""

from __future__ import annotations

import functools
from collections.abc import Callable


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    import ctypes  # here, not at the top: 1.7 MiB private in a server that may never drop a big client
    import ctypes.util

    name = ctypes.util.find_library("c")
    try:
        return getattr(ctypes.CDLL(name), "malloc_trim", None) if name else None
    except OSError:
        return None


def release_freed_memory() -> bool:
    """Return freed heap pages to the OS; True when the C library could do it."""
    trim = _malloc_trim()
    if trim is None:
        return False
    trim(0)
    return True
