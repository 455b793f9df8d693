"""Canvases with pair forces and the documented step (docs/classes.md, "The documented classes").

The phases of a step are the engine's (:mod:`particleShear.base.engine_view`); the canvas-wide
per-term methods (``elastic_force_from_neighbors()`` …) are 1.0.2's loops over the per-sphere API.
"""
__docformat__ = "numpy"
from ..engine.integrate import kick, shift_flow
from ..engine.step import BatchEngine
from ..checks import finite as _check_finite

from .canvas_base import NonNegative, ReplicaValue, check_non_negative, check_time_step
from .pair_canvas import CanvasPointsShear

__all__ = ["CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards", "CanvasPointsFrictionElasticityLeesEdwards"]


class CanvasPointsBasicElasticity(CanvasPointsShear):
    """Adds the central elastic and viscous pair forces (eqs. S1-5a/b, S1-9) and the step.

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing, m
        As for :class:`~particleShear.base.canvas.CanvasPointsMass`.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0 (else ValueError).
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0 (else ValueError).
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

    INTEGRATORS = BatchEngine.INTEGRATORS

    def set_integrator(self, integrator):
        """Choose the time integrator (ValueError for another name).

        ``"euler"`` (default): the reference's semi-implicit Euler.  ``"verlet"``: velocity Verlet with a
        half-kick predictor (Groot-Warren λ = 1/2), second-order accurate in the viscous terms.

        Parameters
        ----------
        integrator : {"euler", "verlet"}
        """
        if integrator not in self.INTEGRATORS:
            raise ValueError(f"integrator must be one of {self.INTEGRATORS}, got {integrator!r}")
        self.integrator = integrator
        self._predictor.drop()

    def set_central_repulsion_coefficient(self, central_repulsion_coefficient=0):
        """Set the law's repulsion coefficient c (0 linear, eq. S1-5a; 1 divergent, eq. S1-5b) on every sphere.

        Parameters
        ----------
        central_repulsion_coefficient : float
            Finite (else ValueError).
        """
        _check_finite("central_repulsion_coefficient", central_repulsion_coefficient)
        self.central_repulsion_coefficient = central_repulsion_coefficient
        self._a["central_repulsion_coefficient"][:] = central_repulsion_coefficient
        self._params_changed()

    def elastic_force_from_neighbors(self):
        """Central elastic force of every relation (eqs. S1-5a/b): each sphere's method in ``sphereList`` order."""
        for sphere in list(self.sphereList):
            sphere.elastic_force_from_neighbors(self.k)

    def central_viscous_force_from_neighbors(self):
        """Central viscous force ``ν v_n`` of every relation (eq. S1-9): each sphere's method in order."""
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
        """First phase of a step: clear the register, update neighbours, add every pair force, run the guard.

        Parameters
        ----------
        dt : float
            Not used (1.0.2 signature).
        """
        self.reset_force_register()
        self._engine_force_phase()
        if self.stability_guard is not None:
            self.stability_guard.check(self, step=self.step_count, phase=self.phase, dt=self._last_dt)

    _last_dt = None

    def mechanical_simulation_step_calculate_acceleration(self, cool_factor=0.97, dt=1):
        """Third phase of a step: kick the velocities (the plates follow), then damp (eqs. S1-10, S1-11).

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step, 0 < f ≤ 1 (1 = no damping).
        dt : float
            Time step (s), finite and > 0 (else ValueError before any work).
        """
        check_time_step(dt, self.step_count)
        self._last_dt = dt
        self._engine_accelerate(cool_factor, dt)

    def mechanical_simulation_step_calculate_movement(self, dt=1):
        """Last phase of a step: ξ rule, drift, strain ``+= γ̇·dt`` (while shearing; always if frictional), wrap, clock.

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0 (else ValueError before any work).
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
        cool_factor, dt : float
            As for :meth:`mechanical_simulation_step_calculate_acceleration`.
        """
        check_time_step(dt, self.step_count)  # before the force phase: a refused step does no work
        self.mechanical_simulation_step_calculate_forces()
        self.record_total_particle_forces()
        self.mechanical_simulation_step_calculate_acceleration(cool_factor, dt)
        self.mechanical_simulation_step_calculate_movement(dt)

    def mechanical_relaxation(self, N=1000, cool_factor=0.97, dt=1, theTk=False, StressTensorEvaluator=False):
        """``N`` steps, each optionally followed by ``theTk.update()`` and a stress evaluation.

        Parameters
        ----------
        N : int
        cool_factor, dt : float
            As for :meth:`mechanical_simulation_step_calculate_acceleration`.
        theTk : object or bool
            Tk root window (False: none).
        StressTensorEvaluator : StressTensorEvaluation or bool
            Evaluator (False: none).
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
    """Adds shear-rate changes that keep velocities relative to the flow (parameters as the base class)."""

    def setShear(self, theShear):
        """Set the shear strain γ (the Lees-Edwards offset is ``Ly·γ``).

        Parameters
        ----------
        theShear : float
        """
        self.shear = theShear
        self._g = None

    def setShearInSpheres(self):
        """Does nothing (1.0.2 API): spheres read γ from the ensemble."""

    def setShearRateInSpheres(self):
        """Does nothing (1.0.2 API): spheres read γ̇ from the ensemble."""

    def adjust_sphere_speed_to_shear_rate_change(self, delta_shear_rate):
        """Add the change of the affine flow to every velocity (and −Δγ̇/2 to every spin).

        Parameters
        ----------
        delta_shear_rate : float
            Δγ̇ (1/s).
        """
        a = self._a
        shift_flow(a["xspeed"], a["omega"], self._y_centred(), delta_shear_rate)

    def setShearRate(self, theShearRate):
        """Change γ̇ (1/s); every sphere keeps its velocity relative to the local flow.

        Parameters
        ----------
        theShearRate : float
        """
        delta = theShearRate - self.shear_rate
        if delta != 0:
            self.adjust_sphere_speed_to_shear_rate_change(delta)
        self.shear_rate = theShearRate


class CanvasPointsFrictionElasticityLeesEdwards(CanvasPointsBasicElasticityLeesEdwards):
    """Adds the tangential force (eqs. S1-3, S1-7), spin and the ξ history.

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing, k, nu, m
        As for :class:`CanvasPointsBasicElasticity`.
    k_t, nu_t : float
        Tangential spring (mg·s⁻² per m depth) and viscosity (mg·s⁻¹ per m depth) constants, ≥ 0.
    mu : float
        Coulomb friction coefficient μ, ≥ 0 (each of the three else ValueError).
    """

    k_t = NonNegative()
    nu_t = NonNegative()
    mu = ReplicaValue(check_non_negative)

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1, k_t=1,
                 nu_t=0.01, mu=0.1):
        CanvasPointsBasicElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m)
        self.k_t = k_t
        self.nu_t = nu_t
        self.mu = mu

    def tangential_force_from_neighbors(self):
        """Tangential force of every relation (eq. S1-3): each sphere's method in ``sphereList`` order."""
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
        kick(self._vel[2:], self._frc[2:], self._a["inertia"], dt)

    _damped_rows = 3

    _strain_only_while_shearing = False       # (the engine's strain advances in every step)

    @property
    def active_terms(self):
        terms = CanvasPointsBasicElasticityLeesEdwards.active_terms.fget(self)
        if self.mu != 0:
            terms.append("tangential")
        return terms
