"""The array namespace of the engine: NumPy by default, CuPy with ``backend="cupy"`` (docs/backends.md).

The engine's kernels take the namespace of their inputs (:func:`array_namespace`) and call only
functions that NumPy and CuPy share.  This module holds the few things that cannot be written
once for both:

* :func:`get_backend` — a backend by name (``"numpy"``, ``"numba"``, ``"cupy"``, or one registered with
  :func:`register_backend`, e.g. the CPU stand-in device of the tests), checked before any work;
  :func:`resolve_backend` — the one rule of selection: ``"auto"`` (every default) is the
  environment variable ``PARTICLESHEAR_BACKEND`` when set, else ``"numba"`` where Numba can be
  imported, else ``"numpy"``; :func:`identity_backend` — the backends that give NumPy's bits are
  one run identity;
* :class:`SegmentSum` — sums of weights into bins (the scatter of pair forces to spheres; on CuPy
  also the sums and minima over a replica's rows): ``bincount`` on NumPy; on CuPy a gather of each
  bin's rows into a padded (bins, width) matrix, built once per candidate set, and a sum along its
  rows, which is deterministic (no atomic adds, so a GPU run is reproducible bit for bit) and reads
  nothing on the host per step (``cupy.bincount`` computes ``max(x) + 1`` on the host every call);
* :func:`to_host` — **the one door from the device to the host**.  Every read of a device value
  by the engine goes through it with a reason from :data:`REASONS`; CuPy forbids the implicit
  ones (``numpy.asarray(device_array)``, ``float()``, ``if device_bool:``) and a step performs only
  the named ones.

CuPy is never imported by importing this module: only :func:`get_backend` ("cupy") imports it,
and :func:`array_namespace` recognises CuPy arrays only once CuPy has been imported by someone.
"""
__docformat__ = "numpy"

import contextlib
import os
import sys
import warnings

import numpy as np

__all__ = ["select", "maximum", "Backend", "get_backend", "register_backend", "unregister_backend", "array_namespace",
           "backend_of", "resolve_backend", "default_backend", "identity_backend", "numba_importable", "backend_names",
           "BACKEND_ENV", "AUTO_DEFAULT", "auto_without_numba", "NUMBA_INSTALL", "to_host", "SegmentSum", "REASONS", "record_host_reads", "CUPY_INSTALL"]

#: how to install CuPy for CUDA 12 (named in the error of ``backend="cupy"`` without it)
CUPY_INSTALL = "pip install cupy-cuda12x"
#: how to install Numba (named in the error of ``backend="numba"`` without it)
NUMBA_INSTALL = "pip install particleShear[fast]"
#: the environment variable that sets what ``backend="auto"`` (the default) stands for (:func:`resolve_backend`)
BACKEND_ENV = "PARTICLESHEAR_BACKEND"

#: the reasons for which the engine reads device values on the host (the argument ``why`` of :func:`to_host`)
REASONS = {
    "flags": "the per-step flags: neighbour-list rebuilds due, the stability guard's verdict",
    "d = 0": "a pair at zero distance needs a random normal from its replica's NumPy generator",
    "rebuild": "positions of the replicas whose candidate list is rebuilt (the candidate search runs on the host)",
    "pair history": "state, ξ and relations of the candidate pairs, written back into the per-replica lists",
    "layout": "the width (largest bin) of the padded gather of a new candidate set",
    "guard": "the values the stability guard reports when a replica failed",
    "series": "the recorded series and tensors, at the end of a phase",
    "state": "copies of the state between host and device: at set-up (radii, boxes, skins) or when inspected",
    "scalar law": "a force law callback that accepts only numbers, evaluated pair by pair on the host",
    "register": "the last force phase's terms, for the force register of a documented ensemble",
    "microstructure": "positions, strain and contact forces at a snapshot of the stroboscopic observer (once per period)",
}

def select(cond, a, b):
    """``a`` where ``cond`` holds, else ``b``: the one branch a law may take (docs/backends.md, "One law, two drivers").

    On arrays (NumPy, or CuPy through NumPy's dispatch) it is ``numpy.where(cond, a, b)``; inside
    compiled code it is ``a if cond else b`` on numbers (registered with Numba by
    :func:`particleShear.engine.numba_driver.register_helpers`, only where Numba is installed).

    Parameters
    ----------
    cond : ndarray of bool or bool
        The condition, per element.
    a, b : ndarray or float
        The values where it holds and where it does not (broadcast).

    Returns
    -------
    ndarray or float
    """
    return np.where(cond, a, b)


