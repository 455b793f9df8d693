"""Whether a contact law compiled by Numba gives NumPy's bits: the check that lets a user's law run compiled.

The compiled step (:mod:`.numba_step`) promises the NumPy engine's numbers bit for bit.  A law of
arithmetic, ``sqrt``, ``abs``, ``minimum``/``maximum``, ``copysign`` and comparisons meets that
promise by construction: IEEE 754 rounds each of these operations correctly, so NumPy's loops and
Numba's scalar code give the same result (Numba contracts no multiply-add without ``fastmath``).
``**`` with a non-trivial exponent, ``exp``, ``log`` and the other transcendental functions are
not correctly rounded: NumPy takes vectorised implementations of them where the CPU has the
instructions (SVML on AVX-512) and Numba the C library's, and the two differ in the last bit for a
few per cent of arguments (measured on an AVX-512 host: ``x**1.5``, ``x**2.0`` and ``exp`` for ≈ 5 %
of uniform draws).  Which laws agree is thus a fact of the machine, not of the law's text.

:func:`law_bits` therefore evaluates the law both ways on many arguments near contact — every
candidate's own law arguments at :data:`PROBE_FACTORS` times its contact distance — and compares
the bits.  A law whose compiled values all agree runs compiled; a law that differs anywhere runs on
NumPy, with the count of differing values in the note (:func:`.numba_step.reason`).  A difference
of a transcendental function shows within a few dozen values (5 % of arguments: the chance of
missing it in :data:`PROBE_FACTORS` · candidates ≥ 256 values is below 1e-5); a law that is a pure
expression of correctly rounded operations can differ nowhere.  The laws of
:data:`.numba_step.COMPILED_LAWS` are checked by the test suite and skip this check.

Forces in mg·µm·s⁻² per m depth; distances in µm.
"""
__docformat__ = "numpy"

import numpy as np

from . import numba_driver

__all__ = ["PROBE_FACTORS", "MAX_PROBED_CANDIDATES", "MAX_PARAMETER_VALUES", "law_adapter", "law_bits"]

#: the centre distances of the check in units of each candidate's contact distance ``d0``: 256
#: values between 0.5·d0 (a deep overlap) and 1.05·d0 (just apart), spread by the golden ratio so that
#: no two candidates see the same rounding pattern
PROBE_FACTORS = 1.05 - 0.55 * ((np.arange(256) * 0.6180339887498949) % 1.0)

#: the most candidates whose arguments the check takes (evenly spaced; 256 values each)
MAX_PROBED_CANDIDATES = 64

#: a row of a law's arguments with at most this many distinct values is a parameter (k, c, the law's
#: own) whose values key the kept verdict; one with more is geometry (d0, radii) and does not
MAX_PARAMETER_VALUES = 64

_kept = {}


def law_adapter(function, m):
    """``function`` compiled with every helper of its module, and the adapter the compiled step calls.

    The adapter ``_central_law(d, a)`` passes the law the first ``m`` numbers of the tuple ``a``
    (:data:`~.numba_driver.LAW_SLOTS` numbers: a candidate's column of the law's arguments); it is
    compiled to be inlined, numbers only, so it costs no reference counts.  Made once per process
    and ``(function, m)``: the compiled step's law variant (:func:`.numba_step._law_kernels`) and
    the check (:func:`law_bits`) call the same object.

    Parameters
    ----------
    function : callable
        ``function(d, a0 … a{m−1})``: the central force on i along ``n_ij`` at centre distance ``d``.
    m : int
        Arguments after ``d`` (≤ :data:`~.numba_driver.LAW_SLOTS`).

    Returns
    -------
    numba.core.registry.CPUDispatcher
        The adapter.

    Raises
    ------
    Exception
        Whatever Numba raises for a law it cannot compile (at the first call of the adapter).
    """
    key = ("adapter", function, m)
    if key not in _kept:
        import numba
        numba_driver.register_helpers()
        law = numba_driver.jit_deep(function)
        source = "def _central_law(d, a):\n    return LAW(d" + "".join(f", a[{i}]" for i in range(m)) + ")\n"
        namespace = {"LAW": law}
        exec(source, namespace)           # (an adapter of m arguments)
        _kept[key] = numba.njit(namespace["_central_law"], inline="always")
    return _kept[key]


