"""The arithmetic of the package's laws, written once, and the law registry.

A *central law* is a pure function of arrays: the central force on i along ``n_ij`` as if the
pair were in contact (negative = repulsion, mg·µm·s⁻² per m depth).  The laws of the laws folder
(:mod:`particleShear.engine.contact_laws`, one file each: ``linear``, ``plateau``, ``hertz``) take
``(d, d0, r_i, r_j, k, c, *parameters)`` (centre distance, contact distance and radii in µm,
spring constant ``k``, repulsion coefficient ``c``, the law's own parameters, one value per pair or
one number); a law :func:`register_law` adds at run time may take ``(d, d0, k, c, *parameters)``.
The caller applies the cut-off: 0 beyond contact for a contact, the tensile law beyond ``d_eq``
for a bond.  A *tensile law* ``law(d, d_eq, k)`` is the force of a stretched bond (positive
attracts).  :data:`LAWS` holds the laws by name; ``contact_law=<name>`` of a run selects one
(docs/design.md, "Adding a contact law").  Written here, shared by the laws' files and the
documented callbacks of :mod:`particleShear.base.laws`:

* :func:`linear_law`: the blend of the linear (eq. S1-5a) and divergent (eq. S1-5b) law with the
  cap of eq. S1-6 — the law of ``contact_laws/linear.py``, the default;
* :func:`plateau_law`: the same law of a plateau-transformed distance (:func:`plateau_distance`),
  the spongy particles of the manual — the law of ``contact_laws/plateau.py``;
* ``"tensile"`` (:func:`tensile_law`, kind ``"tensile"``, registered here): the linear tensile law of bonds.

The documented callbacks of particleShear 1.0.2 (``CircleBasicElasticity.call_back_elastic_force_law``,
``SphereLinkable.call_back_elastic_force_law_tensile``) keep working: the adapter that builds a
state from ensembles gives it :func:`particleShear.base.callbacks.callback_phase_laws`, which the
engine calls once per force phase (:func:`.phase_laws.force_phase_laws`); a callback registered
there (the package's own law functions) is its registered law, any other one is evaluated on arrays when it
accepts them and pair by pair otherwise.

The linear and tensile laws are also split into their constants (:func:`central_constants`,
``−k`` for the tensile law) and a function of those constants (:func:`central_inside`,
:func:`tensile_inside`), so that a caller evaluating the same pairs every step computes the
constants once (the engine's default path).

The functions take the array namespace of their inputs (NumPy or CuPy, :mod:`.xp`).  Forces in
mg·µm·s⁻² per m depth; negative = repulsion.
"""
__docformat__ = "numpy"

import difflib
import importlib
import math
import numbers

from ..checks import in_range
from .xp import array_namespace, maximum, select

__all__ = ["BLEND", "LINEAR", "DIVERGENT", "central_form", "central_constants", "central_inside",
           "central_law", "linear_term", "divergent_term", "blend_inside", "contact_or_bond", "tensile_inside", "tensile_law", "linear_law", "plateau_distance", "plateau_constants",
           "plateau_inside", "plateau_law",
           "check_plateau", "ContactLaw", "LAWS", "register_law", "unregister_law", "get_law", "law_names",
           "law_values"]

#: forms of the compressive law: the general blend, and the two pure laws of c = 0 and c = 1
#: (they drop the term whose coefficient is ±0, which leaves the force unchanged and is faster)
BLEND, LINEAR, DIVERGENT = "blend", "linear", "divergent"


def central_form(c):
    """Form of the compressive law for the repulsion coefficient ``c``.

    Parameters
    ----------
    c : float or ndarray
        Central repulsion coefficient in [0, 1].

    Returns
    -------
    str
        :data:`LINEAR` for a number ``c == 0`` (eq. S1-5a), :data:`DIVERGENT` for a number
        ``c == 1`` (eq. S1-5b), else :data:`BLEND` (arrays, 0-d ones included, always blend).
    """
    if isinstance(c, numbers.Real):   # a Python or NumPy number (a device value would need a host read)
        if c == 1:
            return DIVERGENT
        if c == 0:
            return LINEAR
    return BLEND


