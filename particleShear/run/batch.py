"""Batches of runs that share a step schedule (the replica axis of the run layer).

A *batch* is a list of keyword dictionaries of :func:`~particleShear.run.api.doParticleShearSimulation`
whose runs share N and the time-step rule, so that their measurement (pre-equilibration with
plates, then the oscillatory protocol) has the same number of steps of the same length.  Each
run (a *replica*) keeps its own spheres, pairs, bonds, seed and per-replica parameters (seed,
μ, amplitude, links, cut lines, ...).

:func:`run_batch` runs one batch and returns one :class:`~particleShear.run.api.SimulationResult`
per replica, in the given order; :func:`batches` splits a list of runs into batches of up to
``batch_size`` runs that share a schedule.  ``doParticleShearSimulationSeries(..., batch_size=B)``
submits every batch as one task of its executor.

A replica's result does not depend on the other replicas of its batch: its recorded series and
G′/G″ are bit-identical to its single run (tested).  Runs the engine supports (:func:`engine_supports`:
no drawing, no files, the Euler integrator, the built-in force laws, N ≤ :data:`ENGINE_MAX_N`) —
single runs included — measure through :mod:`particleShear.engine`, all
replicas of a batch in one set of arrays; other runs go through the documented classes one after
the other.  See ``docs/design.md`` (section "Batches of replicas").
"""
import logging
import time

import numpy as np

from ..linkable.builders import time_steps_from_model

__all__ = ["run_batch", "batches", "schedule_key", "engine_supports", "PER_REPLICA_PARAMETERS", "BACKENDS",
           "ENGINE_MAX_N"]

_log = logging.getLogger(__name__)

#: largest N measured by the engine (its candidate search is all-pairs per replica at each rebuild)
ENGINE_MAX_N = 2000

#: parameters a replica may choose on its own (everything else must agree within a batch)
PER_REPLICA_PARAMETERS = frozenset((
    "seed", "theAmplitude", "theMu", "do_permanent_links", "cut_lines", "remove_link_fraction",
    "edge_fuzziness", "interface_reenforcement_central", "interface_reenforcement_tangential",
    "relative_transversal_link_strength", "central_repulsion_coefficient", "avoid_horizontal_angle_degree",
    "avoid_height_spanning_particles", "cut_top_bottom", "doCutByTriangulation", "keep_viscosity_coefficients_constant",
    "root_folder", "saveData", "saveStressTensorData", "saveOutputImages", "imageFileType", "doDrawing",
    "plotStress", "relative_y_scale_force", "verbose", "progress", "reference_header", "correct_drift_sign",
    "renderer", "stability_guard",
))

#: parameters that fix the step schedule: N, the model constants behind τ, the protocol and the integrator
SCHEDULE_PARAMETERS = ("N", "packing_fraction", "Young_modulus_spheres", "density", "bimodal_factor",
                       "relative_viscosity", "relative_frequency", "pre_periods", "periods", "post_periods",
                       "cool_factor", "time_step_factor", "integrator")

#: array backends a batch can run on
BACKENDS = ("numpy",)

def _signature_defaults():
    """Defaults of every keyword of ``doParticleShearSimulation`` (read from its signature)."""
    import inspect

    from .api import doParticleShearSimulation
    return {name: p.default for name, p in inspect.signature(doParticleShearSimulation).parameters.items()
            if p.default is not inspect.Parameter.empty}


def check_backend(backend):
    """Raise ValueError unless ``backend`` is one of :data:`BACKENDS`."""
    if backend not in BACKENDS:
        raise ValueError(f"backend={backend!r} is out of range: allowed {', '.join(map(repr, BACKENDS))} "
                         "(the CuPy backend needs the array-namespace engine, not in this version)")


def check_batch_size(batch_size):
    """Raise ValueError unless ``batch_size`` is None or an integer >= 1."""
    if batch_size is None:
        return
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise ValueError(f"batch_size={batch_size!r} is out of range: allowed None or an integer >= 1")


