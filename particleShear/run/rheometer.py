"""The rheometer's protocols of a run: ``protocol=`` of :func:`~particleShear.run.api.doParticleShearSimulation`.

``"oscillatory"`` (the default) is the reference's experiment (:mod:`particleShear.run.batch`).
The others constitute and pre-equilibrate exactly as it does (the same functions, so one seed
gives the same packing), then drive the engine with another rate schedule
(:mod:`particleShear.engine.rheometer`, docs/protocols.md):

``"steady"``
    γ̇ = ``relative_rate``/τ until the strain ``total_strain``; the steady shear stress (mean and
    standard error by blocking after the detected transient), the viscosity σ/γ̇ and the first
    normal-stress difference N1 of the overall tensor.
``"relaxation"``
    One step at rest (the residual stress σ_res), a ramp to γ₀ = ``theAmplitude`` over
    ``ramp_time``·τ, then ``hold_time``·τ at constant strain; G(t) = (σ(t) − σ_res)/γ₀ (t from
    the end of the ramp) on a log-spaced grid and its plateau.
``"creep"``
    One step at rest (the residual stress σ_res), then the plate stress held at
    ``creep_stress`` (Pa) for ``hold_time``·τ by a PI controller on the strain rate; J(t) = γ(t)/σ₀ on a log grid, the final creep rate, σ₀/γ̇ and the strain plateau.
``"amplitude_sweep"`` / ``"frequency_sweep"``
    One packing, then the oscillatory protocol (``pre_periods``, ``periods``, ``post_periods``)
    for each amplitude of ``sweep_amplitudes`` (or relative frequency of ``sweep_frequencies``)
    in the given order, each after the previous one; one G′/G″ (with standard errors and LAOS
    measures) per step.  The constitution and the first step are those of the independent run
    with the first amplitude (frequency): ``theAmplitude`` (``relative_frequency``) is set to it.

τ is the model time constant (docs/parameters.md): γ̇ in 1/s is ``relative_rate / τ``.
"""
__docformat__ = "numpy"
import difflib
import time

import numpy as np

from ..checks import show_value
from ..engine.rheometer import shear_record
from ..engine.step import protocol as oscillation
from ..parameters import PARAMETERS
from ..protocols import MAX_STRAIN_PER_STEP, PROTOCOLS as REGISTRY
from ..protocols.creep import CREEP_MODULUS_FRACTION
from ..protocols.steady import N1_EVERY
from ..simulation.driver import _console, _constitute, _guarded, pre_equilibrated
from .protocol_summary import PROTOCOL_COLUMNS, STEP_COLUMNS, dt_over_tau  # noqa: F401 - PROTOCOL_COLUMNS, STEP_COLUMNS re-exported
from .result import SimulationResult
from .sessions import build_sessions
from .rheometer_analysis import analyse_record, analyse_sweep
from .rheometer_files import write_protocol_file
from .limits import MAX_TOTAL_STEPS, _protocol_room

__all__ = ["PROTOCOLS", "PROTOCOL_DEFAULTS", "PROTOCOL_COLUMNS", "LIST_PARAMETERS", "STEP_COLUMNS", "MAX_STRAIN_PER_STEP", "RheometerResult", "check_protocol",
           "check_sweep_resolution", "normalize_protocol", "protocol_steps", "measure_rheometer"]

#: the protocols' names, in the order of ``protocol``'s choices (:mod:`particleShear.protocols`)
PROTOCOLS = tuple(REGISTRY)

#: the protocol's selector and the protocols' own parameters with their defaults (roles "protocol" of
#: :mod:`particleShear.parameters`)
PROTOCOL_DEFAULTS = {p.name: p.default for p in PARAMETERS if p.base_role == "protocol"}

#: the protocol parameters whose value is a list (one value of a sweep is a whole list)
LIST_PARAMETERS = tuple(p.name for p in PARAMETERS if p.kind == "float_list")