def maximum(a, b):
    """Element-wise maximum of a law (``max`` on two numbers, ``numpy.maximum`` otherwise; Numba: ``max``).

    Parameters
    ----------
    a, b : ndarray or float
        The operands (broadcast).

    Returns
    -------
    ndarray or float
    """
    if isinstance(a, float) and isinstance(b, float):   # (the documented per-pair callbacks: no ufunc call)
        return max(a, b)
    return np.maximum(a, b)


def minimum(a, b):
    """Element-wise minimum (``min`` on two numbers, ``numpy.minimum`` otherwise; Numba: ``min``).

    Parameters
    ----------
    a, b : ndarray or float
        The operands (broadcast).

    Returns
    -------
    ndarray or float
    """
    if isinstance(a, float) and isinstance(b, float):
        return min(a, b)
    return np.minimum(a, b)


_HOST_TYPES = (np.ndarray, np.generic, bool, int, float, complex, type(None))

_log = None   # list receiving each reason while record_host_reads() is active


@contextlib.contextmanager
def record_host_reads():
    """Record the reason of every :func:`to_host` call made inside the ``with`` block.

    Yields
    ------
    list of str
        The ``why`` of each call, in order (filled while the block runs).
    """
    global _log
    outer, _log = _log, []
    try:
        yield _log
    finally:
        _log = outer


class Backend:
    """An array backend: its namespace and how arrays go to and come back from it.

    Parameters
    ----------
    name : str
        The name users pass as ``backend=``.
    xp : module or object
        The array namespace (NumPy's functions: ``zeros``, ``where``, ``sqrt``, ``concatenate``, ...).
    host : bool
        True when the arrays live in host memory and reading them is free (NumPy): the engine
        then keeps the early exits and caches that cost a host read on a device.
    asarray : callable
        ``asarray(numpy_array) -> device array`` (a copy on the device).
    to_host : callable
        ``to_host(device_array) -> numpy.ndarray``.
    owns : callable
        ``owns(array) -> bool``: the array belongs to this backend.
    ordered_reductions : bool, default True
        The namespace's ``bincount(index, weights, minlength)``, ``add.reduceat`` and
        ``minimum.reduceat`` reduce each bin or segment in row order without a host read (NumPy).
        False (CuPy: ``bincount`` adds atomically, in no fixed order, and reads ``max(index)`` on
        the host; ``add.reduceat`` is a difference of two prefix sums, which rounds otherwise;
        ``minimum.reduceat`` does not exist; docs/backends.md) makes
        :class:`SegmentSum` and the per-replica sums and minima use a padded gather and a
        reduction along rows.
    """

    #: the force terms of a step run in one compiled loop (:mod:`.numba_driver`), on NumPy arrays
    compiled = False

    def __init__(self, name, xp, host, asarray, to_host, owns, ordered_reductions=True):
        self.name, self.xp, self.host = name, xp, bool(host)
        self.asarray, self._to_host, self.owns = asarray, to_host, owns
        self.ordered_reductions = bool(ordered_reductions)

    def __repr__(self):
        return f"Backend({self.name!r})"


def _numpy_backend():
    return Backend("numpy", np, True, np.asarray, np.asarray, lambda a: isinstance(a, (np.ndarray, np.generic)))


def _numba_backend():
    try:
        import numba  # noqa: F401
    except Exception as exc:  # ImportError, or a Numba build that does not fit the installed NumPy
        raise ValueError(f"backend='numba' needs Numba, which cannot be imported here ({exc}): "
                         f"install it with `{NUMBA_INSTALL}`, or choose backend='numpy' or 'auto'") from None
    b = Backend("numba", np, True, np.asarray, np.asarray, lambda a: isinstance(a, (np.ndarray, np.generic)))
    b.compiled = True
    return b