def schedule_key(kwargs):
    """Hashable key of the step schedule of one run (runs with equal keys may share a batch).

    The key holds the values of :data:`SCHEDULE_PARAMETERS` (defaults filled in) and the
    protocol time step ``dt`` of the time-step rule (``time_steps_from_model`` with τ = 1,
    docs/parameters.md), which also depends on the replica's μ, amplitude and link strength: two
    runs with equal keys have the same ``dt``, damping factor and protocol steps.  Their
    pre-equilibration may differ (``dt_max`` depends on the links); the batch then
    pre-equilibrates each group of equal ``dt_max`` on its own and shears them together.
    """
    full = dict(_signature_defaults(), **kwargs)
    shared = tuple((name, repr(full[name])) for name in SCHEDULE_PARAMETERS)
    steps = time_steps_from_model(1.0, full["bimodal_factor"], full["theMu"],
                                  full["relative_transversal_link_strength"], full["theAmplitude"],
                                  full["relative_viscosity"])[0]
    other = tuple(sorted((k, repr(v)) for k, v in kwargs.items()
                         if k not in PER_REPLICA_PARAMETERS and k not in SCHEDULE_PARAMETERS))
    return shared + (("steps", steps),) + other


def batches(all_kwargs, batch_size):
    """Split runs into batches of up to ``batch_size`` runs sharing a schedule.

    Parameters
    ----------
    all_kwargs : list of dict
        Keyword arguments of the runs, in their order.
    batch_size : int
        Largest number of runs per batch (>= 1).

    Returns
    -------
    list of list of int
        Positions into ``all_kwargs``; each batch lists runs of one schedule in increasing
        position, batches are ordered by their first run, and every position appears once.
    """
    check_batch_size(batch_size)
    open_batch = {}
    out = []
    for pos, kw in enumerate(all_kwargs):
        key = schedule_key(kw)
        current = open_batch.get(key)
        if current is None or len(current) >= batch_size:
            current = []
            open_batch[key] = current
            out.append(current)
        current.append(pos)
    return out


def run_batch(list_of_kwargs, backend="numpy"):
    """Run a batch of replicas that share a step schedule; one result per replica, in order.

    Parameters
    ----------
    list_of_kwargs : list of dict
        Keyword arguments of :func:`~particleShear.run.api.doParticleShearSimulation` per replica
        (``return_result`` is implied).  All must have the same :func:`schedule_key`.
    backend : {"numpy"}
        Array backend of the batch.

    Returns
    -------
    list of SimulationResult
        Bit-identical to ``[doParticleShearSimulation(**kw, return_result=True) for kw in list_of_kwargs]``.

    Raises
    ------
    ValueError
        For an empty batch, an unknown backend, replicas of different schedules or any invalid
        parameter of any replica, before any simulation work.
    """
    from .api import doParticleShearSimulation
    from .validation import validate_simulation_parameters

    check_backend(backend)
    runs = [dict(kw) for kw in list_of_kwargs]
    if not runs:
        raise ValueError("list_of_kwargs=[] is invalid: a batch needs at least one run")
    keys = [schedule_key(kw) for kw in runs]
    for n, key in enumerate(keys):
        if key != keys[0]:
            diff = sorted(name for (name, v), (_, w) in zip(key, keys[0]) if v != w)
            raise ValueError(f"list_of_kwargs[{n}] does not share the step schedule of list_of_kwargs[0] "
                             f"(differs in {', '.join(diff) or 'its parameters'}); a batch needs equal N, "
                             "time-step rule and protocol")
    defaults = _signature_defaults()
    for n, kw in enumerate(runs):
        kw.pop("return_result", None)
        unknown = sorted(set(kw) - set(defaults))
        if unknown:
            raise ValueError(f"list_of_kwargs[{n}] has unknown parameters {unknown}: allowed the keywords of "
                             "doParticleShearSimulation")
        validate_simulation_parameters(dict(defaults, **kw))
    full = [dict(defaults, **kw, return_result=True) for kw in runs]  # a batch returns its results
    if not all(engine_supports(kw) for kw in full):
        return [doParticleShearSimulation(**kw, return_result=True) for kw in runs]
    results = measure_batch(full)
    doParticleShearSimulation.last_result = results[-1]
    return results


def engine_supports(kw):
    """Whether the engine measures this run (``kw``: every keyword of doParticleShearSimulation).

    It does when nothing is drawn, plotted or saved, the integrator is "euler", the force laws
    are the built-in ones and N ≤ :data:`ENGINE_MAX_N` (console messages and progress callbacks
    work as in the documented classes).
    """
    from ..base.laws import elastic_force_law, elastic_force_law_tensile
    from ..base.points import CircleBasicElasticity
    from ..linkable.spheres import SphereLinkable
    return (not kw["doDrawing"] and not kw["plotStress"] and not kw["saveData"] and not kw["saveOutputImages"]
            and kw["integrator"] == "euler"
            and int(kw["N"]) <= ENGINE_MAX_N
            and CircleBasicElasticity.call_back_elastic_force_law is elastic_force_law
            and SphereLinkable.call_back_elastic_force_law_tensile is elastic_force_law_tensile)


