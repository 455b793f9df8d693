"""Whether a contact law compiled by Numba gives NumPy's bits: the check that lets a user's law run compiled.

The compiled step (:mod:`.numba_step`) promises the NumPy engine's numbers bit for bit.  A law of
arithmetic, ``sqrt``, ``abs``, ``copysign``, rounding to integers and comparisons meets that promise
by construction: IEEE 754 rounds each of these operations correctly, so NumPy's loops and Numba's
scalar code give the same result (Numba contracts no multiply-add without ``fastmath``; the law is
compiled with NumPy's error model, so a division by zero gives ``inf`` as on NumPy).  ``**`` with an
exponent Numba does not reduce to multiplications, ``exp``, ``log`` and the other transcendental
functions are not correctly rounded: NumPy takes vectorised implementations of them where the CPU
has the instructions (SVML on AVX-512) and Numba the C library's; the two differ in the last bit
for a few per cent of arguments (measured on an AVX-512 host: ``x**1.5``, ``x**2.0`` with an array
exponent and ``exp`` for ≈ 5 % of uniform draws), and a law that adds a small transcendental term
to a large linear one differs for fewer, too few for any sample to find reliably.

So the check reads the code, not a sample (:func:`law_bits`): the law and every helper it calls are
compiled for numbers and their LLVM code is read; every function that code may call must be one of
the correctly rounded intrinsics of :data:`EXACT_INTRINSICS` or C functions of :data:`EXACT_LIBRARY`,
Python's and Numba's runtime (the
wrapper that converts the arguments, the raising of an error) or another compiled helper of the law
that passes the same reading.  A law that calls anything else (``llvm.pow``, ``llvm.exp``, ``fmod``,
a function of a library) runs on NumPy, and the note names what it calls.  A law that passes is
also evaluated both ways at :data:`PROBE_FACTORS` times the contact distance of some candidates, a
second check whose failure (a difference the reading did not foresee) also sends it to NumPy.

The verdict is kept per process under the law's :func:`law_fingerprint` — its code, the code of
the helpers it calls, the values of its closure cells and of the globals it reads (Numba freezes
them at compile time) — which also names the law's compiled step in Numba's cache
(:func:`.numba_step._law_kernels`): a law edited, a closure with other values or a global set
anew gets a new check and a new compile.  The laws of :data:`.numba_step.COMPILED_LAWS` are checked
bit for bit by the test suite and skip this check.

Forces in mg·µm·s⁻² per m depth; distances in µm.
"""
__docformat__ = "numpy"

import hashlib
import re
import types

import numpy as np

from . import numba_driver

__all__ = ["EXACT_INTRINSICS", "EXACT_LIBRARY", "PROBE_FACTORS", "MAX_PROBED_CANDIDATES", "law_fingerprint", "law_adapter",
           "outside_calls", "law_bits"]

#: the LLVM intrinsics a law's compiled code may call (prefixes of their names): correctly rounded
#: or exact floating-point operations (absolute value, square root, sign transfer, rounding to an
#: integer value), integer arithmetic with its overflow checks, and hints that compute nothing
EXACT_INTRINSICS = ("llvm.fabs.", "llvm.sqrt.", "llvm.copysign.", "llvm.floor.", "llvm.ceil.", "llvm.trunc.",
                    "llvm.rint.", "llvm.nearbyint.", "llvm.round.", "llvm.roundeven.",
                    "llvm.sadd.with.overflow.", "llvm.ssub.with.overflow.", "llvm.smul.with.overflow.",
                    "llvm.uadd.with.overflow.", "llvm.usub.with.overflow.", "llvm.umul.with.overflow.",
                    "llvm.abs.", "llvm.smax.", "llvm.smin.", "llvm.umax.", "llvm.umin.",
                    "llvm.lifetime.", "llvm.assume", "llvm.expect.", "llvm.dbg.", "llvm.memcpy.", "llvm.memset.",
                    "llvm.memmove.")

#: the C library's functions a law's compiled code may call (whole names): IEEE 754 requires them
#: correctly rounded or exact (square root, absolute value, sign transfer, rounding to an integer)
EXACT_LIBRARY = frozenset(n + t for n in ("sqrt", "fabs", "copysign", "floor", "ceil", "trunc", "rint", "nearbyint",
                                            "round", "roundeven") for t in ("", "f"))

#: the runtime a compiled function's wrapper and error handling call (prefixes): no arithmetic
_RUNTIME = ("Py", "_Py", "NRT_", "numba_do_raise", "numba_gil_ensure", "numba_gil_release",
            "numba_runtime_build_excinfo_struct", "numba_unpickle")

#: the centre distances of the sampled second check in units of each candidate's contact distance
#: ``d0``: 256 values between 0.5·d0 (a deep overlap) and 1.05·d0 (just apart), spread by the golden ratio
PROBE_FACTORS = 1.05 - 0.55 * ((np.arange(256) * 0.6180339887498949) % 1.0)