def numba_importable():
    """Whether Numba can be imported here (what ``PARTICLESHEAR_BACKEND=auto`` chooses by).

    Returns
    -------
    bool
        False also for a Numba build that fails to import (e.g. one that does not fit the
        installed NumPy).
    """
    try:
        import numba  # noqa: F401
    except Exception:
        return False
    return True


#: why Numba is not what ``"auto"`` stands for in this process although it can be imported (its
#: compile failed: :func:`auto_without_numba`); empty while it is
_AUTO_WITHOUT_NUMBA = []


def auto_without_numba(reason):
    """Make ``"auto"`` stand for NumPy for the rest of this process: Numba imports but its compile
    failed (an unsupported Numba build, for instance).  Warns once, naming the reason; an explicit
    ``backend="numba"`` is not affected (its runs raise the compile's error).

    Parameters
    ----------
    reason : str or Exception
        What failed.
    """
    if not _AUTO_WITHOUT_NUMBA:
        warnings.warn(f"backend 'auto': Numba is installed but compiling its loops failed ({reason}); this process "
                      "runs NumPy (the same numbers)", RuntimeWarning, stacklevel=2)
    _AUTO_WITHOUT_NUMBA.append(str(reason))


def backend_names():
    """The names ``backend=`` accepts: every backend (registered ones included) and ``"auto"``.

    Returns
    -------
    tuple of str
    """
    return (*_FACTORIES, "auto")


#: What ``backend="auto"`` stands for when :data:`BACKEND_ENV` is unset: ``"auto"``, i.e. Numba
#: where it can be imported (the whole step compiled, the same bits as NumPy, the default run
#: ~3× faster once its cache is warm; docs/backends.md, "Selecting a backend"), else NumPy.
AUTO_DEFAULT = "auto"


def default_backend():
    """The backend ``"auto"`` stands for: the environment variable :data:`BACKEND_ENV` when it is
    set (and not empty), else :data:`AUTO_DEFAULT`.

    Returns
    -------
    str
        A name of :func:`backend_names` (``"auto"`` when the variable says so).

    Raises
    ------
    ValueError
        When the variable names no backend (naming the variable, its value and the allowed values).
    """
    value = os.environ.get(BACKEND_ENV, "").strip()
    if not value:
        return AUTO_DEFAULT
    if value not in backend_names():
        raise ValueError(f"the environment variable {BACKEND_ENV}={value!r} is out of range: "
                         f"allowed {', '.join(map(repr, backend_names()))} (or unset)")
    return value


def resolve_backend(name="auto"):
    """The backend a run uses: the one rule of backend selection (docs/backends.md).

    ``"auto"`` (the default of every ``backend=``; also None) is the environment variable
    :data:`BACKEND_ENV` when it is set, otherwise :data:`AUTO_DEFAULT` (``"auto"``); ``"auto"``
    then means ``"numba"`` where Numba can be imported (:func:`numba_importable`), else ``"numpy"``.
    Any other name is returned as it is (:func:`get_backend` checks that it can run here).

    Parameters
    ----------
    name : str or None
        ``"auto"``, ``"numpy"``, ``"numba"``, ``"cupy"``, a registered name, or None (``"auto"``).

    Returns
    -------
    str
        The name of a backend (not ``"auto"``).

    Raises
    ------
    ValueError
        For a value of :data:`BACKEND_ENV` that names no backend.
    """
    if name is None or name == "auto":
        name = default_backend()
    if name == "auto":
        return "numba" if numba_importable() and not _AUTO_WITHOUT_NUMBA else "numpy"
    return name


def identity_backend(name):
    """The backend as the run identity sees it: ``"numpy"`` for every backend that gives NumPy's bits.

    ``"numpy"``, ``"numba"`` (the same laws in a compiled loop, bit-identical) and ``"auto"`` (one
    of them, or the environment's choice) are one run: the same id, the same results row.  Any
    other name (``"cupy"``: equal to rounding, not bit for bit; a registered backend) is itself.

    Parameters
    ----------
    name : object
        A run's ``backend`` input, or its results-table cell.

    Returns
    -------
    object
        ``"numpy"``, or ``name`` unchanged.
    """
    return "numpy" if name is None or name in _BIT_IDENTICAL else name


