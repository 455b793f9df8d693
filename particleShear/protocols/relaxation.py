"""Stress relaxation: a step strain to γ₀ = ``theAmplitude`` and hold (docs/protocols.md).

One step at rest (the residual stress σ_res of the packing), a ramp at the constant rate
``γ₀/t_ramp`` over ``ramp_time``·τ, then ``hold_time``·τ at γ̇ = 0 (the strain held at γ₀).  The
summary is G(t) = (σ(t) − σ_res)/γ₀ (t from the end of the ramp) on a log-spaced grid and its
plateau, of both estimators.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..parameter_entry import Parameter
from . import MAX_STRAIN_PER_STEP, positive, register_protocol

__all__ = ["PROTOCOL", "PARAMETERS"]

POSITION = 2
SIGNATURE = True
PARAMETERS = (
    Parameter('ramp_time', 1.0, 'float', unit='τ', role='protocol:relaxation', batch='shared', keyword_only=True, doc='``protocol="relaxation"``: duration of the strain ramp to γ₀, in units of τ; allowed > 0 with at most 0.005 strain per time step'),
    Parameter('hold_time', 200.0, 'float', unit='τ', role='protocol:relaxation', batch='shared', keyword_only=True, doc='``protocol="relaxation"`` and ``"creep"``: duration of the hold, in units of τ; allowed 0 < value <= 1e9 within the step limit'),
)

_P = "; empty unless protocol is 'relaxation'"
_RC = "; empty unless protocol is 'relaxation' or 'creep'"
COLUMNS = {
    "ramp_time_s": ("float", "s", "duration of the strain ramp to theAmplitude" + _P),
    "residual_stress": ("float", "Pa", "plate stress σ_res of the packing at rest before the step strain or "
                        "stress (the origin of G(t); a solid creeps by (σ₀ − σ_res)/G)" + _RC),
    "G_plateau_surface": ("float", "Pa", "long-time plateau of G(t) = (σ(t) − σ_res)/γ₀, plate forces (last 20 % "
                          "of the hold)" + _P),
    "G_plateau_surface_se": ("float", "Pa", "standard error of G_plateau_surface by block averaging" + _P),
    "G_plateau_internal": ("float", "Pa", "long-time plateau of G(t), internal estimator" + _P),
    "G_plateau_internal_se": ("float", "Pa", "standard error of G_plateau_internal by block averaging" + _P),
}


def check(q):
    """``hold_time`` and ``ramp_time`` in (0, 1e9].

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).

    Raises
    ------
    ValueError, TypeError
        Naming the parameter, its value and the allowed range.
    """
    positive("hold_time", q["hold_time"], 1e9)
    positive("ramp_time", q["ramp_time"], 1e9)


def check_steps(q, steps):
    """A ramp of at most :data:`~particleShear.protocols.MAX_STRAIN_PER_STEP` strain per step.

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
    dtr = steps["dt_over_tau"]
    per_step = q["theAmplitude"] / steps["ramp"]
    if per_step > MAX_STRAIN_PER_STEP:
        raise ValueError(f"ramp_time={q['ramp_time']!r} is out of range: a ramp to theAmplitude="
                         f"{q['theAmplitude']!r} in {steps['ramp']} steps is {per_step:.3g} strain per step, more "
                         f"than {MAX_STRAIN_PER_STEP}; allowed ramp_time >= "
                         f"{q['theAmplitude'] / MAX_STRAIN_PER_STEP * dtr:.4g} (flag --ramp-time)")


def steps(q, dt_over_tau):
    """``ramp`` (>= 1) and ``steps``: a first step at rest, the ramp, the hold.

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
    dtr = dt_over_tau()
    ramp = max(1, int(round(float(q["ramp_time"]) / dtr)))
    return {"dt_over_tau": dtr, "ramp": ramp, "steps": 1 + ramp + int(math.ceil(float(q["hold_time"]) / dtr))}


def room(q, steps, steps_ok):
    """``hold_time`` shortens a relaxation run, or ``ramp_time`` when the ramp alone is too long.

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
    dtr = steps["dt_over_tau"]
    name, room = "hold_time", (steps_ok - 1 - steps["ramp"]) * dtr
    if room <= 0:
        name, room = "ramp_time", (steps_ok - 1) * dtr
    return name, f"{name} <= {max(room, 0.0):.4g}"


