"""Canvases with pair forces: the force, acceleration and movement phases of the documented step (docs/design.md, "The documented classes").

=========================================  ==============================================
``CanvasPointsBasicElasticity``            central elastic + viscous pair term (eqs. S1-5a/b, S1-6, S1-9)
``CanvasPointsBasicElasticityLeesEdwards`` rate changes, boundary-aware registration
``CanvasPointsFrictionElasticityLeesEdwards``  tangential term, torques, ξ history (eqs. S1-3, S1-7)
=========================================  ==============================================

Every law, term and integration rule is the engine's function (:mod:`particleShear.engine.terms`,
:mod:`particleShear.engine.integrate`); the classes apply them to the pairs of
:class:`~particleShear.base.pair_canvas.CanvasPointsNeighbors`'s table, per visit where the
spheres' own parameters differ.
"""
__docformat__ = "numpy"
import numpy as np
from .kernels import min_image, pair_geometry
from .namespace import (where as _where)
from . import laws
from .laws import call_law_vectorised
from ..engine.integrate import damp, xi_increments
from ..engine.terms import (elastic_term, normal_speed, relative_velocity, slip_speed, tangential_term,
                            term_constants, viscous_term)
from .neighbours import SLIP
from .points import CircleBasicElasticity, _check_finite

from .canvas import _PARAMS, _SLIP8, _ZERO_BEYOND_CONTACT, NonNegative, check_time_step
from .pair_canvas import CanvasPointsShear
from .engine_view import EngineStep

__all__ = ["CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards", "CanvasPointsFrictionElasticityLeesEdwards"]


