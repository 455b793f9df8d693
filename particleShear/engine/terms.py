"""The pair force terms, each written once: their constants, the elastic, viscous and tangential terms.

Contacts and bonds, the engine's step and the documented canvas classes all evaluate a pair's
forces through these functions (docs/engine.md, "One step"):

* :func:`relative_velocity`, :func:`normal_speed` and :func:`slip_speed` are the kinematics of a
  contact: the velocity of j's image relative to i, its normal part ``v_n`` and the tangential slip
  ``v_t`` of the two surfaces (with the spins);
* :func:`term_constants` turns the model parameters seen by one visit of a pair (k, c, ν, k_t,
  ν_t, μ and the permanent ratios of a bond) into the constants of its terms, a
  :class:`TermConstants`;
* :func:`elastic_term` is the central elastic law (eqs. S1-5a/b with the cap S1-6; bonds: the
  compressive law below ``d_eq`` and the linear tensile law above it), times the permanent ratio;
* :func:`viscous_term` is the central viscous force ``ν·v_n`` (eq. S1-9) of the relations;
* :func:`tangential_term` is the two-visit tangential rule with the Coulomb bound ``|μ·law|``
  (:func:`~particleShear.engine.tangential.tangential_two_pass`; bonds have no bound);
* :func:`central_term` is the elastic plus the viscous term, the central scalar of a step;
* :func:`pair_forces` turns the central and tangential scalars into the force vector on i and
  splits the internal torque between the two spheres (eq. S1-3).

The engine gathers its per-replica parameters to the candidates and keeps the constants with them
(:class:`~particleShear.engine.forces.PairConstants` has the attributes of a
:class:`TermConstants`); the classes compute them from their per-sphere parameters, once for the
visit from i and, where the spheres' parameters differ, once for the visit from j.

Every function takes the array namespace of its inputs (NumPy or CuPy, :mod:`.xp`).  Units:
distances in µm, velocities in µm/s, forces in mg·µm·s⁻² per m depth (negative central force =
repulsion), k in mg·s⁻² and ν in mg·s⁻¹ per m depth.
"""
__docformat__ = "numpy"

import math

from . import laws
from .laws import central_constants
from .tangential import tangential_two_pass
from .xp import select

__all__ = ["relative_velocity", "normal_speed", "slip_speed", "TermConstants", "term_constants", "term_rows", "TERM_ROWS", "elastic_term", "viscous_term", "viscous_force", "central_term", "tangential_term",
           "pair_forces"]


def relative_velocity(Vi, Vj, dvx=None):
    """Velocity of j's nearest image relative to i, ``v_j − v_i`` (+ the image's ``−Ly·γ̇`` per period above).

    Parameters
    ----------
    Vi, Vj : ndarray (≥ 2, P)
        Velocity rows (``vx, vy``, and possibly ``ω``) of spheres i and j of each pair (µm/s).
    dvx : ndarray (P,) or None
        x velocity of j's image relative to j itself (µm/s; nonzero for pairs across the sheared
        boundary); None: no pair acts through it.

    Returns
    -------
    ndarray (2, P)
        ``(Δv_x, Δv_y)`` (µm/s), a new array.
    """
    rv = Vj[:2] - Vi[:2]
    if dvx is not None:
        rv[0] += dvx
    return rv


def normal_speed(rv, nx, ny):
    """Normal relative velocity ``v_n = Δv·n_ij`` of each pair (µm/s; positive when separating).

    Parameters
    ----------
    rv : ndarray (2, P)
        Relative velocity (:func:`relative_velocity`, µm/s).
    nx, ny : ndarray (P,)
        Unit normal from i towards j.

    Returns
    -------
    ndarray (P,)
    """
    return rv[0] * nx + rv[1] * ny


def slip_speed(rv, nx, ny, ri, rj, omega_i, omega_j):
    """Tangential slip velocity of the two surfaces, ``v_t = Δv·t_ij − (r_i ω_i + r_j ω_j)``, ``t = (−n_y, n_x)``.

    Parameters
    ----------
    rv : ndarray (2, P)
        Relative velocity (:func:`relative_velocity`, µm/s).
    nx, ny : ndarray (P,)
        Unit normal from i towards j.
    ri, rj : ndarray (P,)
        Radii (µm).
    omega_i, omega_j : ndarray (P,)
        Spins (rad/s).

    Returns
    -------
    ndarray (P,)
        Slip velocity along ``t_ij`` seen from i (µm/s); 0 for rolling without slipping.
    """
    spin = ri * omega_i
    spin += rj * omega_j
    vt = rv[0] * -ny + rv[1] * nx
    vt -= spin
    return vt


