"""The array backend of the engine (particleShear.engine.xp): the switch, the named host reads, CuPy.

CI has no GPU, so the backend switch is exercised with a CPU stand-in device: a namespace whose
arrays (:class:`DeviceArray`) wrap ndarrays and refuse every implicit read on the host — truth
value, ``float``/``int``/index conversion, ``item``, ``tolist``, ``tobytes``, iteration,
``numpy.asarray`` — and every mix with a host array, as CuPy does (and stricter: CuPy turns a
truth value into a silent synchronisation).  Only :func:`particleShear.engine.xp.to_host` can read
them.  The stand-in offers only the CuPy API audited for the engine (``CUPY_*`` below; the table
of docs/backends.md), so a NumPy-only function, method, ufunc method or keyword, a
repeated-index assignment (undefined order in CuPy) or a boolean-mask index fails here too.
The stand-in computes with NumPy underneath, operation for operation, so a batch measured on it
must be bit-identical to the NumPy batch: the comparison is exact and needs no tolerance,
and it runs the device variants of the step (branch-free, no host caches) against NumPy's.

With CuPy and a CUDA device, a batch on the GPU is compared with the NumPy batch (tolerance
justified in :class:`TestCuPy`).
"""
import collections
import concurrent.futures
import contextlib
import io
import unittest

import numpy as np

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries
from particleShear.engine import xp as xpmod
from particleShear.run.batch import run_batch

#: ~300 protocol steps of 20 spheres
QUICK = dict(N=20, relative_frequency=0.2, pre_periods=0.5, periods=1, post_periods=0.5, doDrawing=False,
             plotStress=False, verbose=False)

#: mixed replicas sharing one schedule: frictional only; crosslinked and cut with stronger friction and
#: a larger amplitude; crosslinked without friction
MIXED = [dict(QUICK, seed=1, theAmplitude=0.2, theMu=0.01, do_permanent_links=False, cut_lines=0),
         dict(QUICK, seed=2, theAmplitude=0.3, theMu=0.05, do_permanent_links=True, cut_lines=2),
         dict(QUICK, seed=3, theAmplitude=0.1, theMu=0.0, do_permanent_links=True, cut_lines=2)]

STANDIN = "cpu-standin"

# --- What CuPy provides -------------------------------------------------------------------------
# The stand-in offers the engine only the CuPy API audited for it, so an engine edit that uses a
# NumPy-only function, method, ufunc method or keyword fails here, on the CPU, rather than on the
# first GPU run.  Checked against CuPy's source (cupy/cupy 15.0.0a1, 2026-08: cupy/__init__.py;
# ndarray methods in cupy/_core/core.pyx; ufunc.__call__/outer/at/reduce/accumulate/reduceat in
# cupy/_core/_kernel.pyx; copyto in cupy/_manipulation/basic.py; argsort in cupy/_sorting/sort.py;
# where/searchsorted/flatnonzero in cupy/_sorting/search.py; bincount in
# cupy/_statistics/histogram.py; add.reduceat in cupy/_core/_routines_indexing.pyx), its reference
# (docs.cupy.dev: cupy.ufunc, cupy.copyto, cupy.argsort, cupy.bincount) and its page "Differences
# between CuPy and NumPy" (docs.cupy.dev/en/stable/user_guide/difference.html).  The table of
# docs/backends.md, "What the engine uses on a device, checked against CuPy", gives each entry's CuPy
# status and its use by the engine: to add a name, check it there first and add its row.

#: namespace functions -> the keywords CuPy accepts (all the same in NumPy for these uses)
CUPY_FUNCTIONS = {
    "arange": {"dtype"}, "array": {"dtype", "copy"}, "asarray": {"dtype"},
    "clip": set(),                         # cupy.clip(a, a_min, a_max): the box's fold into its interval
    "argsort": {"axis", "kind"},           # kind: only None or "stable" (CuPy >= 12; always stable)
    "concatenate": {"axis"}, "copyto": {"casting", "where"}, "count_nonzero": {"axis"},
    "cumsum": {"axis", "dtype"}, "empty": {"dtype"}, "empty_like": {"dtype"}, "eye": {"dtype"},
    "flatnonzero": set(),                  # synchronises (its size is data-dependent)
    "full": {"dtype"}, "ones": {"dtype"}, "repeat": {"axis"},
    "searchsorted": {"side", "sorter"}, "sort": {"axis"}, "stack": {"axis"}, "where": set(),
    "zeros": {"dtype"},
}
#: what CuPy has but the engine must not use on a device: "bincount" (atomic adds in no fixed order;
#: reads any(x < 0) and max(x) on the host at every call); "errstate" is absent from CuPy (devices
#: do not warn; engine/box.py falls back to a null context)

#: ufuncs, by NumPy's name (the operators of ndarray map onto them)
CUPY_UFUNCS = {"absolute", "add", "subtract", "multiply", "divide", "negative", "floor", "sqrt", "square",
               "maximum", "minimum", "copysign", "isfinite", "equal", "not_equal", "greater", "greater_equal",
               "less", "less_equal", "bitwise_and", "bitwise_or", "invert", "logical_not", "power", "remainder",
               "floor_divide", "nextafter"}
