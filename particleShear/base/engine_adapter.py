"""The documented ensembles as views of the engine's state: conversion, write-back, relaxation.

The engine (:mod:`particleShear.engine`) advances a :class:`~particleShear.engine.state.BatchState`
of plain arrays and knows nothing of the documented classes.  This module is their adapter
(docs/classes.md, "The documented classes"):

* :func:`state_from_ensembles` copies B ensembles into a new batch state (a measurement's batch);
* :func:`state_of_ensembles` (:func:`state_of_ensemble` for one) makes a batch state whose
  per-sphere arrays are the ensembles' own state rows, whose clock, strain, rate and μ are their
  replica cells and whose pair lists are their pair tables, so that what the engine's steps write
  the ensembles hold;
* :func:`adopt_state` is the inverse: an ensemble of a one-replica state's spheres (made by the
  builders, ``particleShear.linkable.builders.ensemble_of_state``) then holds them in the state's
  memory, as if the state had been made by :func:`state_of_ensemble`;
* :func:`ensembles_of` tells whose memory a state is;
* :func:`write_back` hands an ensemble its plates, relations and Verlet predictor after such an
  engine ran, and drops its caches; :func:`untouched_on_failure` puts an ensemble back as it was
  when a run on its own state fails;
* :func:`relax_ensembles` is ``free_pre_equilibration`` of a list of ensembles in one engine
  (:func:`~particleShear.engine.relax.free_relaxation`), written back; :func:`relax_state` the
  same relaxation of a state, :func:`relax_states` of several one-replica states in one engine.

This module and the classes themselves are the only code that reads the classes' state blocks,
pair tables and generators and drops their caches (through the classes' package-private members).

Units: µm, s, mg per m depth (docs/parameters.md).
"""
__docformat__ = "numpy"

import contextlib
import weakref

import numpy as np

from ..checks import integer
from ..engine.loops import relaxation_levels
from ..engine.relax import RELAX_SKIN, free_relaxation
from ..engine.predictor import Predictor
from ..engine.state import PER_REPLICA_PARAMETERS, PER_SPHERE_PARAMETERS, PERMANENT, BatchState
from ..engine.step import BatchEngine
from ..engine.xp import get_backend
from .callbacks import callback_phase_laws
from .fields import REPLICA_FIELDS, ROW

__all__ = ["uniform_parameters", "state_from_ensembles", "state_of_ensemble", "state_of_ensembles", "adopt_state",
           "ensembles_of", "check_adoptable", "write_back", "untouched_on_failure", "relax_ensembles", "relax_state",
           "relax_states", "set_laws", "host_backend"]

#: each per-sphere array of a :class:`BatchState` and the field of the ensembles' state block it holds
SPHERE_ROWS = (("x", "x"), ("y", "y"), ("vx", "xspeed"), ("vy", "yspeed"), ("omega", "omega"), ("phi", "phi"),
               ("r", "r"), ("m", "m"), ("inertia", "inertia"), ("fx", "xforce"), ("fy", "yforce"),
               ("torque", "torque"))


def uniform_parameters(ensemble):
    """Whether every parameter of :data:`PER_SPHERE_PARAMETERS` is one value in ``ensemble`` (then the
    batch state holds it once per replica, else per sphere in :attr:`BatchState.visit`).

    Parameters
    ----------
    ensemble : ensemble
        A documented ensemble (its ``_a`` rows are read).

    Returns
    -------
    bool
    """
    a, n = ensemble._a, len(ensemble.sphereList)
    return all(np.all(np.asarray(a[name][:n]) == a[name][0]) for name in PER_SPHERE_PARAMETERS) if n else True