class TermConstants:
    """Constants of the force terms of P pairs as seen by one visit (see :func:`term_constants`).

    Each attribute is an array over the pairs or a number shared by all of them.

    Attributes
    ----------
    k, c : ndarray or float
        Spring constant and repulsion coefficient the constants were made from (for a law given as
        a callback, which takes them).
    d_law : ndarray or float
        Contact distance of the compressive law (µm): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    d_cap, a_lin, a_div : ndarray or float
        Constants of the compressive law (:func:`~particleShear.engine.laws.central_constants`).
    form : str
        Form of the compressive law (:func:`~particleShear.engine.laws.central_form`).
    d_eq, a_tens : ndarray or float or None
        Equilibrium distance (µm) and ``−k`` of the tensile law of bonds (0 and −0 on contacts:
        ``−0·(0 − d) = +0``); None when no pair is a bond.
    ratio_c : ndarray or float
        Factor on the elastic law: the permanent ratio (central) on bonds, 1 on contacts.
    nu, k_t, nu_t, mu : ndarray or float
        Central viscosity, tangential spring constant, tangential viscosity (bonds: scaled by the
        permanent ratios; the viscosities unless kept constant) and friction coefficient.
    fc_inf : ndarray or float
        Added to the Coulomb bound: ``inf`` on bonds (no bound), 0 on contacts.
    """

    __slots__ = ("k", "c", "d_law", "d_cap", "a_lin", "a_div", "form", "d_eq", "a_tens", "ratio_c", "nu", "k_t", "nu_t", "mu",
                 "fc_inf")

    def __init__(self, **values):
        """Set every attribute.

        Parameters
        ----------
        **values
            One value per attribute name of :attr:`__slots__` (all of them).
        """
        for name in self.__slots__:
            setattr(self, name, values[name])


def term_constants(d0, perm, d_eq, k, c, nu, k_t, nu_t, mu, prc=1.0, prt=1.0, keep=1.0):
    """Constants of the force terms of each pair, from the model parameters seen by one visit.

    Contacts: the compressive law at ``d0 = r_i + r_j`` (eqs. S1-5a/b, S1-6), ``ν``, ``k_t``,
    ``ν_t`` and the Coulomb bound ``|μ·law|``.  Bonds (``perm``): the compressive law at ``d_eq``
    and the tensile law ``−k (d_eq − d)`` above it, both times ``prc``; ``k_t·prt``; the
    viscosities times ``prc`` and ``prt`` unless ``keep``; no Coulomb bound.  All parameters
    broadcast (numbers, or arrays over the pairs).

    Parameters
    ----------
    d0 : ndarray (P,)
        Contact distance ``r_i + r_j`` (µm).
    perm : ndarray of bool (P,) or None
        Which pairs are bonds; None when none is.
    d_eq : ndarray (P,) or None
        Equilibrium distance of each bond (µm; read on bonds only); None when ``perm`` is None.
    k, c : ndarray or float
        Spring constant (eq. S1-8) and central repulsion coefficient in [0, 1].
    nu, k_t, nu_t, mu : ndarray or float
        Central viscosity (eq. S1-9), tangential spring constant and viscosity, friction coefficient.
    prc, prt : ndarray or float, default 1.0
        Permanent ratios (central, tangential) of bonds.
    keep : ndarray or float, default 1.0
        Nonzero where a bond keeps its viscosities (``keep_viscosity_coefficients_constant``).

    Returns
    -------
    TermConstants
    """
    if perm is None:
        d_cap, a_lin, a_div = laws.central_constants(d0, k, c)
        return TermConstants(k=k, c=c, d_law=d0, d_cap=d_cap, a_lin=a_lin, a_div=a_div, form=laws.central_form(c), d_eq=None,
                             a_tens=None, ratio_c=1.0, nu=nu, k_t=k_t, nu_t=nu_t, mu=mu, fc_inf=0.0)
    rows = term_rows(d0, perm, d_eq, k, c, nu, k_t, nu_t, mu, prc, prt, keep)
    return TermConstants(k=k, c=c, form=laws.central_form(c), **dict(zip(TERM_ROWS, rows)))


#: the constants :func:`term_rows` returns, in its order (the attributes of a :class:`TermConstants`
#: but ``k``, ``c`` and ``form``; the rows of the engine's float block from ``d_law`` on)
TERM_ROWS = ("d_law", "d_cap", "a_lin", "a_div", "d_eq", "a_tens", "ratio_c", "nu", "k_t", "nu_t", "mu", "fc_inf")