#: the most candidates whose arguments the sampled check takes (evenly spaced; 256 values each)
MAX_PROBED_CANDIDATES = 64

_kept = {}


def _code_names(code):
    """The names a code object and the code objects nested in it read (globals and attributes)."""
    out = list(code.co_names)
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            out += _code_names(c)
    return out


def _feed_code(h, code):
    h.update(code.co_code)
    h.update(repr(code.co_names).encode())
    for c in code.co_consts:
        if isinstance(c, types.CodeType):
            _feed_code(h, c)
        else:
            h.update(repr(c).encode())


def _feed_value(h, v, seen):
    if isinstance(v, types.FunctionType):
        _feed_function(h, v, seen)
    elif hasattr(v, "py_func") and isinstance(v.py_func, types.FunctionType):   # (a Numba dispatcher)
        _feed_function(h, v.py_func, seen)
    elif isinstance(v, types.ModuleType):
        h.update(b"module " + v.__name__.encode())
    elif isinstance(v, np.ndarray):
        h.update(repr((v.dtype.str, v.shape)).encode() + np.ascontiguousarray(v).tobytes())
    else:
        h.update(type(v).__qualname__.encode() + b" " + repr(v).encode())


def _feed_function(h, f, seen):
    if f in seen:
        return
    seen.add(f)
    h.update(f"{f.__module__}.{f.__qualname__}".encode())
    _feed_code(h, f.__code__)
    for cell in f.__closure__ or ():
        try:
            _feed_value(h, cell.cell_contents, seen)
        except ValueError:          # (an empty cell)
            h.update(b"<empty>")
    names = _code_names(f.__code__)
    modules = []
    for name in dict.fromkeys(names):
        if name in f.__globals__:
            v = f.__globals__[name]
            h.update(name.encode())
            _feed_value(h, v, seen)
            if isinstance(v, types.ModuleType):
                modules.append(v)
    # the values read as attributes of a module (mod.SCALE): frozen by Numba at compile time too
    for module in modules:
        for name in dict.fromkeys(names):
            v = getattr(module, name, None)
            if isinstance(v, (int, float, complex, bool, str, bytes, tuple, np.ndarray, np.generic)):
                h.update(f"{module.__name__}.{name}".encode())
                _feed_value(h, v, seen)


def law_fingerprint(function):
    """A digest of everything a compiled law depends on: its code and the code of the functions it
    calls, its closure's values and the values of the globals (and module attributes) it reads.

    Parameters
    ----------
    function : callable
        The law (a Python function, or a Numba dispatcher of one).

    Returns
    -------
    str
        40 hexadecimal digits (SHA-1).
    """
    h = hashlib.sha1()
    _feed_value(h, function, set())
    return h.hexdigest()


def law_adapter(function, m, fingerprint=None):
    """``function`` compiled with every helper of its module, and the adapter the compiled step calls.

    The adapter ``_central_law(d, a)`` passes the law the first ``m`` numbers of the tuple ``a``
    (:data:`~.numba_driver.LAW_SLOTS` numbers: a candidate's column of the law's arguments); it is
    compiled to be inlined, numbers only, so it costs no reference counts.  Made once per process,
    law fingerprint and ``m``: the compiled step's law variant (:func:`.numba_step._law_kernels`)
    and the check (:func:`law_bits`) call the same object.

    Parameters
    ----------
    function : callable
        ``function(d, a0 … a{m−1})``: the central force on i along ``n_ij`` at centre distance ``d``.
    m : int
        Arguments after ``d`` (≤ :data:`~.numba_driver.LAW_SLOTS`).
    fingerprint : str, optional
        :func:`law_fingerprint` of ``function`` (computed when not given).

    Returns
    -------
    numba.core.registry.CPUDispatcher
        The adapter.

    Raises
    ------
    Exception
        Whatever Numba raises for a law it cannot compile (at the first call of the adapter).
    """
    key = ("adapter", fingerprint or law_fingerprint(function), m)
    if key not in _kept:
        import numba
        numba_driver.register_helpers()
        compiled = {}
        law = numba_driver.jit_deep(function, compiled)
        source = "def _central_law(d, a):\n    return LAW(d" + "".join(f", a[{i}]" for i in range(m)) + ")\n"
        namespace = {"LAW": law}
        exec(source, namespace)           # (an adapter of m arguments)
        adapter = numba.njit(namespace["_central_law"], inline="always")
        adapter.law_functions = tuple(compiled.values())     # (the law and its helpers, for outside_calls)
        _kept[key] = adapter
    return _kept[key]


_DECLARE = re.compile(r'^declare\b[^@]*@"?([^"(\s]+)"?\(', re.MULTILINE)
_DEFINE = re.compile(r'^define\b[^@]*@"?([^"(\s]+)"?\(', re.MULTILINE)