def state_from_ensembles(ensembles, backend="auto", laws=None):
    """Copy B ensembles of equal N (after constitution) into one batch state.

    The ensembles are not modified; each replica keeps a reference to its ensemble's
    random generator, so the random normals of ``d = 0`` continue its stream.

    Parameters
    ----------
    ensembles : sequence of ensemble
        Constituted ensembles (``particleShear.objects`` or ``particleShear.linkable``
        ensembles), all with the same number of spheres.
    backend : str or Backend, default "auto"
        Where the arrays of the state live and how its steps run
        (:func:`~particleShear.engine.xp.resolve_backend`: ``"auto"`` is ``"numpy"`` unless
        ``PARTICLESHEAR_BACKEND`` says otherwise): the
        ensembles are read on the host and the state is copied to the device once.
    laws : sequence, optional
        The central law of each ensemble: ``None`` (the documented callback) or
        ``(name, values)``, a name of :data:`~particleShear.engine.laws.LAWS` and its
        parameter values in order (:func:`~particleShear.engine.laws.law_values`).  One law
        per batch; the values may differ between replicas.  Default: None for every one.

    Returns
    -------
    BatchState
        Replica b holds ``ensembles[b]``: spheres, box, strain, rate, clock, constants and
        the relations and bonds of its pair table.

    Raises
    ------
    ValueError
        If the ensembles differ in N, or their laws differ, or for an unusable backend (before
        any copy).
    """
    target = get_backend(backend)
    laws = _checked_laws(laws, len(ensembles))
    Ns = {len(e.sphereList) for e in ensembles}
    if len(Ns) != 1:
        raise ValueError(f"ensembles have N = {sorted(Ns)}: a batch needs one N")
    B, N = len(ensembles), Ns.pop()
    s = BatchState(B, N, backend="numpy")     # filled on the host, then moved to the target
    own = [not uniform_parameters(e) for e in ensembles]     # spheres with parameters of their own
    if any(own):
        s.visit = np.zeros((len(PER_REPLICA_PARAMETERS), B * N))
    for b, e in enumerate(ensembles):
        a = e._a
        rows = slice(b * N, (b + 1) * N)
        for name, src in SPHERE_ROWS:
            getattr(s, name)[rows] = a[src][:N]
        s.Lx[b], s.Ly[b] = float(e.size_x), float(e.size_y)
        s.gamma[b], s.rate[b], s.t[b] = (float(getattr(e, name, 0.0)) for name in ("shear", "shear_rate", "t"))
        # a frictionless ensemble of particleShear.objects has no tangential constants (a canvas
        # without forces none at all): 0
        s.k[b], s.nu[b], s.k_t[b], s.nu_t[b], s.mu[b] = (float(getattr(e, name, 0.0))
                                                         for name in ("k", "nu", "k_t", "nu_t", "mu"))
        for name, src, empty in zip(PER_REPLICA_PARAMETERS, PER_SPHERE_PARAMETERS, (0.0, 1.0, 1.0, 1.0)):
            getattr(s, name)[b] = float(a[src][0]) if N else empty
        if own[b]:
            s.visit[:, rows] = [np.asarray(a[src][:N], dtype=float) for src in PER_SPHERE_PARAMETERS]
        pt = e._pairs
        keep = pt.active | (pt.state == PERMANENT)
        s.pairs[b] = pt.copy(keep)
        s.rng[b] = e._rng
    if any(own):
        shared = np.repeat(np.logical_not(own), N)
        s.visit[:, shared] = s.per_replica_parameters()[:, shared]
    set_laws(s, laws)
    return s.to_backend(target)


def _checked_laws(laws, B):
    """``laws`` as a list of B entries (None: B times None); ValueError unless they are one law."""
    laws = [None] * B if laws is None else list(laws)
    if len(laws) != B or len({None if law is None else law[0] for law in laws}) > 1:
        raise ValueError(f"laws={laws!r} is invalid: one law per ensemble, the same law for every one "
                         "(its parameters may differ)")
    return laws


def set_laws(state, laws=None):
    """Give a host state the central law of each replica and the classes' law callbacks.

    What :func:`state_from_ensembles` sets: :attr:`~particleShear.engine.state.BatchState.law`,
    ``law_params`` and ``callback_laws`` (:func:`~particleShear.base.callbacks.callback_phase_laws`,
    read at every force phase).

    Parameters
    ----------
    state : BatchState
        On the host, changed in place.
    laws : sequence, optional
        One entry per replica, as :func:`state_from_ensembles` takes them (default: None for every one).

    Raises
    ------
    ValueError
        If the laws are not one law (their parameters may differ) or not one per replica.
    """
    laws = _checked_laws(laws, state.B)
    names = {None if law is None else law[0] for law in laws}
    state.law = names.pop() if names else None
    state.callback_laws = callback_phase_laws      # the classes' law callbacks, read at every force phase
    if state.law is not None:
        state.law_params = np.array([law[1] for law in laws], dtype=float).reshape(state.B, -1).T.copy()