#: the namespace's names of the ufuncs (CuPy has all of them under these names)
CUPY_UFUNC_NAMES = {"abs": "absolute", "absolute": "absolute", "add": "add", "subtract": "subtract",
                    "multiply": "multiply", "divide": "divide", "true_divide": "divide", "negative": "negative",
                    "floor": "floor", "sqrt": "sqrt", "square": "square", "maximum": "maximum",
                    "minimum": "minimum", "copysign": "copysign", "isfinite": "isfinite", "equal": "equal",
                    "not_equal": "not_equal", "greater": "greater", "greater_equal": "greater_equal",
                    "less": "less", "less_equal": "less_equal", "bitwise_and": "bitwise_and",
                    "bitwise_or": "bitwise_or", "invert": "invert", "logical_not": "logical_not",
                    "power": "power", "mod": "remainder", "remainder": "remainder",
                    "floor_divide": "floor_divide", "nextafter": "nextafter"}
#: keywords of a CuPy ufunc call (no public ``where=``: CuPy raises TypeError("Wrong arguments"))
CUPY_UFUNC_KEYWORDS = {"out", "dtype", "casting"}
#: ufunc methods -> the ufuncs that have them in CuPy (None: all).  Left out: ``at`` (only ufuncs
#: with a scatter operation; atomic, so unordered) and ``reduceat`` (``add`` only, since v12, and
#: computed as a difference of two prefix sums: other rounding than NumPy's sum of each segment)
CUPY_UFUNC_METHODS = {"__call__": None, "outer": None, "reduce": {"add", "multiply"},
                      "accumulate": {"add", "multiply"}}
#: ndarray methods -> their keywords in CuPy.  ``take`` has no ``mode`` (out-of-range indices wrap)
CUPY_METHODS = {"all": {"axis", "keepdims"}, "any": {"axis", "keepdims"}, "astype": {"copy"},
                "copy": set(), "max": {"axis", "keepdims"}, "mean": {"axis", "keepdims"},
                "min": {"axis", "keepdims"}, "ravel": set(), "reshape": set(), "sum": {"axis", "dtype", "keepdims"},
                "take": {"axis"}, "transpose": set(), "view": set()}
#: metadata CuPy arrays have (reading it costs no transfer)
CUPY_METADATA = {"shape", "dtype", "ndim", "size", "T", "nbytes", "itemsize", "strides"}
#: constants and dtypes of the namespace (CuPy re-exports NumPy's)
CUPY_CONSTANTS = {"intp", "int8", "int16", "int32", "int64", "uint8", "float32", "float64", "bool_", "inf", "nan",
                  "pi", "e", "newaxis"}

#: what a device with ordered reductions adds (``Backend(ordered_reductions=True)``): a hypothetical
#: device, used to compare the device form of the step bit for bit with NumPy
ORDERED_FUNCTIONS = {"bincount": {"minlength"}}
ORDERED_UFUNC_METHODS = {"reduceat": {"add", "minimum"}}


class CuPyAPIError(AssertionError):
    """An operation on stand-in device arrays that CuPy lacks or treats differently."""


#: every use of an operation CuPy lacks (also those an except clause swallowed)
API_MISSES = []


def _not_cupy(what):
    API_MISSES.append(what)
    raise CuPyAPIError(f"{what}: not in the audited CuPy API (particleShearTest/test_backend.py, CUPY_*; "
                       "docs/backends.md, 'What the engine uses on a device, checked against CuPy')")


def _check_keywords(what, kwargs, allowed):
    extra = set(kwargs) - set(allowed)
    if extra:
        _not_cupy(f"{what}({', '.join(sorted(extra))}=)")
    if what == "argsort" and kwargs.get("kind") not in (None, "stable"):
        _not_cupy(f"argsort(kind={kwargs['kind']!r}) (CuPy accepts only None or 'stable')")


#: the allowances of the active stand-in (set by standin_registered; the ordered one adds ORDERED_*)
_ALLOW = {"functions": dict(CUPY_FUNCTIONS), "ufunc_methods": dict(CUPY_UFUNC_METHODS)}


def _allow(ordered):
    _ALLOW["functions"] = dict(CUPY_FUNCTIONS, **(ORDERED_FUNCTIONS if ordered else {}))
    _ALLOW["ufunc_methods"] = dict(CUPY_UFUNC_METHODS, **(ORDERED_UFUNC_METHODS if ordered else {}))


class HostReadError(AssertionError):
    """An implicit read of a stand-in device array on the host."""


#: every implicit host read attempted (also those an except clause swallowed)
ATTEMPTS = []


def _forbid(what):
    ATTEMPTS.append(what)
    raise HostReadError(f"implicit host read of a device array ({what}); use engine.xp.to_host(array, why)")


