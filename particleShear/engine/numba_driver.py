"""The compiled pair loop (Numba, optional): the force terms of the candidates, from the same law functions.

The laws, the viscous term and the two-visit tangential rule are pure expressions of plain
arguments (:func:`~particleShear.engine.laws.linear_term`, :func:`~particleShear.engine.laws.divergent_term`,
:func:`~particleShear.engine.laws.blend_inside`, :func:`~particleShear.engine.laws.tensile_inside`,
:func:`~particleShear.engine.laws.contact_or_bond`, :func:`~particleShear.engine.terms.viscous_force`,
:func:`~particleShear.engine.tangential.two_visit_rule`, with :func:`~particleShear.engine.xp.select`
and :func:`~particleShear.engine.xp.maximum` for their branches).  The NumPy engine calls them on
arrays; this module registers the very same function objects with Numba
(:func:`jit_laws`; ``select`` becomes ``a if cond else b`` and ``maximum`` ``max`` on numbers) and calls them on numbers inside one compiled loop over the candidate pairs
(:func:`pair_terms`).  Changing a law's body therefore changes both backends (tested).

What this module compiles is the force terms of a candidate set (central scalar, elastic law,
the two tangential visits, the slip flags and the ξ reset), bit-identical to the NumPy terms
(:func:`~particleShear.engine.terms.central_term` and :func:`~particleShear.engine.terms.tangential_term`);
the step loop itself (neighbours, scatter, integration, the protocol) runs on NumPy
(docs/backends.md, "The compiled backend").

Numba is imported only inside the functions here, never by importing the package.  The compiled
code is cached (``cache=True``) in :func:`cache_dir`, a folder keyed by the source of the law
modules (Numba's own cache checks only the file of the compiled function, not the laws it calls).
"""
__docformat__ = "numpy"

import hashlib
import importlib
import inspect
import os
import sys
import tempfile

import numpy as np

from . import laws, tangential, terms, xp
from .forces import PairConstants
from .laws import blend_inside, contact_or_bond, divergent_term, linear_term, tensile_inside
from .tangential import two_visit_rule
from .terms import viscous_force

__all__ = ["available", "cache_dir", "register_helpers", "jit_laws", "jit_deep", "pair_term", "compile_pair_kernel",
           "pair_terms", "FORMS", "LAW_FUNCTIONS", "PAIR_FUNCTIONS"]

#: the code of each form of the compressive law in the compiled loop
FORMS = {laws.BLEND: 0, laws.LINEAR: 1, laws.DIVERGENT: 2}

#: the pure functions the compiled loop calls: ``(module, name)``, looked up when it is compiled
LAW_FUNCTIONS = ((laws, "linear_term"), (laws, "divergent_term"), (laws, "blend_inside"), (laws, "tensile_inside"),
                 (laws, "contact_or_bond"), (terms, "viscous_force"), (tangential, "coulomb_clip"),
                 (tangential, "two_visit_rule"))

#: the constants the compiled loop reads, in the order of the rows of its block (the kernel reads them by position)
TERM_BLOCK = PairConstants.TERM_ROWS
_TERM_START = PairConstants.FLOAT_ROWS.index(TERM_BLOCK[0])     # where they start in the engine's float block
assert PairConstants.FLOAT_ROWS[_TERM_START:_TERM_START + len(TERM_BLOCK)] == TERM_BLOCK

#: the engine modules whose functions the compiled loops run (the cache folder is keyed by their sources)
SOURCE_MODULES = ("laws", "terms", "tangential", "xp", "box", "integrate", "guard", "forces", "neighbours", "state",
                  "numba_driver", "numba_step")
_registered = set()     # the helpers registered with Numba (their ids)
_kernels = {}           # cache flag -> compiled kernel


def available():
    """Whether Numba can be imported here (bool)."""
    return xp.numba_importable()