def state_of_ensemble(ensemble, laws=None, backend="numpy"):
    """:func:`state_of_ensembles` of one ensemble (the ensemble keeps its own block).

    Parameters
    ----------
    ensemble : ensemble
        A documented ensemble of ``particleShear.objects`` or ``particleShear.linkable``.
    laws : sequence, optional
        As :func:`state_from_ensembles` (one entry).
    backend : {"numpy", "numba", "auto"} or Backend, default "numpy"
        As :func:`state_of_ensembles`.

    Returns
    -------
    BatchState
        B = 1 on the host, the memory of ``ensemble`` (:func:`ensembles_of`).
    """
    return state_of_ensembles([ensemble], laws=laws, backend=backend)

def state_of_ensembles(ensembles, laws=None, backend="numpy"):
    """B ensembles of equal N as one batch whose per-sphere arrays, clocks, strains, rates and μ are
    the ensembles' own memory: what the engine's steps write, the ensembles hold (nothing to copy back).

    The sphere rows of replica b are columns ``b·N … b·N + N − 1`` of one state block laid out as
    the ensembles' (:data:`FIELDS` × spheres); a single ensemble keeps its own block, fitted to
    its spheres (so the engine's rows of positions, velocities and forces are contiguous: ≈ 4 %
    of a documented step at N = 150), several move theirs into the joint block, of which each
    then holds its columns as a view (an ensemble that later gains a sphere copies its block
    out again).  Likewise the replica cells (:data:`REPLICA_FIELDS`: clock ``t``, strain
    ``shear``, rate ``shear_rate``, ``mu``): element b of the state's ``t``, ``gamma``, ``rate``
    and ``mu`` is ``ensembles[b]``'s cell, a single ensemble's own, several ensembles' columns of
    one joint array (:meth:`~particleShear.base.canvas_base.CanvasPoints.adopt_replica_cells`).
    Positions, φ, velocities, forces, radii, masses and moments of inertia are views of that
    block, and replica b's pair list is ``ensembles[b]``'s pair table itself; the Verlet predictor
    (:mod:`particleShear.engine.predictor`) is a single ensemble's own, the predictors of several
    joined (:meth:`~particleShear.engine.predictor.Predictor.joined`); the box, constants
    and per-sphere parameters (which a step only reads) are copied as by
    :func:`state_from_ensembles`, the plates (``applying_shear``, one flag per batch) from the
    first ensemble's ``applyingShear``.  An engine on this state built with
    ``numbers_relations=True`` numbers the relations as they form, and :func:`write_back` afterwards gives each ensemble its plates, relations and
    predictor rows and drops its caches (and :func:`untouched_on_failure` puts one back after a
    failed run).

    Parameters
    ----------
    ensembles : sequence of ensemble
        Documented ensembles of ``particleShear.objects`` or ``particleShear.linkable`` with
        equal N, each at most once.
    laws : sequence, optional
        As :func:`state_from_ensembles`.
    backend : {"numpy", "numba", "auto"} or Backend, default "numpy"
        A backend whose arrays are the host's (the rows stay the ensembles' own); ``"numba"``
        runs the engine's steps in the compiled step (:mod:`particleShear.engine.numba_step`);
        ``"auto"`` is the default backend when that is a host one, else ``"numpy"``.

    Returns
    -------
    BatchState
        On the host, the memory of ``ensembles`` (:func:`ensembles_of`).

    Raises
    ------
    ValueError
        As :func:`state_from_ensembles`, or if an ensemble is given twice.
    """
    ensembles = list(ensembles)
    if len({id(e) for e in ensembles}) != len(ensembles):
        raise ValueError("ensembles: an ensemble is given twice; each replica needs state of its own")
    target = host_backend(backend)
    s = state_from_ensembles(ensembles, backend="numpy", laws=laws)   # views of the ensembles' NumPy rows
    N = s.N
    if len(ensembles) == 1:
        ensembles[0]._fit_block()      # no spare columns: the (2|3, N) rows below are contiguous
        block, cells = ensembles[0]._st, ensembles[0]._replica[:, None]
    else:
        block, cells = np.empty((ensembles[0]._st.shape[0], s.B * N)), np.empty((len(REPLICA_FIELDS), s.B))
        for b, e in enumerate(ensembles):
            block[:, b * N:(b + 1) * N], cells[:, b] = e._st, e._replica
            e.adopt_state_block(block[:, b * N:(b + 1) * N])   # (its caches of the old block dropped)
            e.adopt_replica_cells(cells[:, b])
    _use_block(s, block, cells)
    s.pairs = [e._pairs for e in ensembles]
    # the Verlet predictor: a batch of one holds the ensemble's own (successive engines continue it)
    s.predictor = ensembles[0]._predictor if s.B == 1 else Predictor.joined(
        [e._predictor for e in ensembles], [N] * s.B, np)
    s.applying_shear = bool(getattr(ensembles[0], "applyingShear", True))
    _remember(s, ensembles)
    s.backend = target         # (the same host arrays)
    return s