def _unwrap(v):
    if isinstance(v, DeviceArray):
        return v._host
    if isinstance(v, np.ndarray):
        _forbid("a host ndarray mixed with device arrays")
    if isinstance(v, tuple):
        return tuple(_unwrap(u) for u in v)
    if isinstance(v, list):
        return [_unwrap(u) for u in v]
    return v


def _wrap(v):
    if isinstance(v, np.ndarray):
        return DeviceArray(v)
    if isinstance(v, np.generic):
        return DeviceArray(np.asarray(v))      # a reduction stays on the device (0-d), as in CuPy
    if isinstance(v, tuple):
        return tuple(_wrap(u) for u in v)
    if isinstance(v, list):
        return [_wrap(u) for u in v]
    return v


def _key_arrays(key):
    """The index arrays of an (unwrapped) indexing key."""
    parts = key if isinstance(key, tuple) else (key,)
    return [k for k in parts if isinstance(k, np.ndarray)]


class DeviceArray(np.lib.mixins.NDArrayOperatorsMixin):
    """An array of the stand-in device: NumPy arithmetic underneath, CuPy's API, no implicit host reads."""

    __slots__ = ("_host",)

    def __init__(self, a):
        object.__setattr__(self, "_host", a)

    # metadata is free on a device too
    shape = property(lambda self: self._host.shape)
    dtype = property(lambda self: self._host.dtype)
    ndim = property(lambda self: self._host.ndim)
    size = property(lambda self: self._host.size)
    T = property(lambda self: DeviceArray(self._host.T))

    def __len__(self):
        return len(self._host)

    def __repr__(self):
        return f"DeviceArray(shape={self.shape}, dtype={self.dtype})"

    # implicit host reads
    def __array__(self, dtype=None, copy=None):
        _forbid("numpy.asarray")

    def __bool__(self):
        _forbid("truth value")

    def __float__(self):
        _forbid("float()")

    def __int__(self):
        _forbid("int()")

    def __index__(self):
        _forbid("index")

    def __complex__(self):
        _forbid("complex()")

    def __iter__(self):
        _forbid("iteration")

    def item(self, *args):
        _forbid("item()")

    def tolist(self):
        _forbid("tolist()")

    def tobytes(self, *args, **kwargs):
        _forbid("tobytes()")

    def __format__(self, spec):
        _forbid("format")

    # device operations
    def __getitem__(self, key):
        key = _unwrap(key)
        if any(k.dtype == bool for k in _key_arrays(key)):
            _forbid("a boolean mask as index (CuPy reads the number of its True entries on the host)")
        return _wrap(self._host[key])

    def __setitem__(self, key, value):
        key, value = _unwrap(key), _unwrap(value)
        arrays = _key_arrays(key)
        if any(k.dtype == bool for k in arrays):
            _forbid("assignment through a boolean mask (CuPy reads the number of its True entries on the host)")
        if any(k.dtype != bool for k in arrays):
            # CuPy stores an undefined one of the values aimed at one element (NumPy: the last)
            target = np.arange(self._host.size).reshape(self._host.shape)[key].ravel()
            if np.unique(target).size != target.size:
                _not_cupy("assignment through integer indices with repeats (undefined order in CuPy)")
        self._host[key] = value

    def __getattr__(self, name):
        if name.startswith("__"):   # no __array_interface__, __array_struct__, __dlpack__, ...: no host view
            raise AttributeError(name)
        if name in CUPY_METADATA:
            return getattr(self._host, name)
        if name not in CUPY_METHODS:
            _not_cupy(f"ndarray.{name}")
        attr = getattr(self._host, name)

        def method(*args, **kwargs):
            _check_keywords(name, kwargs, CUPY_METHODS[name])
            with np.errstate(all="ignore"):      # a device does not warn
                return _wrap(attr(*_unwrap(args), **{k: _unwrap(v) for k, v in kwargs.items()}))
        return method

    def __array_ufunc__(self, ufunc, method, *inputs, out=None, **kwargs):
        if ufunc.__name__ not in CUPY_UFUNCS:
            _not_cupy(f"ufunc {ufunc.__name__}")
        owners = _ALLOW["ufunc_methods"].get(method, ())
        if owners is not None and ufunc.__name__ not in owners:
            _not_cupy(f"{ufunc.__name__}.{method}")
        if method == "__call__":
            _check_keywords(ufunc.__name__, kwargs, CUPY_UFUNC_KEYWORDS)
            if any(isinstance(v, (list, tuple)) for v in inputs):
                _not_cupy(f"a list or tuple as operand of {ufunc.__name__} (CuPy ufuncs take arrays and scalars)")
        args = _unwrap(inputs)
        kwargs = {k: _unwrap(v) for k, v in kwargs.items()}
        if out is not None:
            kwargs["out"] = _unwrap(tuple(out))
        with np.errstate(all="ignore"):          # a device does not warn
            result = getattr(ufunc, method)(*args, **kwargs)
        if out is not None:
            return out[0] if len(out) == 1 else out
        return _wrap(result)

    def __array_function__(self, func, types, args, kwargs):
        # numpy.f(device array) dispatches to cupy.f in CuPy, so the same whitelist applies
        name = func.__name__
        if name not in _ALLOW["functions"]:
            _not_cupy(f"numpy.{name} on a device array")
        _check_keywords(name, kwargs, _ALLOW["functions"][name])
        with np.errstate(all="ignore"):
            return _wrap(func(*_unwrap(args), **{k: _unwrap(v) for k, v in kwargs.items()}))


