"""The measurement driver: the phases of runs of one schedule, their measurement in the engine.

``runSimulation`` (one session) and a batch of :func:`~particleShear.run.batch.run_batch` (its
sessions) run through :func:`measure_sessions`: the constitution of every replica (relaxations in
the engine), the experiment's preparation, the pre-equilibration and protocol of all replicas in
one engine (:mod:`particleShear.engine`), each replica's drawing an observer of its replica, and
each session's adoption of its record.  It lies in the simulation layer, below the run layer that
builds the sessions (``docs/design.md``, "Layers"; moved from :mod:`particleShear.run.batch`, which
re-exports its names).
"""
__docformat__ = "numpy"
import logging
import time

import numpy as np

from ..base.engine_adapter import relax_ensembles, state_from_ensembles
from ..base.stability import SimulationInstabilityError
from ..engine.microstructure import Stroboscope
from ..engine.numba_step import compile_kernels
from ..engine.state import BatchState
from ..engine.step import BatchEngine, EngineInstability, pre_equilibrate, protocol
from ..engine.xp import auto_without_numba, get_backend
from ..linkable.builders import MAX_RELAXATIONS
from .observers import ReplicaScene

__all__ = ["ENGINE_SKIN_FACTOR", "measure_sessions", "pre_equilibrated", "replica_record"]

#: the logger of the batch phases' messages (the run layer's name, as before the move)
_log = logging.getLogger("particleShear.run.batch")

#: Verlet skin of the engines of a batch (constitution and measurement), in units of each
#: replica's largest radius.  The contacts of every step are exact for any skin and the zero
#: terms of candidates out of contact change no sum, so the numbers do not depend on it; at
#: 0.2 r_max a compressed packing has ~0.9 of its candidates in contact against ~0.6 at 0.5, and
#: a step of 32 default replicas costs ~30 % less (measured: protocol 95–100 → 65–68 µs per
#: replica-step, constitution ~40 % less CPU time), the extra rebuilds included.
ENGINE_SKIN_FACTOR = 0.2


def measure_sessions(sessions, constituted=False):
    """The phases of ``runSimulation`` for every session, the measurement in the engine.

    Constitution (relaxations in the engine, :func:`_constitute`), then per session the
    reservation of its output file, the experiment and the schedule
    (:meth:`~particleShear.simulation.oscillatory.RunSession.prepare`), then the measurement of
    all sessions in the engine (:func:`_measure`), and per session the adoption of its record
    and the writing (:meth:`~particleShear.simulation.oscillatory.RunSession.finish`, which
    fills ``sim.result_info``).  ``runSimulation`` calls it with its one session,
    :func:`measure_batch` with a batch's.  An interrupt (``KeyboardInterrupt``) removes every
    reservation and is re-raised with ``position = (phase, step, total)``.

    Parameters
    ----------
    sessions : list of RunSession
        The sessions of runs that share one schedule.
    constituted : bool, default False
        The sessions' ensembles are built already (their constitution is skipped).

    Returns
    -------
    list of list of float
        ``[G′_surface, G″_surface]`` (Pa) of each session, in order.
    """
    where = ["constitution", 0, 0]
    try:
        if not constituted:
            _constitute(sessions)
        sched = []
        for run in sessions:
            run.prepare()
            # the schedule of the replica: the one function of the measurement
            sc = run.schedule
            sched.append(((sc.dt, sc.f, sc.cool, run.exp.baseline_pre_periods, run.exp.periods,
                           run.exp.baseline_post_periods), (sc.dt_max, sc.N_pre)))
        rec, timings = _measure(sessions, sched, where)
        G = []
        for b, run in enumerate(sessions):
            run.exp.adopt_measurement(sched[b][0][2], rec[b], timings[b])
            rec[b] = None  # the experiment's recording holds it now
            G.append(run.finish())
        return G
    except KeyboardInterrupt as exc:
        exc.position = tuple(where)
        raise
    finally:
        for run in sessions:
            run.close()


