"""The constitution's relaxation in the engine: free relaxation of a batch and the write-back.

The builders of ``particleShear.linkable`` relax an ensemble with
:meth:`~particleShear.linkable.compact.EnsembleCompactParticles.free_pre_equilibration`: shear
and plates off, frictionless damped levels from ``dt_max`` halving down to ``dt`` (each level
ending with the removal of the mean velocity), one frictionless block at ``dt``, one block at
``dt`` with the ensemble's μ.  :func:`free_relaxation` runs exactly these steps on every replica
of a :class:`~particleShear.engine.step.BatchEngine`; :func:`remove_linear_drift` is the classes'
``correct_linear_drift`` per replica.  The engine steps the ensembles' own sphere rows and pair
tables (:meth:`~particleShear.engine.state.BatchState.of_ensembles`), and :func:`write_back`
hands each ensemble its clock and relations and drops its caches, so that the bookkeeping that
follows (crosslinking, cutting, link removal, joining isolated spheres) runs through the
documented classes on the contacts the engine ended with, the relations numbered in the order
they formed, as the classes number them.  :func:`relax_ensembles` does all of it for a list of
ensembles (docs/design.md, "Runs").

A replica's relaxation does not depend on its batch (every operation of the step is per
replica, see :mod:`.step`; the drift is removed per replica), so a run constituted in a batch
is bit-identical to the same run constituted alone.  Against the classes the engine computes
the same equations with sums in another order: the two agree to rounding over short blocks
(tested), while a long relaxation of a random packing, being chaotic, amplifies rounding.

Units: µm, s, mg per m depth (docs/parameters.md).
"""
__docformat__ = "numpy"

import contextlib

import numpy as np

from ..checks import integer
from .integrate import remove_mean_velocity
from .loops import relaxation_levels
from .state import BatchState
from .step import BatchEngine
from .xp import to_host

__all__ = ["free_relaxation", "remove_linear_drift", "write_back", "relax_ensembles", "relaxation_levels",
           "untouched_on_failure"]

#: Verlet skin of the relaxation engine, in units of each replica's largest radius.  The
#: contacts of every step are exact for any skin (the list is rebuilt before a pair can have
#: come into contact); in a compressed packing ~0.9 of the candidates are in contact at
#: 0.2 r_max against ~0.6 at 0.5 r_max, so a step works on 30 % fewer pairs, and the extra
#: rebuilds cost less than that (measured: a batch of 32 default constitutions takes ~40 % less
#: CPU time than at 0.5).
RELAX_SKIN = 0.2


def remove_linear_drift(state):
    """Subtract each replica's unweighted mean velocity from its spheres (``correct_linear_drift``):
    :func:`~particleShear.engine.integrate.remove_mean_velocity` of the batch's (vx, vy) rows.

    Parameters
    ----------
    state : BatchState
        The batch; its velocities are changed in place.
    """
    remove_mean_velocity(state.vel[:2], state.B)


def _steps(engine, n, cool, dt):
    for _ in range(n):
        engine.step(cool, dt)


def free_relaxation(engine, N, dt, dt_max, mu):
    """``free_pre_equilibration(N)`` of the classes on every replica of ``engine``.

    Shear and plates off.  μ = 0 during the coarse levels (:func:`relaxation_levels`: N steps
    each, :func:`remove_linear_drift` after each) and N undamped steps at ``dt``; then μ of
    each replica and N undamped steps at ``dt``.  ``engine.s.mu`` holds ``mu`` afterwards and the
    pair history is flushed into ``engine.s.pairs``.

    Parameters
    ----------
    engine : BatchEngine
        The batch (its γ̇ should be 0, as in a constitution); advanced in place.
    N : int
        Steps per level and per final block (>= 0).
    dt : float
        Final time step (s), > 0.
    dt_max : float
        Step of the first level (s).
    mu : array_like (B,)
        Friction coefficient of each replica for the last block.

    Returns
    -------
    int
        Number of steps run (``N·(levels + 2)``).

    Raises
    ------
    ValueError
        If ``N`` is negative, ``dt`` is not > 0 or ``dt_max`` is not finite (before any step).
    """
    N = integer("N", N, 0)
    levels = relaxation_levels(dt, dt_max)
    s = engine.s
    mu = np.array(np.broadcast_to(np.asarray(mu, dtype=float), (s.B,)))
    s.applying_shear = False
    engine.set_mu(np.zeros(s.B))
    for level_dt, cf in levels:
        _steps(engine, N, cf, level_dt)
        remove_linear_drift(s)
    _steps(engine, N, 1, dt)
    engine.set_mu(mu)
    _steps(engine, N, 1, dt)
    engine.flush()
    return N * (len(levels) + 2)


