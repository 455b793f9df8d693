"""Ensemble factories from physical properties: the constitution of a crosslinked, cut gel.

Constants: eq. S1-8 (spring), S1-9 (viscosity), S1-14 (radii); the time step: docs/accuracy.md.
"""
__docformat__ = "numpy"
import dataclasses
import logging

import numpy as np

from ..base.engine_adapter import adopt_state, check_adoptable, host_backend, relax_ensembles, relax_states, set_laws
from ..base.fields import FIELDS
from ..base.pair_canvas import CanvasPointsNeighbors
from ..checks import finite, in_range, integer, non_negative, positive
from ..engine.relax import RELAX_SKIN
from ..engine.state import PERMANENT, BatchState, PairTable
from ..engine.step import BatchEngine
from ..engine.xp import get_backend
from ..objects.model import particle_shear_model_parameters
from ..objects.placement import bimodal_factors, bimodal_placement
from . import bonds
from .compact import EnsembleCompactParticles, EnsembleCompactParticlesAdjustableInterfaceStrength

__all__ = ["EnsembleCompactParticlesFromModelParameters",
           "EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters",
           "adjustable_interface_constitution", "constitution", "constituted_state", "ConstitutedState",
           "state_constitution",
           "ensemble_of_state",
           "EnsembleRecipe", "Relaxation", "relax_constitution",
           "time_steps_from_model", "MAX_CUT_ATTEMPTS"]

#: attempts at cutting without a height-spanning particle before giving up (the reference loops forever)
MAX_CUT_ATTEMPTS = 1000


#: the builders' checks, in order: (check, parameter, limits...) (particleShear.checks)
_CHECKS = ((positive, "size_x"), (positive, "size_y"), (integer, "N", 2), (positive, "packing_fraction"),
           (non_negative, "mu"), (positive, "Young_modulus_spheres"), (positive, "density"),
           (positive, "bimodal_factor"), (integer, "cut_lines", 0), (non_negative, "relative_viscosity"),
           (finite, "central_repulsion_coefficient"), (positive, "anticipated_amplitude"),
           (non_negative, "relative_transversal_link_strength"),
           (in_range, "avoid_horizontal_angle_degree", 0, 90, False, True),
           (positive, "interface_reenforcement_central"), (positive, "interface_reenforcement_tangential"),
           (in_range, "remove_link_fraction", 0, 1), (non_negative, "edge_fuzziness"))


@dataclasses.dataclass(frozen=True)
class EnsembleRecipe:
    """What one ensemble is constituted of: the builders' physical and cutting parameters, checked when made.

    The one record a constitution (:func:`constitution`) reads its parameters from, field by field:
    the documented builders make it from their arguments (:meth:`of`), a simulation from its
    attributes, and a checked run (``doParticleShearSimulation``) from its
    :class:`~particleShear.run.validation.RunParameters` (``particleShear.run.sessions``), so a
    run's value — μ, say — reaches the ensemble as a field of this record, not through the
    arguments of builders and constructors.  The fields are the parameters of
    :func:`EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters` (same names,
    meanings and units) but the call's options (``theTk``, ``doDrawing``, ``do_debug``, ``rng``,
    ``verbose``); those without a default here are required.

    Parameters
    ----------
    N, packing_fraction, mu, Young_modulus_spheres, density, bimodal_factor, cut_lines, do_permanent_links
        As for the builder (required).
    relative_viscosity, central_repulsion_coefficient, anticipated_amplitude, relative_transversal_link_strength
        As for the builder (required).
    avoid_horizontal_angle_degree, avoid_height_spanning_particles, doCutByTriangulation
        As for the builder (required).
    size_x, size_y, do_pre_equilibration : optional
        The cell (µm; default 500 × 500, the documented simulations'); relax the packing (default True).
    interface_reenforcement_central, interface_reenforcement_tangential, keep_viscosity_coefficients_constant
        As for the builder (defaults 1, 1, True: the legacy builder's interface).
    cut_top_bottom, remove_link_fraction, edge_fuzziness : optional
        As for the builder (defaults True, 0, 0).

    Raises
    ------
    TypeError, ValueError
        If a value is not a real number or out of range (named in the message), in the builders'
        order (:data:`_CHECKS`).
    """
    N: int
    packing_fraction: float
    mu: float
    Young_modulus_spheres: float
    density: float
    bimodal_factor: float
    cut_lines: int
    do_permanent_links: bool
    relative_viscosity: float
    central_repulsion_coefficient: float
    anticipated_amplitude: float
    relative_transversal_link_strength: float
    avoid_horizontal_angle_degree: float
    avoid_height_spanning_particles: bool
    doCutByTriangulation: bool
    size_x: float = 500
    size_y: float = 500
    do_pre_equilibration: bool = True
    interface_reenforcement_central: float = 1
    interface_reenforcement_tangential: float = 1
    keep_viscosity_coefficients_constant: bool = True
    cut_top_bottom: bool = True
    remove_link_fraction: float = 0
    edge_fuzziness: float = 0

    def __post_init__(self):
        for check, name, *limits in _CHECKS:
            check(name, getattr(self, name), *limits)

    @classmethod
    def of(cls, values, **given):
        """The recipe of the fields named in ``values`` (other names ignored), ``given`` taking precedence.

        Parameters
        ----------
        values : Mapping
            Values by field name (a builder's ``locals()``, a run's parameters).
        **given
            Fields by name, over ``values`` (a run's ``theMu`` as ``mu``, say).

        Returns
        -------
        EnsembleRecipe
        """
        return cls(**{f.name: given[f.name] if f.name in given else values[f.name]
                      for f in dataclasses.fields(cls) if f.name in given or f.name in values})


