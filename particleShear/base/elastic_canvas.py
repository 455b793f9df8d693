"""Canvases with pair forces: the force, acceleration and movement phases of the documented step (docs/design.md, "The documented classes").

=========================================  ==============================================
``CanvasPointsBasicElasticity``            central elastic + viscous pair term (eqs. S1-5a/b, S1-6, S1-9)
``CanvasPointsBasicElasticityLeesEdwards`` rate changes, boundary-aware registration
``CanvasPointsFrictionElasticityLeesEdwards``  tangential term, torques, ξ history (eqs. S1-3, S1-7)
=========================================  ==============================================

The phases of a step are the engine's (:mod:`particleShear.base.engine_view`); the canvas-wide
per-term methods (``elastic_force_from_neighbors()`` …) are 1.0.2's loops over the per-sphere API.
"""
__docformat__ = "numpy"
from ..engine.integrate import damp
from .points import _check_finite

from .canvas import NonNegative, check_time_step
from .pair_canvas import CanvasPointsShear

__all__ = ["CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards", "CanvasPointsFrictionElasticityLeesEdwards"]


class CanvasPointsBasicElasticity(CanvasPointsShear):
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

    def elastic_force_from_neighbors(self):
        """Central elastic force of every relation (eqs. S1-5a, S1-5b), 1.0.2's loop: each sphere's
        ``elastic_force_from_neighbors(k)`` in ``sphereList`` order (the per-sphere API, registered
        entry by entry)."""
        for sphere in list(self.sphereList):
            sphere.elastic_force_from_neighbors(self.k)

    def central_viscous_force_from_neighbors(self):
        """Central viscous force ``ν v_n`` of every relation (eq. S1-9), 1.0.2's loop: each sphere's
        ``central_viscous_force_from_neighbors(nu)`` in ``sphereList`` order."""
        for sphere in list(self.sphereList):
            sphere.central_viscous_force_from_neighbors(self.nu)

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

    def tangential_force_from_neighbors(self):
        """Two-visit tangential force of every relation (torque split eq. S1-3), 1.0.2's loop: each
        sphere's ``tangential_force_from_neighbors(nu_t, mu, k, k_t)`` in ``sphereList`` order."""
        for sphere in list(self.sphereList):
            sphere.tangential_force_from_neighbors(self.nu_t, self.mu, self.k, self.k_t)

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

    def _strain_advances(self):
        return True

    @property
    def active_terms(self):
        terms = CanvasPointsBasicElasticityLeesEdwards.active_terms.fget(self)
        if self.mu != 0:
            terms.append("tangential")
        return terms