class CanvasPointsBasicElasticity(EngineStep, CanvasPointsShear):
    """Adds the central elastic and viscous pair forces with constants ``k`` and ``nu``.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``/``nu`` is not a finite number ≥ 0.
    """

    k = NonNegative()
    nu = NonNegative()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1):
        CanvasPointsShear.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self.k = k
        self.nu = nu
        self.central_repulsion_coefficient = 0
        self.integrator = "euler"
        self.stability_guard = None
        self.phase = ""
        self.step_count = 0

    INTEGRATORS = ("euler", "verlet")

    def set_integrator(self, integrator):
        """Choose the time integrator.

        ``"euler"`` (default) is the reference's semi-implicit Euler: kick with the
        forces of the step, damp, drift.  ``"verlet"`` is velocity Verlet with a
        half-kick predictor (Groot-Warren λ = 1/2): the velocity-dependent forces
        see the velocity at the force time instead of half a step earlier, which
        makes the viscous terms second-order accurate.  Positions and the
        conservative forces are updated identically by both.

        Parameters
        ----------
        integrator : str
            One of :attr:`INTEGRATORS` (``"euler"`` or ``"verlet"``).

        Raises
        ------
        ValueError
            If ``integrator`` is not one of them.
        """
        if integrator not in self.INTEGRATORS:
            raise ValueError(f"integrator must be one of {self.INTEGRATORS}, got {integrator!r}")
        self.integrator = integrator
        self._half_kick = None

    def set_central_repulsion_coefficient(self, central_repulsion_coefficient=0):
        """Set the law's repulsion coefficient c ∈ [0, 1] on the ensemble and every sphere.

        Parameters
        ----------
        central_repulsion_coefficient : float
            c of the force law: 0 = linear (eq. S1-5a), 1 = divergent (eq. S1-5b).

        Raises
        ------
        ValueError
            If the value is not finite.
        """
        _check_finite("central_repulsion_coefficient", central_repulsion_coefficient)
        self.central_repulsion_coefficient = central_repulsion_coefficient
        self._a["central_repulsion_coefficient"][:] = central_repulsion_coefficient
        self._params_changed()

    def _builtin_laws(self):
        """Whether the built-in central law is in use (a law replaced through ``call_back_elastic_force_law`` is
        evaluated by :meth:`_user_law_term`)."""
        return CircleBasicElasticity.call_back_elastic_force_law is laws.elastic_force_law

    def _term_constants(self, g):
        """``(K_i, K_j, differ)``: the constants of the force terms of the step's pairs as seen by the visit from i
        and from j (:func:`~particleShear.engine.terms.term_constants`), and the names of the terms whose two
        visits differ (``"elastic"``, ``"viscous"``, ``"tangential"``; empty when every sphere has the same
        parameters, and then ``K_j is K_i``).

        They are made from the pair structure, the ensemble's k, ν, k_t, ν_t, μ and each visit's own sphere
        parameters (c and the permanent ratios, :data:`_PARAMS`), and kept in the memo under exactly
        these (the structure's key, the version of the sphere parameters and the ensemble's values).
        """
        S = g.S
        values = (self.k, self.nu, getattr(self, "k_t", 0.0), getattr(self, "nu_t", 0.0), getattr(self, "mu", 0.0))
        return self._memo.get("term_constants", (S.key, self._params_version) + values,
                              lambda: self._visit_constants(S, *values))

    def _visit_constants(self, S, k, nu, k_t, nu_t, mu):
        """The :meth:`_term_constants` of structure ``S``: a parameter all spheres share is one number, else the
        value of the visiting sphere (i for the first visit, j for the second) per pair."""
        shared = dict(zip(_PARAMS, (self._param(name) for name in _PARAMS)))

        def visit(rows):
            c, prc, prt, keep = (shared[name] if shared[name] is not None else self._a[name].take(rows)
                                 for name in _PARAMS)
            return term_constants(S.d0, S.perm, S.deq, k, c, nu, k_t, nu_t, mu, prc, prt, keep)

        K_i = visit(S.ai)
        # the parameters each term reads (the permanent ratios and kept viscosities only on bonds)
        bonds = S.perm is not None
        reads = {"elastic": ("central_repulsion_coefficient",) + (("permanent_ratio_central",) if bonds else ()),
                 "viscous": ("permanent_ratio_central", "keep_viscosity_coefficients_constant") if bonds else (),
                 "tangential": ("permanent_ratio_tangential", "keep_viscosity_coefficients_constant") if bonds else ()}
        differ = frozenset(term for term, names in reads.items() if any(shared[n] is None for n in names))
        return K_i, (visit(S.aj) if differ else K_i), differ

    def _user_law_term(self, K, g):
        """Elastic term with a law replaced through ``call_back_elastic_force_law``, pair by pair (as
        :func:`~particleShear.engine.terms.elastic_term`): ``(law·ratio_c, law)``, 0 on inactive candidates
        unless the law is one of the built-in ones that vanish beyond contact."""
        law = self._mask_law(call_law_vectorised(CircleBasicElasticity.call_back_elastic_force_law, g.d, K.d_law,
                                                 K.k, K.c))
        return law * K.ratio_c, law

    def _mask_law(self, f):
        """Zero a user law's value on inactive candidates (the built-in laws are 0 beyond contact)."""
        if self._g.active is None or CircleBasicElasticity.call_back_elastic_force_law in _ZERO_BEYOND_CONTACT:
            return f
        return f * self._g.active

    def elastic_force_from_neighbors(self):
        """Central elastic force of every relation (eqs. S1-5a, S1-5b; links in tension: docs/design.md)."""
        self._geometry()
        self._elastic_terms()
        self._term_done()

    def _elastic_terms(self):
        """Central elastic force of every relation, each visit with its own constants: contacts ``law(d, r_i + r_j,
        k, c)`` (0 beyond contact), bonds the law at ``d_eq`` and the tensile law beyond it, × the permanent ratio
        (:func:`~particleShear.engine.terms.elastic_term`).  Keeps the law of the visit from i as ``g.fel``, the
        base of the Coulomb bound."""
        g = self._g
        if not g.P:
            return
        K_i, K_j, differ = self._term_constants(g)
        term = elastic_term if self._builtin_laws() else (lambda K, d: self._user_law_term(K, g))
        f_i, g.fel = term(K_i, g.d)
        f_j = term(K_j, g.d)[0] if "elastic" in differ else None
        self._add_normal(f_i, f_j)

    def _relative_velocity(self, g):
        """Velocity of j's nearest image relative to i (µm/s), shape (2, P), computed once per force phase.

        Also keeps the gathered (xspeed, yspeed, omega) of both spheres for the tangential term."""
        if g.rv is None:
            vel = self._vel
            g.Vi = vel.take(g.ai, axis=1)
            g.Vj = vel.take(g.aj, axis=1)
            g.rv = relative_velocity(g.Vi, g.Vj, g.dvx)
        return g.rv

    def _normal_speed(self, g):
        if g.vn is None:
            g.vn = normal_speed(self._relative_velocity(g), g.n[0], g.n[1])
        return g.vn

    def central_viscous_force_from_neighbors(self):
        """Central viscous force ``ν v_n`` of every relation (eq. S1-9)."""
        self._geometry()
        self._viscous_terms()
        self._term_done()

    def _viscous_terms(self):
        """Central viscous force of every relation, each visit with its own ν (bonds: × the permanent ratio unless
        the viscosities are kept constant; :func:`~particleShear.engine.terms.viscous_term`)."""
        g = self._g
        if not g.P:
            return
        if self.nu == 0:
            # no force, but the reference still registers ν·v_n = 0 per visit (noted for the register only)
            g.parts = (g.parts or []) + [("viscous", None, None)]
            return
        K_i, K_j, differ = self._term_constants(g)
        vn = self._normal_speed(g)
        f_i = viscous_term(K_i, vn, g.active)
        f_j = viscous_term(K_j, vn, g.active) if "viscous" in differ else None
        self._add_normal(f_i, f_j, "viscous")

    def elastic_force(self):
        """All-pairs variant (reference API): a neighbour update, then the elastic term."""
        self.test_neighbor_relation()
        self.elastic_force_from_neighbors()

    def central_viscous_force(self):
        """All-pairs variant (reference API): a neighbour update, then the central viscous term."""
        self.test_neighbor_relation()
        self.central_viscous_force_from_neighbors()

    def mechanical_simulation_step_calculate_forces(self, dt=1):
        """Clear the register, update neighbours, add every pair force (first phase of a step).

        The engine's force phase on the ensemble's own state (:mod:`particleShear.base.engine_view`):
        the forces and torques add to those already on the spheres, and the force register holds
        the phase's terms.  Then the stability guard, if set, checks the state.  ``dt`` is
        accepted for the 1.0.2 signature.

        Parameters
        ----------
        dt : float
            Time step (s); not used by the force phase.
        """
        self.reset_force_register()
        self._engine_force_phase()
        if self.stability_guard is not None:
            self.stability_guard.check(self, step=self.step_count, phase=self.phase, dt=self._last_dt)

    _last_dt = None

    def mechanical_simulation_step_calculate_acceleration(self, cool_factor=0.97, dt=1):
        """Kick the velocities with the forces of the step (the plates follow), then damp them (third
        phase of a step; the engine's :meth:`~particleShear.engine.step.BatchEngine.accelerate`:
        eqs. S1-10, S1-11).

        With velocity Verlet the half kick of the mobile spheres is kept for the next force phase.

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)
        self._last_dt = dt
        self._engine_accelerate(cool_factor, dt)

    def mechanical_simulation_step_calculate_movement(self, dt=1):
        """ξ rule, drift, strain update, wrap, clock (last phase of a step; the engine's
        :meth:`~particleShear.engine.step.BatchEngine.move`).

        The strain advances by ``γ̇·dt`` while shearing (always in the frictional canvases).

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)
        self._engine_move(dt)
        self.step_count += 1
        self._g = None
        if self._renderer is not None:
            self._renderer.update(self)

    def mechanical_simulation_step(self, cool_factor=0.97, dt=1):
        """One step in reference order: forces → totals → kick + damping → movement.

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)  # before the force phase: a refused step does no work
        self.mechanical_simulation_step_calculate_forces()
        self.record_total_particle_forces()
        self.mechanical_simulation_step_calculate_acceleration(cool_factor, dt)
        self.mechanical_simulation_step_calculate_movement(dt)

    def mechanical_relaxation(self, N=1000, cool_factor=0.97, dt=1, theTk=False, StressTensorEvaluator=False):
        """N steps; optionally a window update and a stress evaluation after each.

        Parameters
        ----------
        N : int
            Number of steps.
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.
        theTk : object or bool
            Tk root window updated after each step (False: none).
        StressTensorEvaluator : StressTensorEvaluation or bool
            Evaluator updated after each step (False: none).

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        for _ in range(int(N)):
            self.mechanical_simulation_step(cool_factor, dt)
            if theTk:
                theTk.update()
            if StressTensorEvaluator:
                self.evaluate_stress_tensors(StressTensorEvaluator)

    @property
    def active_terms(self):
        """Names of the force terms a step of this ensemble evaluates now."""
        terms = ["central_elastic"]
        if self.nu != 0:
            terms.append("central_viscous")
        return terms


