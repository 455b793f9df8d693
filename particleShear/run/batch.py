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

A replica's result does not depend on the other replicas of its batch: its trajectory, tensors
and G′/G″ are bit-identical to its single run (tested).  In this version the replicas of a batch
are advanced one after the other, each through the same code path as a single run; see
``docs/design.md`` (section "Batches of replicas") for what a vectorised replica axis will change.
"""
from ..linkable.builders import time_steps_from_model

__all__ = ["run_batch", "batches", "schedule_key", "PER_REPLICA_PARAMETERS", "BACKENDS"]

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
    branches of the time-step rule (``time_steps_from_model`` with τ = 1, docs/parameters.md),
    which also depend on the replica's μ, amplitude and link strength: two runs with equal keys
    have the same ``dt``, ``dt_max``, damping factor and number of steps in every phase.
    """
    full = dict(_signature_defaults(), **kwargs)
    shared = tuple((name, repr(full[name])) for name in SCHEDULE_PARAMETERS)
    steps = time_steps_from_model(1.0, full["bimodal_factor"], full["theMu"],
                                  full["relative_transversal_link_strength"], full["theAmplitude"],
                                  full["relative_viscosity"])
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
    return [doParticleShearSimulation(**kw, return_result=True) for kw in runs]