def _constitute(sessions):
    """Constitute every replica: bookkeeping per replica through the classes, relaxations in the engine.

    Each session's constitution (:meth:`~particleShear.simulation.oscillatory.RunSession.constitution`)
    yields its relaxation requests; the pending requests of equal key (steps, ``dt``, ``dt_max``)
    run together in one engine (:func:`particleShear.base.engine_adapter.relax_ensembles`), the key of
    the first waiting replica first, until every constitution is done.  A replica's ensemble does
    not depend on its companions (each has its own generator, and the engine's relaxation is per
    replica).  Each replica's ``constitution`` timing is its own bookkeeping plus its share of
    the relaxations it took part in."""

    # the backend of each replica's relaxations: its run's, where that keeps the host's arrays (the
    # compiled step is compiled, or loaded from the cache, here: not counted in the timings)
    backends = [_host_backend(run) for run in sessions]
    compiled = [b for b, be in enumerate(backends) if be.compiled]
    if compiled:
        say = _console([run.sim for run in sessions], [0], "constitution", ["constitution", 0, 0])[0]
        requested = {(sessions[b].sim.parameters or {}).get("backend", "auto") for b in compiled}
        if not all(_compiled(requested, say, law) for law in {(run.sim.contact_law or (None,))[0] for run in sessions}):
            backends = [_host_backend(run) for run in sessions]        # ("auto": NumPy now)
    steps = [run.constitution() for run in sessions]
    pending = {}            # replica -> its waiting Relaxation
    since = {}              # replica -> when it was suspended

    def advance(b, share=0.0):
        if b in since:
            sessions[b].waited += time.perf_counter() - since.pop(b) - share
        try:
            pending[b] = next(steps[b])
            since[b] = time.perf_counter()
        except StopIteration:
            pending.pop(b, None)

    for b in range(len(sessions)):
        advance(b)
    for _ in range(MAX_RELAXATIONS * max(len(sessions), 1)):   # each round serves at least one request
        if not pending:
            return
        key = pending[min(pending)].key
        group = [b for b in sorted(pending) if pending[b].key == key]
        t0 = time.perf_counter()
        relax_ensembles([pending[b].ensemble for b in group], key[0], skin_factor=ENGINE_SKIN_FACTOR,
                        laws=[sessions[b].sim.contact_law for b in group], backend=backends[group[0]])
        share = (time.perf_counter() - t0) / len(group)
        for b in group:
            advance(b, share)
    raise RuntimeError("the constitutions of a batch yielded more relaxations than allowed")


def _measure(sessions, sched, where):
    """The engine measurement of the replicas: one engine per protocol schedule, after
    pre-equilibrating in one engine per pre-equilibration schedule.  Returns each replica's
    record of :func:`~particleShear.engine.step.protocol` and its timings; ``where`` follows
    ``(phase, step, total)``.  Each replica's drawing (live window, snapshots, movie, stress
    window: :meth:`~particleShear.simulation.experiment.OscillatoryShearExperiment.observers`)
    observes its own replica in both loops."""

    sims = [run.sim for run in sessions]
    scenes = [ReplicaScene(getattr(run.sim.theEnsemble, "graphical_output_configuration", None)) for run in sessions]
    watch = [run.exp.observers(sc, sc.samples) for run, sc in zip(sessions, scenes)]

    def observers(engine, members):     # each member's observers, shown its replica in this engine
        for col, b in enumerate(members):
            scenes[b].bind(engine, col)
        return [ob for b in members for ob in watch[b]]

    rec = [None] * len(sessions)
    timings = [dict() for _ in sessions]
    for proto in dict.fromkeys(p for p, _ in sched):
        members = [b for b, (p, _) in enumerate(sched) if p == proto]
        dt, f, cool, pre_p, periods, post = proto
        engine, order = pre_equilibrated(sessions, members, [sched[b][1] for b in members], dt, cool, where,
                                         observers, timings)
        t0 = time.perf_counter()
        say, report = _console(sims, order, "protocol", where)
        keep = [bool(sessions[b].exp.keep_tensor_history) for b in order]
        strobe = _stroboscope(sessions, order, dt, f, pre_p, periods)
        out = _guarded(protocol, engine, dt, f, [sessions[b].exp.amplitude for b in order], cool, pre_p, periods,
                       post, any(keep), say, report, observers(engine, order) + ([strobe] if strobe else []), dt=dt)
        for col, b in enumerate(order):
            sessions[b].microstructure = strobe.replica(col) if strobe else None
            rec[b] = replica_record(out, col, keep[col])
            timings[b]["protocol"] = (time.perf_counter() - t0) / len(order)
        del out
    return rec, timings