def schedule(kws, steps, tau, dt, backend):
    """One step at rest, the ramp at ``γ₀/(n_ramp·dt)`` for ``n_ramp`` steps, then γ̇ = 0.

    Parameters
    ----------
    kws : list of dict
        The arguments of the batch's replicas, in batch order.
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    tau : float
        Model time constant τ (s).
    dt : float
        Time step (s).
    backend : Backend
        The batch's array backend (``asarray``, ``xp``).

    Returns
    -------
    dict
        ``n_steps``, ``rate_of(i)`` (γ̇ of every replica at step i, 1/s) and optionally ``after_step``, ``tensors_every``.
    """
    st = steps[0]
    n_ramp = st["ramp"]
    ramp = backend.asarray(np.asarray([k["theAmplitude"] for k in kws], dtype=float) / (n_ramp * dt))
    zero = backend.xp.zeros(len(kws))
    return {"n_steps": st["steps"], "rate_of": lambda i: ramp if 1 <= i <= n_ramp else zero}


def summary(kw, series, tau, steps, stats):
    """G(t) from the end of the ramp, its plateau and the residual stress (module docstring).

    Parameters
    ----------
    kw : dict
        The run's arguments.
    series : dict of ndarray
        The replica's record (:func:`particleShear.engine.rheometer.shear_record`).
    tau : float
        Model time constant τ (s).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    stats : namespace
        :data:`particleShear.run.rheometer_analysis.STATS` (estimators, statistics, verdict checks).

    Returns
    -------
    tuple of dict
        ``(scalars, curves, checks)``: column → value, ``name → (t, y, y_sem)``, check → bool or None.
    """
    t = series["t"]
    out, curves = {}, {}
    g0 = kw["theAmplitude"]
    n_ramp = steps["ramp"] + 1          # the first hold sample: step 0 at rest, then the ramp
    t_end = t[n_ramp] if len(t) > n_ramp else math.nan
    th = t[n_ramp:] - t_end
    out["step_strain"], out["ramp_time_s"] = g0, t_end
    out["residual_stress"] = float(series["stress_surface"][0])
    for est, key in stats.ESTIMATORS:
        # the stress the step strain adds to the packing's residual stress (step 0, γ = 0)
        G = (series[key][n_ramp:] - series[key][0]) / g0
        ba = stats.plateau(th, G)
        out[f"G_plateau_{est}"], out[f"G_plateau_{est}_se"] = ba.mean, ba.sem
        tm, gm, gs, _ = stats.log_grid(th, G)
        curves[f"G_{est}"] = (tm, gm, gs)
    checks = stats.verdicts.relaxation_checks(
        th, {est: (series[key][n_ramp:] - series[key][0]) / g0 for est, key in stats.ESTIMATORS},
        g0, {est: float(series[key][0]) for est, key in stats.ESTIMATORS})
    return out, curves, checks


def values(s):
    """``[G_plateau]`` of the plate forces.

    Parameters
    ----------
    s : dict
        The run's summary.

    Returns
    -------
    list of float
    """
    return [s["G_plateau_surface"]]


def shorten(q, steps, n, steps_of):
    """The ramp kept (its rate is bounded), the hold cut.

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
    return {"hold_time": min(float(q["hold_time"]), max(n - 1 - steps["ramp"], 1) * steps["dt_over_tau"])}


PROTOCOL = register_protocol("relaxation", parameters=PARAMETERS,
                             shorten=shorten, shown=("G_plateau_surface", "G_plateau", "Pa"),
                             header=("theAmplitude", "ramp_time", "hold_time"), file_name=("strain", "theAmplitude"),
                             required=("G_plateau_surface", "G_plateau_internal"), steps=steps, check=check, check_steps=check_steps,
                             schedule=schedule, summary=summary, values=values, columns=COLUMNS,
                             checks=("plateau_reached", "strain_above_noise"), room=room,
                             quantities={"G_plateau_{est}": "Pa", "residual_stress": "Pa"},
                             doc="a step strain to theAmplitude and hold")
