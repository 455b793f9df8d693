"""The rheometer's protocols of a run: ``protocol=`` of :func:`~particleShear.run.api.doParticleShearSimulation`.

``"oscillatory"`` (the default) is the reference's experiment.  Every protocol is measured by the
one driver (:func:`particleShear.simulation.driver.measure_sessions`, through
:func:`particleShear.run.measurement.measure`): the others constitute and pre-equilibrate exactly
as it does (the same functions, so one seed gives the same packing), then drive the engine with
another rate schedule (:mod:`particleShear.engine.rheometer`, docs/protocols.md).  This module
checks and normalizes their parameters and counts their steps (:func:`protocol_steps`, the
driver's):

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

from ..checks import show_value
from ..parameters import PARAMETERS
from ..protocols import MAX_STRAIN_PER_STEP, PROTOCOLS as REGISTRY
from ..protocols.creep import CREEP_MODULUS_FRACTION  # noqa: F401 - re-exported
from ..protocols.steady import N1_EVERY  # noqa: F401 - re-exported
from ..simulation.driver import protocol_steps
from .protocol_summary import PROTOCOL_COLUMNS, STEP_COLUMNS  # noqa: F401 - PROTOCOL_COLUMNS, STEP_COLUMNS re-exported
from .result import SimulationResult
from .measurement import measure_rheometer  # noqa: F401 - re-exported (deprecated)
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