def cache_dir():
    """The folder of the compiled code: ``$NUMBA_CACHE_DIR`` or the user's cache folder, keyed by the law sources.

    ``$PARTICLESHEAR_CACHE`` or ``$XDG_CACHE_HOME/particleShear`` (default ``~/.cache/particleShear``),
    then ``numba-<hash>``, the hash of the source files of :data:`SOURCE_MODULES` (the modules whose
    functions the compiled loops run): an edited law or rule gets a fresh folder (Numba's cache
    checks only the file of each compiled function, not the functions it calls).

    Returns
    -------
    str
        A writable folder (created; the system's temporary folder when that one cannot be written).
    """
    h = hashlib.sha1()
    for name in SOURCE_MODULES:
        with open(importlib.import_module(f"{__package__}.{name}").__file__, "rb") as f:
            h.update(f.read())
    base = os.environ.get("PARTICLESHEAR_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "particleShear")
    name = f"numba-{h.hexdigest()[:12]}"
    folder = os.path.join(os.environ.get("NUMBA_CACHE_DIR") or base, name)
    try:
        os.makedirs(folder, exist_ok=True)
        if not os.access(folder, os.W_OK):
            raise PermissionError(folder)
    except OSError:        # a read-only home: the system's temporary folder
        folder = os.path.join(tempfile.gettempdir(), "particleShear", name)
        os.makedirs(folder, exist_ok=True)
    return folder


#: the start of the symbols of this package's compiled engine functions (Numba's mangled names:
#: ``_ZN`` and the lengths and names of ``particleShear.engine``)
OWN_SYMBOLS = "_ZN13particleShear6engine"


def _indices_as_given():
    """Index arrays in this package's compiled engine functions without the wrap of negative indices.

    Numba treats a signed integer index as Python does (``a[-1]`` is the last element): every
    ``a[i]`` with a signed ``i`` tests ``i < 0`` and adds the length, a few instructions on each of the
    compiled step's many gathers (``pos[0, Ci[1, p]]``, ``Cf[_ILX, p]``, …), about a sixth of its
    time.  The engine's compiled functions (those whose symbol starts with :data:`OWN_SYMBOLS`)
    never index with a negative number, so their indices are taken as they are (what Numba does for
    an unsigned index); every other function Numba compiles (a user's law, Numba's own library)
    keeps the wrap.  The same addresses, so the same bits; once per process, before any compile
    (it changes how the code is generated, not what it computes for the engine's indices).  Where
    Numba's ``numba.np.arrayobj.fix_integer_index`` is not there or has another signature (another
    Numba), nothing changes.
    """
    try:
        from numba.core import types
        from numba.np import arrayobj
    except ImportError:          # pragma: no cover
        return
    given = getattr(arrayobj, "fix_integer_index", None)
    if given is None or getattr(given, "own_symbols", None) == OWN_SYMBOLS:
        return
    try:        # (only the function this was written against: another signature, another Numba)
        if list(inspect.signature(given).parameters) != ["context", "builder", "idxty", "idx", "size"]:
            return
    except (TypeError, ValueError):          # pragma: no cover
        return

    def fix_integer_index(context, builder, idxty, idx, size):
        if idxty.signed and builder.function.name.startswith(OWN_SYMBOLS):
            return context.cast(builder, idx, idxty, types.uintp)
        return given(context, builder, idxty, idx, size)

    fix_integer_index.own_symbols = OWN_SYMBOLS
    arrayobj.fix_integer_index = fix_integer_index


def borrowed(arrays):
    """The arrays of the tuple ``arrays`` as they are (in Python; compiled: views that own no reference).

    Numba counts the references of every array it passes to a compiled function or binds to a
    name (``NRT_incref`` and ``NRT_decref``, an atomic add each, a call of its runtime): a compiled
    block (:func:`~.numba_step._block_kernel`) calls its step once per replica and step with ~100
    arrays, about 6 % of its time in those counts.  In compiled code each array of the tuple is
    given back as a view of the same memory, shape and strides without its owner (a null
    ``meminfo``, as a view of foreign memory has): the counts of such a view are a test of a null
    pointer, and every view taken from it (a row, a slice) owns nothing either.  The same
    addresses, so the same numbers; only for a function that holds the arrays themselves for the
    whole life of the views (the block's arguments, held by its caller for the call): a view
    outliving them would point to freed memory.  Other elements of the tuple are given back as they are.
    Never in a function compiled with ``parallel=True``: Numba's parfor passes cannot see that the
    views alias the arguments and remove stores through them in a ``prange`` loop as dead (a small
    kernel lost every write), and a parfor's threads take their arrays as views owning no
    reference already (:data:`~.numba_step.BORROWED_VIEWS`).

    Parameters
    ----------
    arrays : tuple
        Arrays (and other values).

    Returns
    -------
    tuple
        The same values (compiled: the arrays as views owning no reference).
    """
    return arrays


def _borrowed_views():
    """The compiled form of :func:`borrowed` (an intrinsic of Numba's code generation), registered once."""
    from numba.core import cgutils, types
    from numba.extending import intrinsic, overload

    @intrinsic
    def _views(typingctx, arrays):
        if not isinstance(arrays, types.BaseTuple):
            return None

        def codegen(context, builder, sig, args):
            out = []
            for k, ty in enumerate(sig.args[0]):
                value = builder.extract_value(args[0], k)
                if isinstance(ty, types.Array):
                    a = context.make_array(ty)(context, builder, value=value)
                    view = context.make_array(ty)(context, builder)
                    for field in ("data", "shape", "strides", "itemsize", "nitems"):
                        setattr(view, field, getattr(a, field))
                    view.meminfo = cgutils.get_null_value(view.meminfo.type)
                    view.parent = cgutils.get_null_value(view.parent.type)
                    out.append(view._getvalue())
                else:
                    context.nrt.incref(builder, ty, value)
                    out.append(value)
            return context.make_tuple(builder, sig.return_type, out)
        return arrays(arrays), codegen

    @overload(borrowed)
    def _borrowed(arrays):
        return lambda arrays: _views(arrays)


def register_helpers():
    """Register :func:`~particleShear.engine.xp.select`, :func:`~particleShear.engine.xp.maximum` and
    :func:`~particleShear.engine.xp.minimum` with Numba for numbers (``a if cond else b``, ``max``,
    ``min``) and :func:`borrowed`, and take the engine's array indices as given
    (:func:`_indices_as_given`); once per process.

    Raises
    ------
    ImportError
        Without Numba.
    """
    from numba.extending import overload

    _indices_as_given()
    if id(xp.select) not in _registered:
        @overload(xp.select)
        def _select(cond, a, b):
            return lambda cond, a, b: a if cond else b

        @overload(xp.maximum)
        def _maximum(a, b):
            return lambda a, b: max(a, b)

        @overload(xp.minimum)
        def _minimum(a, b):
            return lambda a, b: min(a, b)

        _borrowed_views()
        _registered.add(id(xp.select))


def jit_laws(cache=True, functions=LAW_FUNCTIONS, inline=(), extra=None, rename=None, parallel=()):
    """The pure functions ``functions`` as they are now, each compiled by Numba.

    Each function is compiled from its own code object with its module's globals, in which the
    names of the other compiled functions are their compiled versions (so ``blend_inside`` calls the
    compiled ``linear_term`` of this call: a law replaced in its module is read afresh).  No
    function is a closure, so Numba's cache (keyed by the function's file, name and types) finds
    the compiled code again in the next process.

    Parameters
    ----------
    cache : bool, default True
        ``cache=True`` for Numba (the folder :func:`cache_dir`).
    functions : sequence of (module, name), default :data:`LAW_FUNCTIONS`
        The functions to compile.
    inline : collection of str, default ()
        Names compiled with ``inline="always"`` (inlined into their callers).
    extra : dict, optional
        Further names of the functions' globals → compiled functions (a variant's adapter).
    rename : dict, optional
        Name → the qualified name its compiled copy gets (a variant's own entry in Numba's cache,
        which is keyed by file, qualified name and types).
    parallel : collection of str, default ()
        Names compiled with ``parallel=True``, their ``prange`` (``range`` in the module) bound to
        ``numba.prange`` (loops over independent replicas on several threads).

    Returns
    -------
    dict
        Name → Numba dispatcher.
    """
    import numba

    register_helpers()
    compiled, namespaces = {}, []
    for module, name in functions:
        f = getattr(module, name)
        copy = _copy(f, (rename or {}).get(name))
        namespaces.append(copy.__globals__)
        options = {"inline": "always"} if name in inline else {}
        if name in parallel:
            copy.__globals__["prange"] = numba.prange
            options["parallel"] = True
        compiled[name] = numba.njit(copy, cache=cache, **options)
    for g in namespaces:      # (globals are read when a function is compiled, at its first call)
        g.update(compiled)
        g.update(extra or {})
    return compiled


def _copy(f, qualname=None):
    """``f`` as a new function of the same code with a copy of its globals (to bind other names to
    compiled functions there), under ``qualname`` (default its own)."""
    import types

    copy = types.FunctionType(f.__code__, dict(f.__globals__), f.__name__, f.__defaults__, f.__closure__)
    copy.__qualname__, copy.__module__ = qualname or f.__qualname__, f.__module__
    return copy


def jit_deep(f, done=None):
    """``f`` compiled (not cached), with every Python function its globals name compiled as well,
    recursively (:func:`~particleShear.engine.xp.select`, ``maximum`` and ``minimum`` are Numba's
    overloads): a contact law and the helpers of its module.

    Parameters
    ----------
    f : function
        A pure function of numbers.
    done : dict, optional
        Function → its compiled version, shared by the recursion.

    Returns
    -------
    numba.core.registry.CPUDispatcher
    """
    import types

    import numba

    done = {} if done is None else done
    if f in done:
        return done[f]
    copy = _copy(f)
    done[f] = compiled = numba.njit(copy, error_model="numpy")     # (x/0 is inf as on NumPy, no exception)
    for name in f.__code__.co_names:
        v = f.__globals__.get(name)
        if isinstance(v, types.FunctionType) and v not in (xp.select, xp.maximum, xp.minimum):
            copy.__globals__[name] = jit_deep(v, done)
    return compiled


#: the most arguments after ``d`` of a run's law in the compiled step (:func:`pair_term`'s ``a``)
LAW_SLOTS = 8
_NO_ARGUMENTS = (0.0,) * LAW_SLOTS


def _central_law(d, a):
    """The run's compressive law in compiled code, ``law(d, a)`` (``a``: its arguments): here the one of a run
    without a law of its own (never called: the built-in forms run); a compiled variant of the step
    binds the name to an adapter of the run's law (:func:`~.numba_step._law_kernels`)."""
    return 0.0


def pair_term(form, r, vn, vt, touching, active, xi_ij, xi_ji, d_law, d_cap, a_lin, a_div, d_eq, a_tens, ratio_c,
              nu, k_t, nu_t, mu, fc_inf, k_t_j, nu_t_j, friction, custom, a):
    """The force terms of one candidate pair on numbers (compiled; see :func:`compile_pair_kernel`).

    The body both compiled loops run per pair (the force terms of :func:`pair_terms` and the whole
    step of :mod:`.numba_step`): the compressive law of the form, the tensile law of bonds, the
    viscous term, the Coulomb bound and the two-visit tangential rule, from the same functions as
    the NumPy terms.  Numbers only (an array argument costs a reference count per call).

    Parameters
    ----------
    form : int
        :data:`FORMS` code of the compressive law.
    r, vn, vt : float
        Distance (µm), normal and tangential relative velocity (µm/s).
    touching, active : bool
        Overlap; relation.
    xi_ij, xi_ji : float
        Histories (µm).
    d_law, d_cap, a_lin, a_div, d_eq, a_tens, ratio_c, nu, k_t, nu_t, mu, fc_inf : float
        The pair's constants of :data:`TERM_BLOCK` (:func:`~particleShear.engine.terms.term_constants`).
    k_t_j, nu_t_j : float
        The constants of the visit from j.
    friction : bool
        False: no tangential term (0, 0, slip where active, ξ reset), the engine's frictionless shortcut.
    custom : bool
        The compressive law is the run's law, ``_central_law(r, a)`` (``a`` the arguments of
        :func:`~particleShear.engine.phase_laws.run_law` for this pair), instead of the form.
    a : tuple of float
        Those arguments, :data:`LAW_SLOTS` numbers (unused ones 0; a tuple keeps the call within
        the 30 arguments Python passes without packing them, which Numba's inlining needs).

    Returns
    -------
    tuple
        ``(fn, law, F_i, F_j, slip, reset)``: ``reset`` where both histories become 0.
    """
    if custom:
        inside = _central_law(r, a)
    elif form == 1:
        inside = linear_term(r, d_law, a_lin)
    elif form == 2:
        inside = divergent_term(r, d_law, d_cap, a_div)
    else:
        inside = blend_inside(r, d_law, d_cap, a_lin, a_div)
    law = contact_or_bond(r, d_law, inside, tensile_inside(r, d_eq, a_tens))
    f = law * ratio_c
    f += viscous_force(nu, vn, active)
    if not friction:          # no tangential force (the frictionless shortcut): every relation slips
        return f, law, 0.0, 0.0, active, True
    fc = np.abs(mu * law)
    fc += fc_inf
    F_i, F_j, s, reset = two_visit_rule(vt, 1.0 if touching else 0.0, xi_ij, xi_ji, k_t, k_t_j, nu_t, nu_t_j, fc)
    return f, law, F_i, F_j, s, reset


def _pair_kernel(form, d, vn, vt, touching, active, xi, T, k_t_j, nu_t_j, fn, law_out, F, slip):
    """The force terms of every candidate (compiled; see :func:`pair_terms`): writes ``fn, law_out, F, slip``."""
    for p in range(d.shape[0]):
        fn[p], law_out[p], F[0, p], F[1, p], slip[p], reset = pair_term(
            form, d[p], vn[p], vt[p], touching[p], active[p], xi[0, p], xi[1, p], T[0, p], T[1, p], T[2, p],
            T[3, p], T[4, p], T[5, p], T[6, p], T[7, p], T[8, p], T[9, p], T[10, p], T[11, p], k_t_j[p], nu_t_j[p],
            True, False, _NO_ARGUMENTS)
        if reset:
            xi[0, p] = 0.0
            xi[1, p] = 0.0


#: the functions of the compiled pair loop besides the laws, and those inlined into their callers
PAIR_FUNCTIONS = (LAW_FUNCTIONS + ((sys.modules[__name__], "_central_law"), (sys.modules[__name__], "pair_term"),
                                   (sys.modules[__name__], "_pair_kernel")))
INLINE = ("pair_term",)


def on_disk(dispatcher):
    """Whether Numba's cache holds compiled code of ``dispatcher`` (its index file exists): a compile
    is then a load, which needs no announcement.

    Parameters
    ----------
    dispatcher : numba.core.registry.CPUDispatcher

    Returns
    -------
    bool
    """
    try:
        return os.path.exists(dispatcher._cache._cache_file._index_path)
    except AttributeError:          # (no cache, or another Numba's layout: announce)
        return False


def compile_pair_kernel(cache=True, say=None):
    """The compiled loop over candidate pairs that evaluates their force terms (see :func:`pair_terms`).

    Parameters
    ----------
    cache : bool, default True
        Keep the compiled code in :func:`cache_dir` (and reuse the kernel of this process); False
        compiles afresh from the law functions as they are now (a test that edits a law).
    say : callable, optional
        ``say(message)``: told before a compile (not before a load from the cache).

    Returns
    -------
    numba.core.registry.CPUDispatcher
        ``kernel(form, d, vn, vt, touching, active, xi, T, k_t_j, nu_t_j, fn, law, F, slip)`` with
        ``T`` the (12, P) constants of :data:`TERM_BLOCK`; writes ``fn, law, F, slip`` and resets
        ``xi`` (all arrays of the P candidates, ``xi`` and ``F`` (2, P)).
    """
    if cache and True in _kernels:
        return _kernels[True]
    import numba

    if cache:
        numba.config.CACHE_DIR = cache_dir()
    # the functions the loop calls, compiled from the module attributes now (a test may have replaced one)
    compiled = jit_laws(cache, PAIR_FUNCTIONS, inline=INLINE)["_pair_kernel"]
    if say is not None and not on_disk(compiled):
        say(f"backend 'numba': compiling the force loop (first use; kept in {numba.config.CACHE_DIR or 'memory'})")
    # compile (or load) now, for the argument types of the engine's call
    e, b = np.empty(0), np.empty(0, dtype=np.bool_)
    compiled(0, e, e, e, b, b, np.empty((2, 0)), np.empty((len(TERM_BLOCK), 0)), e, e, np.empty(0), np.empty(0),
             np.empty((2, 0)), np.empty(0, dtype=np.bool_))
    if cache:
        _kernels[True] = compiled
    return compiled


def _rows(value, P):
    """``value`` as a contiguous float array over the P candidates (a number is repeated)."""
    if type(value) is np.ndarray and value.dtype == np.float64 and value.shape == (P,) and value.flags.c_contiguous:
        return value        # (the engine's constants per candidate: as they are)
    return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=float), (P,)))


