"""The central force laws, written once (eqs. S1-5a, S1-5b, S1-6; docs/design.md "Force laws").

This module is the single definition of the arithmetic of the compressive law and of the
linear tensile law of bonds.  Every caller uses it: the engine (on whole pair arrays, with
per-candidate constants precomputed once per bond set), the classes' vectorised step (with the
constants computed where the law is evaluated) and the documented per-sphere callbacks
:func:`~particleShear.base.laws.elastic_force_law` and
:func:`~particleShear.base.laws.elastic_force_law_tensile` (on Python scalars).

The laws are split into their constants (:func:`central_constants`, ``−k`` for the tensile
law) and a function of those constants (:func:`central_inside`, :func:`tensile_inside`), so
that a caller evaluating the same pairs every step computes the constants once.

The functions take the array namespace of their inputs (NumPy or CuPy, :mod:`.xp`).  Forces in
mg·µm·s⁻² per m depth; negative = repulsion.
"""
__docformat__ = "numpy"

import numbers

from .xp import array_namespace

__all__ = ["BLEND", "LINEAR", "DIVERGENT", "central_form", "central_constants", "central_inside",
           "central_law", "tensile_inside", "tensile_law"]

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


def central_inside(d, d0, d0_cap, a_lin, a_div, form=BLEND, maximum=None):
    """Compressive law from its constants, as if every pair were in contact (no cut-off at ``d0``).

    ``a_lin (d0 − d) + a_div (d0 / max(d, d0_cap) − 1)``, i.e. with the constants of
    :func:`central_constants` ``−k(1−c)(d0−d) − k·c·d0·(d0/d − 1)``: the blend of the linear
    law (eq. S1-5a) and the divergent law (eq. S1-5b) with the cap of eq. S1-6.

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the pair (µm).
    d0, d0_cap, a_lin, a_div : ndarray or float
        Contact distance (µm) and the constants of :func:`central_constants`.
    form : {BLEND, LINEAR, DIVERGENT}, default BLEND
        :data:`LINEAR` keeps only the linear term, :data:`DIVERGENT` only the divergent term
        (the other one is ±0 for c = 0, resp. c = 1; see :func:`central_form`).
    maximum : callable, optional
        Element-wise maximum (default: ``maximum`` of the namespace of ``d``); the scalar path
        passes the builtin :func:`max`.

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0 for ``d ≤ d0``).
    """
    if maximum is None:
        maximum = array_namespace(d, d0_cap).maximum
    if form is DIVERGENT:
        return a_div * (d0 / maximum(d, d0_cap) - 1)
    if form is LINEAR:
        return a_lin * (d0 - d)
    return a_lin * (d0 - d) + a_div * (d0 / maximum(d, d0_cap) - 1)


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