def central_constants(d0, k, c):
    """Per-pair constants of the compressive law: ``(d0/1000, −k(1−c), −k·c·d0)``.

    Parameters
    ----------
    d0 : ndarray or float
        Contact distance (µm, > 0): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Central repulsion coefficient in [0, 1] (0 linear, 1 divergent).

    Returns
    -------
    d0_cap : ndarray or float
        Smallest distance the divergent term sees (µm): the cap ``d0/d ≤ 1000`` of eq. S1-6.
    a_lin : ndarray or float
        Coefficient of the linear term (mg·s⁻² per m depth).
    a_div : ndarray or float
        Coefficient of the divergent term (mg·µm·s⁻² per m depth).
    """
    return d0 / 1000, -k * (1 - c), -k * c * d0


def linear_term(d, d0, a_lin):
    """Linear term of the compressive law, ``a_lin (d0 − d)`` (eq. S1-5a with ``a_lin = −k(1−c)``).

    A pure expression (docs/backends.md, "One law, two drivers"): the NumPy engine calls it on
    arrays, the compiled driver on numbers.

    Parameters
    ----------
    d, d0 : ndarray or float
        Centre and contact distance (µm).
    a_lin : ndarray or float
        Coefficient of :func:`central_constants` (mg·s⁻² per m depth).

    Returns
    -------
    ndarray or float
        Force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    return a_lin * (d0 - d)


def divergent_term(d, d0, d0_cap, a_div):
    """Divergent term of the compressive law, ``a_div (d0 / max(d, d0_cap) − 1)`` (eqs. S1-5b, S1-6).

    A pure expression (docs/backends.md, "One law, two drivers"): arrays or numbers.

    Parameters
    ----------
    d, d0 : ndarray or float
        Centre and contact distance (µm).
    d0_cap, a_div : ndarray or float
        Constants of :func:`central_constants` (µm; mg·µm·s⁻² per m depth).

    Returns
    -------
    ndarray or float
        Force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    return a_div * (d0 / maximum(d, d0_cap) - 1)


