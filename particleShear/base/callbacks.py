"""The documented law callbacks of particleShear 1.0.2, as the engine's laws of a force phase.

``CircleBasicElasticity.call_back_elastic_force_law`` and
``SphereLinkable.call_back_elastic_force_law_tensile`` are class attributes of the documented
classes; those classes name themselves as the holders (:func:`hold_callbacks`; the linkable
class lives in a higher layer).  The adapter that builds the engine's state from ensembles
(:mod:`.engine_adapter`) gives the state :func:`callback_phase_laws`, which the engine's
:func:`~particleShear.engine.phase_laws.force_phase_laws` calls once per force phase: a callback
registered with :func:`register_callback` (the package's own law functions) is its registered
law, any other one is evaluated by :func:`call_law`, on arrays when it accepts them and pair by
pair otherwise (docs/design.md, "Adding a contact law").  The engine keeps nothing of the
callbacks: all of it lives here, next to the classes.

Forces in mg·µm·s⁻² per m depth; negative = repulsion.
"""
__docformat__ = "numpy"

import numbers
import weakref

import numpy as np

from ..engine.contact_laws import LAWS, law_values
from ..engine.phase_laws import cached, law_arguments, law_function
from ..engine.xp import array_namespace, to_host

__all__ = ["register_callback", "callback_law", "call_law", "callback_phase_laws", "callback_central_law",
           "callback_key", "class_callbacks", "hold_callbacks"]


# -- the documented callbacks ----------------------------------------------------------------------
_CALLBACKS = {}         # callback -> (name of its registered law, its parameters() or None)


def _registered(callback):
    """Name of the registered law of a callback (:func:`register_callback`), else None."""
    try:
        return _CALLBACKS.get(callback, (None,))[0]
    except TypeError:     # an unhashable callable
        return None
#: callbacks found to accept numbers only (evaluated pair by pair without trying arrays again)
_SCALAR_ONLY = weakref.WeakSet()


def register_callback(callback, name, parameters=None):
    """Declare a law function of the classes' callbacks to be the registered law ``name``.

    Parameters
    ----------
    callback : callable
        A function users assign to ``call_back_elastic_force_law`` (or ``…_tensile``).
    name : str
        The registered law it is.
    parameters : callable, optional
        ``parameters()`` returns ``{parameter: value}`` of the law, read when a force phase
        looks the callback up (the plateau law reads ``PlateauConfiguration`` then); None: the
        law's defaults.
    """
    _CALLBACKS[callback] = (name, parameters)
    try:
        callback.accepts_arrays = True
    except (AttributeError, TypeError):
        pass


def callback_law(callback):
    """``(ContactLaw, values)`` of a callback declared by :func:`register_callback`, else None.

    Parameters
    ----------
    callback : callable
        The callback.

    Returns
    -------
    tuple or None
    """
    try:
        found = _CALLBACKS.get(callback)
    except TypeError:     # an unhashable callable
        return None
    if found is None:
        return None
    name, given = found
    law = LAWS[name]
    if given is None and not law.parameters:
        return law, ()
    return law, law_values(law, None if given is None else given())


def call_law(law, *args, select=None):
    """Evaluate a (possibly user-supplied, number-only) law on pair arrays (NumPy).

    A law that accepts arrays (``law.accepts_arrays``, or one whose call on the arrays returns
    an array of their shape) is called once on the arrays; any other one is applied pair by
    pair, on the pairs of ``select`` only when given (0 elsewhere), and remembered as such.

    Parameters
    ----------
    law : callable
        Force law ``law(d, d0, k[, c])`` returning the central force (negative = repulsion).
    *args : float or numpy.ndarray
        Its arguments, arrays of one length (the pairs) or numbers; the first sets the length.
    select : numpy.ndarray of bool, optional
        The pairs whose value is needed (the pair-by-pair path evaluates only these).

    Returns
    -------
    numpy.ndarray
        Force of every pair (mg·µm·s⁻² per m depth), float array of the first argument's shape.
    """
    n = np.shape(args[0])
    if getattr(law, "accepts_arrays", False):
        return np.asarray(law(*args), dtype=float)
    if n == () or n[0] == 0:
        return np.zeros(n)
    try:
        scalar_only = law in _SCALAR_ONLY
    except TypeError:
        scalar_only = False
    if not scalar_only:
        try:
            out = np.asarray(law(*args), dtype=float)
            if out.shape == n:
                return out
        except Exception:
            pass
        try:
            _SCALAR_ONLY.add(law)
        except TypeError:
            pass
    bc = np.broadcast_arrays(*[np.asarray(a, dtype=float) for a in args])
    if select is None:
        return np.array([float(law(*vals)) for vals in zip(*[b.tolist() for b in bc])], dtype=float)
    out = np.zeros(n)
    idx = np.flatnonzero(select)
    out[idx] = [float(law(*vals)) for vals in zip(*[b[idx].tolist() for b in bc])]
    return out


