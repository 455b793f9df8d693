"""Allocator tuning: keep a step's temporary host arrays in the heap (the classes' and the engine's).

A step allocates and frees a few dozen arrays of up to a few MB.  With glibc's
default thresholds large blocks are returned to the system after every step and
page-faulted back in the next one, which costs more than the arithmetic for
N ≳ 1,000 (measured: 9.8 → 4.9 ms per step at N = 10,000).  Raising the mmap and
trim thresholds once keeps that memory mapped.  The engine tunes when a NumPy
:class:`~particleShear.engine.step.BatchEngine` is made, the classes when a canvas is made
(a process-wide setting of the C library, done once and explicitly).  Only glibc on Linux is tuned;
set ``PARTICLESHEAR_NO_MALLOPT=1`` to leave the allocator alone.
"""
__docformat__ = "numpy"

import ctypes
import os
import sys

__all__ = ["tune_allocator"]

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_done = None


def tune_allocator(mmap_threshold=16 * 2 ** 20, trim_threshold=128 * 2 ** 20):
    """Raise glibc's mmap and trim thresholds once per process, so step temporaries stay mapped.

    Only the first call acts; later calls return its result.  Nothing is done off
    Linux/glibc or when the environment variable ``PARTICLESHEAR_NO_MALLOPT`` is set.

    Parameters
    ----------
    mmap_threshold : int
        Size (bytes) from which a block is allocated with ``mmap`` (default 16 MiB).
    trim_threshold : int
        Free memory (bytes) at the top of the heap above which it is returned to the
        system (default 128 MiB).

    Returns
    -------
    bool
        True if both thresholds were set, False otherwise (not glibc, disabled, or refused).
    """
    global _done
    if _done is not None:
        return _done
    _done = False
    if os.environ.get("PARTICLESHEAR_NO_MALLOPT") or not sys.platform.startswith("linux"):
        return _done
    try:
        mallopt = ctypes.CDLL("libc.so.6").mallopt
        mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
        _done = bool(mallopt(_M_MMAP_THRESHOLD, int(mmap_threshold))) and bool(
            mallopt(_M_TRIM_THRESHOLD, int(trim_threshold)))
    except (OSError, AttributeError):
        _done = False
    return _done