def time_steps_from_model(time_constant, bimodal_factor, mu, relative_transversal_link_strength,
                          anticipated_amplitude, relative_viscosity):
    """Return ``(dt, dt_max)`` (s), the builders' final and coarsest step, chosen as in particleShear 1.0.2.

    Parameters
    ----------
    time_constant, bimodal_factor, mu : float
        τ = sqrt(m/k) (s), large/small radius ratio bf, Coulomb coefficient μ.
    relative_transversal_link_strength, anticipated_amplitude, relative_viscosity : float
        rts = k_t/k, strain amplitude A, rv (eq. S1-9).
    """
    tau, bf, rts, A, rv = (time_constant, bimodal_factor, relative_transversal_link_strength,
                           anticipated_amplitude, relative_viscosity)
    dt = 0.1 * tau / bf
    for halve in (mu <= 1 or rts < 1, A <= 0.05, mu <= 0.1 or rts < 0.1, A <= 0.005, A >= 0.5):
        if halve:
            dt = dt / 2
    dt_max = 0.25 * tau / bf
    if (rv <= 0.1 and mu < 0.1) or rts < 0.1 or rts > 5:
        dt_max = 0.125 * tau / bf
    if (rv < 0.01 and mu < 0.01) or rts < 0.01:
        dt_max = 0.04 * tau / bf
    if dt > dt_max:
        dt = dt_max
    if rv > 1:
        dt_max = dt_max / rv
    return dt, dt_max


def _crosslink_and_cut(ens, cut_lines, doCutByTriangulation, edge_fuzziness, cut_top_bottom, avoid, verbose):
    """Crosslink all contacts and cut; re-cut while a particle spans > 0.9·Ly (at most MAX_CUT_ATTEMPTS)."""
    attempts = 0
    while True:
        ens.makeAllLinksPermanent()
        if cut_top_bottom:
            ens.cutTopBottomEdge()
        if doCutByTriangulation:
            ens.cutByTriangulation(cut_lines, edge_fuzziness)
        else:
            for _ in range(int(cut_lines)):
                ens.cutRandomLine()
        attempts += 1
        if not avoid:
            return
        h = ens.maximal_particle_height()
        if not h > 0.9 * ens.size_y:
            return
        if attempts >= MAX_CUT_ATTEMPTS:
            raise RuntimeError(f"no cut without a height-spanning particle found in {attempts} attempts "
                               f"(cut_lines={cut_lines}); use more cuts or avoid_height_spanning_particles=False")
        if verbose:
            logging.getLogger(__name__).info("Height spanning particle (height " + str(h) + "), cutting again")
        ens.particles = []


class Relaxation:
    """Request to run ``ensemble.free_pre_equilibration(N)`` in the engine, yielded by a constitution.

    The target is a documented ensemble (:func:`constitution`) or the engine state of a
    constitution on the state (:func:`state_constitution`); it is run by :meth:`run` or, with
    the waiting requests of other constitutions, by :meth:`run_together` (a batch's driver);
    ``dt``, ``dt_max``, ``mu`` are read then (docs/engine.md, "Runs").

    Parameters
    ----------
    ensemble : EnsembleCompactParticles or the state's target
        What is relaxed (attribute ``ensemble`` for either).
    N : int
        Steps per level and per final block, >= 0.
    """
    __slots__ = ("ensemble", "N")

    def __init__(self, ensemble, N):
        self.ensemble = ensemble
        self.N = int(N)

    @property
    def key(self):
        """``(N, dt, dt_max)``: requests with equal keys run the same steps."""
        e = self.ensemble
        return (self.N, float(e.dt), float(e.dt_max))

    @property
    def batch_key(self):
        """:attr:`key` and what else one engine needs to be common: requests of equal batch keys can run together.

        For a state's request also its backend, law and Verlet skin (:func:`state_constitution`);
        an ensemble's takes them from :meth:`run_together`'s arguments.
        """
        e = self.ensemble
        if not isinstance(e, _StateTarget):
            return self.key + ("ensemble",)
        s = e.state
        return self.key + ("state", s.backend.name, s.law, float(e.skin_factor))

    def run(self):
        """Relax this target alone in the engine (the target's ``free_pre_equilibration``)."""
        self.ensemble.free_pre_equilibration(self.N)

    @staticmethod
    def run_together(requests, skin_factor=RELAX_SKIN, laws=None, backend="numpy"):
        """Run requests of one :attr:`batch_key` in one engine, each target as if alone (bit for bit).

        States' by :func:`~particleShear.base.engine_adapter.relax_states` (with their own law,
        backend and skin), ensembles' by :func:`~particleShear.base.engine_adapter.relax_ensembles`
        (with the settings given here).

        Parameters
        ----------
        requests : sequence of Relaxation
            Of equal :attr:`batch_key`, each target once.
        skin_factor, laws, backend : optional
            The Verlet skin, central law of each target and host backend of an ensembles' engine,
            as :func:`~particleShear.base.engine_adapter.relax_ensembles` takes them (unused for states).

        Raises
        ------
        ValueError
            If the requests' batch keys differ (before any step), or as the relaxation raises.
        """
        requests = list(requests)
        keys = {r.batch_key for r in requests}
        if len(keys) > 1:
            raise ValueError(f"requests of the batch keys {sorted(keys, key=str)}: one engine relaxes one kind")
        if not requests:
            return
        targets = [r.ensemble for r in requests]
        if isinstance(targets[0], _StateTarget):
            _StateTarget.relax(targets, requests[0].N)
        else:
            relax_ensembles(targets, requests[0].N, skin_factor=skin_factor, laws=laws, backend=backend)

    def __repr__(self):
        N, dt, dt_max = self.key
        return f"Relaxation(N={N}, dt={dt!r}, dt_max={dt_max!r}, mu={self.ensemble.mu!r})"


#: most requests one constitution may yield (the builder yields at most 20): a bound, not a tuning knob
MAX_RELAXATIONS = 10000