def term_rows(d0, perm, d_eq, k, c, nu, k_t, nu_t, mu, prc, prt, keep):
    """The constants of the force terms of pairs some of which may be bonds (:data:`TERM_ROWS`), a pure
    expression: :func:`term_constants` calls it on arrays, the compiled backend's rebuild on the
    numbers of each candidate (:func:`~particleShear.engine.forces.pair_rows`).

    Contacts: the compressive law at ``d0`` (eqs. S1-5a/b, S1-6), ``ν``, ``k_t``, ``ν_t``, ``μ`` as
    given, no Coulomb offset.  Bonds: the compressive law at ``d_eq`` and the tensile law
    ``−k (d_eq − d)`` (``a_tens = −k``; ``−0`` on contacts, so that ``−0·(0 − d) = +0``), the factor
    ``prc`` on the elastic law, ``k_t·prt``, the viscosities times ``prc``, ``prt`` where ``keep`` is 0,
    and ``fc_inf = inf`` (no bound).  A factor 1 where it does not apply (``x·1.0`` is ``x``).

    Parameters
    ----------
    d0, d_eq : ndarray or float
        Contact distance ``r_i + r_j`` and equilibrium distance of a bond (µm).
    perm : ndarray of bool or bool
        Which pairs are bonds.
    k, c, nu, k_t, nu_t, mu, prc, prt, keep : ndarray or float
        As :func:`term_constants`.

    Returns
    -------
    tuple
        The values of :data:`TERM_ROWS` (arrays, or numbers on numbers).
    """
    d_law = select(perm, d_eq, d0)
    d_cap, a_lin, a_div = central_constants(d_law, k, c)
    loose = perm & (keep == 0)          # (bonds whose viscosities take the permanent ratios)
    return (d_law, d_cap, a_lin, a_div, select(perm, d_eq, 0.0), -select(perm, k, 0.0), select(perm, prc, 1.0),
            nu * select(loose, prc, 1.0), k_t * select(perm, prt, 1.0), nu_t * select(loose, prt, 1.0), mu,
            select(perm, math.inf, 0.0))


def elastic_term(K, d, central=None, tensile=None):
    """Central elastic force of each pair and its law before the permanent ratio.

    The compressive law (eqs. S1-5a/b, cap S1-6, or the law ``central``) up to ``K.d_law``;
    beyond it the tensile law of a stretched bond (``−k (d_eq − d)``, or the law ``tensile``),
    and +0 for a contact that has separated.

    Parameters
    ----------
    K : TermConstants or PairConstants
        Constants of the pairs (:func:`term_constants`).
    d : ndarray (P,)
        Centre distances (µm).
    central : callable, optional
        ``central(d)``: the compressive law of every pair as if in contact (a law of the
        registry, :func:`~particleShear.engine.phase_laws.force_phase_laws`); None: the linear law
        from the constants of ``K``.
    tensile : callable, optional
        ``tensile(d)``: the tensile law on the stretched bonds, 0 on the other pairs; None: the
        linear tensile law from the constants of ``K``.

    Returns
    -------
    f : ndarray (P,)
        Elastic force on i along ``n_ij``, ``law·ratio_c`` (mg·µm·s⁻² per m depth; negative repels);
        a new array.
    law : ndarray (P,)
        The law before the ratio (same unit), the base of the Coulomb bound.
    """
    if central is None:
        inside = laws.central_inside(d, K.d_law, K.d_cap, K.a_lin, K.a_div, form=K.form)
    else:
        inside = central(d)
    if K.a_tens is None:
        beyond = 0.0
    else:
        beyond = laws.tensile_inside(d, K.d_eq, K.a_tens) if tensile is None else tensile(d)
    law = laws.contact_or_bond(d, K.d_law, inside, beyond)
    return law * K.ratio_c, law


