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
G′/G″ are bit-identical to its single run (tested).  Every run — single runs included, drawn or
not, any integrator, any contact law, any N, saving data and snapshots or not — measures through :mod:`particleShear.engine`, all replicas of a batch
in one set of arrays, each replica's drawing an observer of its replica
(:mod:`particleShear.simulation.observers`).  See ``docs/design.md`` (sections "Batches of
replicas" and "Observers").

The contact law (``contact_law``) must agree within a batch (:func:`batches` groups runs by it, as
it groups them by schedule): the engine evaluates one law function on all candidates of a step.
Its parameters (``plateau_begin``, ``plateau_end``, ``plateau_slope``) may differ per replica.
"""
__docformat__ = "numpy"
from ..linkable.builders import time_steps_from_model
from ..parameters import PARAMETERS
from ..parameters import defaults as _defaults
from ..parameters import names as _names
from ..simulation.driver import ENGINE_SKIN_FACTOR, _guarded, measure_sessions, pre_equilibrated, replica_record
from .guard import PARAMETER_ALIASES, checked_keywords, resolve_names

__all__ = ["run_batch", "batches", "schedule_key", "measure_sessions", "PER_REPLICA_PARAMETERS", "BACKENDS",
           "check_backend", "check_run_backend"]

#: moved to the simulation layer (particleShear.simulation.driver), importable here as before
_DRIVER = (ENGINE_SKIN_FACTOR, _guarded, pre_equilibrated, replica_record)


#: parameters a replica may choose on its own (everything else must agree within a batch)
PER_REPLICA_PARAMETERS = frozenset(_names(batch="replica"))

#: parameters that fix the step schedule: N, the model constants behind τ, the protocol's periods and
#: the integrator (batch class "schedule" of :mod:`particleShear.parameters`)
SCHEDULE_PARAMETERS = _names(batch="schedule")

#: array backends a batch can run on ("cupy" needs CuPy and a CUDA device; see particleShear.engine.xp)
BACKENDS = ("numpy", "numba", "auto", "cupy")


def _signature_defaults():
    """Defaults of every keyword of ``doParticleShearSimulation`` (the parameter table's)."""
    return _defaults()


def check_backend(backend):
    """Raise ValueError unless ``backend`` names a backend that can run here.

    Parameters
    ----------
    backend : str
        Name of the array library of a measurement: one of :data:`BACKENDS` (or a backend
        registered with :func:`particleShear.engine.xp.register_backend`).

    Raises
    ------
    ValueError
        For an unknown name (naming ``backend``, its value and the allowed values), or for
        ``"cupy"`` without CuPy or without a CUDA device.
    """
    from ..engine.xp import get_backend
    get_backend(backend)


def check_run_backend(kw):
    """Check the backend of one run: usable here (every run is measured by the engine).

    Parameters
    ----------
    kw : dict
        Keyword arguments of :func:`~particleShear.run.api.doParticleShearSimulation` (missing
        ones take their defaults).

    Raises
    ------
    ValueError
        Naming ``backend``, for an unusable backend.
    """
    check_backend(dict(_signature_defaults(), **kw)["backend"])


def check_batch_size(batch_size):
    """Raise ValueError unless ``batch_size`` is None or an integer >= 1.

    Parameters
    ----------
    batch_size : int or None
        Largest number of replicas per batch.
    """
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

    Parameters
    ----------
    kwargs : dict
        Keyword arguments of :func:`~particleShear.run.api.doParticleShearSimulation` (missing
        ones take their defaults).

    Returns
    -------
    tuple
    """
    from .rheometer import normalize_protocol, protocol_steps
    full = normalize_protocol(dict(_signature_defaults(), **kwargs))
    shared = tuple((name, repr(full[name])) for name in SCHEDULE_PARAMETERS)
    steps = time_steps_from_model(1.0, full["bimodal_factor"], full["theMu"],
                                  full["relative_transversal_link_strength"], full["theAmplitude"],
                                  full["relative_viscosity"])[0]
    other = tuple(sorted((k, repr(v)) for k, v in kwargs.items()
                         if k not in PER_REPLICA_PARAMETERS and k not in SCHEDULE_PARAMETERS))
    segments = ()
    if full["protocol"].endswith("sweep"):     # each step of a one-packing sweep has its own dt
        st = protocol_steps(full)
        segments = (("segments", repr((tuple(st["dts"]), tuple(st["segments"])))),)
    return shared + (("steps", steps),) + other + segments


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


@checked_keywords(documented="help(particleShear.run.batch.run_batch)")
def run_batch(list_of_kwargs, backend=None):
    """Run a batch of replicas that share a step schedule; one result per replica, in order.

    Parameters
    ----------
    list_of_kwargs : list of dict
        Keyword arguments of :func:`~particleShear.run.api.doParticleShearSimulation` per replica
        (``return_result`` is implied; the aliases ``amplitude`` and ``mu`` are accepted as there).
        All must have the same :func:`schedule_key`.
    backend : {None, "numpy", "cupy"}, default None
        Array backend of the batch; None: the runs' own ``backend`` keyword (default "numpy").
        A backend other than "numpy" needs runs the engine measures (see :func:`check_run_backend`).

    Returns
    -------
    list of SimulationResult
        Bit-identical to ``[doParticleShearSimulation(**kw, return_result=True) for kw in list_of_kwargs]``.

    Raises
    ------
    ValueError
        For an empty batch, an unknown backend, replicas of different schedules or any invalid
        parameter of any replica, before any simulation work.
    particleShear.run.guard.UnknownParameterError
        For a key of a replica's dict that is not a parameter (naming ``list_of_kwargs[n]`` and
        the closest parameters), or a keyword of this function that is not one of its parameters.
    """
    from .api import doParticleShearSimulation
    from .validation import validate_run

    names = list(_signature_defaults())
    runs = [resolve_names(kw, names, f"run_batch list_of_kwargs[{n}]", aliases=PARAMETER_ALIASES)
            for n, kw in enumerate(list_of_kwargs)]
    runs = [kw if backend is None else dict(kw, backend=backend) for kw in runs]
    if not runs:
        raise ValueError("list_of_kwargs=[] is invalid: a batch needs at least one run")
    for kw in runs:
        kw.pop("return_result", None)
        validate_run(kw)   # every replica, before any work (and before its schedule is computed)
    keys = [schedule_key(kw) for kw in runs]
    for n, key in enumerate(keys):
        if key != keys[0]:
            diff = sorted(name for (name, v), (_, w) in zip(key, keys[0]) if v != w)
            raise ValueError(f"list_of_kwargs[{n}] does not share the step schedule of list_of_kwargs[0] "
                             f"(differs in {', '.join(diff) or 'its parameters'}); a batch needs equal N, "
                             "time-step rule and protocol")
    defaults = _signature_defaults()
    full = [dict(defaults, **kw, return_result=True) for kw in runs]  # a batch returns its results
    if full[0]["protocol"] != "oscillatory":      # the protocol is part of the schedule key
        from .rheometer import measure_rheometer, normalize_protocol
        results = measure_rheometer([normalize_protocol(kw) for kw in full])
        doParticleShearSimulation.last_result = results[-1]
        return results
    results = measure_batch(full)
    doParticleShearSimulation.last_result = results[-1]
    return results


def measure_batch(runs):
    """Constitute every replica with the documented builder, then measure all of them in one engine.

    ``runs``: complete, validated keyword dicts sharing one schedule.  Each replica runs through
    the phases of ``runSimulation`` (:class:`~particleShear.simulation.simulations.RunSession`:
    validation, constitution, reservation of its output file, experiment set-up, schedule) except
    the measurement, which the engine does for all replicas at once; each experiment then adopts
    its replica's record and the session writes the output file as ``runSimulation`` does.
    Returns the :class:`~particleShear.run.api.SimulationResult` of each run, in order.  An
    interrupt (``KeyboardInterrupt``) removes every reservation and is re-raised with
    ``position = (phase, step, total)``.

    Parameters
    ----------
    runs : list of dict
        Complete, validated keyword dicts of the replicas (one schedule).

    Returns
    -------
    list of SimulationResult
    """
    from .api import SimulationResult

    sims, seeds, sessions = build_sessions(runs)
    measure_sessions(sessions)
    results = []
    for kw, sim, run, (seed_entropy, spawn_key, params) in zip(runs, sims, sessions, seeds):
        info = sim.result_info
        # a replica's wall time is its share of the batch: its own phases and its part of the shared ones
        info["timings"]["total"] = sum(info["timings"].get(k, 0.0) for k in
                                       ("constitution", "pre_equilibration", "protocol", "demodulation", "output"))
        results.append(SimulationResult(
            G_surface=info["G_surface"], G_internal=info["G_internal"], stress_surface=info["stress_surface"],
            stress_internal=info["stress_internal"], parameters=params, seed=seed_entropy,
            spawn_key=spawn_key, timings=info["timings"], output_path=info["output_path"],
            image_folder=info["image_folder"], n_images=info["n_images"], dt=info["dt"], f=info["f"],
            N_steps=info["N_steps"], damping_factor=info["damping_factor"],
            removed_fraction=getattr(sim.theEnsemble, "removed_fraction", 0.0),
            series=run.exp.plotter.arrays(), run_id=sim.run_id, write_error=info.get("write_error"),
            microstructure=getattr(run, "microstructure", None)))
        results[-1].parameters = dict(kw)  # every input, as doParticleShearSimulation records it
    return results


def build_sessions(runs):
    """The simulation object and :class:`~particleShear.simulation.simulations.RunSession` of every run.

    Parameters
    ----------
    runs : list of dict
        Complete, validated keyword dicts of the replicas.

    Returns
    -------
    sims : list
        The documented simulation of each run (not constituted).
    seeds : list of tuple
        ``(seed entropy, spawn key, reference parameters)`` of each run.
    sessions : list of RunSession
        One session per run, in order.
    """
    from ..simulation.provenance import run_identity
    from ..simulation.simulations import RunSession
    from .api import _build_simulation, _seed_sequence
    from .validation import contact_law_spec

    sims, seeds, sessions = [], [], []
    for kw in runs:  # every replica's settings are checked before any work
        ss, rng = _seed_sequence(kw["seed"])
        seed_entropy, spawn_key = (None, ()) if ss is None else (ss.entropy, tuple(ss.spawn_key))
        params = {k: kw[k] for k in _REFERENCE_ARGUMENTS}
        sim = _build_simulation(params, rng, verbose=kw["verbose"], progress=kw["progress"],
                                correct_drift_sign=kw["correct_drift_sign"], reference_header=kw["reference_header"],
                                renderer=kw.get("renderer", "auto"), time_step_factor=kw["time_step_factor"],
                                integrator=kw["integrator"], stability_guard=kw["stability_guard"])
        sim.output_format = kw.get("output_format", "text")
        sim.saveOutputMovie = bool(kw.get("saveOutputMovie", False))
        sim.run_id, sim.seed_entropy, sim.spawn_key = run_identity(kw, seed_entropy, spawn_key), seed_entropy, spawn_key
        sim.parameters = kw
        sim.contact_law = contact_law_spec(kw)
        sessions.append(RunSession(sim, kw["cool_factor"], kw["periods"], kw["plotStress"]))
        sims.append(sim)
        seeds.append((seed_entropy, spawn_key, params))
    return sims, seeds, sessions


#: the arguments a SimulationResult lists in ``parameters`` (the reference's, in its order)
_REFERENCE_ARGUMENTS = tuple(p.name for p in PARAMETERS if not p.keyword_only)