class DeviceNamespace:
    """CuPy's namespace on :class:`DeviceArray`, as far as audited (``asarray``/``array`` also upload host data).

    A name CuPy lacks raises AttributeError (as ``cupy.<name>`` does, so ``getattr(xp, name, None)``
    works); one CuPy has but the engine must not use on a device raises :class:`CuPyAPIError`."""

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        if name in CUPY_CONSTANTS:
            return getattr(np, name)
        if name in CUPY_UFUNC_NAMES:
            return getattr(np, CUPY_UFUNC_NAMES[name])   # dispatches through DeviceArray.__array_ufunc__
        if name == "bincount" and name not in _ALLOW["functions"]:
            _not_cupy("bincount on a device without ordered reductions")
        if name not in _ALLOW["functions"]:
            raise AttributeError(f"the CuPy namespace has no audited {name!r} (particleShearTest/test_backend.py, "
                                 "CUPY_FUNCTIONS; "
                                 "docs/backends.md, 'What the engine uses on a device, checked against CuPy')")
        f = getattr(np, name)

        def function(*args, **kwargs):
            _check_keywords(name, kwargs, _ALLOW["functions"][name])
            with np.errstate(all="ignore"):      # a device does not warn
                return _wrap(f(*_unwrap(args), **{k: _unwrap(v) for k, v in kwargs.items()}))
        function.__name__ = name
        return function

    def asarray(self, a, dtype=None):
        return a if isinstance(a, DeviceArray) and dtype is None else DeviceArray(np.array(_host(a), dtype=dtype))

    def array(self, a, dtype=None, copy=True):
        return DeviceArray(np.array(_host(a), dtype=dtype))


def _host(a):
    return a._host if isinstance(a, DeviceArray) else a


def standin_backend(name=STANDIN, ordered=True):
    """The stand-in device as an engine backend (device semantics: ``host=False``).

    ``ordered=False`` declares, as CuPy does, that its ``bincount``/``reduceat`` cannot be used
    (atomic, unordered): the engine then takes CuPy's padded-gather sums on the CPU, with exactly
    the audited CuPy API.  ``ordered=True`` adds NumPy's ordered reductions (:data:`ORDERED_FUNCTIONS`,
    :data:`ORDERED_UFUNC_METHODS`) to it.  The allowances follow :func:`standin_registered`.
    """
    return xpmod.Backend(name, DeviceNamespace(), host=False, asarray=lambda a: DeviceArray(np.array(a)),
                         to_host=lambda a: np.array(a._host), owns=lambda a: isinstance(a, DeviceArray),
                         ordered_reductions=ordered)


@contextlib.contextmanager
def standin_registered(name=STANDIN, ordered=True):
    xpmod.register_backend(name, lambda: standin_backend(name, ordered))
    _allow(ordered)
    try:
        yield
    finally:
        _allow(False)
        xpmod.unregister_backend(name)


class InlineExecutor(concurrent.futures.Executor):
    """Runs each task at submission (the registered stand-in exists in this process only)."""

    def submit(self, fn, /, *args, **kwargs):
        fut = concurrent.futures.Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 - handed to the caller through the future
            fut.set_exception(exc)
        return fut


def assert_bit_identical(test, a, b):
    """Every number of two SimulationResults equal bit for bit (wall-clock timings excluded)."""
    for name in ("G_surface", "G_internal", "stress_surface", "stress_internal", "dt", "f", "N_steps",
                 "damping_factor", "removed_fraction"):
        test.assertEqual(getattr(a, name), getattr(b, name), name)
    test.assertEqual(sorted(a.series), sorted(b.series))
    for key in a.series:
        x, y = np.asarray(a.series[key]), np.asarray(b.series[key])
        test.assertEqual(x.shape, y.shape, key)
        test.assertEqual(x.tobytes(), y.tobytes(), key)  # also the sign of zeros


class TestStandInDevice(unittest.TestCase):
    """The stand-in itself refuses what CuPy refuses (so the engine tests below can fail)."""

    def test_implicit_reads_raise(self):
        a = DeviceArray(np.arange(3.0))
        for what, read in (("truth value", lambda: bool(a[0] > 1)), ("float()", lambda: float(a[1])),
                           ("index", lambda: [0, 1, 2][a.astype(int)[1]]), ("numpy.asarray", lambda: np.asarray(a)),
                           ("iteration", lambda: list(a)), ("tobytes()", lambda: a.tobytes()),
                           ("mix", lambda: a + np.ones(3)), ("any", lambda: bool((a > 1).any()))):
            with self.subTest(what):
                with self.assertRaises(HostReadError):
                    read()
        ATTEMPTS.clear()

    def test_device_arithmetic_is_numpy_arithmetic(self):
        x = np.linspace(-1.0, 2.0, 7)
        with standin_registered():
            dev = xpmod.get_backend(STANDIN)
            d = dev.asarray(x)
            d *= 3.0
            got = xpmod.to_host(dev.xp.where(d > 0, dev.xp.sqrt(abs(d)), 0.0), "state")
        self.assertEqual(got.tobytes(), np.where(3.0 * x > 0, np.sqrt(np.abs(3.0 * x)), 0.0).tobytes())


