"""What the two one-packing sweeps share (a helper of the protocols folder, not a protocol).

A sweep runs the oscillatory protocol (``pre_periods``, ``periods``, ``post_periods``) at each
amplitude (``amplitudes(q)``) and relative frequency (``frequencies(q)``) of its steps in turn, on
one packing, each after the previous one; each step has its own time step (the time-step rule
depends on the amplitude).
"""
__docformat__ = "numpy"

from . import MIN_STEPS_PER_PERIOD, MIN_STEPS_PER_PERIOD_COARSENED

__all__ = ["sweep_steps", "check_resolution", "room", "shorten"]


def sweep_steps(q, dt_over_tau, amps, freqs):
    """``dts`` (each step's dt/τ) and ``segments`` (each step's oscillatory steps).

    Parameters
    ----------
    q : dict
        The run's arguments (normalized).
    dt_over_tau : callable
        ``dt_over_tau(amplitude=None)``: the protocol time step in units of τ.
    amps, freqs : list of float
        Each step's amplitude and relative frequency f·τ.

    Returns
    -------
    dict
        ``dt_over_tau``, ``dts``, ``segments``.
    """
    out = {"dt_over_tau": dt_over_tau()}
    out["dts"] = [dt_over_tau(A) for A in amps]
    n_per = float(q["pre_periods"]) + float(q["periods"]) + float(q["post_periods"])
    out["segments"] = [int(n_per / fr / d) for fr, d in zip(freqs, out["dts"])]
    return out


def check_resolution(q, steps, freqs, name_of, allowed_of):
    """Check every step of a sweep as the single oscillatory run is checked.

    Each step ``j`` must resolve its excitation period with at least :data:`MIN_STEPS_PER_PERIOD`
    steps at the reference time step, and with at least :data:`MIN_STEPS_PER_PERIOD_COARSENED` at
    the coarsened one (``time_step_factor``), the two rules of the oscillatory run's first step.

    Parameters
    ----------
    q : dict
        The arguments of the run (normalized).
    steps : dict
        :func:`sweep_steps` of ``q``.
    freqs : list of float
        The relative frequency of each step.
    name_of : callable
        ``name_of(j) -> (name, value, flag)`` of step ``j`` for the message.
    allowed_of : callable
        ``allowed_of(j, fr, spp, flag) -> str``: what is allowed when step ``j`` resolves its
        period with ``spp`` < :data:`MIN_STEPS_PER_PERIOD` steps.

    Raises
    ------
    ValueError
        Naming the step's value, its steps per period, the limit, the allowed range and the flag.
    """
    proto = q["protocol"]
    factor = float(q["time_step_factor"])
    for j, (fr, dtr) in enumerate(zip(freqs, steps["dts"])):
        spp = 1.0 / (fr * dtr / factor)        # steps per period at the reference time step
        if spp >= MIN_STEPS_PER_PERIOD and spp / factor >= MIN_STEPS_PER_PERIOD_COARSENED:
            continue
        name, value, flag = name_of(j)
        if spp < MIN_STEPS_PER_PERIOD:
            raise ValueError(
                f"{name}={value:g} is out of range: this step of protocol={proto!r} (relative frequency {fr:g}, "
                f"dt = {dtr / factor:.3g} τ at the reference time step) would resolve an excitation period with "
                f"{spp:.3g} steps, fewer than {MIN_STEPS_PER_PERIOD}; allowed {allowed_of(j, fr, spp, flag)}")
        raise ValueError(
            f"time_step_factor={q['time_step_factor']!r} is out of range: it leaves {spp / factor:.3g} steps per "
            f"excitation period at {name}={value:g}, fewer than {MIN_STEPS_PER_PERIOD_COARSENED}; allowed "
            f"time_step_factor <= {spp / MIN_STEPS_PER_PERIOD_COARSENED:.3g} (flag --time-step-factor)")


def room(q, steps, steps_ok, list_name):
    """The largest of pre_periods / periods / post_periods shortens a sweep, else its list.

    Parameters
    ----------
    q : dict
        The run's arguments (normalized).
    steps : dict
        :func:`sweep_steps` of ``q``.
    steps_ok : float
        The most steps the run may take.
    list_name : str
        The sweep's list parameter.

    Returns
    -------
    tuple of str
        ``(parameter, allowed text)``.
    """
    n_periods = float(q["pre_periods"]) + float(q["periods"]) + float(q["post_periods"])
    per_period = sum(steps["segments"]) / n_periods      # steps of one period of every step
    name = max(("periods", "pre_periods", "post_periods"), key=lambda n: float(q[n]))
    room = steps_ok / max(per_period, 1e-300) - (n_periods - float(q[name]))
    if room <= 0:
        return list_name, "fewer or shorter steps"
    return name, f"{name} <= {max(room, 0.0):.4g}"


def shorten(q, n, steps_of, list_name):
    """The first two values of ``list_name``, no baseline periods, the excitation periods cut so that
    both steps together take about ``n`` steps (a sweep's cost calibration).

    Parameters
    ----------
    q : dict
        The run's arguments (normalized).
    n : int
        About how many steps the cut sweep takes.
    steps_of : callable
        ``steps_of(q)``: the step counts of other arguments.
    list_name : str
        The sweep's list parameter.

    Returns
    -------
    dict
        The parameters to change.
    """
    q2 = dict(q, **{list_name: q[list_name][:2]}, pre_periods=0, post_periods=0, periods=1)
    per_period = max(1, sum(steps_of(q2)["segments"]))
    return {list_name: list(q[list_name][:2]), "pre_periods": 0, "post_periods": 0,
            "periods": min(float(q["periods"]), n / per_period)}