def blend_inside(d, d0, d0_cap, a_lin, a_div):
    """The blended compressive law from its constants: :func:`linear_term` + :func:`divergent_term`.

    Parameters
    ----------
    d, d0, d0_cap, a_lin, a_div : ndarray or float
        As :func:`central_inside`.

    Returns
    -------
    ndarray or float
        Force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    return linear_term(d, d0, a_lin) + divergent_term(d, d0, d0_cap, a_div)


def central_inside(d, d0, d0_cap, a_lin, a_div, form=BLEND):
    """Compressive law from its constants, as if every pair were in contact (no cut-off at ``d0``).

    ``a_lin (d0 − d) + a_div (d0 / max(d, d0_cap) − 1)``, i.e. with the constants of
    :func:`central_constants` ``−k(1−c)(d0−d) − k·c·d0·(d0/d − 1)``: the blend of the linear
    law (eq. S1-5a) and the divergent law (eq. S1-5b) with the cap of eq. S1-6
    (:func:`blend_inside`; the pure terms :func:`linear_term`, :func:`divergent_term`).

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the pair (µm).
    d0, d0_cap, a_lin, a_div : ndarray or float
        Contact distance (µm) and the constants of :func:`central_constants`.
    form : {BLEND, LINEAR, DIVERGENT}, default BLEND
        :data:`LINEAR` keeps only the linear term, :data:`DIVERGENT` only the divergent term
        (the other one is ±0 for c = 0, resp. c = 1; see :func:`central_form`).

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0 for ``d ≤ d0``).
    """
    if form is DIVERGENT:
        return divergent_term(d, d0, d0_cap, a_div)
    if form is LINEAR:
        return linear_term(d, d0, a_lin)
    return blend_inside(d, d0, d0_cap, a_lin, a_div)


def central_law(d, d0, k, c):
    """Compressive law: ``−k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)`` for ``d ≤ d0``, else 0.

    ``c`` blends the linear law (eq. S1-5a, c = 0) and the divergent law (eq. S1-5b, c = 1);
    the ratio ``d0/d`` is capped at 1000 (eq. S1-6).  All arguments broadcast.

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the pair (µm).
    d0 : ndarray or float
        Contact distance (µm, > 0): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Central repulsion coefficient in [0, 1] (0 linear, 1 divergent).

    Returns
    -------
    ndarray
        Scalar central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0, repulsive,
        and 0 beyond ``d0``).
    """
    xp = array_namespace(d, d0)
    d = xp.asarray(d, dtype=float)
    inside = central_inside(d, d0, *central_constants(d0, k, c), form=central_form(c))
    return xp.where(d > d0, 0.0, inside)


def tensile_inside(d, d_eq, a_t):
    """Linear tensile law from its constant ``a_t = −k``: ``a_t (d_eq − d)`` (eq. S1-5a in tension).

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the bonded pair (µm).
    d_eq : ndarray or float
        Equilibrium distance of the bond (µm).
    a_t : ndarray or float
        Minus the spring constant, ``−k`` (mg·s⁻² per m depth, eq. S1-8).

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; positive, attractive, for
        ``d > d_eq``).
    """
    return a_t * (d_eq - d)


def contact_or_bond(d, d_law, inside, beyond):
    """The elastic law of a pair: the compressive law ``inside`` up to ``d_law``, ``beyond`` above it.

    ``beyond`` is the tensile law of a stretched bond (:func:`tensile_inside`) and +0 for a contact
    that has separated.  A pure expression (docs/backends.md, "One law, two drivers").

    Parameters
    ----------
    d, d_law : ndarray or float
        Centre distance and the distance where the compressive law ends (µm: ``r_i + r_j`` for a
        contact, ``d_eq`` for a bond).
    inside, beyond : ndarray or float
        The compressive and the tensile law at ``d`` (mg·µm·s⁻² per m depth).

    Returns
    -------
    ndarray or float
        Force on i along ``n_ij`` (mg·µm·s⁻² per m depth; negative repels).
    """
    return select(d > d_law, beyond, inside)


def tensile_law(d, d_eq, k):
    """Linear tensile law of a stretched bond, ``−k (d_eq − d)`` (≥ 0 for ``d ≥ d_eq``, attractive).

    The linear law eq. S1-5a on the stretched side of a permanent link.

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the bonded pair (µm).
    d_eq : ndarray or float
        Equilibrium distance of the bond (µm).
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).

    Returns
    -------
    ndarray or float
        Scalar central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; positive attracts).
    """
    return tensile_inside(d, d_eq, -k)


# -- the built-in laws of the registry ------------------------------------------------------------
def linear_law(d, d0, k, c):
    """The default compressive law as if in contact: ``−k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)``.

    The blend of the linear law (eq. S1-5a, c = 0) and the divergent law (eq. S1-5b, c = 1)
    with the cap ``d0/d ≤ 1000`` of eq. S1-6: :func:`central_inside` of :func:`central_constants`
    (the engine evaluates it from constants prepared once per candidate set).

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the pair (µm).
    d0 : ndarray or float
        Contact distance (µm, > 0): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Central repulsion coefficient in [0, 1].

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0 for ``d ≤ d0``).
    """
    return central_inside(d, d0, *central_constants(d0, k, c))


def plateau_distance(d, plateau_begin, plateau_end, slope):
    """Continuous distance mapping that flattens a law between ``plateau_begin`` and ``plateau_end``.

    ``d`` for ``d ≥ pe``; ``pe + (d − pe)·s`` on the plateau ``pb ≤ d < pe``; below it
    ``d·(pe + (pb − pe)·s)/pb``, a linear map to 0 that is continuous at ``pb``.

    Parameters
    ----------
    d : ndarray or float
        Centre distance (µm).
    plateau_begin, plateau_end : ndarray or float
        Where the plateau begins and ends (µm), ``0 < pb < pe``.
    slope : ndarray or float
        Slope of the mapping on the plateau (dimensionless; 0 = flat, 1 = no plateau).

    Returns
    -------
    ndarray
        Transformed distance (µm).
    """
    pb, pe, s = plateau_begin, plateau_end, slope
    return _plateau_map(d, pb, pe, s, pe + (pb - pe) * s)


def _plateau_map(d, pb, pe, s, low):
    """:func:`plateau_distance` with its constant ``low = pe + (pb − pe)·s`` (the map at ``d = pb``)."""
    return select(d >= pe, d, select(d >= pb, pe + (d - pe) * s, d * low / pb))


def plateau_constants(d0, k, c, plateau_begin, plateau_end, plateau_slope):
    """Per-pair constants of :func:`plateau_law`: the plateau in µm, the map's constant, the law's.

    Parameters
    ----------
    d0, k, c : ndarray or float
        Contact distance (µm), spring constant, repulsion coefficient (as in :func:`linear_law`).
    plateau_begin, plateau_end, plateau_slope : ndarray or float
        The law's parameters (fractions of ``d0``, relative slope).

    Returns
    -------
    tuple
        ``(pb, pe, s, pe + (pb − pe)·s, d0)`` followed by :func:`central_constants` of
        ``(d0, k, c)``: the arguments after ``d`` of :func:`plateau_inside`.
    """
    pb, pe, s = plateau_begin * d0, plateau_end * d0, plateau_slope
    return (pb, pe, s, pe + (pb - pe) * s, d0) + central_constants(d0, k, c)


def plateau_inside(d, pb, pe, s, low, d0, d0_cap, a_lin, a_div):
    """:func:`plateau_law` from its constants (:func:`plateau_constants`), as if in contact.

    Parameters
    ----------
    d : ndarray or float
        Centre distance (µm).
    pb, pe, s, low, d0, d0_cap, a_lin, a_div : ndarray or float
        The constants of :func:`plateau_constants`.

    Returns
    -------
    ndarray
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    return central_inside(_plateau_map(d, pb, pe, s, low), d0, d0_cap, a_lin, a_div)