def pair_terms(K, d, vn, vt, touching, active, xi, K_j=None, kernel=None):
    """Force terms of P candidates in one compiled loop: what ``central_term`` and ``tangential_term`` give.

    Parameters
    ----------
    K : TermConstants or PairConstants
        Constants of the pairs seen by the visit from i (:func:`~particleShear.engine.terms.term_constants`).
    d, vn, vt : ndarray (P,)
        Centre distances (µm), normal and tangential relative velocities (µm/s).
    touching, active : ndarray of bool (P,)
        Overlapping pairs; relations (touching, or a bond).
    xi : ndarray (2, P)
        Histories ξ_ij, ξ_ji (µm), reset to 0 in place on slip.
    K_j : TermConstants, optional
        Constants seen by the visit from j (its ``k_t``, ``nu_t``; default ``K``).
    kernel : callable, optional
        A kernel of :func:`compile_pair_kernel` (default: the cached one).

    Returns
    -------
    fn : ndarray (P,)
        Central scalar on i along ``n_ij`` (elastic + viscous; mg·µm·s⁻² per m depth).
    law : ndarray (P,)
        The elastic law before the permanent ratio.
    F : ndarray (2, P)
        Tangential forces of the two visits.
    slip : ndarray of bool (P,)
        The final slip flag.
    """
    kernel = compile_pair_kernel() if kernel is None else kernel
    P = len(d)
    if isinstance(K, PairConstants) and isinstance(K.f, np.ndarray):
        T = K.f[_TERM_START:_TERM_START + len(TERM_BLOCK)]    # the engine's constants: rows of its block, as they are
    else:
        # no bond: the tensile law of contacts, −0·(0 − d) = +0 (what the NumPy term puts beyond contact)
        values = dict(d_eq=0.0, a_tens=-0.0) if K.a_tens is None else {}
        T = np.empty((len(TERM_BLOCK), P))
        for k, name in enumerate(TERM_BLOCK):
            T[k] = values.get(name, getattr(K, name))
    if K_j is None:
        k_t_j, nu_t_j = T[8], T[9]
    else:
        k_t_j, nu_t_j = _rows(K_j.k_t, P), _rows(K_j.nu_t, P)
    if not (isinstance(xi, np.ndarray) and xi.dtype == np.float64 and xi.flags.c_contiguous):
        raise ValueError(f"xi of dtype {getattr(xi, 'dtype', type(xi))} is invalid: allowed a C-contiguous float64 "
                         "(2, P) NumPy array (reset in place)")
    fn, law, F, slip = np.empty(P), np.empty(P), np.empty((2, P)), np.empty(P, dtype=np.bool_)
    kernel(FORMS[K.form], _rows(d, P), _rows(vn, P), _rows(vt, P), np.asarray(touching, dtype=np.bool_),
           np.asarray(active, dtype=np.bool_), xi, T, k_t_j, nu_t_j, fn, law, F, slip)
    return fn, law, F, slip