def check_protocol(p):
    """Check the protocol parameters of one run (``p``: every argument, defaults filled in).

    Parameters
    ----------
    p : dict
        The arguments of the run.

    Returns
    -------
    dict
        The steps of the protocol (:func:`protocol_steps`).

    Raises
    ------
    ValueError, TypeError
        An unknown protocol (the closest name suggested), a missing or non-positive rate, strain,
        time or stress, a sweep list that is empty or not monotonic, a rate or ramp the time step
        cannot resolve (more than :data:`MAX_STRAIN_PER_STEP` strain per step), a controller
        response time shorter than 10 steps, a step of a sweep that its time step cannot resolve
        (:func:`check_sweep_resolution`), a protocol of more than
        :data:`~particleShear.run.validation.MAX_TOTAL_STEPS` steps (naming the parameter to
        shorten), or options of the drawing with a protocol other than "oscillatory".
    """
    proto = p.get("protocol", "oscillatory")
    if proto not in REGISTRY:
        near = difflib.get_close_matches(str(proto), PROTOCOLS, n=1)
        raise ValueError(f"protocol={proto!r} is invalid: allowed one of {PROTOCOLS}"
                         + (f"; did you mean {near[0]!r}?" if near else "") + " (flag --protocol)")
    if proto == "oscillatory":
        return {}
    if p.get("saveOutputImages") or p.get("saveOutputMovie"):
        raise ValueError(f"saveOutputImages=True is invalid with protocol={proto!r}: snapshots are taken of the "
                         "oscillatory protocol only")
    q = normalize_protocol(p)
    spec = REGISTRY[proto]
    if spec.check is not None:
        spec.check(q)
    steps = protocol_steps(q)
    if spec.check_steps is not None:
        spec.check_steps(q, steps)
    total = sum(steps["segments"]) if spec.segmented else steps["steps"]
    if total > MAX_TOTAL_STEPS:
        name, allowed = _protocol_room(q, steps, MAX_TOTAL_STEPS)
        raise ValueError(f"{name}={_shown(q[name])} is out of range: protocol={proto!r} needs {total:.3g} steps, more "
                         f"than the limit of {MAX_TOTAL_STEPS:.0e}; allowed {allowed} (flag --{name.replace('_', '-')})")
    return steps


def _shown(v):
    """A value for a message: a long list cut to its first and last values."""
    if isinstance(v, (list, tuple)) and len(v) > 6:
        return f"[{', '.join(f'{x:g}' for x in v[:3])}, ..., {v[-1]:g}] ({len(v)} values)"
    return show_value(v)


def check_sweep_resolution(q, steps=None):
    """Check every step of a one-packing sweep as the single oscillatory run is checked.

    Each step ``j`` (amplitude ``A_j``, relative frequency ``f_j``) has its own time step (the
    time-step rule depends on the amplitude) and must resolve its excitation period with at
    least :data:`~particleShear.run.validation.MIN_STEPS_PER_PERIOD` steps at the reference time
    step, and with at least
    :data:`~particleShear.run.validation.MIN_STEPS_PER_PERIOD_COARSENED` at the coarsened one
    (``time_step_factor``), the two rules of the oscillatory run's first step.

    Parameters
    ----------
    q : dict
        The arguments of the run (:func:`normalize_protocol`: a sweep's list as floats).
    steps : dict, optional
        :func:`protocol_steps` of ``q`` (computed when None).

    Raises
    ------
    ValueError
        Naming the step's value (``sweep_frequencies[j]`` or ``sweep_amplitudes[j]``), its steps
        per period, the limit, the allowed range and the CLI flag.
    """
    steps = protocol_steps(q) if steps is None else steps
    REGISTRY[q["protocol"]].check_steps(q, steps)


def normalize_protocol(p):
    """The arguments of a run as its protocol measures them: a sweep's first value becomes
    ``theAmplitude`` (amplitude sweep) or ``relative_frequency`` (frequency sweep).

    Parameters
    ----------
    p : dict
        The arguments of the run (defaults filled in); not modified.

    Returns
    -------
    dict
        A copy with the sweep's first value put in (lists as lists of float).

    Raises
    ------
    ValueError
        For a sweep without its list, or a list that is empty or not monotonic.
    """
    q = dict(p)
    spec = REGISTRY.get(q.get("protocol", "oscillatory"))
    if spec is not None and spec.normalize is not None:
        spec.normalize(q)
    return q


def protocol_steps(q):
    """Step counts of a (normalized, checked) protocol.

    Parameters
    ----------
    q : dict
        The arguments of the run (:func:`normalize_protocol`).

    Returns
    -------
    dict
        ``dt_over_tau``; ``steps`` (steady, relaxation, creep: all steps), ``ramp`` (relaxation);
        ``segments`` (sweeps: the oscillatory steps of each step of the sweep) and ``dts`` (sweeps:
        each step's dt/τ).
    """
    return REGISTRY[q.get("protocol", "oscillatory")].steps(q, lambda amplitude=None: dt_over_tau(q, amplitude))


class RheometerResult(SimulationResult):
    """Deprecated: every protocol's run returns a :class:`~particleShear.run.result.SimulationResult`.

    ``RheometerResult(protocol, parameters, seed, spawn_key, run_id, tau, dt, series, summary, curves,
    steps, timings)`` (2.x) makes that result (:meth:`SimulationResult.of_protocol
    <particleShear.run.result.SimulationResult.of_protocol>`) with a ``DeprecationWarning``; the
    name stays so that scripts and pickles of 2.x keep working.
    """

    def __new__(cls, *args, **kwargs):
        if not args and not kwargs:      # unpickling a 2.x RheometerResult: its fields come with its state
            return super().__new__(cls)
        import warnings
        warnings.warn("RheometerResult is deprecated: every protocol's run returns a SimulationResult "
                      "(SimulationResult.of_protocol takes these arguments)", DeprecationWarning, stacklevel=2)
        return SimulationResult.of_protocol(*args, **kwargs)