class TestStandInIsCuPy(unittest.TestCase):
    """The stand-in refuses what CuPy lacks or treats differently (the audit of docs/backends.md)."""

    def test_numpy_only_calls_raise(self):
        with standin_registered("cpu-standin-cupy", ordered=False):
            xp = xpmod.get_backend("cpu-standin-cupy").xp
            a, i = xp.asarray(np.arange(6.0)), xp.asarray(np.array([0, 2, 4]))
            with self.assertRaises(AttributeError):        # CuPy has no errstate (engine/box.py falls back)
                xp.errstate
            self.assertIsNone(getattr(xp, "errstate", None))
            with self.assertRaises(AttributeError):        # not audited
                xp.lexsort
            for what, call in (
                    ("bincount: atomic, reads max(x) on the host", lambda: xp.bincount(i, minlength=6)),
                    ("add.reduceat: a difference of prefix sums", lambda: xp.add.reduceat(a, i)),
                    ("minimum.reduceat: missing", lambda: xp.minimum.reduceat(a, i)),
                    ("maximum.reduce: missing", lambda: xp.maximum.reduce(a)),
                    ("add.at: atomic", lambda: xp.add.at(a, i, 1.0)),
                    ("argsort kind", lambda: xp.argsort(a, kind="quicksort")),
                    ("take mode", lambda: a.take(i, mode="clip")),
                    ("ufunc where=", lambda: xp.add(a, 1.0, where=a > 2)),
                    ("list operand", lambda: xp.add(a[:3], [1.0, 2.0, 3.0])),
                    ("ndarray.resize: absent in CuPy", lambda: a.resize(3)),
                    ("numpy function", lambda: np.unique(a))):
                with self.subTest(what), self.assertRaises(CuPyAPIError):
                    call()
            with self.assertRaises(CuPyAPIError):           # CuPy keeps an undefined one of the repeats
                a[xp.asarray(np.array([1, 1]))] = xp.asarray(np.array([5.0, 6.0]))
            with self.assertRaises(HostReadError):          # CuPy counts the mask on the host
                a[a > 2]
            with self.assertRaises(HostReadError):          # also to assign a scalar (copyto(where=) does not)
                a[a > 2] = 0.0
            self.assertEqual(xpmod.to_host(xp.argsort(a, kind="stable"), "state").tolist(), list(range(6)))
        API_MISSES.clear()
        ATTEMPTS.clear()

    def test_ordered_device_has_numpy_reductions(self):
        with standin_registered():
            xp = xpmod.get_backend(STANDIN).xp
            a, i = xp.asarray(np.arange(6.0)), xp.asarray(np.array([0, 2, 4]))
            self.assertEqual(xpmod.to_host(xp.add.reduceat(a, i), "state").tolist(), [1.0, 5.0, 9.0])
            self.assertEqual(xpmod.to_host(xp.minimum.reduceat(a, i), "state").tolist(), [0.0, 2.0, 4.0])

    def test_random_normal_at_zero_distance(self):
        # the d = 0 branch (not met by the batches above): a unit normal drawn from the pair's own
        # replica's generator, the same on the device as on the host
        from particleShear.engine.forces import normals
        dx, dy, d = np.array([3.0, 0.0, 1.0]), np.array([4.0, 0.0, 0.0]), np.array([5.0, 0.0, 1.0])
        rep = np.array([0, 1, 1])
        want = normals(dx, dy, d, rep, [np.random.default_rng(1), np.random.default_rng(2)])
        with standin_registered("cpu-standin-cupy", ordered=False):
            dev = xpmod.get_backend("cpu-standin-cupy")
            got = normals(dev.asarray(dx), dev.asarray(dy), dev.asarray(d), rep,
                          [np.random.default_rng(1), np.random.default_rng(2)])
            got = [xpmod.to_host(g, "state") for g in got]
        self.assertAlmostEqual(want[0][1] ** 2 + want[1][1] ** 2, 1.0, delta=4e-16)   # a unit vector
        self.assertEqual((want[0][0], want[1][0]), (0.6, 0.8))                       # D/d elsewhere
        for w, g in zip(want, got):
            self.assertEqual(w.tobytes(), g.tobytes())
        self.assertEqual(API_MISSES, [])