def viscous_term(K, vn, active):
    """Central viscous force ``ν·v_n`` of each relation (eq. S1-9); 0 on other candidates.

    Parameters
    ----------
    K : TermConstants or PairConstants
        Constants of the pairs (``nu``).
    vn : ndarray (P,)
        Normal relative velocity ``(v_j − v_i)·n_ij`` (µm/s; positive when separating).
    active : ndarray of bool (P,) or None
        Relations (touching, or a bond); None when every pair is one.

    Returns
    -------
    ndarray (P,)
        Viscous force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    if active is None:
        return K.nu * vn
    return viscous_force(K.nu, vn, active)


def viscous_force(nu, vn, active):
    """Central viscous force ``ν·v_n`` of a relation (eq. S1-9), 0 on a candidate that is none.

    A pure expression (docs/backends.md, "One law, two drivers"): arrays or numbers.

    Parameters
    ----------
    nu : ndarray or float
        Central viscosity (mg·s⁻¹ per m depth).
    vn : ndarray or float
        Normal relative velocity (µm/s; positive when separating).
    active : ndarray of bool or bool
        Relation (touching, or a bond).

    Returns
    -------
    ndarray or float
        Viscous force on i along ``n_ij`` (mg·µm·s⁻² per m depth).
    """
    return select(active, nu, 0.0) * vn


def central_term(K, d, vn, active, central=None, tensile=None):
    """Elastic + viscous central scalar of each candidate (on i along ``n_ij``; −n on j) and the law.

    Parameters
    ----------
    K : TermConstants or PairConstants
        Constants of the pairs.
    d : ndarray (P,)
        Centre distances (µm).
    vn : ndarray (P,)
        Normal relative velocity (µm/s).
    active : ndarray of bool (P,)
        Relations; only they get the viscous term.
    central, tensile : callable, optional
        The laws of this force phase (:func:`elastic_term`); None: the linear laws.

    Returns
    -------
    f : ndarray (P,)
        :func:`elastic_term` + :func:`viscous_term` (mg·µm·s⁻² per m depth).
    law : ndarray (P,)
        The elastic law before the permanent ratio (the base of the Coulomb bound).
    """
    f, law = elastic_term(K, d, central, tensile)
    f += viscous_term(K, vn, active)
    return f, law


def tangential_term(K, vt, touching, xi, law, K_j=None):
    """Two-visit tangential rule with the Coulomb bound ``|μ·law|`` (bonds: none); updates ``xi``.

    Parameters
    ----------
    K : TermConstants or PairConstants
        Constants of the pairs seen by the visit from i (``k_t``, ``nu_t``, ``mu``, ``fc_inf``).
    vt : ndarray (P,)
        Tangential slip velocity along ``t_ij`` seen from i (µm/s).
    touching : ndarray (P,) of float or bool
        1 where the pair overlaps (``d < r_i + r_j``), else 0.
    xi : ndarray (2, P)
        Histories ξ_ij, ξ_ji (µm), updated in place (reset on slip).
    law : ndarray (P,)
        Elastic law of each pair before the ratio (:func:`elastic_term`).
    K_j : TermConstants, optional
        Constants seen by the visit from j, where the spheres' parameters differ (default ``K``).

    Returns
    -------
    F : ndarray (2, P)
        Tangential forces of the two visits (mg·µm·s⁻² per m depth), see
        :func:`~particleShear.engine.tangential.tangential_two_pass`.
    slip : ndarray of bool (P,)
        The final slip flag.
    """
    K_j = K if K_j is None else K_j
    fc = abs(K.mu * law)
    fc += K.fc_inf
    return tangential_two_pass(vt, touching, xi, K.k_t, K_j.k_t, K.nu_t, K_j.nu_t, fc)


def pair_forces(fn, ft, nx, ny, d, w):
    """Force on sphere i of each pair, and the torques on i and j (eq. S1-3).

    ``F_i = f_n·n + f_t·t`` with ``t = (−n_y, n_x)`` (j receives ``−F_i``); the internal torque
    ``d·f_t`` is split in proportion to the radii, ``d·f_t·r_i/(r_i + r_j)`` on i and
    ``d·f_t·r_j/(r_i + r_j)`` on j.

    Parameters
    ----------
    fn : ndarray (P,) or float
        Central scalar on i along ``n_ij`` (:func:`central_term`; mg·µm·s⁻² per m depth).
    ft : ndarray (P,) or None
        Tangential scalar along ``t_ij`` (the mean of the two visits of :func:`tangential_term`);
        None: no tangential force and no torques.
    nx, ny : ndarray (P,)
        Unit normal from i towards j.
    d : ndarray (P,)
        Centre distances (µm).
    w : ndarray (2, P) or None
        Lever fractions ``r_i/(r_i + r_j)``, ``r_j/(r_i + r_j)``; None: no torques wanted.

    Returns
    -------
    fx_i, fy_i : ndarray (P,)
        Force on i (mg·µm·s⁻² per m depth).
    dF : ndarray (P,) or None
        Internal torque ``d·f_t`` of each pair (mg·µm²·s⁻² per m depth; the torque terms of the
        stress tensors), None without ``ft``.
    tq : ndarray (2, P) or None
        Torques on i and on j (mg·µm²·s⁻² per m depth), None without ``ft`` or ``w``.
    """
    if ft is None:
        return fn * nx, fn * ny, None, None
    dF = d * ft
    return fn * nx - ft * ny, fn * ny + ft * nx, dF, (None if w is None else dF * w)
