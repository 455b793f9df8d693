"""Steady shear: γ̇ = ``relative_rate``/τ until the strain ``total_strain`` (flow curves, docs/protocols.md).

The summary is the steady shear stress (mean and standard error by blocking after the detected
transient) of both estimators, the viscosity σ/γ̇ and the first normal-stress difference N1 of the
overall tensor (sampled every :data:`N1_EVERY` steps).
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..parameter_entry import Parameter
from . import MAX_STRAIN_PER_STEP, positive, register_protocol

__all__ = ["PROTOCOL", "PARAMETERS", "N1_EVERY"]

POSITION = 1
SIGNATURE = True
#: N1 of the overall tensor is sampled every this many steps (the tensors cost about one step)
N1_EVERY = 10

PARAMETERS = (
    Parameter('relative_rate', 0.01, 'float', unit='1', role='protocol:steady', keyword_only=True, doc='``protocol="steady"``: shear rate γ̇·τ, dimensionless like ``relative_frequency`` (γ̇ = relative_rate/τ in 1/s, τ the model time constant); allowed > 0 with at most 0.005 strain per time step'),
    Parameter('total_strain', 2.0, 'float', unit='1', role='protocol:steady', keyword_only=True, doc='``protocol="steady"``: strain sheared in all; allowed 0 < value <= 1e6'),
)

_P = "; empty unless protocol is 'steady'"
COLUMNS = {
    "strain_rate": ("float", "1/s", "imposed shear rate γ̇ = relative_rate/τ" + _P),
    "stress_surface": ("float", "Pa", "steady shear stress from the plate forces (mean after the transient)" + _P),
    "stress_surface_se": ("float", "Pa", "standard error of stress_surface by block averaging" + _P),
    "stress_internal": ("float", "Pa", "steady shear stress of the internal estimator (stress tensor, eq. S1-24)" + _P),
    "stress_internal_se": ("float", "Pa", "standard error of stress_internal by block averaging" + _P),
    "viscosity_surface": ("float", "Pa·s", "viscosity stress_surface/strain_rate" + _P),
    "viscosity_surface_se": ("float", "Pa·s", "standard error of viscosity_surface" + _P),
    "viscosity_internal": ("float", "Pa·s", "viscosity stress_internal/strain_rate" + _P),
    "viscosity_internal_se": ("float", "Pa·s", "standard error of viscosity_internal" + _P),
    "N1": ("float", "Pa", "first normal-stress difference σ_xx − σ_yy of the overall tensor after the transient" + _P),
    "N1_se": ("float", "Pa", "standard error of N1 by block averaging" + _P),
    "t_transient": ("float", "s", "end of the start-up transient (MSER-5 on the plate stress)" + _P),
    "strain_transient": ("float", "1", "strain at the end of the start-up transient" + _P),
}


def check(q):
    """``relative_rate`` and ``total_strain`` > 0 (``total_strain`` <= 1e6).

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).

    Raises
    ------
    ValueError, TypeError
        Naming the parameter, its value and the allowed range.
    """
    positive("relative_rate", q["relative_rate"])
    positive("total_strain", q["total_strain"], 1e6)


def check_steps(q, steps):
    """At most :data:`~particleShear.protocols.MAX_STRAIN_PER_STEP` strain per step.

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
    rate = float(q["relative_rate"])
    if rate * dtr > MAX_STRAIN_PER_STEP:
        raise ValueError(f"relative_rate={rate!r} is out of range: the time step (dt = {dtr:.3g} τ) "
                         f"resolves at most {MAX_STRAIN_PER_STEP} strain per step, i.e. relative_rate <= "
                         f"{MAX_STRAIN_PER_STEP / dtr:.4g} (flag --relative-rate)")


def steps(q, dt_over_tau):
    """``steps``: the strain over the strain per step, rounded up.

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
    return {"dt_over_tau": dtr, "steps": int(math.ceil(float(q["total_strain"]) / (float(q["relative_rate"]) * dtr)))}


def room(q, steps, steps_ok):
    """``total_strain`` shortens a steady run.

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
    room = steps_ok * float(q["relative_rate"]) * steps["dt_over_tau"]
    return "total_strain", f"total_strain <= {max(room, 0.0):.4g}"


def schedule(kws, steps, tau, dt, backend):
    """A constant γ̇ per replica from the first step (``set_rate`` moves every sphere onto the new
    flow, so the start is no velocity shock); N1 every :data:`N1_EVERY` steps.

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
    R = backend.asarray(np.asarray([k["relative_rate"] / tau for k in kws], dtype=float))
    return {"n_steps": max(s["steps"] for s in steps), "rate_of": lambda i: R, "tensors_every": N1_EVERY}


def summary(kw, series, tau, steps, stats):
    """The steady stress, viscosity and N1 after the transient (module docstring).

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
    out = {}
    rate = kw["relative_rate"] / tau
    out["strain_rate"] = rate
    for est, key in stats.ESTIMATORS:
        ss = stats.steady_state(t, series[key])
        out[f"stress_{est}"], out[f"stress_{est}_se"] = ss.mean, ss.sem
        out[f"viscosity_{est}"], out[f"viscosity_{est}_se"] = ss.mean / rate, ss.sem / rate
        if est == "surface":
            out["t_transient"], out["strain_transient"] = ss.t_transient, ss.t_transient * rate
    n1 = series["N1"]
    keep = np.isfinite(n1) & (t >= out["t_transient"])
    ba = stats.plateau(t[keep], n1[keep], 1.0) if keep.sum() >= 2 else None
    out["N1"], out["N1_se"] = (ba.mean, ba.sem) if ba else (math.nan, math.nan)
    checks = stats.verdicts.steady_checks(t, {key: series[key] for _, key in stats.ESTIMATORS}, kw["total_strain"])
    return out, {}, checks


def values(s):
    """``[σ, η]`` of the plate forces.

    Parameters
    ----------
    s : dict
        The run's summary.

    Returns
    -------
    list of float
    """
    return [s["stress_surface"], s["viscosity_surface"]]


def shorten(q, steps, n, steps_of):
    """The strain of ``n`` steps at the run's rate.

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
    return {"total_strain": min(float(q["total_strain"]), n * float(q["relative_rate"]) * steps["dt_over_tau"])}


PROTOCOL = register_protocol("steady", parameters=PARAMETERS,
                             shorten=shorten, shown=("stress_surface", "σ", "Pa"),
                             header=("relative_rate", "total_strain"), file_name=("rate", "relative_rate"),
                             required=("stress_surface", "stress_internal", "strain_rate"), steps=steps, check=check, check_steps=check_steps, schedule=schedule,
                             summary=summary, values=values, columns=COLUMNS,
                             checks=("plateau_reached", "strain_sufficient"), room=room, record_bytes=2 * 6 * 8,
                             quantities={"sigma_y": "Pa", "K": "Pa·s^n", "n": "1"},
                             doc="a constant shear rate")
