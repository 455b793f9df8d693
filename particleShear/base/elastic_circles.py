"""Elastic and frictional circles: the per-sphere force API of 1.0.2 (docs/classes.md, "The documented classes").

Each method evaluates :mod:`particleShear.engine.terms` on the pairs it is asked about, one visit per
call.  ``theSphere`` is the partner; ``k``, ``k_t`` the central and tangential spring constants
(mg·s⁻² per m depth, eq. S1-8), ``nu`` a viscosity (mg·s⁻¹ per m depth, eq. S1-9), ``mu`` the friction
coefficient; forces are in mg·µm·s⁻² per m depth.
"""
__docformat__ = "numpy"
import inspect
import math

import numpy as np

from . import callbacks as _callbacks
from ..engine.box import flow_velocity
from ..engine.integrate import damp, kick, xi_increments
from ..engine.terms import (elastic_term, normal_speed, pair_forces, tangential_term, term_constants, viscous_term)
from .laws import elastic_force_law
from .circles import Circle, CircleMassNeighbors
from .point_base import ArrayField, Point, PointLeesEdwards, _one, _with

__all__ = ["CircleBasicElasticity", "CircleFrictionElasticity"]


def _for_every_relation(method):
    """Document ``<visit>_from_neighbors(self, *constants)``, which applies ``<visit>`` for every relation."""
    constants = ", ".join(list(inspect.signature(method).parameters)[1:])
    method.__doc__ = (f"Apply :meth:`{method.__name__[:-len('_from_neighbors')]}` for every relation, in "
                      f"``neighbors`` order.\n\n        Parameters\n        ----------\n        {constants} : float\n")
    return method