def _cupy_backend():
    try:
        import cupy
    except Exception as exc:  # ImportError, or a CuPy build that fails to load its CUDA libraries
        raise ValueError(f"backend='cupy' needs CuPy and a CUDA device: CuPy cannot be imported ({exc}); "
                         f"install it with `{CUPY_INSTALL}` (CUDA 12) or choose backend='numpy'") from None
    try:
        n = cupy.cuda.runtime.getDeviceCount()
    except Exception as exc:  # no driver, no device
        raise ValueError(f"backend='cupy' needs CuPy and a CUDA device: no CUDA device is usable ({exc}); "
                         "choose backend='numpy'") from None
    if n < 1:
        raise ValueError("backend='cupy' needs CuPy and a CUDA device: CuPy found no CUDA device; "
                         "choose backend='numpy'")
    return Backend("cupy", cupy, False, cupy.asarray, cupy.asnumpy, lambda a: isinstance(a, cupy.ndarray),
                   ordered_reductions=False)


_FACTORIES = {"numpy": _numpy_backend, "numba": _numba_backend, "cupy": _cupy_backend}
#: the backends whose runs are NumPy's bit for bit (one run identity, :func:`identity_backend`)
_BIT_IDENTICAL = ("numpy", "numba", "auto")
_MADE = {}


def register_backend(name, factory):
    """Make ``factory()`` (returning a :class:`Backend`) available as ``backend=name``.

    Used by the tests for a CPU stand-in device; a factory raises ValueError when its backend
    cannot run here.

    Parameters
    ----------
    name : str
        The new backend's name.
    factory : callable
        ``factory() -> Backend``, called at the first :func:`get_backend` of ``name``.
    """
    _FACTORIES[name] = factory
    _MADE.pop(name, None)


def unregister_backend(name):
    """Remove a backend added with :func:`register_backend` ("numpy" and "cupy" stay).

    Parameters
    ----------
    name : str
    """
    if name not in ("numpy", "numba", "cupy"):
        _FACTORIES.pop(name, None)
        _MADE.pop(name, None)


def get_backend(name="auto"):
    """The backend called ``name``, checked to be usable here.

    Parameters
    ----------
    name : str or Backend or None
        ``"auto"`` (default; also None: :func:`resolve_backend`), ``"numpy"``, ``"numba"`` (needs
        Numba), ``"cupy"`` (needs CuPy and a CUDA device) or a registered name; a
        :class:`Backend` is returned as it is.

    Returns
    -------
    Backend

    Raises
    ------
    ValueError
        For an unknown name (naming ``backend``, its value and the allowed values), for a value
        of :data:`BACKEND_ENV` that names no backend, for ``"numba"`` without Numba, or for
        ``"cupy"`` without CuPy or without a CUDA device.
    """
    if isinstance(name, Backend):
        return name
    if not (name is None or isinstance(name, str) and name in backend_names()):
        raise ValueError(f"backend={name!r} is out of range: allowed {', '.join(map(repr, backend_names()))}")
    name = resolve_backend(name)
    b = _MADE.get(name)
    if b is None:
        b = _MADE[name] = _FACTORIES[name]()
    return b


def backend_of(*arrays):
    """The :class:`Backend` of the arrays (NumPy for ndarrays and Python numbers).

    Parameters
    ----------
    *arrays : array or number
        Arrays of one backend (numbers and None are ignored).

    Returns
    -------
    Backend
    """
    for a in arrays:
        if isinstance(a, _HOST_TYPES):
            continue
        for name, b in _MADE.items():
            if name != "numpy" and b.owns(a):
                return b
        if "cupy" in sys.modules and "cupy" not in _MADE:   # a CuPy array made outside get_backend
            import cupy
            if cupy.get_array_module(a) is cupy:
                return get_backend("cupy")
    return get_backend("numpy")


def array_namespace(*arrays):
    """The array namespace of the arrays: ``numpy`` for ndarrays, ``cupy`` for CuPy arrays.

    Parameters
    ----------
    *arrays : array or number
        Arrays of one backend (numbers and None are ignored).

    Returns
    -------
    module
        The namespace whose functions accept and return such arrays.
    """
    for a in arrays:
        if not isinstance(a, _HOST_TYPES):
            return backend_of(*arrays).xp
    return np