#: state → weak references to the ensembles whose memory it is, one per replica (set by
#: :func:`state_of_ensembles` and :func:`adopt_state`); a copy of a state is a new object, not in it
_MEMORY_OF = weakref.WeakKeyDictionary()


def ensembles_of(state):
    """The documented ensembles whose memory ``state`` is, one per replica; None for a state of its own.

    Parameters
    ----------
    state : BatchState

    Returns
    -------
    list of ensemble or None
        Set by :func:`state_of_ensembles` and :func:`adopt_state` (a copy of the state, a pickle
        or ``to_backend`` to another backend, owns its arrays and gives None).  An entry is None
        where that ensemble no longer exists; a state whose ensembles are all gone is its own
        again (None).
    """
    refs = _MEMORY_OF.get(state)
    if refs is None:
        return None
    members = [ref() for ref in refs]
    if all(e is None for e in members):
        del _MEMORY_OF[state]
        return None
    return members


def _remember(state, ensembles):
    """Record that ``state`` is the memory of ``ensembles`` (:func:`ensembles_of`)."""
    _MEMORY_OF[state] = [weakref.ref(e) for e in ensembles]


def _use_block(state, block, cells):
    """Make the rows of a state block (fields × B·N) and of replica cells (values × B) the state's arrays."""
    x, vx, fx = ROW["x"], ROW["xspeed"], ROW["xforce"]
    state.use_rows(block[x:x + 2], block[vx:vx + 3], block[fx:fx + 3],
                   *(block[ROW[name]] for name in ("phi", "r", "m", "inertia")))
    state.use_replica_rows(**{name: row for name, row in zip(REPLICA_FIELDS.values(), cells)})