def _probe(function, m):
    """A compiled loop of the adapter over columns: ``out[p] = adapter(d[p], A[:, p])`` (kept per law)."""
    key = ("probe", function, m)
    if key not in _kept:
        import numba
        slots = ", ".join(f"A[{i}, p]" for i in range(numba_driver.LAW_SLOTS))
        source = ("def _probe(d, A, out):\n"
                  "    for p in range(d.shape[0]):\n"
                  f"        out[p] = LAW(d[p], ({slots}))\n")
        namespace = {"LAW": law_adapter(function, m)}
        exec(source, namespace)
        _kept[key] = numba.njit(namespace["_probe"])
    return _kept[key]


def law_bits(name, function, rows, d0):
    """Whether the compiled ``function`` gives NumPy's bits on the arguments of these candidates.

    Parameters
    ----------
    name : str
        The law's name, for the text.
    function : callable
        ``function(d, a0 … a{m−1})``, evaluated by NumPy on arrays and compiled on numbers.
    rows : ndarray (m, P)
        Each candidate's arguments after ``d`` (``m`` ≤ :data:`~.numba_driver.LAW_SLOTS`).
    d0 : ndarray (P,)
        Each candidate's contact distance (µm): the scale of the probed distances.

    Returns
    -------
    str or None
        None where every probed value has the same bits both ways (NaN matching NaN); else why
        the law runs on NumPy (how many of how many values differ), a text for the step's note.
        Kept per process for the law and the values of its parameter rows
        (:data:`MAX_PARAMETER_VALUES`): the candidates of later rebuilds reuse it.

    Raises
    ------
    Exception
        Whatever Numba raises for a law it cannot compile.
    """
    rows = np.asarray(rows, dtype=float)
    m, P = rows.shape
    if P == 0:
        return None
    # the verdict is kept per law and per values of its parameter-like rows (those with few distinct
    # values: k, c, the law's own parameters), not of its geometric rows (d0, radii: new at every
    # rebuild of the candidate lists), so a run checks its law once, not at every rebuild
    distinct = [np.unique(row) for row in rows]
    key = ("verdict", function, m) + tuple(u.tobytes() for u in distinct if len(u) <= MAX_PARAMETER_VALUES)
    if key not in _kept:
        _kept[key] = _verdict(name, function, rows, d0)
    return _kept[key]


def _verdict(name, function, rows, d0):
    """:func:`law_bits` evaluated (not kept)."""
    m, P = rows.shape
    take = np.unique(np.linspace(0, P - 1, min(P, MAX_PROBED_CANDIDATES)).round().astype(np.int64))
    K = len(PROBE_FACTORS)
    d = (np.asarray(d0, dtype=float)[take][None, :] * PROBE_FACTORS[:, None]).ravel()
    A = np.zeros((numba_driver.LAW_SLOTS, d.size))
    A[:m] = np.tile(rows[:, take], (1, K))
    with np.errstate(all="ignore"):
        expected = np.broadcast_to(np.asarray(function(d, *A[:m]), dtype=float), d.shape)
        got = np.empty(d.size)
        _probe(function, m)(d, np.ascontiguousarray(A), got)
    same = (expected.view(np.int64) == got.view(np.int64)) | (np.isnan(expected) & np.isnan(got))
    bad = int(d.size - np.count_nonzero(same))
    if bad == 0:
        return None
    return (f"contact_law={name!r} compiled differs from NumPy in the last bit for {bad} of {d.size} probed "
            "distances (a function such as ** or exp that the two round otherwise on this machine)")