class TestGuardOnTheStandInDevice(unittest.TestCase):
    """The stability guard fires on a device as on the host: same replica, step, phase and numbers.

    A run at 40 times the default time step blows up within a few steps (kinetic energy ~40 times
    its bound at step 4 on NumPy); the device computes the verdict branch-free and reads it with the
    step's flags, then reports through the same host code."""

    def test_same_instability_as_numpy(self):
        from particleShear.base.stability import SimulationInstabilityError
        kw = dict(N=20, do_permanent_links=False, cut_lines=0, seed=1, time_step_factor=40, doDrawing=False,
                  plotStress=False, verbose=False, return_result=True)
        with self.assertRaises(SimulationInstabilityError) as host:
            doParticleShearSimulation(**kw)
        API_MISSES.clear()
        for name, ordered in (("cpu-standin-ordered", True), ("cpu-standin-cupy", False)):
            with self.subTest(name), standin_registered(name, ordered=ordered):
                with self.assertRaises(SimulationInstabilityError) as dev:
                    doParticleShearSimulation(backend=name, **kw)
                self.assertEqual((dev.exception.step, dev.exception.phase, dev.exception.pair),
                                 (host.exception.step, host.exception.phase, host.exception.pair))
                self.assertEqual(str(dev.exception), str(host.exception))
        self.assertEqual(API_MISSES, [])


class TestBatchOnTheStandInDevice(unittest.TestCase):
    """A mixed batch measured on the stand-in device equals the NumPy batch bit for bit."""

    @classmethod
    def setUpClass(cls):
        ATTEMPTS.clear()
        API_MISSES.clear()
        cls.numpy = run_batch(MIXED)
        with standin_registered(), xpmod.record_host_reads() as reads:
            cls.device = run_batch(MIXED, backend=STANDIN)
            cls.single = doParticleShearSimulation(**MIXED[1], backend=STANDIN, return_result=True)
            cls.series = doParticleShearSimulationSeries(
                executor=InlineExecutor(), batch_size=2, backend=STANDIN, N_repetitions=1, amplitudes=[0.2, 0.3],
                mu=[0.01], cut_lines=0, seed=7, **{k: v for k, v in QUICK.items() if k != "verbose"})
        cls.reads = list(reads)
        cls.attempts = list(ATTEMPTS)
        cls.misses = list(API_MISSES)
        cls.series_numpy = doParticleShearSimulationSeries(
            executor=InlineExecutor(), batch_size=2, N_repetitions=1, amplitudes=[0.2, 0.3], mu=[0.01],
            cut_lines=0, seed=7, **{k: v for k, v in QUICK.items() if k != "verbose"})

    def test_no_implicit_host_read(self):
        self.assertEqual(self.attempts, [])

    def test_only_the_audited_cupy_api(self):
        # also a miss an except clause swallowed
        self.assertEqual(self.misses, [])

    def test_batch_is_bit_identical_to_numpy(self):
        self.assertEqual(len(self.device), len(MIXED))
        for n, (d, h) in enumerate(zip(self.device, self.numpy)):
            with self.subTest(replica=n):
                assert_bit_identical(self, d, h)
                self.assertEqual(d.parameters["backend"], STANDIN)

    def test_single_run_is_bit_identical_to_numpy(self):
        # a single run is a batch of one, and a replica of a batch equals its single run
        assert_bit_identical(self, self.single, self.numpy[1])

    def test_series_is_bit_identical_to_numpy(self):
        self.assertEqual(len(self.series), 2)
        for d, h in zip(self.series, self.series_numpy):
            assert_bit_identical(self, d, h)

    def test_host_reads_are_named_and_few(self):
        # every read has a reason of REASONS (to_host refuses others); a step reads its flags once and
        # checks for pairs at d = 0 once in the force phase and once more in the ξ rule, which a batch
        # without friction and bonds (the constitution's μ = 0 blocks before crosslinking) leaves out;
        # everything else (list rebuilds, copies of the state, the series at the end) is rare
        c = collections.Counter(self.reads)
        self.assertTrue(set(c) <= set(xpmod.REASONS), set(c) - set(xpmod.REASONS))
        steps = c["flags"]
        self.assertGreater(steps, 2 * self.device[0].N_steps)     # the protocols of the batch and of the series
        self.assertGreater(c["d = 0"], steps + 2 * self.device[0].N_steps)   # the measured steps have the ξ rule
        self.assertLess(c["d = 0"], 2 * steps)                    # the frictionless blocks do not
        self.assertGreater(c["series"], 0)
        self.assertLess(sum(n for why, n in c.items() if why not in ("flags", "d = 0")), 0.2 * steps)


def assert_close(test, a, b, rtol):
    """Series and G′/G″ of two SimulationResults equal to ``rtol`` of their scale."""
    for key in ("stress_internal", "stress_surface", "strain"):
        x, y = np.asarray(a.series[key]), np.asarray(b.series[key])
        test.assertEqual(x.shape, y.shape, key)
        test.assertLessEqual(np.max(np.abs(x - y)), rtol * np.max(np.abs(y)), key)
    for name in ("G_surface", "G_internal"):
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        test.assertLessEqual(np.max(np.abs(x - y)), rtol * np.max(np.abs(y)), name)