def relax_constitution(steps):
    """Run every :class:`Relaxation` a constitution yields and return the generator's value.

    Parameters
    ----------
    steps : generator
        A constitution such as :func:`adjustable_interface_constitution` (RuntimeError after
        :data:`MAX_RELAXATIONS` requests).
    """
    try:
        request = next(steps)
        for _ in range(MAX_RELAXATIONS):
            request.run()
            request = next(steps)
    except StopIteration as done:
        return done.value
    raise RuntimeError(f"a constitution yielded more than {MAX_RELAXATIONS} relaxations")


def _free_mu0(ens, n, mu):
    """``μ=0: free(n)``: a relaxation block with the ensemble's μ set to 0, then μ restored (generator)."""
    ens.mu = 0
    yield Relaxation(ens, n)
    ens.mu = mu


def EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters(
        size_x=500, size_y=500, N=100, packing_fraction=1, mu=1, Young_modulus_spheres=10000, density=50,
        bimodal_factor=1.4, cut_lines=5, do_permanent_links=True, theTk=False, do_pre_equilibration=True,
        relative_viscosity=0.01, central_repulsion_coefficient=0, anticipated_amplitude=0.1,
        relative_transversal_link_strength=1, avoid_horizontal_angle_degree=0,
        avoid_height_spanning_particles=False, interface_reenforcement_central=1,
        interface_reenforcement_tangential=1, keep_viscosity_coefficients_constant=True, cut_top_bottom=True,
        doCutByTriangulation=True, remove_link_fraction=0, edge_fuzziness=0, doDrawing=True, do_debug=False,
        rng=None, verbose=False):
    """Relaxed, crosslinked and cut ensemble with reinforced transient interfaces; the main factory.

    The factory of ``doParticleShearSimulation`` (same parameter names: docs/parameters.md).  From
    :class:`~particleShear.objects.model.particle_shear_model_parameters` (``bimodal_factor=1``) it
    sets ``k = k_model·irc``, ``k_t = k_model·rts·irt``, ``ν = rv·k_model·τ``, ``ν_t = ν·rts`` (times
    irc, irt unless ``keep_viscosity_coefficients_constant``; bonds scaled back by 1/irc, 1/irt) and
    the steps of :func:`time_steps_from_model`, then runs :func:`adjustable_interface_constitution`.

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, bimodal_factor : optional
        Cell (µm, > 0), number of spheres (>= 2), nominal area fraction φ (eq. S1-14, > 0), large/small
        radius ratio (> 0).
    mu, Young_modulus_spheres, density : float, optional
        Coulomb coefficient μ of transient contacts (>= 0), Young modulus (Pa; eq. S1-8), density (kg/m³).
    relative_viscosity, relative_transversal_link_strength : float, optional
        rv in ν = rv·√(m k) (eq. S1-9) and rts = k_t/k = ν_t/ν, >= 0.
    central_repulsion_coefficient, anticipated_amplitude : float, optional
        c of the central law (1: divergent, eq. S1-5b; 0: linear, eq. S1-5a); strain amplitude A (> 0),
        which selects the time step and the length of the relaxation.
    interface_reenforcement_central, interface_reenforcement_tangential, keep_viscosity_coefficients_constant
        irc, irt (> 0): factors on k, k_t of transient contacts relative to bonds; True: ν, ν_t not scaled.
    do_pre_equilibration, do_permanent_links : bool, optional
        Relax the random packing; crosslink and cut it afterwards (False: frictional spheres only).
    cut_lines, doCutByTriangulation : optional
        Number of Voronoi particles (<= 1: uncut) or, with False, of random straight cuts (0: uncut).
    avoid_horizontal_angle_degree : float, optional
        Line cuts: half-width (degrees, in [0, 90)) of the redrawn band of near-horizontal lines.
    avoid_height_spanning_particles, cut_top_bottom : bool, optional
        Re-cut while a particle is taller than 0.9·size_y; cut every bond through the y boundary.
    remove_link_fraction, edge_fuzziness : float, optional
        Fraction (0 … 1) of non-essential links removed; roughening of Voronoi borders (units of r_max).
    theTk, doDrawing, do_debug : optional
        Unused (1.0.2 compatibility); draw the spheres (no window); ten times shorter relaxations.
    rng, verbose : optional
        Generator or seed of every random choice (None: fresh entropy); log 1.0.2's messages (INFO, module logger).

    Returns
    -------
    EnsembleCompactParticlesAdjustableInterfaceStrength
        The ensemble; ``dt``, ``dt_max`` (s) are the steps to use, ``model`` the model constants.

    Raises
    ------
    TypeError, ValueError
        If a parameter is not a real number or out of range (named in the message), before any work.
    RuntimeError
        If no cut without a height-spanning particle is found in :data:`MAX_CUT_ATTEMPTS` attempts.
    """
    return relax_constitution(adjustable_interface_constitution(**locals()))   # every parameter, as passed


def adjustable_interface_constitution(
        size_x=500, size_y=500, N=100, packing_fraction=1, mu=1, Young_modulus_spheres=10000, density=50,
        bimodal_factor=1.4, cut_lines=5, do_permanent_links=True, theTk=False, do_pre_equilibration=True,
        relative_viscosity=0.01, central_repulsion_coefficient=0, anticipated_amplitude=0.1,
        relative_transversal_link_strength=1, avoid_horizontal_angle_degree=0,
        avoid_height_spanning_particles=False, interface_reenforcement_central=1,
        interface_reenforcement_tangential=1, keep_viscosity_coefficients_constant=True, cut_top_bottom=True,
        doCutByTriangulation=True, remove_link_fraction=0, edge_fuzziness=0, doDrawing=True, do_debug=False,
        rng=None, verbose=False):
    """Constitution of :func:`EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters` as a generator.

    Each ``free_pre_equilibration`` block is yielded as a :class:`Relaxation` for the caller to run
    (:func:`relax_constitution`, or ``particleShear.run.batch`` for all replicas; docs/engine.md,
    "Runs"); the ensemble is returned (``StopIteration.value``).  Invalid inputs raise as in the
    builder, on the first ``next()``.

    Yields
    ------
    Relaxation
        The next block (the ensemble's ``dt``, ``dt_max`` and ``mu`` set for it).
    """
    return (yield from constitution(EnsembleRecipe.of(locals()), doDrawing=doDrawing, do_debug=do_debug, rng=rng,
                                    verbose=verbose))