def _concatenated(records):
    """The records of a sweep's steps one after the other, with ``sweep_position`` (each step keeps
    its own clock ``t``)."""
    keys = ("t", "strain", "strain_rate", "stress_surface", "stress_internal")
    out = {key: np.concatenate([rec[key] for rec in records]) for key in keys}
    out["sweep_position"] = np.concatenate([np.full(len(rec["t"]), j, dtype=np.int64) for j, rec in enumerate(records)])
    return out


def measure_rheometer(runs):
    """Constitute, pre-equilibrate and measure runs of one protocol other than "oscillatory".

    The constitution and pre-equilibration are those of the oscillatory runs
    (:func:`~particleShear.run.batch.build_sessions`, ``_constitute``,
    :func:`~particleShear.simulation.driver.pre_equilibrated`); every replica then runs its rate
    schedule in one engine.  Replicas may differ in rate, strain, stress, γ₀ and amplitude list;
    the batch runs the longest and cuts each record at the replica's own length.

    Parameters
    ----------
    runs : list of RunParameters
        The checked arguments of the runs (:func:`~particleShear.run.validation.validated_run`:
        complete, normalized), sharing a protocol and a schedule.

    Returns
    -------
    list of SimulationResult
    """
    proto = runs[0]["protocol"]
    spec = REGISTRY[proto]
    sims, seeds, sessions = build_sessions(runs)
    where = ["constitution", 0, 0]
    _constitute(sessions)
    scheds, steps = [], []
    for run, kw in zip(sessions, runs):
        scheds.append(run.sim.measurement_schedule(kw["cool_factor"]))
        steps.append(protocol_steps(kw))
    sc = scheds[0]
    timings = [dict(constitution=run.sim.timings.get("constitution", 0.0)) for run in sessions]
    members = list(range(len(sessions)))
    engine, order = pre_equilibrated(sessions, members, [(s.dt_max, s.N_pre) for s in scheds], sc.dt, sc.cool,
                                     where, lambda e, m: [], timings)
    kws = [runs[b] for b in order]
    tau = sc.dt / steps[0]["dt_over_tau"]
    say, report = _console(sims, order, "protocol", where)
    t0 = time.perf_counter()
    recs, sweep_recs = None, None
    if spec.recorded:
        # the one recording loop, driven by the protocol's rate schedule or controller
        drive = spec.schedule(kws, [steps[b] for b in order], tau, sc.dt, engine.backend)
        recs = _guarded(lambda e: shear_record(e, sc.dt, sc.cool, drive["n_steps"], drive["rate_of"],
                                               drive.get("tensors_every", 0), say, report,
                                               after_step=drive.get("after_step")), engine, dt=sc.dt)
    else:
        sweep_recs = []
        for f, A, dt in spec.segments(kws, [steps[b] for b in order], tau, sc.f):
            cool = kws[0]["cool_factor"] ** (f * dt)
            out = _guarded(oscillation, engine, dt, f, A, cool, kws[0]["pre_periods"], kws[0]["periods"],
                           kws[0]["post_periods"], False, say, report, (), dt=dt)
            sweep_recs.append((f, A, dt, out))
    t_protocol = (time.perf_counter() - t0) / len(order)
    results = [None] * len(sessions)
    for col, b in enumerate(order):
        kw = runs[b]
        t1 = time.perf_counter()
        if sweep_recs is None:
            n = steps[b]["steps"]
            series = {key: np.ascontiguousarray(v[:n, col]) for key, v in recs.items()}
            summary, curves = analyse_record(proto, kw, series, tau, steps[b])
            sweep = []
        else:
            segments = [(f, A[col], dt, {key: np.ascontiguousarray(v[:, col]) for key, v in out.items()
                                         if not key.endswith("tensors")}) for f, A, dt, out in sweep_recs]
            sweep = analyse_sweep(kw, segments, tau)
            series, curves, summary = _concatenated([rec for *_, rec in segments]), {}, {}
        seed_entropy, spawn_key, _ = seeds[b]
        tm = dict(timings[b], protocol=t_protocol, analysis=time.perf_counter() - t1)
        results[b] = SimulationResult.of_protocol(proto, sessions[b].sim.parameters_record(), seed_entropy,
                                                  spawn_key, kw.run_id, tau, sc.dt, series,
                                                  summary, curves, sweep, tm)
        if kw["saveData"]:
            t2 = time.perf_counter()
            write_protocol_file(sessions[b].sim, results[b])
            tm["output"] = time.perf_counter() - t2
    for run in sessions:
        run.close()
    return results