class TestCuPySumsOnTheStandInDevice(unittest.TestCase):
    """CuPy's own code paths (padded-gather scatter, replica sums and minima) run on the CPU stand-in.

    The sums add the same terms in another order, so the results differ from NumPy's by rounding
    only (observed: ≤ 1.1e-14 of the scale of the series, ≤ 4.5e-15 for G′/G″); the tolerance 1e-9
    is that of :class:`TestCuPy`, and a wrong gather (a lost or doubled pair, a pair summed into
    another replica) changes the stresses at the percent level.
    """

    @classmethod
    def setUpClass(cls):
        ATTEMPTS.clear()
        API_MISSES.clear()
        cls.numpy = run_batch(MIXED)
        with standin_registered("cpu-standin-unordered", ordered=False):
            cls.device = run_batch(MIXED, backend="cpu-standin-unordered")
        cls.attempts = list(ATTEMPTS)
        cls.misses = list(API_MISSES)

    def test_no_implicit_host_read(self):
        self.assertEqual(self.attempts, [])

    def test_only_the_audited_cupy_api(self):
        # exactly CuPy's API (no ordered extras): a NumPy-only call of the GPU path fails here
        self.assertEqual(self.misses, [])

    def test_equal_to_numpy_to_rounding(self):
        for n, (d, h) in enumerate(zip(self.device, self.numpy)):
            with self.subTest(replica=n):
                assert_close(self, d, h, 1e-9)
                self.assertEqual(d.N_steps, h.N_steps)


class TestBadBackend(unittest.TestCase):
    """An unknown backend, or CuPy where it cannot run, is refused before any work."""

    def test_unknown_backend(self):
        for call in (lambda: run_batch(MIXED[:1], backend="nonsense"),
                     lambda: doParticleShearSimulation(backend="nonsense", **QUICK),
                     lambda: doParticleShearSimulationSeries(backend="nonsense", **QUICK),
                     lambda: xpmod.get_backend("nonsense")):
            with self.assertRaisesRegex(ValueError, r"backend='nonsense' is out of range: allowed 'numpy', 'numba', 'cupy', 'auto'"):
                call()

    def test_cupy_without_cupy_or_device(self):
        try:
            xpmod.get_backend("cupy")
        except ValueError as exc:
            self.assertIn("backend='cupy' needs CuPy and a CUDA device", str(exc))
            with self.assertRaisesRegex(ValueError, r"backend='cupy' needs CuPy and a CUDA device"):
                doParticleShearSimulation(backend="cupy", **QUICK)
        else:
            self.skipTest("CuPy and a CUDA device are present")

    def test_runs_the_engine_cannot_measure(self):
        import os
        import tempfile
        with standin_registered():
            # a drawn run is the engine's (its drawing observes the loops, reading the device state)
            plain = doParticleShearSimulation(backend=STANDIN, seed=2, return_result=True, **QUICK)
            with tempfile.TemporaryDirectory() as d:
                drawn = doParticleShearSimulation(d, backend=STANDIN, seed=2, return_result=True,
                                                  **dict(QUICK, doDrawing=True, plotStress=True, saveOutputImages=True,
                                                         imageFileType="svg", renderer="pillow"))
                self.assertEqual(len(os.listdir(drawn.image_folder)), drawn.n_images)
            self.assertGreater(drawn.n_images, 100)
            for key in plain.series:
                self.assertEqual(np.asarray(plain.series[key]).tobytes(), np.asarray(drawn.series[key]).tobytes(), key)
            # a Verlet run too (the engine's integrator)
            verlet = doParticleShearSimulation(backend=STANDIN, seed=2, integrator="verlet", return_result=True,
                                               **QUICK)
            numpy_verlet = doParticleShearSimulation(seed=2, integrator="verlet", return_result=True, **QUICK)
            self.assertEqual(verlet.G_surface, numpy_verlet.G_surface)

    def test_cli_names_the_flag(self):
        from particleShear.run.cli import main
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main(["--backend", "nonsense", "--N", "20", "--quiet"])
        self.assertEqual(code, 2)   # refused by the API's validation, with its message
        self.assertIn("--backend='nonsense' is out of range: allowed 'numpy', 'numba', 'cupy', 'auto'", err.getvalue())
        try:
            xpmod.get_backend("cupy")
        except ValueError:
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main(["--backend", "cupy", "--N", "20", "--quiet"])
            self.assertEqual(code, 2)
            self.assertIn("--backend='cupy' needs CuPy and a CUDA device", err.getvalue())

    def test_sweep_cli_names_the_flag(self):
        import json
        import os
        import tempfile

        from particleShear.sweep.cli import main
        with tempfile.TemporaryDirectory() as tmp:
            spec = os.path.join(tmp, "s.json")
            with open(spec, "w") as fh:
                json.dump({"parameters": {"N": 20, "doDrawing": False, "plotStress": False},
                           "seeds": {"root": 1, "repetitions": 1}}, fh)
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = main([spec, "--out", os.path.join(tmp, "out"), "--backend", "nonsense"])
            self.assertEqual(code, 2)
            self.assertIn("backend='nonsense' (--backend) is out of range", err.getvalue())