def constitution(recipe, *, legacy=False, doDrawing=False, do_debug=False, rng=None, verbose=False):
    """The constitution of the ensemble of ``recipe`` as a generator of its relaxations (both builders').

    Every parameter is read from ``recipe`` where it is used; ``legacy``: the constitution of
    :func:`EnsembleCompactParticlesFromModelParameters` (no halved step when dense, 25 steps per
    level after the cut, the adjustable interface at the recipe's defaults).  μ is set on the
    ensemble by the constitution itself, as for its μ = 0 blocks.

    Parameters
    ----------
    recipe : EnsembleRecipe
        The checked parameters of the ensemble.
    legacy : bool, optional
        The legacy builder's constitution.
    doDrawing, do_debug, rng, verbose : optional
        As for :func:`EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters`.

    Yields
    ------
    Relaxation
        The next block (the ensemble's ``dt``, ``dt_max`` and ``mu`` set for it).

    Returns
    -------
    EnsembleCompactParticles or EnsembleCompactParticlesAdjustableInterfaceStrength
        The constituted ensemble (``StopIteration.value``).
    """
    c = _Constants(recipe, legacy, do_debug, verbose)
    ens = _documented_ensemble(recipe, c, legacy, doDrawing, np.random.default_rng(rng))
    return (yield from _schedule(ens, recipe, c, legacy, verbose))


def _documented_ensemble(r, c, legacy, doDrawing, rng, placement=None):
    """The documented ensemble of a constitution before its schedule: class, constants, spheres, μ, model.

    The one construction of :func:`constitution` (which lets the class draw its placement from
    ``rng``) and :func:`ensemble_of_state` (which gives the placement: nothing is drawn).

    Parameters
    ----------
    r : EnsembleRecipe
    c : _Constants
    legacy : bool
        :class:`~.compact.EnsembleCompactParticles` (else the adjustable interface's class).
    doDrawing : bool
    rng : numpy.random.Generator
        The ensemble's generator (used, not copied).
    placement : tuple of ndarray (N,) or None, optional
        ``(x, y, r, mass)`` of the spheres (µm, mg per m depth); None: drawn by the class.

    Returns
    -------
    EnsembleCompactParticles or EnsembleCompactParticlesAdjustableInterfaceStrength
    """
    cls, extra = ((EnsembleCompactParticles, {}) if legacy else (
        EnsembleCompactParticlesAdjustableInterfaceStrength,
        dict(permanent_ratio_central=c.prc, permanent_ratio_tangential=c.prt,
             keep_viscosity_coefficients_constant=r.keep_viscosity_coefficients_constant)))
    ens = cls(r.size_x, r.size_y, c.N if placement is None else 0, packing_fraction=r.packing_fraction,
              theCanvas=False, doDrawing=doDrawing, k=c.k, nu=c.nu, m=c.model.m, bimodal_factor=r.bimodal_factor,
              k_t=c.k_t, nu_t=c.nu_t, dt=c.dt, dt_max=c.dt_max, theTkSimulation=False,
              avoid_horizontal_angle_degree=r.avoid_horizontal_angle_degree, rng=rng, **extra)
    if placement is not None:
        ens.N = c.N
        ens._append_spheres(*placement)
    ens.mu = r.mu        # the constitution's to set, as in its μ = 0 blocks (_free_mu0)
    ens.set_central_repulsion_coefficient(r.central_repulsion_coefficient)
    ens.avoid_height_spanning_particles = c.avoid
    ens.model = c.model
    ens.edge_fuzziness = r.edge_fuzziness
    return ens


class _Constants:
    """What a constitution derives from its recipe before any sphere exists (both paths read it).

    ``N``, ``cut_lines`` (int); ``R`` (10 with ``do_debug``: shorter relaxations, else 1); the
    permanent ratios ``prc = 1/irc``, ``prt = 1/irt``; ``avoid`` (the height check, off when the
    gel is not cut into separate particles); ``model``
    (:class:`~particleShear.objects.model.particle_shear_model_parameters`, ``bimodal_factor=1``);
    ``tau`` (s); ``dt``, ``dt_max`` (s, :func:`time_steps_from_model`); the ensemble's ``k, k_t``
    (mg·s⁻² per m depth) and ``nu, nu_t`` (mg·s⁻¹ per m depth), eq. S1-8, S1-9.
    """

    def __init__(self, r, legacy, do_debug, verbose):
        self.N, self.cut_lines = int(r.N), int(r.cut_lines)
        self.R = 10 if do_debug else 1
        irc, irt = r.interface_reenforcement_central, r.interface_reenforcement_tangential
        rv, rts, bf = r.relative_viscosity, r.relative_transversal_link_strength, r.bimodal_factor
        self.prc = 1 / irc
        self.prt = 1 / irt
        avoid = r.avoid_height_spanning_particles
        if avoid and self.cut_lines <= (1 if r.doCutByTriangulation else 0):   # not cut into separate particles
            if verbose:
                logging.getLogger(__name__).info("avoid_height_spanning_particles ignored: with cut_lines="
                                                 + str(self.cut_lines)
                                                 + " the gel is not cut into separate particles")
            avoid = False
        self.avoid = avoid
        model = self.model = particle_shear_model_parameters(r.size_x, r.size_y, self.N, r.packing_fraction,
                                                             r.Young_modulus_spheres, r.density, bimodal_factor=1)
        tau, k = model.time_constant, model.k
        self.tau = tau
        self.dt, self.dt_max = time_steps_from_model(tau, bf, r.mu, rts, r.anticipated_amplitude, rv)
        self.k = k * irc
        self.k_t = k * rts * irt
        self.nu = rv * k * tau
        self.nu_t = rv * k * tau * rts
        if not r.keep_viscosity_coefficients_constant:
            self.nu = self.nu * irc
            self.nu_t = self.nu_t * irt