def to_host(array, why):
    """Read a device array on the host: the engine's only device → host transfer.

    On NumPy it returns the array itself (no copy).  ``why`` names the reason (a key of
    :data:`REASONS`); it is recorded while :func:`record_host_reads` is active.

    Parameters
    ----------
    array : array
        An array of any backend.
    why : str
        A key of :data:`REASONS`.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ValueError
        If ``why`` is not a key of :data:`REASONS` (a host read without a named reason).
    """
    if why not in REASONS:
        raise ValueError(f"why={why!r} is out of range: allowed {', '.join(map(repr, REASONS))}")
    if _log is not None:
        _log.append(why)
    if isinstance(array, (np.ndarray, np.generic)):
        return array
    return backend_of(array)._to_host(array)


class SegmentSum:
    """Sums of weights into ``n`` bins by a fixed index: ``out[k] = Σ_{index[p] = k} w[p]``.

    Built once per index (the scatter of a candidate set, the replica of each row) and applied
    every step.  On NumPy it is ``numpy.bincount(index, w, n)`` (each bin summed in row order);
    on CuPy (:attr:`Backend.ordered_reductions` false) the rows of each bin are gathered into a
    padded ``(n, width)`` matrix (padding points to an appended 0) and summed along its rows —
    deterministic and free of host reads.
    The two agree to rounding (a different order of the same additions).

    Parameters
    ----------
    index : numpy.ndarray of int (P,)
        Bin of each row (0 … n−1), on the host.
    n : int
        Number of bins.
    backend : Backend
        Where the weights live.
    """

    def __init__(self, index, n, backend):
        self.n = int(n)
        self.backend = backend
        self.index = backend.asarray(np.asarray(index, dtype=np.intp))
        self._min_gather = None
        self.gather = None if backend.ordered_reductions else self._padded()

    def _padded(self):
        """The (n, width) gather matrix: row k lists the rows of bin k in order, padded with P (→ the appended value).

        Built on the backend (a stable sort of the index, each bin's first and last sorted row by
        ``searchsorted``); its width is read on the host ("layout").  ``bincount`` is avoided: on
        CuPy it reads ``any(index < 0)`` and ``max(index)`` on the host at every call."""
        xp = self.backend.xp
        index = self.index
        P = len(index)
        try:
            order = xp.argsort(index, kind="stable")
        except TypeError:  # pragma: no cover - CuPy before v12 sorts stably without the keyword
            order = xp.argsort(index)
        bins = index[order]                                   # the bin of each sorted row (non-decreasing)
        edges = xp.arange(self.n)
        start = xp.searchsorted(bins, edges, side="left")    # first sorted row of each bin
        counts = xp.searchsorted(bins, edges, side="right") - start
        width = int(to_host(counts.max(), "layout")) if P and self.n else 0
        rank = xp.arange(P) - start[bins]                     # position of each row within its bin
        gather = xp.full((self.n, max(width, 1)), P, dtype=np.intp)
        gather[bins, rank] = order
        return gather

    def __call__(self, w):
        """The sums per bin of ``w`` (P,), or of each row of ``w`` (rows, P).

        Parameters
        ----------
        w : array (P,) or (rows, P)
            Weights of the rows, any unit, on the backend.

        Returns
        -------
        array (n,) or (rows, n)
        """
        xp = self.backend.xp
        if self.gather is None:
            if w.ndim == 1:
                return xp.bincount(self.index, w, self.n)
            return xp.stack([xp.bincount(self.index, w[k], self.n) for k in range(w.shape[0])])
        pad = xp.zeros(w.shape[:-1] + (1,), dtype=w.dtype)
        padded = xp.concatenate((w, pad), axis=-1)
        return padded[..., self.gather].sum(axis=-1)

    def minimum(self, w):
        """The smallest value of ``w`` per bin (``inf`` for a bin without rows).

        Order-free, so every backend uses the padded gather (padding ``inf``).

        Parameters
        ----------
        w : array (P,)
            Values of the rows, on the backend.

        Returns
        -------
        array (n,)
        """
        xp = self.backend.xp
        if self.gather is None and self._min_gather is None:
            self._min_gather = self._padded()
        gather = self._min_gather if self.gather is None else self.gather
        padded = xp.concatenate((w, xp.full(1, float("inf"), dtype=w.dtype)))
        return padded[gather].min(axis=1)