class CanvasPointsBasicElasticityLeesEdwards(CanvasPointsBasicElasticity):
    """Adds shear-rate changes that keep velocities relative to the flow (docs/design.md).

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``/``nu`` is not a finite number ≥ 0.
    """

    def setShear(self, theShear):
        """Set the shear strain γ (the Lees-Edwards offset is ``Ly·γ``).

        Parameters
        ----------
        theShear : float
            Strain (dimensionless).
        """
        self.shear = theShear
        self._g = None

    def setShearInSpheres(self):
        """Kept for the 1.0.2 API: spheres read γ from the ensemble (does nothing)."""
        pass  # spheres read γ from the ensemble

    def setShearRateInSpheres(self):
        """Kept for the 1.0.2 API: spheres read γ̇ from the ensemble (does nothing)."""
        pass  # spheres read γ̇ from the ensemble

    def adjust_sphere_speed_to_shear_rate_change(self, delta_shear_rate):
        """Add the change of the affine flow to every velocity (and −Δγ̇/2 to every spin).

        Parameters
        ----------
        delta_shear_rate : float
            Change Δγ̇ of the shear rate (1/s).
        """
        a = self._a
        a["xspeed"] += self._y_centred() * delta_shear_rate
        a["omega"] -= delta_shear_rate / 2

    def setShearRate(self, theShearRate):
        """Change γ̇; every sphere keeps its velocity relative to the local flow.

        Parameters
        ----------
        theShearRate : float
            New shear rate γ̇ (1/s).
        """
        delta = theShearRate - self.shear_rate
        if delta != 0:
            self.adjust_sphere_speed_to_shear_rate_change(delta)
        self.shear_rate = theShearRate