def adopt_state(ensemble, state):
    """Make ``ensemble`` a view of the one-replica host ``state``: the inverse of :func:`state_of_ensemble`.

    The state's per-sphere arrays are laid out as one state block (:data:`FIELDS` × N, the
    per-sphere parameters from :meth:`~particleShear.engine.state.BatchState.visit_rows`), its
    clock, strain, rate and μ as replica cells; the ensemble adopts both
    (:meth:`~particleShear.base.canvas_base.CanvasPoints.adopt_state_block`,
    :meth:`~particleShear.base.canvas_base.CanvasPoints.adopt_replica_cells`) and the state
    takes views of them (:meth:`~particleShear.engine.state.BatchState.use_rows`,
    :meth:`~particleShear.engine.state.BatchState.use_replica_rows`), so that what either
    writes the other reads, as after :func:`state_of_ensemble`.  The ensemble's pair table is
    the state's ``pairs[0]``, its Verlet predictor the state's, its generator ``rng[0]``; its
    caches are dropped.  The box, constants and plates (which an ensemble holds as attributes,
    the state as copies) are left to the caller.  Arrays of the state read before the call are
    no longer its own afterwards: read them again.

    Parameters
    ----------
    ensemble : ensemble of ``particleShear.linkable``
        An ensemble of the state's N spheres (their values are replaced by the state's).
    state : BatchState
        One replica on a host backend.

    Raises
    ------
    ValueError
        As :func:`check_adoptable`.
    """
    check_adoptable(state, len(ensemble.sphereList))
    ensemble._fit_block()
    block = ensemble._block
    for name, field in SPHERE_ROWS:
        block[ROW[field]] = getattr(state, name)
    block[[ROW[name] for name in PER_SPHERE_PARAMETERS]] = state.visit_rows()
    cells = np.array([getattr(state, name)[0] for name in REPLICA_FIELDS.values()], dtype=float)
    _use_block(state, block, cells[:, None])
    ensemble.adopt_state_block(block)
    ensemble.adopt_replica_cells(cells)
    ensemble._pairs, ensemble._predictor = state.pairs[0], state.predictor
    ensemble.set_random_generator(state.rng[0])
    ensemble.invalidate_caches()
    _remember(state, [ensemble])


def check_adoptable(state, n):
    """Raise unless ``state`` can become the memory of an ensemble of ``n`` spheres (:func:`adopt_state`).

    Parameters
    ----------
    state : BatchState
    n : int
        The ensemble's number of spheres.

    Raises
    ------
    ValueError
        If the state has more than one replica, lives on a device, has another N, or is already
        an ensemble's memory (one ensemble per state: ``copy.deepcopy`` that one for another).
    """
    if state.B != 1 or not state.backend.host or state.N != n:
        raise ValueError(f"state of B = {state.B}, N = {state.N} on {state.backend.name!r}: adopt_state needs one "
                         f"replica of the ensemble's N = {n} spheres on a host backend")
    if ensembles_of(state) is not None:
        raise ValueError("the state is already the memory of an ensemble (ensembles_of): one ensemble per state; "
                         "copy.deepcopy that ensemble for another")


def host_backend(backend):
    """The host backend a state on host arrays runs on: ``backend``, or NumPy for ``"auto"`` on a device.

    Parameters
    ----------
    backend : {"numpy", "numba", "auto"} or Backend
        ``"auto"`` is the default backend when that is a host one, else ``"numpy"``.

    Returns
    -------
    Backend

    Raises
    ------
    ValueError
        For a device backend named explicitly (or an unknown one).
    """
    target = get_backend(backend)
    if not target.host and backend == "auto":
        target = get_backend("numpy")   # ("auto" on a device's default: the rows stay on the host)
    if not target.host:
        raise ValueError(f"backend={target.name!r} is not allowed here: the ensembles' own rows are host "
                         "arrays (numpy, numba or auto)")
    return target