class CircleBasicElasticity(CircleMassNeighbors):
    """Disc with central elastic and viscous contact forces (eqs. S1-5a/b, S1-6, S1-9).

    The class attribute ``call_back_elastic_force_law`` (default
    :func:`~particleShear.base.laws.elastic_force_law`) is the central law of every sphere; the engine reads it.

    Parameters
    ----------
    color, x, y, diameter, m, theCanvas, doDrawing, force_register, use_lees_edwards
        As for :class:`~particleShear.base.circles.CircleMass` (and raising as it does).
    """

    call_back_elastic_force_law = elastic_force_law
    central_repulsion_coefficient = ArrayField(0, param=True)

    def _bond(self, theSphere):
        """Equilibrium distance (µm) of the bond to ``theSphere``; None: a contact (these spheres have no bonds)."""
        return None

    def _terms(self, theSphere, d_eq=None, k=1.0, nu=0.0, k_t=0.0, nu_t=0.0, mu=0.0):
        """:func:`~particleShear.engine.terms.term_constants` of the visit to ``theSphere`` (a contact, or a bond at
        ``d_eq``), with this sphere's c and permanent ratios (1 where it has none); constants a method does not
        take keep their defaults and do not enter its term."""
        bond = d_eq is not None
        return term_constants(_one(self.r + theSphere.r), np.array([True]) if bond else None,
                              _one(d_eq) if bond else None, k, self.central_repulsion_coefficient, nu, k_t, nu_t, mu,
                              getattr(self, "permanent_ratio_central", 1.0),
                              getattr(self, "permanent_ratio_tangential", 1.0),
                              getattr(self, "keep_viscosity_coefficients_constant", 1.0))

    def _replaced_law(self, K, d):
        """A replaced ``call_back_elastic_force_law`` at ``(d, d_law, k, c)`` as an array of 1 (called with floats,
        as in 1.0.2); None for the built-in law."""
        law = CircleBasicElasticity.call_back_elastic_force_law
        return None if law is elastic_force_law else _one(law(d.item(), K.d_law.item(), K.k, K.c))

    def _elastic(self, K, d):
        """``(law·ratio_c, law)`` of the pair at distance ``d`` (arrays of 1), built in or replaced."""
        law = self._replaced_law(K, d)
        return elastic_term(K, d) if law is None else (law * K.ratio_c, law)

    def _apply_central(self, theSphere, p, f):
        """Apply and register the central force ``f·n`` of the pair ``p``; return ``[F_x, F_y]``."""
        fx, fy = pair_forces(f, None, p.nx, p.ny, p.d, None)[:2]
        vec = [fx.item(), fy.item()]
        self.applyInternalForceAndRegister(vec, theSphere)
        return vec

    def get_elastic_force(self, theSphere, k=1):
        """Return the central force ``law(d, r_i + r_j, k, c)`` of the active contact law (negative = repulsion).

        The built-in laws (eqs. S1-5a/b, S1-6) give 0 beyond contact.

        Parameters
        ----------
        theSphere : Point
        k : float
        """
        return self._elastic(self._terms(theSphere, k=k), self._pairs([theSphere], normal=False).d)[0].item()

    def elastic_force(self, theSphere, k):
        """Apply, register and return the central elastic force along ``n`` if the discs overlap, else ``[0, 0]``.

        A bond of a linkable sphere acts at any distance, with the law of ``get_elastic_force_permanent``.

        Parameters
        ----------
        theSphere : Point
        k : float
        """
        d_eq = self._bond(theSphere)
        p = self._pairs([theSphere])
        if d_eq is None and not p.d[0] < self.r + theSphere.r:
            return [0, 0]
        return self._apply_central(theSphere, p, self._elastic(self._terms(theSphere, d_eq, k=k), p.d)[0])

    @_for_every_relation
    def elastic_force_from_neighbors(self, k):
        for rel in list(self.neighbors):
            self.elastic_force(rel.theSphere, k)

    def _viscous(self, theSphere, nu):
        """The pair's ``_Pairs`` and its viscous term ``ν·v_n`` (a bond's ν × its ratio unless kept constant)."""
        p = self._pairs([theSphere])
        vn = normal_speed(p.velocity(), p.nx, p.ny)
        return p, viscous_term(self._terms(theSphere, self._bond(theSphere), nu=nu), vn, None)

    def get_central_viscous_force(self, theSphere, nu):
        """Return the central viscous force ``ν v_n`` (eq. S1-9; a bond's ν × its ratio unless kept constant).

        Parameters
        ----------
        theSphere : Point
        nu : float
        """
        return self._viscous(theSphere, nu)[1].item()

    def central_viscous_force(self, theSphere, nu):
        """Apply, register and return the force ``ν v_n n`` of :meth:`get_central_viscous_force`.

        Parameters
        ----------
        theSphere : Point
        nu : float
        """
        return self._apply_central(theSphere, *self._viscous(theSphere, nu))

    @_for_every_relation
    def central_viscous_force_from_neighbors(self, nu):
        for rel in list(self.neighbors):
            self.central_viscous_force(rel.theSphere, nu)