def plateau_law(d, d0, k, c, plateau_begin, plateau_end, plateau_slope):
    """Law of spongy particles: :func:`linear_law` of the plateau-transformed distance.

    ``linear_law(dp, d0, k, c)`` with ``dp = plateau_distance(d, plateau_begin·d0,
    plateau_end·d0, plateau_slope)``: the force grows with the overlap as the default law down to
    ``plateau_end·d0``, by the factor ``plateau_slope`` more slowly on the plateau, and again
    steeply below ``plateau_begin·d0`` (the manual's ``elastic_force_law_plateau``).  The engine
    evaluates it as :func:`plateau_inside` of :func:`plateau_constants` kept per candidate set
    (the same arithmetic).

    Parameters
    ----------
    d, d0, k, c : ndarray or float
        As in :func:`linear_law` (µm, µm, mg·s⁻² per m depth, dimensionless).
    plateau_begin, plateau_end : ndarray or float
        Begin and end of the plateau as fractions of ``d0`` (:func:`check_plateau`).
    plateau_slope : ndarray or float
        Relative slope of the force on the plateau (dimensionless).

    Returns
    -------
    ndarray
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0 for ``d ≤ d0``).
    """
    return plateau_inside(d, *plateau_constants(d0, k, c, plateau_begin, plateau_end, plateau_slope))


def check_plateau(plateau_begin, plateau_end, plateau_slope):
    """Raise ValueError unless ``0 < plateau_begin < plateau_end ≤ 1`` and ``0 ≤ plateau_slope ≤ 1``.

    The transformed distance must stay positive and increasing (which needs
    ``slope < end/(end − begin)``, more than 1); a slope above 1 would make the plateau steeper
    than the law itself, so the allowed slopes are 0 (flat) … 1 (no plateau).

    Parameters
    ----------
    plateau_begin, plateau_end : float
        Begin and end of the plateau (fractions of the contact distance).
    plateau_slope : float
        Relative slope on the plateau.

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range.
    """
    values = {"plateau_begin": plateau_begin, "plateau_end": plateau_end, "plateau_slope": plateau_slope}
    for name, v in values.items():
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            raise ValueError(f"{name}={v!r} is invalid: allowed a finite number")
    if not 0 < plateau_begin < plateau_end:
        raise ValueError(f"plateau_begin={plateau_begin!r} is out of range: allowed 0 < plateau_begin < plateau_end "
                         f"(plateau_end={plateau_end!r})")
    if not plateau_end <= 1:
        raise ValueError(f"plateau_end={plateau_end!r} is out of range: allowed plateau_begin < plateau_end <= 1 "
                         "(fractions of the contact distance)")
    if not 0 <= plateau_slope <= 1:
        raise ValueError(f"plateau_slope={plateau_slope!r} is out of range: allowed 0 <= plateau_slope <= 1")