def write_back(engine, b, ensemble, steps=0, constitution=True, dt=None):
    """Hand replica ``b`` of a relaxed (or measured) engine on the ensembles' state back to its ensemble.

    The spheres, the clock, strain, rate, μ and the pair table are the ensemble's own already
    (:func:`state_of_ensembles`): what is handed back is the plates (one flag per batch), the
    relations of the last step (written into the table, with the creation numbers the engine
    gave them as they formed: the order of ``neighbors``), the Verlet predictor (its rows of a
    batch of several; a batch of one holds the ensemble's own), and the bookkeeping: the
    ensemble's neighbour list and caches are invalidated, its ``step_count`` and
    ``n_constitution_steps`` advance by ``steps``.

    Parameters
    ----------
    engine : BatchEngine
        The engine after :func:`~particleShear.engine.relax.free_relaxation`, with ``numbers_relations`` set before its first step.
    b : int
        Replica index (0 … B−1).
    ensemble : ensemble of ``particleShear.linkable``
        The ensemble that is replica ``b`` of the engine's state (``ensembles_of(state)[b]``).
    steps : int, optional
        Steps the replica was advanced (bookkeeping of the classes).
    constitution : bool, default True
        The steps were a relaxation of the constitution (plates off afterwards, the ensemble's
        ``n_constitution_steps`` advances); False: a measurement (plates as the engine had them).
    dt : float, optional
        The time step of the last step (default: the ensemble's ``dt``).

    Raises
    ------
    ValueError
        If the engine's state is not the ensembles' own with ``ensemble`` as replica b, or the
        engine does not number its relations (``numbers_relations`` False).
    """
    s = engine.s
    members = ensembles_of(s)
    if members is None or ensemble is None or members[b] is not ensemble:
        raise ValueError("write_back needs an engine on the ensemble's own state "
                         "(state_of_ensembles, of which replica b is the ensemble)")
    if not engine.numbers_relations:
        raise ValueError("write_back needs an engine with numbers_relations = True from its first step "
                         "(the creation numbers of the relations order the ensemble's neighbors)")
    rows = s.replica(b)
    ensemble.applyingShear = bool(s.applying_shear) and not constitution

    engine.flush()

    ensemble.invalidate_caches()
    ensemble._last_dt = float(ensemble.dt if dt is None else dt)
    if s.predictor is not ensemble._predictor:      # (a batch of several: its rows)
        ensemble._predictor.half = s.predictor.rows_of(rows)
    ensemble.step_count += int(steps)
    if constitution and hasattr(ensemble, "n_constitution_steps"):
        ensemble.n_constitution_steps += int(steps)


@contextlib.contextmanager
def untouched_on_failure(ensemble):
    """Leave ``ensemble`` as it was when the block raises (an instability, an interrupt).

    An engine on the ensemble's own state (:func:`state_of_ensemble`)
    steps its spheres, replica cells (clock, strain, rate, μ), pair table and Verlet predictor in
    place; a run that fails before its write-back would leave them half-advanced, out of step with
    the ensemble's caches.  This keeps a copy of the four and puts it back (and drops the
    ensemble's caches) on any exception, which is re-raised.

    Parameters
    ----------
    ensemble : ensemble
        A documented ensemble.
    """
    n = len(ensemble.sphereList)
    block, cells, pairs = ensemble._block[:, :n].copy(), ensemble._replica.copy(), ensemble._pairs.copy()
    half = ensemble._predictor.half         # (replaced by the steps, never written into)
    try:
        yield
    except BaseException:
        ensemble._block[:, :n] = block
        ensemble._replica[:] = cells
        ensemble._pairs.assign(pairs)
        ensemble._predictor.half = half
        ensemble.invalidate_caches()
        raise


def relax_ensembles(ensembles, N, skin_factor=RELAX_SKIN, laws=None, backend="numpy"):
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
        The central law of each ensemble, as :func:`state_from_ensembles`
        takes them (default: the documented callback for every one).
    backend : {"numpy", "numba", "auto"}, default "numpy"
        The host backend of the engine (:func:`state_of_ensembles`).

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
        state = state_of_ensembles(ensembles, laws=laws, backend=backend)
        engine, steps = relax_state(state, N, dt, dt_max, skin_factor=skin_factor, integrator=integrators.pop(),
                                    guard=[g is not None for g in guards], check_interval=interval,
                                    min_distance_ratio=ratio, max_kinetic_energy=ke)
    for b, e in enumerate(ensembles):
        write_back(engine, b, e, steps)
    return steps