class TestDocumentedClassesStayOnTheHost(unittest.TestCase):
    def test_a_device_default_leaves_the_documented_classes_on_the_host(self):
        """With a device as the default backend (``PARTICLESHEAR_BACKEND``), the documented classes,
        whose engine steps the ensemble's own host rows (``state_of_ensemble(backend="auto")``), run
        on NumPy: the same spheres as with ``PARTICLESHEAR_BACKEND=numpy``, no error."""
        import math
        import os
        from unittest import mock

        from particleShearTest.test_engine import constituted

        runs = {}
        for default in ("numpy", STANDIN):
            with standin_registered(), mock.patch.dict(os.environ, {"PARTICLESHEAR_BACKEND": default}):
                ens = constituted(97, theMu=0.3, do_permanent_links=False, cut_lines=0, theAmplitude=0.1)[1]
                ens.applyingShear = True
                for k in range(10):
                    ens.setShearRate(300.0 * math.cos(0.05 * k))
                    ens.mechanical_simulation_step_calculate_forces()
                    ens.mechanical_simulation_step_calculate_acceleration(0.999, ens.dt)
                    ens.mechanical_simulation_step_calculate_movement(ens.dt)
                runs[default] = np.array([(q.x, q.y, q.xspeed, q.yspeed) for q in ens.sphereList])
        np.testing.assert_array_equal(runs["numpy"], runs[STANDIN])     # (NumPy's bits: not the device's)


class TestNoCuPyAtImport(unittest.TestCase):
    def test_importing_the_package_does_not_import_cupy(self):
        # CuPy initialises CUDA when imported: a NumPy user must never pay for it, nor a forked worker break
        import subprocess
        import sys
        code = ("import sys, particleShear, particleShear.engine.step, particleShear.run.batch; "
                "from particleShear.engine.xp import array_namespace; import numpy; "
                "assert array_namespace(numpy.zeros(2)) is numpy; print('cupy' in sys.modules)")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout.strip(), "False")


class TestSegmentSum(unittest.TestCase):
    """The device scatter (padded gather) sums the same rows into the same bins as bincount."""

    def test_padded_sum_equals_bincount(self):
        rng = np.random.default_rng(3)
        index = rng.integers(0, 40, 500)
        index[:7] = 5                     # a crowded bin; bins without rows stay 0
        numpy_ordered = xpmod.get_backend("numpy")
        padded = xpmod.Backend("padded", np, True, np.asarray, np.asarray, numpy_ordered.owns, ordered_reductions=False)
        # integer-valued weights: every partial sum is exact, so any order of the additions gives the same bits
        w = rng.integers(-1000, 1000, 500).astype(float)
        self.assertEqual(xpmod.SegmentSum(index, 45, padded)(w).tobytes(), np.bincount(index, w, 45).tobytes())
        # general weights: the same additions in another order, within n·eps of the sum of |w|
        w = rng.normal(size=500)
        got, want = xpmod.SegmentSum(index, 45, padded)(w), np.bincount(index, w, 45)
        bound = 64 * np.finfo(float).eps * np.bincount(index, np.abs(w), 45)
        self.assertTrue(np.all(np.abs(got - want) <= bound))
        self.assertEqual(xpmod.SegmentSum(index, 45, numpy_ordered)(w).tobytes(), want.tobytes())


def _cupy_usable():
    try:
        xpmod.get_backend("cupy")
        return True
    except ValueError:
        return False


@unittest.skipUnless(_cupy_usable(), "needs CuPy and a CUDA device")
class TestCuPy(unittest.TestCase):
    """A batch on the GPU equals the NumPy batch to rounding.

    Tolerance: each CuPy ufunc is one kernel, IEEE-rounded like NumPy's, but the reductions (the
    padded-gather scatter and replica sums, ``sum``/``mean`` along an axis) add in another order
    (docs/backends.md), so single sums differ by ~1 ulp (1e-16 relative).  How much the dynamics amplifies such differences was measured on the CPU:
    a 1-ulp change of every initial position and velocity of these replicas changes the recorded
    stresses by at most 1.2e-14 of their scale and G′/G″ by at most 5e-15 over this protocol
    (~1,000 steps).  A GPU injects ~1 ulp at every step, which adds up to well below 1e-12; the
    series and moduli are compared at 1e-9 of their scale, a margin of 1,000, while a real error (a
    wrong sign, a lost term or pair) changes them by more than 1e-3.
    """

    @classmethod
    def setUpClass(cls):
        cls.numpy = run_batch(MIXED)
        cls.gpu = run_batch(MIXED, backend="cupy")

    def test_series_and_moduli_match_numpy(self):
        for n, (g, h) in enumerate(zip(self.gpu, self.numpy)):
            with self.subTest(replica=n):
                assert_close(self, g, h, 1e-9)


if __name__ == "__main__":
    unittest.main()