def write_back(engine, b, ensemble, steps=0, constitution=True, dt=None):
    """Hand replica ``b`` of a relaxed (or measured) engine on the ensembles' state back to its ensemble.

    The spheres and the pair table are the ensemble's own already
    (:meth:`~particleShear.engine.state.BatchState.of_ensembles`): what is handed back is the
    clock, the strain, the plates, μ, the relations of the last step (written into the table,
    with the creation numbers the engine gave them as they formed: the order of ``neighbors``), a
    Verlet engine's half kick, and the bookkeeping: the ensemble's neighbour list and caches are
    invalidated, its ``step_count`` and ``n_constitution_steps`` advance by ``steps``.

    Parameters
    ----------
    engine : BatchEngine
        The engine after :func:`free_relaxation`, with ``numbers_relations`` set before its first step.
    b : int
        Replica index (0 … B−1).
    ensemble : ensemble of ``particleShear.linkable``
        The ensemble that is replica ``b`` of the engine's state (``state.ensembles[b]``).
    steps : int, optional
        Steps the replica was advanced (bookkeeping of the classes).
    constitution : bool, default True
        The steps were a relaxation of the constitution (plates off afterwards, the ensemble's
        ``n_constitution_steps`` advances); False: a measurement (plates as the engine had them,
        the shear rate of its last step; a Verlet engine's half kick becomes the ensemble's).
    dt : float, optional
        The time step of the last step (default: the ensemble's ``dt``).

    Raises
    ------
    ValueError
        If the engine's state is not the ensembles' own with ``ensemble`` as replica b, or the
        engine does not number its relations (``numbers_relations`` False).
    """
    s = engine.s
    if s.ensembles is None or s.ensembles[b] is not ensemble:
        raise ValueError("write_back needs an engine on the ensemble's own state "
                         "(BatchState.of_ensembles, of which replica b is the ensemble)")
    if not engine.numbers_relations:
        raise ValueError("write_back needs an engine with numbers_relations = True from its first step "
                         "(the creation numbers of the relations order the ensemble's neighbors)")
    rows = s.replica(b)
    ensemble.t = float(s.t[b])
    ensemble.shear = float(s.gamma[b])
    ensemble.applyingShear = bool(s.applying_shear) and not constitution
    if not constitution:
        ensemble.shear_rate = float(s.rate[b])
    if hasattr(ensemble, "mu"):        # a frictionless ensemble of particleShear.objects has none
        ensemble.mu = float(s.mu[b])

    engine.flush()

    ensemble._invalidate_neighbours()
    ensemble._links_changed()
    ensemble._relations_edited()
    ensemble._g = None
    ensemble._last_dt = float(ensemble.dt if dt is None else dt)
    if engine.half is not None and hasattr(ensemble, "_half_kick"):
        h = to_host(engine.half[:, rows], "state")
        ensemble._half_kick = (h[0].copy(), h[1].copy(), h[2].copy())
    ensemble.step_count += int(steps)
    if constitution and hasattr(ensemble, "n_constitution_steps"):
        ensemble.n_constitution_steps += int(steps)


