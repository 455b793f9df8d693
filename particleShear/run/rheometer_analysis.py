"""The summary of one replica's record of a rheometer protocol (docs/protocols.md, "Outputs").

Used by :func:`particleShear.run.rheometer.measure_rheometer`; the statistics are those of
:mod:`particleShear.analysis.rheometry`, the sweeps' moduli the oscillatory run's demodulation
(:func:`particleShear.simulation.evaluation.demodulation`) and measures
(:func:`particleShear.analysis.measures.run_measures`).
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..analysis import verdicts as vd
from ..analysis.rheometry import final_rate, log_grid, plateau, steady_state

__all__ = ["analyse_record", "analyse_sweep"]

_EST = (("surface", "stress_surface"), ("internal", "stress_internal"))


def analyse_record(protocol, kw, series, tau, steps, rate_limit=math.inf):
    """Scalars and log-grid curves of one replica's record (steady, relaxation, creep).

    Parameters
    ----------
    protocol : {"steady", "relaxation", "creep"}
        The protocol.
    kw : dict
        The run's arguments.
    series : dict of ndarray
        Its record (:func:`particleShear.engine.rheometer.shear_record`).
    tau : float
        Model time constant (s).
    steps : dict
        :func:`particleShear.run.rheometer.protocol_steps` of the run.
    rate_limit : float, default inf
        The creep controller's largest strain per step (its rate limit times dt).

    Returns
    -------
    summary : dict
        Column → float (units in docs/protocols.md), the protocol's checks (bool or None) and
        ``verdict`` (:mod:`particleShear.analysis.verdicts`).
    curves : dict
        ``name -> (t, y, y_sem)``.
    """
    t = series["t"]
    out, curves = {}, {}
    if protocol == "steady":
        rate = kw["relative_rate"] / tau
        out["strain_rate"] = rate
        for est, key in _EST:
            ss = steady_state(t, series[key])
            out[f"stress_{est}"], out[f"stress_{est}_se"] = ss.mean, ss.sem
            out[f"viscosity_{est}"], out[f"viscosity_{est}_se"] = ss.mean / rate, ss.sem / rate
            if est == "surface":
                out["t_transient"], out["strain_transient"] = ss.t_transient, ss.t_transient * rate
        n1 = series["N1"]
        keep = np.isfinite(n1) & (t >= out["t_transient"])
        ba = plateau(t[keep], n1[keep], 1.0) if keep.sum() >= 2 else None
        out["N1"], out["N1_se"] = (ba.mean, ba.sem) if ba else (math.nan, math.nan)
        checks = vd.steady_checks(t, {key: series[key] for _, key in _EST}, kw["total_strain"])
    elif protocol == "relaxation":
        g0 = kw["theAmplitude"]
        n_ramp = steps["ramp"] + 1          # the first hold sample: step 0 at rest, then the ramp
        t_end = t[n_ramp] if len(t) > n_ramp else math.nan
        th = t[n_ramp:] - t_end
        out["step_strain"], out["ramp_time_s"] = g0, t_end
        out["residual_stress"] = float(series["stress_surface"][0])
        for est, key in _EST:
            # the stress the step strain adds to the packing's residual stress (step 0, γ = 0)
            G = (series[key][n_ramp:] - series[key][0]) / g0
            ba = plateau(th, G)
            out[f"G_plateau_{est}"], out[f"G_plateau_{est}_se"] = ba.mean, ba.sem
            tm, gm, gs, _ = log_grid(th, G)
            curves[f"G_{est}"] = (tm, gm, gs)
        checks = vd.relaxation_checks(th, {est: (series[key][n_ramp:] - series[key][0]) / g0 for est, key in _EST},
                                      g0, {est: float(series[key][0]) for est, key in _EST})
    elif protocol == "creep":
        s0 = kw["creep_stress"]
        gam = series["strain"] - series["strain"][0]
        out["creep_stress"] = s0
        rate, rate_se = final_rate(t, gam)
        out["creep_rate"], out["creep_rate_se"] = rate, rate_se
        out["creep_viscosity"] = s0 / rate if rate > 0 else math.inf
        ba = plateau(t, gam)
        out["strain_plateau"], out["strain_plateau_se"] = ba.mean, ba.sem
        half = t >= t[-1] / 2
        res0 = float(series["stress_surface"][0])      # step 0 at rest: the residual stress
        out["residual_stress"] = res0
        out["stress_tracking"] = float((series["stress_surface"][half].mean() - s0) / s0)
        tm, jm, js, _ = log_grid(t, gam / s0)
        curves["J"] = (tm, jm, js)
        dt = float(t[1] - t[0]) if len(t) >= 2 else math.nan
        checks = vd.creep_checks(t, series["strain_rate"], out["stress_tracking"], rate_limit / dt,
                                 kw["hold_time"], kw["creep_response_time"])
    else:
        return out, curves
    out.update(checks)
    out["verdict"] = vd.verdict(checks)
    return out, curves


def analyse_sweep(kw, segments, tau):
    """One dict per step of a one-packing sweep: position, amplitude, frequency, G′/G″, errors, LAOS.

    Parameters
    ----------
    kw : dict
        The run's arguments (``pre_periods``, ``periods``, ``post_periods``, ``correct_drift_sign``).
    segments : list of tuple
        ``(f, amplitude, dt, record)`` per step, the record of :func:`~particleShear.engine.step.protocol`.
    tau : float
        Model time constant (s).

    Returns
    -------
    list of dict
    """
    from ..analysis.measures import run_measures
    from ..simulation.evaluation import demodulation
    rows = []
    pre, periods, post = kw["pre_periods"], kw["periods"], kw["post_periods"]
    for j, (f, A, dt, rec) in enumerate(segments):
        row = {"position": j, "amplitude": A, "relative_frequency": f * tau, "f": f, "dt": dt,
               "N_steps": len(rec["t"])}
        for est, key in _EST:
            SA, SB, Gp, Gpp = demodulation(rec["t"], rec[key], f, A, pre, periods, post,
                                           correct_drift_sign=kw["correct_drift_sign"])
            row[f"Gp_{est}"], row[f"Gpp_{est}"] = Gp, Gpp
        row.update(run_measures(rec, f, A, pre, periods,
                                moduli={est: (row[f"Gp_{est}"], row[f"Gpp_{est}"]) for est, _ in _EST}))
        rows.append(row)
    return rows