def outside_calls(dispatchers):
    """The functions the compiled code of ``dispatchers`` may call that are not known to round
    as NumPy does: what is neither an intrinsic of :data:`EXACT_INTRINSICS`, a function of
    :data:`EXACT_LIBRARY`, the runtime, nor a function defined in the code read.

    Parameters
    ----------
    dispatchers : iterable of numba.core.registry.CPUDispatcher
        Compiled functions (every signature they were compiled for is read).

    Returns
    -------
    list of str
        The names, sorted (empty: the code calls only exact operations).
    """
    texts = [ir for f in dispatchers for ir in f.inspect_llvm().values()]
    defined = {name for t in texts for name in _DEFINE.findall(t)}
    out = set()
    for t in texts:
        for name in _DECLARE.findall(t):
            if name in defined or name in EXACT_LIBRARY or name.startswith(_RUNTIME):
                continue
            if name.startswith("llvm.") and name.startswith(EXACT_INTRINSICS):
                continue
            out.add(name)
    return sorted(out)


def _probe(adapter):
    """A compiled loop of the adapter over columns: ``out[p] = adapter(d[p], A[:, p])`` (kept per adapter)."""
    key = ("probe", adapter)
    if key not in _kept:
        import numba
        slots = ", ".join(f"A[{i}, p]" for i in range(numba_driver.LAW_SLOTS))
        source = ("def _probe(d, A, out):\n"
                  "    for p in range(d.shape[0]):\n"
                  f"        out[p] = LAW(d[p], ({slots}))\n")
        namespace = {"LAW": adapter}
        exec(source, namespace)
        _kept[key] = numba.njit(namespace["_probe"])
    return _kept[key]


def law_bits(name, function, rows, d0, fingerprint=None):
    """Whether the compiled ``function`` gives NumPy's bits for every argument (the module's rule).

    Parameters
    ----------
    name : str
        The law's name, for the text.
    function : callable
        ``function(d, a0 … a{m−1})``, evaluated by NumPy on arrays and compiled on numbers.
    rows : ndarray (m, P)
        Each candidate's arguments after ``d`` (``m`` ≤ :data:`~.numba_driver.LAW_SLOTS`), for the
        sampled second check.
    d0 : ndarray (P,)
        Each candidate's contact distance (µm): the scale of the sampled distances.
    fingerprint : str, optional
        :func:`law_fingerprint` of ``function`` (computed when not given).

    Returns
    -------
    str or None
        None where the law's code calls only exact operations and the sample agrees bit for bit
        (NaN matching NaN); else why the law runs on NumPy, a text for the step's note.  Kept per
        process under the law's fingerprint and ``m``: a run checks its law once.

    Raises
    ------
    Exception
        Whatever Numba raises for a law it cannot compile.
    """
    rows = np.asarray(rows, dtype=float)
    m = rows.shape[0]
    fingerprint = fingerprint or law_fingerprint(function)
    key = ("verdict", fingerprint, m)
    if key not in _kept:
        _kept[key] = _verdict(name, function, rows, np.asarray(d0, dtype=float), fingerprint)
    return _kept[key]


def _verdict(name, function, rows, d0, fingerprint):
    """:func:`law_bits` evaluated (not kept)."""
    m, P = rows.shape
    adapter = law_adapter(function, m, fingerprint)
    take = np.unique(np.linspace(0, P - 1, min(P, MAX_PROBED_CANDIDATES)).round().astype(np.int64)) if P else \
        np.zeros(0, np.int64)
    K = len(PROBE_FACTORS)
    d = (d0[take][None, :] * PROBE_FACTORS[:, None]).ravel()
    A = np.zeros((numba_driver.LAW_SLOTS, max(d.size, 1)))
    A[:m, :d.size] = np.tile(rows[:, take], (1, K))
    if d.size == 0:             # (no candidate: one value at a unit distance, to compile the law)
        d = np.array([1.0])
    got = np.empty(d.size)
    _probe(adapter)(d, A, got)          # (compiles the law: Numba's error if it cannot)
    calls = outside_calls(adapter.law_functions)
    if calls:
        return (f"contact_law={name!r} calls {', '.join(calls)} in compiled code, which may round otherwise "
                "than NumPy in the last bit")
    try:
        with np.errstate(all="ignore"):
            expected = np.broadcast_to(np.asarray(function(d, *A[:m]), dtype=float), d.shape)
    except Exception as exc:       # noqa: BLE001 - the NumPy step reports it where it runs the law
        return f"contact_law={name!r} could not be evaluated on arrays by the check ({type(exc).__name__})"
    same = (expected.view(np.int64) == got.view(np.int64)) | (np.isnan(expected) & np.isnan(got))
    bad = int(d.size - np.count_nonzero(same))
    if bad == 0:
        return None
    return (f"contact_law={name!r} compiled differs from NumPy in the last bit for {bad} of {d.size} sampled "
            "distances")