@contextlib.contextmanager
def untouched_on_failure(ensemble):
    """Leave ``ensemble`` as it was when the block raises (an instability, an interrupt).

    An engine on the ensemble's own state (:meth:`~particleShear.engine.state.BatchState.of_ensemble`)
    steps its spheres and pair table in place; a run that fails before its write-back would leave
    them half-advanced, out of step with the ensemble's clock and caches.  This keeps a copy of
    both and puts it back (and drops the ensemble's caches) on any exception, which is re-raised.

    Parameters
    ----------
    ensemble : ensemble
        A documented ensemble.
    """
    n = len(ensemble.sphereList)
    block, pairs = ensemble._block[:, :n].copy(), ensemble._pairs.copy()
    try:
        yield
    except BaseException:
        ensemble._block[:, :n] = block
        ensemble._pairs.assign(pairs)
        ensemble._invalidate_neighbours()
        ensemble._links_changed()
        ensemble._relations_edited()
        ensemble._g = None
        raise


def relax_ensembles(ensembles, N, skin_factor=RELAX_SKIN, laws=None):
    """``free_pre_equilibration(N)`` of every ensemble, all in one engine, written back.

    Parameters
    ----------
    ensembles : sequence of ensemble
        Ensembles of ``particleShear.linkable`` with equal N, ``dt`` and ``dt_max`` (their μ may
        differ); shear rate 0, as in a constitution.
    N : int
        Steps per level and per final block (>= 0).
    skin_factor : float, optional
        Verlet skin of the engine in units of each replica's largest radius (> 0).  The result
        does not depend on it: the contacts are exact for any skin, and the zero terms of the
        candidates out of contact change no sum.
    laws : sequence, optional
        The central law of each ensemble, as :meth:`~particleShear.engine.state.BatchState.from_ensembles`
        takes them (default: the documented callback for every one).

    Returns
    -------
    int
        Steps run per ensemble.

    Raises
    ------
    ValueError
        If the ensembles differ in N, ``dt``, ``dt_max``, integrator or the settings of their
        stability guards, or a step is not usable (before any step).
    EngineInstability
        If the stability guard of an ensemble (its interval and thresholds) finds it unstable; the
        ensembles are then left as they were (:func:`untouched_on_failure`).
    """
    ensembles = list(ensembles)
    N = integer("N", N, 0)
    if not ensembles:
        return 0
    dts = {(float(e.dt), float(e.dt_max)) for e in ensembles}
    if len(dts) != 1:
        raise ValueError(f"ensembles have (dt, dt_max) = {sorted(dts)}: one engine relaxes one schedule")
    (dt, dt_max), = dts
    relaxation_levels(dt, dt_max)   # checks the steps before any work
    integrators = {getattr(e, "integrator", "euler") for e in ensembles}
    if len(integrators) != 1:
        raise ValueError(f"ensembles use the integrators {sorted(integrators)}: one engine relaxes with one")
    # the guard where an ensemble has one (a script's; the builders guard the measurement only), with
    # its interval and thresholds (one set per engine)
    guards = [getattr(e, "stability_guard", None) for e in ensembles]
    settings = {(getattr(g, "interval", 4), getattr(g, "min_distance_ratio", 0.05), getattr(g, "max_kinetic_energy", None))
                for g in guards if g is not None}
    if len(settings) > 1:
        raise ValueError(f"the ensembles' stability guards differ ({sorted(settings, key=str)}): one engine "
                         "relaxes with one guard")
    interval, ratio, ke = settings.pop() if settings else (4, 0.05, None)
    with contextlib.ExitStack() as stack:      # their own state is stepped: put back on any failure
        for e in ensembles:
            stack.enter_context(untouched_on_failure(e))
        # the engine steps the ensembles' own sphere rows and pair tables (nothing of them to copy back)
        state = BatchState.of_ensembles(ensembles, laws=laws)
        engine = BatchEngine(state, skin_factor=skin_factor, integrator=integrators.pop(), check_interval=interval,
                             guard=[g is not None for g in guards])
        engine.min_distance_ratio, engine.max_kinetic_energy = ratio, ke
        engine.phase = "constitution"
        engine.numbers_relations = True
        steps = free_relaxation(engine, N, dt, dt_max, state.mu.copy())
    for b, e in enumerate(ensembles):
        write_back(engine, b, e, steps)
    return steps