def measure_batch(runs):
    """Constitute every replica with the documented builder, then measure all of them in one engine.

    ``runs``: complete, validated keyword dicts sharing one schedule.  Returns the
    :class:`~particleShear.run.api.SimulationResult` of each run, in order.
    """
    from ..engine.state import BatchState
    from ..engine.step import BatchEngine, pre_equilibrate, protocol
    from ..simulation.evaluation import demodulation
    from ..simulation.provenance import run_identity
    from .api import SimulationResult, _build_simulation, _seed_sequence

    sims, seeds, constitution = [], [], []
    for kw in runs:
        if not kw["periods"] > 0:
            raise ValueError(f"periods={kw['periods']!r} is out of range: allowed > 0")
        if not 0 < kw["cool_factor"] <= 1:
            raise ValueError(f"cool_factor={kw['cool_factor']!r} is out of range: allowed 0 < value <= 1")
    sched = []
    for kw in runs:
        ss, rng = _seed_sequence(kw["seed"])
        params = {k: kw[k] for k in _REFERENCE_ARGUMENTS}
        t0 = time.perf_counter()
        sim = _build_simulation(params, rng, verbose=kw["verbose"], progress=kw["progress"],
                                correct_drift_sign=kw["correct_drift_sign"], reference_header=kw["reference_header"],
                                renderer="none", time_step_factor=kw["time_step_factor"], integrator="euler",
                                stability_guard=kw["stability_guard"])
        if sim.progress is not None:
            sim.progress("constitution", 0, 0, 0.0)
        sim.initEnsemble()
        constitution.append(time.perf_counter() - t0)
        if sim.progress is not None:
            sim.progress("constitution", 1, 1, constitution[-1])
        sims.append(sim)
        seeds.append((ss, params))
        # the schedule of the replica (with the console messages of the reference's set-up, in its order)
        e = sim.theEnsemble
        factor = float(kw["time_step_factor"])
        model = sim.model or getattr(e, "model", False)
        dt = e.dt * factor
        f = sim.relative_frequency / model.time_constant
        if sim.verbose:
            _log.info("Setting relative frequency: " + str(sim.relative_frequency) + " f= " + str(f) + "Hz")
            _log.info("Creating oscillatory shear experiment, dt = " + str(dt) + " max dt = " + str(e.dt_max * factor))
            _log.info("OscillatoryShearExperiment: Plot stress graph: " + str(kw["plotStress"]))
        N_pre = 25 * int(sim.adjustment_factor_for_bounded_preequilibration_steps())
        cool = kw["cool_factor"] ** (1 / (1 / f / dt))
        if sim.verbose:
            _log.info("cool factor per dt= " + str(cool))
        sched.append(((dt, f, cool, kw["pre_periods"], kw["periods"], kw["post_periods"]), (e.dt_max * factor, N_pre)))
    # replicas sharing the protocol schedule are measured in one engine, after pre-equilibrating
    # (in one engine per pre-equilibration schedule)
    rec = [None] * len(runs)
    protocol_time = {}
    pre_time = {}
    for proto in dict.fromkeys(p for p, _ in sched):
        members = [b for b, (p, _) in enumerate(sched) if p == proto]
        dt, f, cool, pre_p, periods, post = proto
        states = []
        order = []
        for pre in dict.fromkeys(sched[b][1] for b in members):
            group = [b for b in members if sched[b][1] == pre]
            t0 = time.perf_counter()
            st = BatchState.from_ensembles([sims[b].theEnsemble for b in group])
            guard = [bool(runs[b]["stability_guard"]) for b in group]
            say, report = _console(sims, group, "pre-equilibration")
            _guarded(pre_equilibrate, BatchEngine(st, guard=guard), pre[1], dt, pre[0], cool, say, report, dt=dt)
            for b in group:
                pre_time[b] = (time.perf_counter() - t0) / len(group)
            states.append(st)
            order += group
        t0 = time.perf_counter()
        engine = BatchEngine(BatchState.concat(states), guard=[bool(runs[b]["stability_guard"]) for b in order])
        say, report = _console(sims, order, "protocol")
        out = _guarded(protocol, engine, dt, f, [runs[b]["theAmplitude"] for b in order], cool, pre_p, periods, post,
                       False, say, report, dt=dt)
        for col, b in enumerate(order):
            rec[b] = {key: (np.ascontiguousarray(v[col]) if key.endswith("_tensors") else
                            np.ascontiguousarray(v[:, col])) for key, v in out.items()}
            protocol_time[b] = (time.perf_counter() - t0) / len(order)
    results = []
    for b, (kw, sim, (ss, params)) in enumerate(zip(runs, sims, seeds)):
        t0 = time.perf_counter()
        dt, f, cool, pre, periods, post = sched[b][0]
        series = {key: rec[b][key] for key in ("t", "strain", "strain_rate", "stress_surface", "stress_internal")}
        A = kw["theAmplitude"]
        G_int = demodulation(series["t"], series["stress_internal"], f, A, pre, periods, post,
                             correct_drift_sign=kw["correct_drift_sign"])
        G_surf = demodulation(series["t"], series["stress_surface"], f, A, pre, periods, post,
                              correct_drift_sign=kw["correct_drift_sign"])
        t_demod = time.perf_counter() - t0
        if sim.verbose:
            if "last_tensors" in rec[b]:
                _log.info("Overall stress tensor, last step: %s", rec[b]["last_tensors"][-1].tolist())
                _log.info("Overall stress tensor, first step: %s", rec[b]["first_tensors"][-1].tolist())
            for label, v in (("G'", G_int[2]), ("G''", G_int[3]), ("G'(by surface force)", G_surf[2]),
                             ("G''(by surface force)", G_surf[3])):
                _log.info("%s", label)
                _log.info("%s", v)
                _log.info("Pa")
        tim = {"constitution": constitution[b], "pre_equilibration": pre_time[b], "protocol": protocol_time[b],
               "demodulation": t_demod, "output": 0.0}
        tim["total"] = sum(tim.values())
        results.append(SimulationResult(
            G_surface=(G_surf[2], G_surf[3]), G_internal=(G_int[2], G_int[3]),
            stress_surface=(G_surf[0], G_surf[1]), stress_internal=(G_int[0], G_int[1]), parameters=params,
            seed=None if ss is None else ss.entropy, spawn_key=() if ss is None else tuple(ss.spawn_key),
            timings=tim, output_path=None, image_folder=None, n_images=0, dt=dt, f=f,
            N_steps=len(series["t"]), damping_factor=cool,
            removed_fraction=getattr(sim.theEnsemble, "removed_fraction", 0.0), series=series,
            run_id=run_identity(kw, None if ss is None else ss.entropy, () if ss is None else tuple(ss.spawn_key))))
        results[-1].parameters = dict(kw)  # every input, as doParticleShearSimulation records it
    return results