def _schedule(ens, r, c, legacy, verbose):
    """The relaxations, crosslinking and cuts of a constitution on ``ens`` (generator of its relaxations).

    ``ens`` is a documented ensemble (:func:`constitution`) or the state's target
    (:class:`_StateTarget`, :func:`constituted_state`): the schedule reads and sets its ``dt``,
    ``dt_max``, ``mu``, ``particles``, ``cut_top_bottom`` and calls its crosslinking and cutting
    methods; every relaxation is yielded as a :class:`Relaxation` of ``ens``.  Returns ``ens``.
    """
    R, A, rts, bf = c.R, r.anticipated_amplitude, r.relative_transversal_link_strength, r.bimodal_factor
    irc, irt = r.interface_reenforcement_central, r.interface_reenforcement_tangential
    prc, tau, dt, dt_max = c.prc, c.tau, c.dt, c.dt_max
    if r.do_pre_equilibration:
        ens.dt = dt
        ens.dt_max = 0.2 * tau / bf if r.relative_viscosity <= 0.1 else 0.25 * tau / bf
        if r.packing_fraction > 2 and not legacy:
            ens.dt_max = ens.dt_max / 2
        n1 = int(300 / R) if prc == 1 else int(100 / R)
        yield Relaxation(ens, n1)
        if A <= 0.01 or rts < 0.1:
            yield Relaxation(ens, n1)
        ens.dt = dt
        ens.dt_max = dt_max
        yield Relaxation(ens, int(200 / R) if prc == 1 else int(100 / R))
        for threshold in (0.01, 0.001):
            if A <= threshold and prc == 1:
                yield Relaxation(ens, int(200 / R))

    if r.do_permanent_links:
        _crosslink_and_cut(ens, c.cut_lines, r.doCutByTriangulation, r.edge_fuzziness, r.cut_top_bottom, c.avoid,
                           verbose)
        if r.cut_top_bottom and not legacy:
            ens.cut_top_bottom = True
        if r.remove_link_fraction > 0:
            ens.remove_non_essential_links(r.remove_link_fraction, True)
            if verbose:
                logging.getLogger(__name__).info("Actual fraction of removed non-essential links: "
                                                 + str(ens.removed_fraction))
        ens.join_isolated_spheres()
        ens.dt_max = min(2 * ens.dt, ens.dt_max)
        if rts > 5:
            ens.dt_max = ens.dt_max / 2
        if legacy:
            yield Relaxation(ens, 25)   # free_pre_equilibration() with its default N
            return ens
        yield Relaxation(ens, int(300 / R))
        n = int(150 / R)
        if A < 0.1:
            yield from _free_mu0(ens, n, r.mu)
            yield Relaxation(ens, n)
        n = int(100 / R)
        for threshold in (0.01, 0.001, 0.0001):
            if A <= threshold:
                yield Relaxation(ens, n)
                yield from _free_mu0(ens, n, r.mu)
                yield Relaxation(ens, n)
        if A <= 0.001 and (irt != 1 or irc != 1):
            ens.dt_max = ens.dt_max / 3
            n = int(200 / R)
            yield Relaxation(ens, n)
            yield from _free_mu0(ens, n, r.mu)
            yield Relaxation(ens, n)
    return ens


@dataclasses.dataclass(frozen=True)
class ConstitutedState:
    """A constituted gel as the engine's state, with the facts a result or file reports of it.

    Parameters
    ----------
    state : BatchState
        One replica on the requested backend: spheres, box, strain, rate, clock, constants, the
        pair list (bonds and relations with their history) and the generator (``rng[0]``, at the
        position the constitution left it).
    dt, dt_max : float
        The steps to use (s), as the builders leave them on their ensemble.
    model : particle_shear_model_parameters
        The model constants (``ensemble.model``).
    removed_fraction : float or int
        Fraction of the non-essential links removed: the value the builders' ensemble holds (the
        int 0 without ``remove_link_fraction``, which a file's header writes as ``0``).
    triangulation_points : ndarray (n, 2) or None
        The Voronoi seeds of the last cut (µm), None without a Voronoi cut.
    r_max : float
        The largest radius (µm).
    steps : int, optional
        Relaxation steps run (the builders' ensemble's ``step_count`` and ``n_constitution_steps``).
    sphere_seed : ndarray (N,) of int or None, optional
        The Voronoi seed of each sphere at the last cut, None where nothing was cut.
    particle_labels : ndarray (N,) of int or None, optional
        The particle of each sphere at the last height check (``avoid_height_spanning_particles``:
        the builders' ensemble's ``particles``), None without a check.
    cut_top_bottom : bool, optional
        The builders' ensemble's flag ``cut_top_bottom``: the constitution cut the bonds through
        the y boundary (never set by the legacy one).
    legacy : bool, optional
        The legacy builder's constitution (``constituted_state(legacy=True)``): the class of its
        documented ensemble (:func:`ensemble_of_state`).
    """
    state: object
    dt: float
    dt_max: float
    model: object
    removed_fraction: float
    triangulation_points: object
    r_max: float
    steps: int = 0
    sphere_seed: object = None
    particle_labels: object = None
    cut_top_bottom: bool = False
    legacy: bool = False


