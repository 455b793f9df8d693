"""Frequency sweep: on one packing, the oscillatory protocol at each relative frequency of ``sweep_frequencies`` in turn.

The constitution and the first step are those of the independent oscillatory run with the first
frequency (``relative_frequency`` is set to it); one G′/G″ (with standard errors and LAOS
measures) per step (docs/protocols.md).
"""
__docformat__ = "numpy"

from ..parameter_entry import Parameter
from . import MIN_STEPS_PER_PERIOD, monotonic_values, register_protocol
from ._oscillations import check_resolution, room as _room, shorten as _shorten, sweep_steps
from .amplitude_sweep import COLUMNS

__all__ = ["PROTOCOL", "PARAMETERS"]

POSITION = 5
SIGNATURE = True
PARAMETERS = (
    Parameter('sweep_frequencies', None, 'float_list', unit='1', role='protocol:frequency_sweep', batch='shared', keyword_only=True, nullable=True, doc='``protocol="frequency_sweep"`` (required there): the relative frequencies f·τ, in the order run, strictly monotonic; ``relative_frequency`` is set to the first'),
)


def normalize(q):
    """``sweep_frequencies`` as floats (checked), ``relative_frequency`` its first.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    """
    q["sweep_frequencies"] = monotonic_values("sweep_frequencies", q.get("sweep_frequencies"), 0, 1e6)
    q["relative_frequency"] = q["sweep_frequencies"][0]


def steps(q, dt_over_tau):
    """Each step's dt/τ (``dts``) and oscillatory steps (``segments``).

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    dt_over_tau : callable
        ``dt_over_tau(amplitude=None)``: the protocol time step in units of τ (at ``theAmplitude`` or the amplitude given).

    Returns
    -------
    dict
        ``dt_over_tau`` and the protocol's counts (module docstring of :mod:`particleShear.protocols`).
    """
    freqs = q["sweep_frequencies"]
    return sweep_steps(q, dt_over_tau, [q["theAmplitude"]] * len(freqs), freqs)


def check_steps(q, steps):
    """Every step resolves its period (:func:`~particleShear.protocols._oscillations.check_resolution`).

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range.
    """
    def allowed(j, fr, spp, flag):
        return f"every value of sweep_frequencies <= {fr * spp / MIN_STEPS_PER_PERIOD:.4g} (flag {flag})"
    freqs = q["sweep_frequencies"]
    check_resolution(q, steps, freqs, lambda j: (f"sweep_frequencies[{j}]", freqs[j], "--sweep-frequencies"), allowed)


def segments(kws, steps, tau, f):
    """``(f, amplitudes of the replicas, dt)`` of each step: the step's frequency, the run's amplitude.

    Parameters
    ----------
    kws : list of dict
        The arguments of the batch's replicas, in batch order.
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    tau : float
        Model time constant τ (s).
    f : float
        The run's excitation frequency (Hz).

    Returns
    -------
    list of tuple
        ``(f (Hz), amplitude of each replica, dt (s))`` of each step.
    """
    return [(kws[0]["sweep_frequencies"][j] / tau, [k["theAmplitude"] for k in kws], dtr * tau)
            for j, dtr in enumerate(steps[0]["dts"])]


def room(q, steps, steps_ok):
    """The longest of the periods, else fewer or shorter steps.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    steps_ok : float
        The most steps the run may take.

    Returns
    -------
    tuple of str
        ``(parameter, allowed text)``.
    """
    return _room(q, steps, steps_ok, "sweep_frequencies")


def label(step):
    """``f·τ = …`` of a step.

    Parameters
    ----------
    step : dict
        One step of a sweep (``SimulationResult.steps``).

    Returns
    -------
    str
    """
    return f"f·τ = {step.get('relative_frequency', float('nan')):.4g}"


def shorten(q, steps, n, steps_of):
    """The first two values of the list, no baseline periods, the excitation periods cut so that both
    steps together take about ``n`` steps.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    n : int
        About how many steps the cut protocol takes.
    steps_of : callable
        ``steps_of(q)``: the step counts of other arguments.

    Returns
    -------
    dict
        The parameters to change.
    """
    return _shorten(q, n, steps_of, "sweep_frequencies")


def n_rows(q):
    """One row per value of ``sweep_frequencies``.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).

    Returns
    -------
    int
    """
    return len(q["sweep_frequencies"])


PROTOCOL = register_protocol("frequency_sweep", parameters=PARAMETERS,
                             shorten=shorten, n_rows=n_rows, step_value=("relative_frequency", "sweep_relative_frequency"),
                             header=("sweep_frequencies", "theAmplitude", "pre_periods", "periods", "post_periods"),
                             required=("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal", "sweep_position"), normalize=normalize, steps=steps,
                             check_steps=check_steps, segments=segments, columns=COLUMNS,
                             checks=("steady_state", "linear_response", "estimators_agree", "moduli_positive",
                                     "excitation_resolved"), room=room, record_bytes=200, label=label,
                             doc="the oscillation at each of sweep_frequencies in turn on one packing")
