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
(:mod:`particleShear.simulation.observers`).  See ``docs/engine.md`` (sections "Runs" and
"Observers").

The contact law (``contact_law``) must agree within a batch (:func:`batches` groups runs by it, as
it groups them by schedule): the engine evaluates one law function on all candidates of a step.
Its parameters (``plateau_begin``, ``plateau_end``, ``plateau_slope``) may differ per replica.
"""
__docformat__ = "numpy"
from ..linkable.builders import time_steps_from_model
from ..parameters import names as _names
from ..simulation.driver import ENGINE_SKIN_FACTOR, _guarded, measure_sessions, pre_equilibrated, replica_record
from .guard import PARAMETER_ALIASES, checked_keywords, resolve_names
from .sessions import (BACKENDS, _REFERENCE_ARGUMENTS, _signature_defaults, build_sessions,  # noqa: F401 - re-exported
                       check_backend, check_batch_size, check_run_backend)
from .api import doParticleShearSimulation
from .measurement import measure, measure_batch  # noqa: F401 - measure_batch re-exported (deprecated)
from .rheometer import normalize_protocol, protocol_steps
from .validation import validated_run

__all__ = ["run_batch", "batches", "schedule_key", "measure_sessions", "PER_REPLICA_PARAMETERS", "BACKENDS",
           "check_backend", "check_run_backend"]

#: moved to the simulation layer (particleShear.simulation.driver), importable here as before
_DRIVER = (ENGINE_SKIN_FACTOR, _guarded, pre_equilibrated, replica_record)


#: parameters a replica may choose on its own (everything else must agree within a batch)
PER_REPLICA_PARAMETERS = frozenset(_names(batch="replica"))

#: parameters that fix the step schedule: N, the model constants behind τ, the protocol's periods and
#: the integrator (batch class "schedule" of :mod:`particleShear.parameters`)
SCHEDULE_PARAMETERS = _names(batch="schedule")


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
    backend : {None, "auto", "numpy", "numba", "cupy"}, default None
        Array backend of the batch; None: the runs' own ``backend`` keyword (default "auto":
        :func:`particleShear.engine.xp.resolve_backend`).  Every result records the backend used.

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

    names = list(_signature_defaults())
    runs = [resolve_names(kw, names, f"run_batch list_of_kwargs[{n}]", aliases=PARAMETER_ALIASES)
            for n, kw in enumerate(list_of_kwargs)]
    runs = [kw if backend is None else dict(kw, backend=backend) for kw in runs]
    if not runs:
        raise ValueError("list_of_kwargs=[] is invalid: a batch needs at least one run")
    for kw in runs:
        kw.pop("return_result", None)
    # every replica checked, completed and identified once, before any work (and before its schedule
    # is computed); a batch returns its results
    runs = [validated_run(dict(kw, return_result=True)) for kw in runs]
    keys = [schedule_key(kw) for kw in runs]
    for n, key in enumerate(keys):
        if key != keys[0]:
            diff = sorted(name for (name, v), (_, w) in zip(key, keys[0]) if v != w)
            raise ValueError(f"list_of_kwargs[{n}] does not share the step schedule of list_of_kwargs[0] "
                             f"(differs in {', '.join(diff) or 'its parameters'}); a batch needs equal N, "
                             "time-step rule and protocol")
    return measure_replicas(runs)       # the protocol is part of the schedule key


def measure_replicas(runs):
    """Measure checked runs of one step schedule as one batch, as :func:`run_batch` does after its checks.

    The schedule is not checked here: the runs are a batch of :func:`batches` (a sweep's worker
    measures the batches its driving process grouped), or :func:`run_batch` has compared their
    :func:`schedule_key`.  The last result becomes ``doParticleShearSimulation.last_result``.

    Parameters
    ----------
    runs : list of RunParameters
        The checked arguments of the replicas (:func:`~particleShear.run.validation.validated_run`),
        all of one :func:`schedule_key`.

    Returns
    -------
    list of SimulationResult
        One per replica, in order.
    """
    results = measure(runs)
    doParticleShearSimulation.last_result = results[-1]
    return results