class _StateTarget:
    """What :func:`_schedule` reads and calls of an ensemble, on an engine state of one replica.

    Its methods are the documented classes' (same names) on the state's rows and pair table,
    through :mod:`.bonds`; a relaxation runs the engine on the state, alone or joined with other
    targets' (:meth:`relax`, :func:`~particleShear.base.engine_adapter.relax_states`, the settings of
    :func:`~particleShear.base.engine_adapter.relax_ensembles` for an ensemble without a guard:
    the relaxations' central law ``law``, host backend ``backend`` and Verlet skin ``skin_factor``).
    """

    def __init__(self, r, c, legacy, rng, law=None, backend="numpy", skin_factor=RELAX_SKIN):
        g = np.random.default_rng(rng)
        lower, upper = bimodal_factors(r.bimodal_factor)
        x, y, radius, mass = bimodal_placement(g, c.N, r.size_x, r.size_y, r.packing_fraction, lower, upper,
                                               c.model.m)
        s = self.state = BatchState(1, c.N, backend="numpy")
        s.x[:], s.y[:], s.r[:], s.m[:] = x, y, radius, mass
        s.phi[:] = FIELDS["phi"]
        s.inertia[:] = mass * radius * radius / 2          # as the spheres' m r²/2
        s.Lx[0], s.Ly[0] = float(r.size_x), float(r.size_y)
        s.k[0], s.nu[0], s.k_t[0], s.nu_t[0] = c.k, c.nu, c.k_t, c.nu_t
        s.mu[0] = r.mu
        s.c[0] = r.central_repulsion_coefficient
        if not legacy:
            s.prc[0], s.prt[0], s.keep[0] = c.prc, c.prt, float(bool(r.keep_viscosity_coefficients_constant))
        else:
            s.prc[0], s.prt[0], s.keep[0] = (FIELDS[name] for name in (
                "permanent_ratio_central", "permanent_ratio_tangential", "keep_viscosity_coefficients_constant"))
        s.pairs[0] = PairTable()
        s.rng[0] = g
        s.applying_shear = False
        set_laws(s, [law])        # the relaxations' law (None: the classes' callbacks)
        s.backend = host_backend(backend)       # (the same host arrays)
        self.skin_factor = skin_factor
        self.size_x, self.size_y = r.size_x, r.size_y
        self.avoid_horizontal_angle_degree = r.avoid_horizontal_angle_degree
        self.r_max = float(radius.max()) if c.N else 0
        self.mu = r.mu
        self.dt, self.dt_max = c.dt, c.dt_max
        self.removed_fraction = 0
        self.triangulation_points = self.sphere_seed = self.particle_labels = None
        self.particles = []
        self.cut_top_bottom = False
        self.steps = 0

    # -- the state's rows, as the algorithms of .bonds take them
    def _rows(self):
        s = self.state
        return s.x, s.y, s.r

    def _shift(self):
        s = self.state
        return float(s.Ly[0] * s.gamma[0])     # the ensemble's size_y·shear

    @property
    def _pairs(self):
        return self.state.pairs[0]

    def free_pre_equilibration(self, N):
        _StateTarget.relax([self], N)

    @staticmethod
    def relax(targets, N):
        """``free_pre_equilibration(N)`` of every target, all in one engine.

        :func:`~particleShear.base.engine_adapter.relax_states` of the targets' states.

        Each target's μ is set on its state first; the targets share ``dt``, ``dt_max`` and the
        skin (ValueError otherwise, before any step); each one's step count advances.
        """
        settings = {(float(t.dt), float(t.dt_max), float(t.skin_factor)) for t in targets}
        if len(settings) != 1:
            raise ValueError(f"targets have (dt, dt_max, skin_factor) = {sorted(settings)}: one engine relaxes "
                             "one schedule")
        (dt, dt_max, skin_factor), = settings
        for t in targets:
            t.state.mu[0] = float(t.mu)
        steps = relax_states([t.state for t in targets], N, dt, dt_max, skin_factor=skin_factor)
        for t in targets:
            t.steps += steps

    def makeAllLinksPermanent(self):
        if not self._pairs.active.any():       # the ensemble's neighbour update (test_neighbor_relation)
            s = self.state
            s.mu[0] = float(self.mu)
            backend, s.backend = s.backend, host_backend("auto")      # (the ensemble's own engine's)
            try:
                engine = BatchEngine(s, skin_factor=CanvasPointsNeighbors.neighbour_skin, guard=False,
                                     numbers_relations=True)
                engine.relations()
                engine.flush()
            finally:
                s.backend = backend
        bonds.link_relations(self._pairs, self.state.r)

    def cutTopBottomEdge(self):
        x, y, _ = self._rows()
        bonds.cut_top_bottom_edge(self._pairs, x, y, self.size_x, self.size_y, self._shift())

    def cutByTriangulation(self, n_points, edge_fuzziness=0):
        pts = self.triangulation_points = bonds.seed_points(self.state.rng[0], n_points, self.size_x, self.size_y)
        x, y, _ = self._rows()
        seed = bonds.voronoi_cut(self._pairs, x, y, self.size_x, self.size_y, self._shift(), pts, edge_fuzziness,
                                 self.r_max, self.state.rng[0])
        if seed is not None:
            self.sphere_seed = seed

    def cutRandomLine(self):
        x, y, _ = self._rows()
        point, angle = bonds.random_line(self.state.rng[0], self.size_x, self.size_y,
                                         self.avoid_horizontal_angle_degree)
        bonds.cut_line(self._pairs, x, y, self.size_x, self.size_y, self._shift(), point, angle)

    def maximal_particle_height(self):
        x, y, r = self._rows()
        self.particle_labels = bonds.particle_labels(self._pairs, x, y, self.size_x, self.size_y)
        return bonds.maximal_particle_height(self.particle_labels, y, r)

    def remove_non_essential_links(self, fraction, physical_only=True):
        x, y, r = self._rows()
        self.removed_fraction = bonds.remove_non_essential_links(self._pairs, x, y, r, self.size_x, self.size_y,
                                                                 fraction, self.state.rng[0], physical_only)

    def join_isolated_spheres(self):
        x, y, r = self._rows()
        bonds.join_isolated_spheres(self._pairs, x, y, r, self.size_x, self.size_y, self.state.rng[0])


