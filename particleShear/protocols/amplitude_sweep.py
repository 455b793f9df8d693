"""Amplitude sweep: on one packing, the oscillatory protocol at each amplitude of ``sweep_amplitudes`` in turn.

The constitution and the first step are those of the independent oscillatory run with the first
amplitude (``theAmplitude`` is set to it); one G′/G″ (with standard errors and LAOS measures) per
step (docs/protocols.md).
"""
__docformat__ = "numpy"

from ..parameter_entry import Parameter
from . import MIN_STEPS_PER_PERIOD, monotonic_values, register_protocol
from ._oscillations import check_resolution, room as _room, shorten as _shorten, sweep_steps

__all__ = ["PROTOCOL", "PARAMETERS"]

POSITION = 4
SIGNATURE = True
PARAMETERS = (
    Parameter('sweep_amplitudes', None, 'float_list', unit='1', role='protocol:amplitude_sweep', keyword_only=True, nullable=True, doc='``protocol="amplitude_sweep"`` (required there): the strain amplitudes, in the order run, strictly increasing or strictly decreasing, each 0 < A <= 100; ``theAmplitude`` is set to the first'),
)
_SW = "; empty unless protocol is 'amplitude_sweep' or 'frequency_sweep'"
#: the columns of a sweep's step (shared with frequency_sweep)
COLUMNS = {
    "sweep_position": ("int", "", "position of the step in its one-packing sweep (0, 1, ...; one row per step)" + _SW),
    "sweep_amplitude": ("float", "1", "strain amplitude of the step" + _SW),
    "sweep_relative_frequency": ("float", "1", "relative frequency f·τ of the step" + _SW),
}


def normalize(q):
    """``sweep_amplitudes`` as floats (checked), ``theAmplitude`` its first.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    """
    q["sweep_amplitudes"] = monotonic_values("sweep_amplitudes", q.get("sweep_amplitudes"), 0, 100)
    q["theAmplitude"] = q["sweep_amplitudes"][0]


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
    amps = q["sweep_amplitudes"]
    return sweep_steps(q, dt_over_tau, amps, [q["relative_frequency"]] * len(amps))


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
    factor = float(q["time_step_factor"])

    def allowed(j, fr, spp, flag):
        rf_max = min(1.0 / (MIN_STEPS_PER_PERIOD * d / factor) for d in steps["dts"])
        return f"relative_frequency <= {rf_max:.4g} for every amplitude of this sweep (flag --relative-frequency)"
    check_resolution(q, steps, [float(q["relative_frequency"])] * len(steps["dts"]),
                     lambda j: (f"sweep_amplitudes[{j}]", q["sweep_amplitudes"][j], "--sweep-amplitudes"), allowed)


def segments(kws, steps, tau, f):
    """``(f, amplitudes of the replicas, dt)`` of each step: the run's frequency, the step's amplitude.

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
    return [(f, [k["sweep_amplitudes"][j] for k in kws], dtr * tau) for j, dtr in enumerate(steps[0]["dts"])]


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
    return _room(q, steps, steps_ok, "sweep_amplitudes")


def label(step):
    """``A = …`` of a step.

    Parameters
    ----------
    step : dict
        One step of a sweep (``SimulationResult.steps``).

    Returns
    -------
    str
    """
    return f"A = {step.get('amplitude', float('nan')):.4g}"


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
    return _shorten(q, n, steps_of, "sweep_amplitudes")


def n_rows(q):
    """One row per value of ``sweep_amplitudes``.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).

    Returns
    -------
    int
    """
    return len(q["sweep_amplitudes"])


PROTOCOL = register_protocol("amplitude_sweep", parameters=PARAMETERS,
                             shorten=shorten, n_rows=n_rows, step_value=("theAmplitude", "sweep_amplitude"),
                             header=("sweep_amplitudes", "relative_frequency", "pre_periods", "periods", "post_periods"),
                             required=("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal", "sweep_position"), normalize=normalize, steps=steps,
                             check_steps=check_steps, segments=segments, columns=COLUMNS,
                             checks=("steady_state", "linear_response", "estimators_agree", "moduli_positive",
                                     "excitation_resolved"), room=room, record_bytes=200, label=label,
                             doc="the oscillation at each of sweep_amplitudes in turn on one packing")