# -- the registry ---------------------------------------------------------------------------------
class ContactLaw:
    """A registered law: its name, function, parameters with their defaults, kind and check.

    Parameters
    ----------
    name : str
        The name a run selects it by (``contact_law=name``).
    function : callable
        ``function(d, d0, r_i, r_j, k, c, *parameters)`` (kind ``"central"``, ``radii`` True: the
        form of the laws folder), ``function(d, d0, k, c, *parameters)`` (``radii`` False: the
        form of :func:`register_law` before the laws folder) or ``function(d, d_eq, k)`` (kind
        ``"tensile"``), on arrays; see the module docstring.
    parameters : dict
        Parameter name → default, in the order ``function`` takes them.
    kind : {"central", "tensile"}
        Compressive law of contacts and bonds, or tensile law of stretched bonds.
    check : callable or None
        ``check(**values)`` raises ValueError for values the law does not allow; None: any
        finite numbers (within the declared ranges).
    prepared : tuple or None
        ``(constants, inside)`` with ``function(d, *a) == inside(d, *constants(*a))`` (``a`` the
        arguments after ``d``): the engine keeps the constants per candidate set; None: it calls
        ``function``.
    radii : bool, default False
        ``function`` takes the radii ``r_i, r_j`` (µm) after ``d0``.
    declared : tuple of Parameter, default ()
        The parameters as declared in the law's file (:class:`particleShear.parameter_entry.Parameter`:
        unit, range, one-line doc); empty for a law registered with a plain dict.
    """

    __slots__ = ("name", "function", "parameters", "kind", "check", "prepared", "radii", "declared")

    def __init__(self, name, function, parameters, kind, check, prepared=None, radii=False, declared=()):
        self.name, self.function, self.parameters, self.kind, self.check = name, function, parameters, kind, check
        self.prepared, self.radii, self.declared = prepared, bool(radii), tuple(declared)

    def __repr__(self):
        return f"ContactLaw({self.name!r}, {self.kind}, parameters={self.parameters!r})"


#: the registered laws, name → :class:`ContactLaw` (add one with :func:`register_law`)
LAWS = {}
#: the laws that cannot be replaced: the tensile law and the laws of the laws folder (added on discovery)
_BUILT_IN = {"tensile"}


