"""The summary of one replica's record of a rheometer protocol (docs/protocols.md, "Outputs").

Given to the one driver (:data:`particleShear.run.measurement.CONCLUSION`, for
:func:`particleShear.simulation.driver.measure_sessions`); the statistics are those of
:mod:`particleShear.analysis.rheometry`, the sweeps' moduli the oscillatory run's demodulation
(:func:`particleShear.simulation.evaluation.demodulation`) and measures
(:func:`particleShear.analysis.measures.run_measures`).
"""
__docformat__ = "numpy"
import types

from ..analysis import verdicts as vd
from ..analysis.measures import run_measures
from ..analysis.rheometry import final_rate, log_grid, plateau, steady_state
from ..protocols import PROTOCOLS
from ..simulation.evaluation import demodulation

__all__ = ["analyse_record", "analyse_sweep", "STATS"]

_EST = (("surface", "stress_surface"), ("internal", "stress_internal"))

#: what a protocol's ``summary`` computes with (:mod:`particleShear.protocols`): the estimators
#: ``ESTIMATORS`` (``(name, series key)``), the statistics of :mod:`particleShear.analysis.rheometry`
#: (``steady_state``, ``plateau``, ``log_grid``, ``final_rate``) and :mod:`particleShear.analysis.verdicts`
STATS = types.SimpleNamespace(ESTIMATORS=_EST, steady_state=steady_state, plateau=plateau, log_grid=log_grid,
                              final_rate=final_rate, verdicts=vd)


def analyse_record(protocol, kw, series, tau, steps):
    """Scalars and log-grid curves of one replica's record (a protocol run by the recording loop).

    Parameters
    ----------
    protocol : str
        The protocol (its ``summary``, :mod:`particleShear.protocols`).
    kw : dict
        The run's arguments.
    series : dict of ndarray
        Its record (:func:`particleShear.engine.rheometer.shear_record`).
    tau : float
        Model time constant (s).
    steps : dict
        :func:`particleShear.run.rheometer.protocol_steps` of the run.

    Returns
    -------
    summary : dict
        Column → float (units in docs/protocols.md), the protocol's checks (bool or None) and
        ``verdict`` (:mod:`particleShear.analysis.verdicts`).
    curves : dict
        ``name -> (t, y, y_sem)``.
    """
    summarise = PROTOCOLS[protocol].summary
    if summarise is None:
        return {}, {}
    out, curves, checks = summarise(kw, series, tau, steps, STATS)
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