class CircleFrictionElasticity(CircleBasicElasticity):
    """Disc with spin and tangential (frictional) contact forces (eqs. S1-3, S1-7); inertia ``m r²/2``.

    Parameters
    ----------
    color, x, y, diameter, m, theCanvas, doDrawing, force_register, use_lees_edwards
        As for :class:`~particleShear.base.circles.CircleMass` (and raising as it does).
    """

    _spins = True
    phi = ArrayField(-math.pi / 2)
    omega = ArrayField(0)
    torque = ArrayField(0)
    inertia = ArrayField(0.5, positive=True, param=True)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                       force_register, use_lees_edwards)
        self.rotation_line = None
        self.inertia = self.m * self.r * self.r / 2

    def cool(self, f=0.8, shear_rate_to_rotation_rate_coefficient=0):
        """Damp by ``f`` the velocity relative to the flow ``u = γ̇ (y − Ly/2)`` and ω relative to ``κ·u``.

        Without Lees-Edwards the velocity is damped plainly; κ = ``shear_rate_to_rotation_rate_coefficient``.

        Parameters
        ----------
        f : float
        shear_rate_to_rotation_rate_coefficient : float
        """
        PointLeesEdwards.cool(self, f) if self.use_lees_edwards else Point.cool(self, f)
        spin = _one(self.omega)[:, None]
        kappa_u = flow_velocity(_one(self.y), self.size_y, self.shear_rate) * shear_rate_to_rotation_rate_coefficient
        damp(spin, kappa_u, f)
        self.omega = spin.item()

    def _visit(self, theSphere, p, K, xi_ij, xi_ji=0.0, bounded=True):
        """One visit of :func:`~particleShear.engine.terms.tangential_term`, the engine's second after a first that
        applies nothing (``k_t = ν_t = 0``): ``clamp(ν_t v_t·[d < r_i + r_j] + k_t ξ_ij)`` within ``|μ·law|`` (no
        bound for bonds and ``bounded=False``).  ``xi_ij``, ``xi_ji``: the histories of this sphere's relation and
        the partner's (µm).  Returns the force along ``t_ij`` (array of 1), whether it slipped, and the (2, 1)
        ``ξ_ji, ξ_ij`` after it (both 0 after a slip)."""
        ri, rj = p.radii()
        law = self._elastic(K, p.d)[1] if bounded else _one(0.0)
        first = _with(K, k_t=0.0, nu_t=0.0, fc_inf=K.fc_inf if bounded else math.inf)
        xi = _one(xi_ji, xi_ij)[:, None]
        F, slip = tangential_term(first, p.slip(), p.d < ri + rj, xi, law, K)
        return F[1], bool(slip[0]), xi

    def _tangential_part(self, theSphere, bond, xi=None, **constants):
        """A part of a visit's force without bound (:meth:`_visit`): the viscous part (``xi`` None; 0 without
        overlap) or the elastic part ``k_t ξ``; ``bond``: with a bond's constants (``d_eq`` does not enter them)."""
        p = self._pairs([theSphere])
        if xi is None and not p.d[0] < self.r + theSphere.r:
            return 0
        K = self._terms(theSphere, self.r + theSphere.r if bond else None, **constants)
        return self._visit(theSphere, p, K, 0.0 if xi is None else xi, bounded=False)[0].item()

    def tangential_force_viscous(self, theSphere, nu):
        """Return the tangential viscous force ``ν_t v_t`` (``nu`` = ν_t) if the discs overlap, else 0.

        Parameters
        ----------
        theSphere : Point
        nu : float
        """
        return self._tangential_part(theSphere, False, nu_t=nu)

    def tangential_force_elastic(self, theSphere, k_t):
        """Return the tangential elastic force ``k_t ξ`` if the discs overlap and are related, else 0.

        Parameters
        ----------
        theSphere : Point
        k_t : float
        """
        rel = self._relation(theSphere)
        if rel is None or not self.d(theSphere) < self.r + theSphere.r:
            return 0
        return self._tangential_part(theSphere, False, rel.friction_position, k_t=k_t)

    def distribute_tangential_couple(self, theSphere, force):
        """Apply ``force`` along ``t_ij`` on self, the opposite on the partner, and the torques (eq. S1-3).

        The torques ``d·f·r_i/(r_i + r_j)`` on self and ``d·f·r_j/(r_i + r_j)`` on the partner have the same
        sign; the two forces and two torques are registered.

        Parameters
        ----------
        theSphere : Point
        force : float
        """
        p = self._pairs([theSphere])
        w = _one(self.r, theSphere.r)[:, None] / (self.r + theSphere.r)
        fx, fy, _, tq = pair_forces(0.0, _one(force), p.nx, p.ny, p.d, w)
        vec = [fx.item(), fy.item()]
        self.applyInternalForceAndRegister(vec, theSphere)
        theSphere.applyInternalForceAndRegister([-vec[0], -vec[1]], self)
        ti, tj = tq[:, 0].tolist()
        self.torque = self.torque + ti
        theSphere.torque = theSphere.torque + tj
        for a, b, t in ((self, theSphere, ti), (theSphere, self, tj)):
            if hasattr(a.force_register, "record_individual_internal_torque"):
                a.force_register.record_individual_internal_torque(a, b, t)

    def tangential_force(self, theSphere, nu, mu, k, k_t):
        """One visit of the tangential routine (a contact; for a linkable sphere also a bond); return its force.

        The force ``ν_t v_t·[d < r_i + r_j] + k_t ξ`` of a contact is limited by ``μ |law(d, r_i + r_j, k, c)|``;
        the visit sets the state of both directions (stick or slip) and a slip resets both histories.  A bond
        has no bound and keeps its state.  Half of the force is applied (:meth:`distribute_tangential_couple`).
        0 without a relation or, for a contact, without overlap.

        Parameters
        ----------
        theSphere : Point
        nu, mu, k, k_t : float
            Tangential viscosity ν_t, friction coefficient μ, spring constants k and k_t.
        """
        rel = self._relation(theSphere)
        d_eq = self._bond(theSphere)
        p = self._pairs([theSphere])
        if rel is None or (d_eq is None and not p.d[0] < self.r + theSphere.r):
            return 0
        back = theSphere._relation(self) if hasattr(theSphere, "_relation") else None
        F, slip, xi = self._visit(theSphere, p, self._terms(theSphere, d_eq, k=k, k_t=k_t, nu_t=nu, mu=mu),
                                  rel.friction_position, 0.0 if back is None else back.friction_position)
        if d_eq is None:
            state = "slip" if slip else "stick"
            for r, x in ((rel, xi[1]), (back, xi[0])):
                if r is not None:
                    r.friction_position = x.item()
                    r.interface_type = state
        f = F.item()
        self.distribute_tangential_couple(theSphere, f / 2)
        return f

    @_for_every_relation
    def tangential_force_from_neighbors(self, nu, mu, k, k_t):
        for rel in list(self.neighbors):
            self.tangential_force(rel.theSphere, nu, mu, k, k_t)

    def do_rotational_acceleration(self, dt):
        """Register the net torque, kick the spin by ``T dt / I`` (``dt`` in s), reset the torque.

        Parameters
        ----------
        dt : float
        """
        reg = self.force_register
        if hasattr(reg, "record_unbalanced_moment"):
            reg.record_unbalanced_moment(self, self.torque)
        spin, torque = _one(self.omega)[:, None], _one(self.torque)[:, None]
        kick(spin, torque, self.inertia, dt)
        self.omega, self.torque = spin.item(), torque.item()

    def move(self, dt=1):
        """Advance φ, integrate ξ of the stick and permanent relations, then drift by ``dt`` (s).

        ``ξ_ij += ξ̇_ij·dt`` (:func:`~particleShear.engine.integrate.xi_increments`) with the current
        velocities and positions (partners moved before count at their new positions); the partner
        integrates ``ξ_ji`` in its own move.

        Parameters
        ----------
        dt : float
        """
        rels = [rel for rel in self.neighbors if rel.interface_type in ("stick", "permanent")]
        if rels:
            p = self._pairs([rel.theSphere for rel in rels])
            inc = xi_increments(p.rows([self]), p.rows(p.spheres), p.dvx, p.nx, p.ny, *p.radii(), -p.dx, -p.dy,
                                lambda Rx, Ry: (-p.nx, -p.ny))[0]
            for rel, step in zip(rels, (inc * dt).tolist()):
                rel.friction_position = rel.friction_position + step
        Circle.move(self, dt)


# the engine reads the documented callback from this class at every force phase (it never imports this layer)
_callbacks.hold_callbacks("central", CircleBasicElasticity)