def _stroboscope(sessions, order, dt, f, pre, periods):
    """The stroboscopic observer of the replicas (columns of ``order``) whose run asks for it
    (``stroboscopic=True``), or None when none does (then nothing is computed)."""
    want = [col for col, b in enumerate(order) if (sessions[b].sim.parameters or {}).get("stroboscopic")]
    if not want:
        return None
    return Stroboscope(dt, f, pre, periods, replicas=want)


def replica_record(out, col, keep):
    """Replica ``col``'s own record out of a batch's :func:`~particleShear.engine.step.protocol` record.

    Parameters
    ----------
    out : dict of ndarray
        The batch's record: series (n_steps, B), "first_tensors"/"last_tensors" (B, 9, 2, 2) and,
        when kept, "tensors" (n_steps, B, 9, 2, 2).
    col : int
        The replica's column.
    keep : bool
        Keep its tensor history.

    Returns
    -------
    dict of ndarray
        The same keys for that replica alone (contiguous copies; "tensors" only with ``keep``).
    """
    return {key: (np.ascontiguousarray(v[col]) if key.endswith("_tensors") else np.ascontiguousarray(v[:, col]))
            for key, v in out.items() if key != "tensors" or keep}


def pre_equilibrated(sessions, members, pre, dt, cool, where, observers, timings):
    """The pre-equilibrated engine of the replicas ``members``, ready for a protocol at step ``dt``.

    Each group of equal pre-equilibration schedule ``(dt_max, N_pre)`` is pre-equilibrated in an
    engine of its own (:func:`~particleShear.engine.step.pre_equilibrate`); the states are then
    joined into one engine, the Verlet predictor carried on.  Each member's
    ``timings["pre_equilibration"]`` is its share of its group's wall time.

    Parameters
    ----------
    sessions : list of RunSession
        All sessions of the batch (constituted).
    members : list of int
        The sessions measured together (one protocol schedule).
    pre : list of tuple
        ``(dt_max, N_pre)`` of each member, in the order of ``members``.
    dt : float
        Final time step (s).
    cool : float
        Damping factor per step of the last N_pre steps.
    where : list
        ``[phase, step, total]``, followed for an interrupt's position.
    observers : callable
        ``observers(engine, members) -> list`` of the observers of those members in that engine.
    timings : list of dict
        Per session, filled with ``"pre_equilibration"``.

    Returns
    -------
    engine : BatchEngine
        The engine of the joined state (no step taken yet).
    order : list of int
        The session of each replica of ``engine``, in replica order.
    """

    sims = [run.sim for run in sessions]
    backend = (sims[members[0]].parameters or {}).get("backend", "auto")   # one backend per batch
    guard_of = [bool(run.sim.stability_guard) for run in sessions]
    integrator = sims[members[0]].integrator        # part of the schedule key
    states, halves, order = [], [], []
    for key in dict.fromkeys(pre):
        group = [b for b, k in zip(members, pre) if k == key]
        t0 = time.perf_counter()
        st = state_from_ensembles([sims[b].theEnsemble for b in group], backend=backend,
                                       laws=[sims[b].contact_law for b in group])
        for b in group:           # the backend used ("auto" resolved), as the result records it
            sims[b].backend_used = st.backend.name
        say, report = _console(sims, group, "pre-equilibration", where)
        if st.backend.compiled:       # compiled (or loaded from the cache) here, not counted in the timings
            tc = time.perf_counter()
            if not _compiled({backend}, say, st.law):       # ("auto" without a usable Numba: NumPy)
                st = state_from_ensembles([sims[b].theEnsemble for b in group], backend=backend,
                                          laws=[sims[b].contact_law for b in group])
                for b in group:
                    sims[b].backend_used = st.backend.name
            t0 += time.perf_counter() - tc
        engine = BatchEngine(st, skin_factor=ENGINE_SKIN_FACTOR, guard=[guard_of[b] for b in group],
                             integrator=integrator)
        _guarded(pre_equilibrate, engine, key[1], dt, key[0], cool, say, report, observers(engine, group), dt=dt)
        halves.append(engine.half)
        for b in group:
            timings[b]["pre_equilibration"] = (time.perf_counter() - t0) / len(group)
        states.append(st)
        order += group
    state = BatchState.concat(states)
    half = None
    if integrator == "verlet":
        # the predictor carries on from the pre-equilibration, as in one ensemble (no step yet: none)
        half = state.xp.concatenate([state.xp.zeros((3, st.B * st.N)) if h is None else h
                                     for h, st in zip(halves, states)], axis=1)
    engine = BatchEngine(state, skin_factor=ENGINE_SKIN_FACTOR, guard=[guard_of[b] for b in order],
                         integrator=integrator, half=half)
    return engine, order