def register_law(name, function, parameters=None, kind="central", check=None, replace=False, prepared=None,
                 radii=False, built_in=False):
    """Add a contact law to :data:`LAWS`, the one place the engine and the run layer read laws from.

    The laws folder (:mod:`particleShear.engine.contact_laws`) calls it in each law's file (with
    the declared parameters, ``radii=True``, ``built_in=True``); a script may call it at run time
    (the law is then known in this process only, not in spawn workers: a law for those is a file
    of the laws folder or ``contact_law="package.module:function"``).  The function must accept arrays (the engine calls it once per force phase on all candidate
    pairs, values beyond contact are discarded); it is marked ``accepts_arrays``.

    Parameters
    ----------
    name : str
        Name of the law (a run selects it with ``contact_law=name``).
    function : callable
        ``function(d, d0, k, c, *parameters)`` for kind ``"central"`` (``function(d, d0, r_i,
        r_j, k, c, *parameters)`` with ``radii``): the force as if in contact (mg·µm·s⁻² per m
        depth, negative repels); ``function(d, d_eq, k)`` for kind ``"tensile"``.
    parameters : dict or tuple of Parameter, optional
        Parameter name → default value, or the declared parameters
        (:class:`particleShear.parameter_entry.Parameter`), in the order of the function's extra
        arguments.
    kind : {"central", "tensile"}, default "central"
        Which law it is.
    check : callable, optional
        ``check(**values)`` raising ValueError for values the law does not allow.
    replace : bool, default False
        Replace a law already registered under ``name`` (the built-in ones cannot be replaced).
    prepared : tuple, optional
        ``(constants, inside)``: the law split into per-pair constants and a function of them
        (:class:`ContactLaw`), so that the engine computes the constants once per candidate set.
    radii : bool, default False
        The function takes the radii ``r_i, r_j`` (µm) after ``d0``.
    built_in : bool, default False
        A law of the laws folder (it cannot be replaced or unregistered).

    Returns
    -------
    ContactLaw

    Raises
    ------
    ValueError
        For an empty or taken name, a non-callable function, an unknown kind or non-numeric defaults.
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"name={name!r} is invalid: allowed a non-empty identifier")
    if name in LAWS and (not replace or name in _BUILT_IN):
        raise ValueError(f"name={name!r} is invalid: a law of that name is registered (replace=True replaces "
                         f"one that is not built in: {', '.join(sorted(_BUILT_IN))})")
    if not callable(function):
        raise ValueError(f"function={function!r} is invalid: allowed a callable")
    if kind not in ("central", "tensile"):
        raise ValueError(f"kind={kind!r} is invalid: allowed 'central' or 'tensile'")
    declared = ()
    if parameters and not isinstance(parameters, dict):
        declared = tuple(parameters)
        parameters = {p.name: p.default for p in declared}
    parameters = dict(parameters or {})
    for p, v in parameters.items():
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise ValueError(f"parameters[{p!r}]={v!r} is invalid: allowed a number")
    try:
        function.accepts_arrays = True
    except (AttributeError, TypeError):
        pass
    LAWS[name] = law = ContactLaw(name, function, parameters, kind, check, prepared, radii, declared)
    if built_in:
        _BUILT_IN.add(name)
    return law


def unregister_law(name):
    """Remove a law registered with :func:`register_law` (not a built-in one).

    Parameters
    ----------
    name : str
        Its name.

    Raises
    ------
    ValueError
        For a built-in or unknown name.
    """
    if name in _BUILT_IN or name not in LAWS:
        raise ValueError(f"name={name!r} is invalid: allowed a registered law that is not built in "
                         f"({', '.join(n for n in LAWS if n not in _BUILT_IN) or 'none'})")
    del LAWS[name]


def law_names(kind="central"):
    """Names of the registered laws of one kind, in registration order (list of str).

    Parameters
    ----------
    kind : {"central", "tensile"}, default "central"
        Which laws.

    Returns
    -------
    list of str
    """
    return [n for n, law in LAWS.items() if law.kind == kind]


def get_law(name, kind="central", what="contact_law"):
    """The registered law ``name`` of the given kind.

    Parameters
    ----------
    name : str
        Its name.
    kind : {"central", "tensile"}, default "central"
        The kind wanted.
    what : str, default "contact_law"
        The parameter named in the error.

    Returns
    -------
    ContactLaw

    Raises
    ------
    ValueError
        For an unknown name: naming ``what``, the value, the allowed names and the closest one.
    """
    law = LAWS.get(name) if isinstance(name, str) else None
    if law is None and kind == "central" and isinstance(name, str) and ":" in name:
        law = _import_law(name, what)
    if law is not None and law.kind == kind:
        return law
    names = law_names(kind)
    close = difflib.get_close_matches(str(name), names, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ValueError(f"{what}={name!r} is invalid: allowed {', '.join(repr(n) for n in names)}{hint}")


def _import_law(spec, what):
    """Register the law ``"package.module:function"`` under that name (imported where it is used,
    spawn workers included): the module's ``LAW`` (a :class:`ContactLaw` it registered) when the
    function is its function, else ``function(d, d0, r_i, r_j, k, c, *parameters)`` with the
    module's ``PARAMETERS`` (declared parameters; none when absent)."""
    module_name, _, attr = spec.partition(":")
    try:
        module = importlib.import_module(module_name)
        function = getattr(module, attr)
    except (ImportError, AttributeError) as e:
        raise ValueError(f"{what}={spec!r} is invalid: cannot import it ({e}); allowed a registered law or "
                         "'package.module:function'") from None
    own = getattr(module, "LAW", None)
    if isinstance(own, ContactLaw) and own.function is function:
        LAWS[spec] = own
        return own
    if not callable(function):
        raise ValueError(f"{what}={spec!r} is invalid: {attr!r} of {module_name} is not callable")
    declared = tuple(getattr(module, "PARAMETERS", ()) or ())
    parameters = {p.name: p.default for p in declared}
    try:
        function.accepts_arrays = True
    except (AttributeError, TypeError):
        pass
    LAWS[spec] = law = ContactLaw(spec, function, parameters, "central", getattr(module, "check", None),
                                  radii=True, declared=declared)
    return law


def law_values(law, given=None):
    """The parameter values of ``law``: ``given`` where it names one, else the default; checked.

    Parameters
    ----------
    law : ContactLaw or str
        The law (or its name).
    given : dict, optional
        Parameter name → value (names the law does not take are ignored).

    Returns
    -------
    tuple of float
        In the order of ``law.parameters``.

    Raises
    ------
    ValueError
        From the law's check, or for a value that is not a finite number.
    """
    law = get_law(law) if isinstance(law, str) else law
    given = given or {}
    values = {p: given.get(p, default) for p, default in law.parameters.items()}
    for p, v in values.items():
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
            raise ValueError(f"{p}={v!r} is invalid: allowed a finite number")
    for p in law.declared:
        if p.has_range:
            in_range(p.name, values[p.name], p.low, p.high, p.low_open, p.high_open)
    if law.check is not None:
        law.check(**values)
    return tuple(float(v) for v in values.values())


register_law("tensile", tensile_law, kind="tensile")