def state_constitution(recipe, *, legacy=False, rng=None, law=None, backend="numpy", relaxation_law=None,
                       relaxation_backend="numpy", skin_factor=RELAX_SKIN, do_debug=False, verbose=False):
    """The constitution of ``recipe`` on the engine's state as a generator of its relaxations.

    :func:`constituted_state` with each relaxation yielded as a :class:`Relaxation` of the
    state's target (its ``dt``, ``dt_max`` and ``mu`` set for it) for the caller to run:
    alone (:meth:`Relaxation.run`, :func:`relax_constitution`) or with the waiting requests of
    other constitutions in one engine (:meth:`Relaxation.run_together`, a run's driver,
    ``simulation.driver``); the result does not depend on which (docs/engine.md, "Runs").
    Invalid backends raise on the first ``next()``, before any work.

    Parameters
    ----------
    recipe, legacy, rng, law, backend, relaxation_law, relaxation_backend, skin_factor, do_debug, verbose
        As for :func:`constituted_state`.

    Yields
    ------
    Relaxation
        The next block.

    Returns
    -------
    ConstitutedState
        The constituted gel (``StopIteration.value``).
    """
    target_backend = get_backend(backend)
    host_backend(relaxation_backend)
    c = _Constants(recipe, legacy, do_debug, verbose)
    target = _StateTarget(recipe, c, legacy, rng, relaxation_law, relaxation_backend, skin_factor)
    yield from _schedule(target, recipe, c, legacy, verbose)
    w = target.state
    s = BatchState(1, w.N, backend="numpy")       # the hand-over's copy (state_from_ensembles)
    for name in BatchState.SPHERE_ARRAYS + BatchState.REPLICA_ARRAYS:
        getattr(s, name)[...] = getattr(w, name)
    s.mu[0] = float(target.mu)      # the ensemble's μ (also where no relaxation ran)

    pt = w.pairs[0]
    s.pairs[0] = pt.copy(pt.active | (pt.state == PERMANENT))
    s.rng[0] = w.rng[0]
    set_laws(s, [law])
    return ConstitutedState(state=s.to_backend(target_backend), dt=float(target.dt), dt_max=float(target.dt_max),
                            model=c.model, removed_fraction=target.removed_fraction,
                            triangulation_points=target.triangulation_points, r_max=float(target.r_max),
                            steps=target.steps, sphere_seed=target.sphere_seed, particle_labels=target.particle_labels,
                            cut_top_bottom=target.cut_top_bottom, legacy=bool(legacy))


def constituted_state(recipe, *, legacy=False, rng=None, law=None, backend="numpy", relaxation_law=None,
                      relaxation_backend="numpy", skin_factor=RELAX_SKIN, do_debug=False, verbose=False):
    """The constitution of ``recipe`` made on the engine's state, without a documented ensemble.

    The same placement, relaxations, crosslinking, cuts, link removal and joining as
    :func:`constitution` (one schedule, one implementation of each step: :mod:`.bonds`,
    :mod:`particleShear.objects.placement`), run on a one-replica
    :class:`~particleShear.engine.state.BatchState` with the random draws in the same order from
    the same generator: the state is bit-identical to
    ``state_from_ensembles([ensemble], backend, laws=[law])`` of the ensemble :func:`constitution`
    builds from the same recipe and seed (docs/engine.md, "Runs").  Its relaxations are those of
    :func:`state_constitution`, run one by one (:func:`relax_constitution`).

    Parameters
    ----------
    recipe : EnsembleRecipe
        The checked parameters of the gel.
    legacy : bool, optional
        The legacy builder's constitution (:func:`EnsembleCompactParticlesFromModelParameters`).
    rng : numpy.random.Generator, int or None, optional
        Generator or seed of every random choice (None: fresh entropy); a generator is used, not copied.
    law : tuple or None, optional
        The central law of the measurement, ``(name, values)`` as
        :func:`~particleShear.base.engine_adapter.state_from_ensembles` takes it (None: the classes'
        callback), given to the returned state; the relaxations use ``relaxation_law``.
    backend : str or Backend, optional
        Where the returned state lives (the constitution runs on the host).
    relaxation_law, relaxation_backend, skin_factor : optional
        The central law, host backend (``"numpy"``, ``"numba"`` or ``"auto"``) and Verlet skin of
        the relaxations, as :func:`~particleShear.base.engine_adapter.relax_ensembles` takes them
        (defaults: the builders' — the classes' callbacks, NumPy, ``RELAX_SKIN``; a run's driver
        relaxes with its run's law and backend, ``simulation.driver``).
    do_debug, verbose : bool, optional
        Ten times shorter relaxations; log the builders' messages.

    Returns
    -------
    ConstitutedState

    Raises
    ------
    RuntimeError
        If no cut without a height-spanning particle is found in :data:`MAX_CUT_ATTEMPTS` attempts.
    ValueError
        For an unusable backend or relaxation backend (before any work).
    """
    return relax_constitution(state_constitution(
        recipe, legacy=legacy, rng=rng, law=law, backend=backend, relaxation_law=relaxation_law,
        relaxation_backend=relaxation_backend, skin_factor=skin_factor, do_debug=do_debug, verbose=verbose))