def _compiled(requested, say, law):
    """Compile (or load) the compiled backend's loops before the timings (:func:`~particleShear.engine.numba_step.compile_kernels`).

    Returns False when the compile failed for runs that asked for ``"auto"`` (which then stands for
    NumPy in this process: :func:`~particleShear.engine.xp.auto_without_numba`); a run that asked
    for ``"numba"`` gets the error."""
    try:
        compile_kernels(say=say, law=law)
        return True
    except Exception as exc:
        if not requested <= {"auto", None}:
            raise
        auto_without_numba(f"{type(exc).__name__}: {exc}")
        return False


def _host_backend(run):
    """The backend of a session's constitution: its run's backend where that works on the host's
    arrays (NumPy, Numba), else NumPy (the ensembles' own rows are relaxed in place)."""
    be = get_backend((run.sim.parameters or {}).get("backend", "auto"))
    return be if be.host else get_backend("numpy")


def _console(sims, members, phase, where):
    """``say`` and ``report`` callbacks of a batch phase: the reference's messages when any member is
    verbose, each member's progress callback at most ~10 times per second (and at the end);
    ``where`` follows ``[phase, step, total]``."""
    verbose = any(sims[b].verbose for b in members)
    callbacks = [sims[b].progress for b in members if sims[b].progress is not None]
    say = (lambda *a: _log.info(" ".join(str(x) for x in a))) if verbose else (lambda *a: None)
    t0 = time.perf_counter()
    last = [0.0]

    def report(step, total):
        where[:] = [phase, step, total]
        if not callbacks:
            return
        now = time.perf_counter()
        if step == total or now - last[0] >= 0.1:
            last[0] = now
            for cb in callbacks:
                cb(phase, step, total, now - t0)
    return say, report


def _guarded(phase, engine, *args, dt, **kwargs):
    """Run an engine phase; a diverging replica raises SimulationInstabilityError (step, phase, suggested dt)."""
    try:
        return phase(engine, *args, **kwargs)
    except EngineInstability as e:
        if e.step == 0 and e.phase == "pre-equilibration":   # the state the constitution left (its step ignores time_step_factor)
            raise SimulationInstabilityError(
                f"{e}: the packing diverged during the constitution (before the measurement's first step), whose "
                "time step time_step_factor does not change; relative_viscosity, relative_transversal_link_strength "
                "or interface_reenforcement_central/_tangential are beyond what the time-step rule integrates "
                "stably: use smaller values (docs/parameters.md, Limits)", step=e.step, phase=e.phase,
                pair=(e.replica,), suggested_dt=None, reason=str(e)) from e
        raise SimulationInstabilityError(
            f"{e} (time step {dt:.3g} s, try dt <= {dt / 2:.3g} s)", step=e.step, phase=e.phase,
            pair=(e.replica,), suggested_dt=dt / 2, reason=str(e)) from e