def hold_callbacks(kind, cls):
    """Name the class whose attribute is a documented law callback (called by the classes' modules).

    ``kind`` "central": ``cls.call_back_elastic_force_law`` (``base.points.CircleBasicElasticity``);
    "tensile": ``cls.call_back_elastic_force_law_tensile`` (``linkable.spheres.SphereLinkable``).
    The engine reads the attribute at every force phase and never imports the classes' layers.

    Parameters
    ----------
    kind : {"central", "tensile"}
        Which callback the class holds.
    cls : type
        The class.

    Raises
    ------
    ValueError
        If ``kind`` is neither.
    """
    if kind not in ("central", "tensile"):
        raise ValueError(f"kind={kind!r} is not allowed: 'central' or 'tensile'")
    _HOLDERS[kind] = cls


def class_callbacks():
    """The documented law callbacks now: ``(CircleBasicElasticity.call_back_elastic_force_law,
    SphereLinkable.call_back_elastic_force_law_tensile)``; None for a callback whose class is not
    loaded (then the built-in law).

    Returns
    -------
    tuple of callable or None
    """
    central, tensile = _HOLDERS.get("central"), _HOLDERS.get("tensile")
    return (None if central is None else central.call_back_elastic_force_law,
            None if tensile is None else tensile.call_back_elastic_force_law_tensile)


_HOLDERS = {}     # kind -> the class holding that documented callback (hold_callbacks)


def _on_host(law, *args, select=None):
    """:func:`call_law` of a callback on the arrays' backend (a device's arrays are read on the host)."""
    xp = array_namespace(*args)
    if xp is np:
        return call_law(law, *args, select=select)
    host = [a if isinstance(a, numbers.Number) else to_host(a, "scalar law") for a in args]
    return xp.asarray(call_law(law, *host, select=None if select is None else to_host(select, "scalar law")))


def callback_phase_laws(C, central=True):
    """The laws of one force phase from the documented callbacks (the state's ``callback_laws``
    that :mod:`.engine_adapter` gives the engine; :func:`particleShear.engine.phase_laws.force_phase_laws`).

    The central law is ``CircleBasicElasticity.call_back_elastic_force_law``: a registered law
    when it was declared one (:func:`register_callback`), a user function otherwise
    (:func:`call_law`, pair by pair on the pairs inside their contact distance when it accepts
    numbers only).  The tensile law of bonds is ``SphereLinkable.call_back_elastic_force_law_tensile``
    in the same way.  The class attributes are read at every call, as 1.0.2 reads them.

    Parameters
    ----------
    C : PairConstants or VisitConstants
        The constants of one visit of the candidates.
    central : bool
        Whether the central law is asked for (False: the run has a ``contact_law`` of its own).

    Returns
    -------
    central, tensile : callable or None
        ``law(d)`` on the candidates, or None for the built-in law (prepared constants).
    """
    compressive, stretched = class_callbacks()
    law_c = None
    if central and not (compressive is None or _registered(compressive) == "linear"):
        if callback_law(compressive) is None:
            args = cached(C, ("callback",), lambda: (C.d_law, C.k, C.c))
            law_c = (lambda d: _on_host(compressive, d, *args, select=d <= args[0]))
        else:
            got = callback_central_law(C)
            law_c = None if got is None else (lambda d: got[1](d, *got[2]))
    tensile = None
    if not (stretched is None or _registered(stretched) == "tensile"):
        found = callback_law(stretched)
        if found is None or found[0].name != "tensile":
            law = stretched if found is None else found[0].function
            tensile = (lambda d: _stretched(law, C, d))
    return law_c, tensile


def callback_central_law(C):
    """The central law callback as a registered law on the candidates ``C``: ``(name, function,
    arguments)``, the law of every candidate at ``d`` being ``function(d, *arguments)`` (what
    :func:`callback_phase_laws` evaluates, :func:`~particleShear.engine.phase_laws.law_function`);
    None for the built-in linear law, a user function, or no callback.

    Parameters
    ----------
    C : PairConstants or VisitConstants
        The constants of one visit of the candidates.

    Returns
    -------
    tuple or None
    """
    compressive = class_callbacks()[0]
    found = None if compressive is None or _registered(compressive) == "linear" else callback_law(compressive)
    if found is None or found[0].name == "linear":
        return None
    law, values = found
    return (law.name,) + law_function(law, C, (law.name, values), lambda: law_arguments(law, C) + values)


def callback_key():
    """What the laws of a phase depend on besides the candidates, compared by equality: the classes'
    two law attributes now and the parameter values of a registered central law (the plateau law's
    ``PlateauConfiguration``), read at every phase.

    Returns
    -------
    tuple
    """
    compressive, stretched = class_callbacks()
    found = None if compressive is None else callback_law(compressive)
    return compressive, stretched, None if found is None else found[1]


# what an engine that keeps anything made from the laws (the compiled step's workspace) reads
callback_phase_laws.key = callback_key
callback_phase_laws.central = callback_central_law


def _stretched(law, C, d):
    """A tensile callback on the stretched bonds of ``C`` (``d > d_eq``), 0 on every other candidate."""
    xp = array_namespace(d)
    out = xp.zeros_like(d)
    idx = xp.flatnonzero(C.perm & (d > C.d_law))
    if idx.size:
        out[idx] = _on_host(law, d[idx], C.d_eq[idx], C.k[idx])
    return out
