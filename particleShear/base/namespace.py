"""The array namespace of the documented classes' step, and its NumPy-only speed shims.

The classes of ``base``/``objects``/``linkable`` step NumPy arrays only.  Their hot path calls a
few NumPy functions hundreds of times per step on small arrays, where the Python wrapper or the
``__array_function__`` dispatch of a call costs as much as the work.  The C functions behind them
are bound here, and only here, so that every other module stays free of private NumPy imports
(the backend-neutral engine, :mod:`particleShear.engine`, uses none of them).  With another NumPy
layout the public functions are used instead.

Attributes
----------
xp : module
    The array namespace (NumPy).
count_nonzero, dot, where, copyto, bincount, concatenate : callable
    ``numpy.count_nonzero`` … ``numpy.concatenate`` without their Python wrapper or dispatch layer
    (identical results for ndarray arguments).
"""
__docformat__ = "numpy"

import numpy as np

xp = np

try:  # the C function behind np.count_nonzero, without its Python wrapper (a third of the call cost)
    from numpy._core.multiarray import count_nonzero
except ImportError:  # pragma: no cover - NumPy 1.x
    count_nonzero = np.count_nonzero

try:  # the C functions behind np.dot, np.where, …, without their __array_function__ dispatch (~0.3 µs a call);
    # the classes pass only ndarrays, for which dispatch changes nothing
    from numpy._core import _multiarray_umath as _mu
    dot, where, copyto = _mu.dot, _mu.where, _mu.copyto
    bincount, concatenate = _mu.bincount, _mu.concatenate
except (ImportError, AttributeError):  # pragma: no cover - other NumPy layouts
    dot, where, copyto, bincount, concatenate = np.dot, np.where, np.copyto, np.bincount, np.concatenate

__all__ = ["xp", "count_nonzero", "dot", "where", "copyto", "bincount", "concatenate"]