def ensemble_of_state(constituted, recipe, *, legacy=None, doDrawing=False):
    """The documented ensemble of a constituted state, as a view of the state: nothing drawn or relaxed.

    The ensemble :func:`constitution` and :func:`relax_constitution` make from the same recipe
    and seed (same class, constants, spheres, relations and bonds with their history, generator
    position, clock, strain, μ, steps, step counts and facts of the cut; the builders' pair table
    also keeps rows of relations that ended, which a step reads as exact zeros), made from ``constituted``
    (:func:`constituted_state`, ``legacy`` as given there) instead: the class's construction of
    a constitution (:func:`_documented_ensemble`) with the state's placement, then
    :func:`~particleShear.base.engine_adapter.adopt_state`, after which the ensemble's state
    block, replica cells, pair table, Verlet predictor and generator are the state's own
    memory (a step of either is the other's); the facts the state does not hold (``dt``,
    ``dt_max``, ``removed_fraction``, ``triangulation_points``, ``sphere_seed``, ``particles``,
    ``cut_top_bottom``, the step counts) are set from ``constituted``.  Its plates are off, as
    after a constitution; the state's flag is left as it is.

    Parameters
    ----------
    constituted : ConstitutedState
        A constitution of ``recipe`` on a host backend (its state's arrays are replaced by views:
        read them again).
    recipe : EnsembleRecipe
        The recipe ``constituted`` was made of (the ensemble's constants and class parameters).
    legacy : bool or None, optional
        :class:`~.compact.EnsembleCompactParticles`, the legacy builder's; None (default): as
        ``constituted`` was made (``constituted.legacy``), which a value given must equal.
    doDrawing : bool, optional
        Draw the spheres (no window), as :func:`constitution` takes it.

    Returns
    -------
    EnsembleCompactParticles or EnsembleCompactParticlesAdjustableInterfaceStrength

    Raises
    ------
    ValueError
        If the state is not one replica on the host or is an ensemble's already
        (:func:`~particleShear.base.engine_adapter.check_adoptable`), its N, box, constants or μ
        are not the recipe's, or ``legacy`` is not the constitution's.
    """
    s = constituted.state
    made = bool(getattr(constituted, "legacy", False))
    if legacy is None:
        legacy = made
    elif bool(legacy) != made:
        raise ValueError(f"legacy={legacy!r}, but the state is a constitution with legacy={made!r} "
                         "(the builder's class follows it: leave legacy out)")
    c = _Constants(recipe, legacy, False, False)
    given = (s.B, s.N, s.Lx[0], s.Ly[0], s.k[0], s.nu[0], s.k_t[0], s.nu_t[0], s.mu[0])
    if given != (1, c.N, recipe.size_x, recipe.size_y, c.k, c.nu, c.k_t, c.nu_t, float(recipe.mu)):   # (μ as stored)
        raise ValueError(f"the state (B, N, Lx, Ly, k, nu, k_t, nu_t, mu) = {given} is not a constitution of the "
                         "recipe")
    check_adoptable(s, c.N)           # (before any work)
    ens = _documented_ensemble(recipe, c, legacy, doDrawing, s.rng[0], (s.x, s.y, s.r, s.m))
    adopt_state(ens, s)
    _set_constitution_facts(ens, constituted)
    return ens


def _set_constitution_facts(ens, constituted):
    """Set on ``ens`` what its constitution left on a documented ensemble besides the state's memory.

    The steps, the cut's facts where a cut made them (:meth:`~.compact.EnsembleCompactParticles.cutByTriangulation`,
    :meth:`~.compact.EnsembleCompactParticles.maximal_particle_height`) and the bookkeeping of
    :func:`~particleShear.base.engine_adapter.write_back` after its relaxations.
    """
    ens.dt, ens.dt_max = constituted.dt, constituted.dt_max
    ens.removed_fraction = constituted.removed_fraction
    if constituted.triangulation_points is not None:
        ens.triangulation_points, ens.doCutByTriangulation = constituted.triangulation_points, True
    if constituted.sphere_seed is not None:
        ens.sphere_seed = constituted.sphere_seed
    if constituted.particle_labels is not None:
        ens.particles = ens._particles_from_labels(constituted.particle_labels)
    if constituted.cut_top_bottom:
        ens.cut_top_bottom = True
    ens.step_count = ens.n_constitution_steps = constituted.steps
    if constituted.steps:
        ens._last_dt = float(constituted.dt)


def _parameters_section(doc):
    """The numpydoc ``Parameters`` section of ``doc`` (up to the next section), indented as given."""
    start = doc.index("    Parameters\n")
    end = doc.index("    Returns\n", start)
    return doc[start:end]


# the generator takes the builder's parameters: their documentation is written once, in the builder
adjustable_interface_constitution.__doc__ = adjustable_interface_constitution.__doc__.replace(
    "    Yields\n", _parameters_section(
        EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters.__doc__) + "    Yields\n", 1)


def EnsembleCompactParticlesFromModelParameters(
        size_x=500, size_y=500, N=100, packing_fraction=1, mu=1, Young_modulus_spheres=10000, density=50,
        bimodal_factor=1.4, cut_lines=5, do_permanent_links=True, theTk=False, do_pre_equilibration=True,
        relative_viscosity=0.01, central_repulsion_coefficient=0, anticipated_amplitude=0.1,
        relative_transversal_link_strength=1, avoid_horizontal_angle_degree=0,
        avoid_height_spanning_particles=False, doCutByTriangulation=True, doDrawing=True, do_debug=False,
        rng=None, verbose=False):
    """Legacy factory of ``Simulation_dermal_filler_rheology``; returns an :class:`EnsembleCompactParticles`.

    The main builder (same parameters, checks and errors) with ``irc = irt = 1``, bonds through the y
    boundary always cut, no edge fuzziness or link removal, and a final relaxation of 25 steps per level.

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, bimodal_factor, mu, Young_modulus_spheres, density, cut_lines
    relative_viscosity, relative_transversal_link_strength, central_repulsion_coefficient, doDrawing
    anticipated_amplitude, do_pre_equilibration, do_debug, do_permanent_links, doCutByTriangulation
    avoid_horizontal_angle_degree, avoid_height_spanning_particles, theTk, rng, verbose
    """
    return relax_constitution(constitution(EnsembleRecipe.of(locals()), legacy=True, doDrawing=doDrawing,
                                           do_debug=do_debug, rng=rng, verbose=verbose))