def relax_state(state, N, dt, dt_max, skin_factor=RELAX_SKIN, integrator="euler", guard=False, check_interval=4,
                min_distance_ratio=0.05, max_kinetic_energy=None):
    """``free_pre_equilibration(N)`` of every replica of ``state``, in a new engine on it.

    The relaxation of :func:`relax_ensembles` (which runs it on the ensembles' own rows) and of
    :func:`particleShear.linkable.builders.constituted_state` (on an engine state): an engine of
    phase ``"constitution"`` that numbers the relations as they form, then
    :func:`~particleShear.engine.relax.free_relaxation` with each replica's μ (``state.mu``) for
    the last block.  The state holds the clock, strain, μ, spheres and pair lists afterwards.

    Parameters
    ----------
    state : BatchState
        The batch (shear rate 0, as in a constitution); advanced in place.
    N : int
        Steps per level and per final block (>= 0).
    dt, dt_max : float
        Final and coarsest step (s).
    skin_factor : float, optional
        Verlet skin in units of each replica's largest radius (the result does not depend on it).
    integrator : {"euler", "verlet"}, optional
    guard : bool or sequence of bool, optional
        Stability guard per replica (the builders' ensembles have none).
    check_interval, min_distance_ratio, max_kinetic_energy : optional
        The guard's settings, as :class:`~particleShear.engine.step.BatchEngine` takes them.

    Returns
    -------
    engine : BatchEngine
        The engine after the relaxation (for a write-back; the state's Verlet predictor is started
        afresh, :meth:`~particleShear.engine.predictor.Predictor.drop`).
    steps : int
        Steps run per replica.
    """
    state.predictor.drop()       # (a relaxation starts the Verlet predictor afresh: none carried into a constitution)
    engine = BatchEngine(state, skin_factor=skin_factor, integrator=integrator, check_interval=check_interval,
                         guard=guard, min_distance_ratio=min_distance_ratio, max_kinetic_energy=max_kinetic_energy,
                         phase="constitution", numbers_relations=True)
    return engine, free_relaxation(engine, N, dt, dt_max, state.mu.copy())


def relax_states(states, N, dt, dt_max, skin_factor=RELAX_SKIN):
    """:func:`relax_state` of several one-replica states, all in one engine, each handed its replica back.

    The batch of a run's driver on the engine's states, as :func:`relax_ensembles` is on the
    documented ensembles: the states are joined (:meth:`~particleShear.engine.state.BatchState.concat`,
    their rows, clocks, strains, μ and constants copied, their generators shared), relaxed once, and
    each state gets its rows, replica values and pair table back (the joint state's table
    itself: the engine's rebuilds replace a replica's table, its history is flushed into it) and
    the rows of the Verlet predictor; its contacts are dropped (an engine built on it starts them
    from its table).  Each replica is relaxed as it would be alone, bit for bit: the relaxation is
    per replica, and each has its own generator (docs/engine.md, "Runs").  A single state is
    relaxed in place, without a copy (its contacts are the relaxing engine's).

    Parameters
    ----------
    states : sequence of BatchState
        One-replica host states of equal N, backend, law and law callbacks (shear rate 0), each once.
    N : int
        Steps per level and per final block (>= 0).
    dt, dt_max : float
        Final and coarsest step (s), the same for every state.
    skin_factor : float, optional
        Verlet skin in units of each replica's largest radius (the result does not depend on it).

    Returns
    -------
    int
        Steps run per state.

    Raises
    ------
    ValueError
        If a state is given twice, has more than one replica or lives on a device, or the states
        differ in N, backend, law or law callbacks (before any step).
    """
    states = list(states)
    if len({id(st) for st in states}) != len(states):
        raise ValueError("states: a state is given twice; each replica needs state of its own")
    if any(st.B != 1 or not st.backend.host for st in states):
        raise ValueError("relax_states needs one-replica states on a host backend: "
                         f"(B, backend) = {[(st.B, st.backend.name) for st in states]}")
    if len(states) == 1:
        return relax_state(states[0], N, dt, dt_max, skin_factor=skin_factor)[1]
    joint = BatchState.concat(states)           # (checks N, backend, law and callbacks before any step)
    _, steps = relax_state(joint, N, dt, dt_max, skin_factor=skin_factor)
    for b, st in enumerate(states):
        rows = joint.replica(b)
        for name in BatchState.SPHERE_ARRAYS:
            getattr(st, name)[...] = getattr(joint, name)[rows]
        for name in BatchState.REPLICA_ARRAYS:
            getattr(st, name)[0] = getattr(joint, name)[b]
        st.pairs[0] = joint.pairs[b]
        st.predictor.half = joint.predictor.rows_of(rows)
        st.contacts = None
    return steps