def _console(sims, members, phase):
    """``say`` and ``report`` callbacks of a batch phase: the reference's messages when any member is
    verbose, each member's progress callback at most ~10 times per second (and at the end)."""
    verbose = any(sims[b].verbose for b in members)
    callbacks = [sims[b].progress for b in members if sims[b].progress is not None]
    say = (lambda *a: _log.info(" ".join(str(x) for x in a))) if verbose else (lambda *a: None)
    if not callbacks:
        return say, lambda step, total: None
    t0 = time.perf_counter()
    last = [0.0]

    def report(step, total):
        now = time.perf_counter()
        if step == total or now - last[0] >= 0.1:
            last[0] = now
            for cb in callbacks:
                cb(phase, step, total, now - t0)
    return say, report


def _guarded(phase, engine, *args, dt):
    """Run an engine phase; a diverging replica raises SimulationInstabilityError (step, phase, suggested dt)."""
    from ..base.stability import SimulationInstabilityError
    from ..engine.step import EngineInstability
    try:
        return phase(engine, *args)
    except EngineInstability as e:
        raise SimulationInstabilityError(
            f"{e} (time step {dt:.3g} s, try dt <= {dt / 2:.3g} s)", step=e.step, phase=e.phase,
            pair=(e.replica,), suggested_dt=dt / 2, reason=str(e)) from e


#: the arguments a SimulationResult lists in ``parameters`` (the reference's, in its order)
_REFERENCE_ARGUMENTS = (
    "root_folder", "theAmplitude", "theMu", "do_permanent_links", "cut_lines", "Young_modulus_spheres", "N",
    "packing_fraction", "density", "bimodal_factor", "relative_viscosity", "relative_transversal_link_strength",
    "relative_frequency", "avoid_horizontal_angle_degree", "interface_reenforcement_central",
    "interface_reenforcement_tangential", "keep_viscosity_coefficients_constant", "avoid_height_spanning_particles",
    "cut_top_bottom", "saveOutputImages", "imageFileType", "remove_link_fraction", "edge_fuzziness",
    "central_repulsion_coefficient", "doCutByTriangulation", "doDrawing", "saveData", "saveStressTensorData",
    "plotStress", "relative_y_scale_force", "pre_periods", "periods", "post_periods", "cool_factor", "seed")