class CanvasPointsFrictionElasticityLeesEdwards(CanvasPointsBasicElasticityLeesEdwards):
    """Adds the tangential force (``k_t``, ``nu_t``, Coulomb ``mu``), spin and the ξ history.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).
    k_t : float
        Tangential spring constant (mg·s⁻² per m depth), ≥ 0.
    nu_t : float
        Tangential viscosity constant (mg·s⁻¹ per m depth), ≥ 0.
    mu : float
        Coulomb friction coefficient μ (dimensionless), ≥ 0.

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``, ``nu``, ``k_t``, ``nu_t`` or ``mu`` is not a finite number ≥ 0.
    """

    k_t = NonNegative()
    nu_t = NonNegative()
    mu = NonNegative()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1, k_t=1,
                 nu_t=0.01, mu=0.1):
        CanvasPointsBasicElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m)
        self.k_t = k_t
        self.nu_t = nu_t
        self.mu = mu

    def _tangential_speed(self, g):
        if g.vt is None:
            g.vt = slip_speed(self._relative_velocity(g), g.n[0], g.n[1], g.ri, g.rj, g.Vi[2], g.Vj[2])
        return g.vt

    def _add_tangential(self, f_pair):
        g = self._g
        g.ft = f_pair if g.ft is None else g.ft + f_pair

    def _tangential_needed(self):
        return self.mu != 0

    def tangential_force_from_neighbors(self):
        """Two-visit tangential force of every relation (torque split eq. S1-3; visit order: docs/design.md)."""
        self._geometry()
        self._tangential_terms()
        self._term_done()

    def _tangential_terms(self):
        """Tangential force of every relation: the two-visit rule with the Coulomb bound ``|μ·law|`` (bonds: an
        unbounded spring, k_t and ν_t × the permanent ratio; :func:`~particleShear.engine.terms.tangential_term`),
        then the states (slip, stick, permanent) and histories ξ of the relations."""
        g = self._g
        if not g.P:
            return
        pt = self._pairs
        if g.perm is None and not self._tangential_needed():
            # μ = 0 and no bonds: the Coulomb bound is zero, every moving contact slips and ξ is reset.
            if g.active is None:
                pt.state[g.slots] = SLIP
                pt.xi[:, g.slots] = 0.0
            else:
                pt.state[g.active] = SLIP
                pt.xi[...] = 0.0   # inactive candidates hold ξ = 0 already
            g.all_slip = True
            g.ft_visits = 0.0   # every visit applies a zero force (Coulomb bound 0)
            return
        K_i, K_j, differ = self._term_constants(g)
        if g.fel is None:   # the elastic term did not run in this force phase: the law of the bound
            g.fel = (elastic_term(K_i, g.d) if self._builtin_laws() else self._user_law_term(K_i, g))[1]
        sel = g.S.sel
        xi = pt.xi if sel is None else pt.xi.take(sel, axis=1)
        F, slip = tangential_term(K_i, self._tangential_speed(g), g.touching, xi, g.fel,
                                  K_j if "tangential" in differ else None)
        # states: slip 1, stick 0, and permanent on bonds
        state = slip.view(np.int8)
        perm_code = g.S.perm_code
        if sel is None:
            if perm_code is not None:
                np.add(state, perm_code, out=pt.state)
            else:
                pt.state[...] = state
        else:
            pt.state[sel] = state if perm_code is None else state + perm_code
            pt.xi.reshape(-1)[g.S.sel2] = xi.reshape(-1)   # flat 1-D scatter: much cheaper than [:, sel]
        g.ft_visits = F
        f = F[0] + F[1]
        f *= 0.5     # = F1/2 + F2/2 exactly (halving is exact in binary floating point)
        self._add_tangential(f)

    def tangential_force(self):
        """All-pairs variant (reference API)."""
        self.test_neighbor_relation()
        self.tangential_force_from_neighbors()

    def _torque_total(self):
        return self._a["torque"]

    def do_rotational_acceleration(self, dt):
        """Kick every spin ``ω += T dt / I`` and reset the torques.

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        a = self._a
        a["omega"] += a["torque"] * dt / a["inertia"]
        a["torque"][:] = 0.0

    def _cool_spin(self, f):
        self._a["omega"] *= f

    def cool(self, f=0.8):
        """Damp velocity relative to the affine flow and spin by ``f`` (docs/design.md), all three rows at once.

        Parameters
        ----------
        f : float
            Factor applied to the peculiar velocity (0 < f ≤ 1; 1 = no damping).
        """
        if type(self)._cool_spin is not CanvasPointsFrictionElasticityLeesEdwards._cool_spin:
            return CanvasPointsBasicElasticityLeesEdwards.cool(self, f)
        rate = getattr(self, "shear_rate", 0)
        damp(self._vel, self._affine_vx(rate) if rate else None, f)

    def _integrate_xi(self, dt):
        """Sequential ξ rule of the reference, without a Python loop (docs/design.md).

        Relation i→j (i < j) sees both spheres at their old positions; relation
        j→i sees i already moved by ``v_i·dt``.  Both use the velocities after
        the kick and damping; slip relations are not integrated (their increment
        is multiplied by 0, which leaves their ξ = 0 exactly).  The increments are
        :func:`particleShear.engine.integrate.xi_increments`, the engine's own.
        """
        g = self._g
        if g is None or not g.P or g.all_slip:
            return
        pt = self._pairs
        sel = g.S.sel
        P = g.P
        # the factor dt on relations that did not slip, 0 on slipped ones and on inactive candidates
        if sel is None:
            kd = _where(pt.state == _SLIP8, np.zeros(P), dt * g.active)
        else:
            kd = _where(pt.state.take(sel) == _SLIP8, 0.0, dt)
        vel = self._vel
        Vi = vel.take(g.ai, axis=1)
        Vj = vel.take(g.aj, axis=1)
        # relation j→i: i has moved by v_i·dt; the pair vector is −(x_j − x_i) of the force phase
        # plus that move (same image, the cell being much larger than any candidate pair)
        R = Vi[:2] * dt
        R -= g.D
        dvx_ji = None
        if not g.S.safe_images:
            Lx, Ly = float(self.size_x), float(self.size_y)
            if np.abs(R[0]).max() >= Lx / 2 or np.abs(R[1]).max() >= Ly / 2:
                # a cell barely larger than a contact: R may lie in another image than the force phase's D
                rx = (self._pos[0].take(g.ai) + Vi[0] * dt) - self._pos[0].take(g.aj)
                ry = (self._pos[1].take(g.ai) + Vi[1] * dt) - self._pos[1].take(g.aj)
                dx, dy, dvx_ji = min_image(rx, ry, Lx, Ly, self._le_shift(), self._shear_rate_for_images())
                R = np.array((dx, dy))
                if dvx_ji is None:
                    dvx_ji = 0.0
        unit = lambda rx, ry: pair_geometry(rx, ry, self._rng)[1:]   # noqa: E731 (random direction at |R| = 0)
        inc = np.array(xi_increments(Vi, Vj, g.dvx, g.n[0], g.n[1], g.ri, g.rj, R[0], R[1], unit, dvx_ji))
        inc *= kd   # ×dt on kept relations, ×0 (±0) on the others
        if sel is None:
            pt.xi += inc
        else:
            flat = pt.xi.reshape(-1)
            inc += flat.take(g.S.sel2).reshape(2, P)
            flat[g.S.sel2] = inc.reshape(-1)

    def move(self, dt=1):
        """ξ rule, then drift and turn: x, y, φ += (u_x, u_y, ω)·dt (φ is not read by the ξ rule).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        self._integrate_xi(dt)
        self._drift(dt, spin=True)

    def _strain_advances(self):
        return True

    @property
    def active_terms(self):
        terms = CanvasPointsBasicElasticityLeesEdwards.active_terms.fget(self)
        if self._tangential_needed():
            terms.append("tangential")
        return terms
