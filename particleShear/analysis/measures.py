"""What every run reports beyond G′ and G″: their standard errors, a steady-state flag, LAOS measures.

:func:`run_measures` evaluates them once from a run's recorded series; they go into
``SimulationResult.measures`` and the results table (:data:`MEASURE_COLUMNS`, docs/analysis.md).
"""
__docformat__ = "numpy"
import math
import warnings

import numpy as np

from .demodulation import ESTIMATOR_COLUMNS, measurement_periods
from .microstructure import MICRO_COLUMNS
from .laos import laos
from .periods import FALSE_ALARM, measured_period_count, period_moduli
from .verdicts import baseline_noise, oscillatory_checks, verdict

__all__ = ["MEASURE_COLUMNS", "NON_NUMERIC_MEASURES", "MEASURE_N_MAX", "MeasurementWarning", "empty_measures", "run_measures", "measured_window", "warn_few_periods"]

#: highest harmonic order of the table's LAOS ratios: G_M and η_M weight order n by n, and orders above
#: 5 of a run at N <= 150 are at its noise level (their S, T change sign with the order kept)
MEASURE_N_MAX = 5

#: columns of the results table after the four moduli, in order (units in docs/analysis.md); the last,
#: :data:`~particleShear.analysis.microstructure.MICRO_COLUMNS`, are empty unless the run was stroboscopic
MEASURE_COLUMNS = ("Gp_surface_se", "Gpp_surface_se", "Gp_internal_se", "Gpp_internal_se", "steady_state",
                   "I3_I1_surface", "I3_I1_internal", "S_surface", "T_surface", "S_internal", "T_internal",
                   "linear_response", "estimators_agree", "moduli_positive", "excitation_resolved", "verdict") + MICRO_COLUMNS
#: the measure columns that are not numbers: checks (bool or None) and the verdict (str or None)
NON_NUMERIC_MEASURES = ("steady_state", "linear_response", "estimators_agree", "moduli_positive", "excitation_resolved",
                "verdict")


class MeasurementWarning(UserWarning):
    """A run measures too little of the excitation for its G′, G″ to carry an error bar."""


def warn_few_periods(periods):
    """Warn (:class:`MeasurementWarning`) when fewer than 2 whole excitation periods are measured.

    With fewer, G′ and G″ come from one period or a fraction of one: no standard error, no
    steady-state check, and a fraction of a period does not even separate G′ from G″.

    Parameters
    ----------
    periods : float
        Excitation periods P of the run.

    Returns
    -------
    bool
        True when it warned.
    """
    n = measured_period_count(0, periods)
    if n >= 2:
        return False
    skipped = " (the first, a transient, is skipped)" if float(periods) >= 2 else ""
    why = "G′ and G″ get no standard error" + ("" if float(periods) >= 1 else
                                                 ", and a fraction of a period does not separate G′ from G″")
    warnings.warn(f"periods={periods!r} measures {n} whole excitation period(s){skipped}: {why}; use periods >= 3 "
                  "(--periods 3)", MeasurementWarning, stacklevel=2)   # one place: shown once per process
    return True


def measured_window(t, f, pre_periods, periods):
    """Mask of the samples the measures use: the R package's ``"oscillatory_measurement"``.

    Parameters
    ----------
    t : array_like
        Sample times since the start of the protocol (s).
    f : float
        Excitation frequency (Hz).
    pre_periods, periods : float
        Baseline periods before the excitation and excitation periods.

    Returns
    -------
    numpy.ndarray of bool
    """
    return measurement_periods(t, f, pre_periods, periods) == "oscillatory_measurement"


def empty_measures():
    """The measures of a run that has none: NaN, the checks, ``verdict`` and the microstructure
    columns (not evaluated without the stroboscopic observer) None.

    Returns
    -------
    dict
    """
    return {c: (None if c in NON_NUMERIC_MEASURES or c in MICRO_COLUMNS else math.nan) for c in MEASURE_COLUMNS}


def run_measures(series, f, strain_amplitude, pre_periods, periods, moduli=None):
    """The standard errors, steady-state flag, LAOS measures and verdict of one run (:data:`MEASURE_COLUMNS`).

    * ``G*_se`` — standard error of the mean over the whole excitation periods of the
      package's demodulation window, each demodulated alone
      (:func:`~particleShear.analysis.periods.period_moduli`); NaN with fewer than 2 periods.
    * ``steady_state`` — False when G′ or G″ of either estimator drifts from period to period
      significantly (a linear trend larger than its own error, Student's t at a level such that a
      run without drift is called unsteady with probability ≤ 5 %), True when none does, None
      (empty in the table) with fewer than 3 measured periods.
    * ``I3_I1_*``, ``S_*``, ``T_*`` — intensity ratio of the third harmonic and the
      Ewoldt–Hosoi–McKinley stiffening and thickening ratios over the ``"oscillatory_measurement"``
      samples (:func:`~particleShear.analysis.laos.laos` with orders up to :data:`MEASURE_N_MAX`); NaN
      when that span is shorter than a period.
    * ``linear_response``, ``estimators_agree``, ``moduli_positive``, ``excitation_resolved``
      and ``verdict`` — the run's checks and verdict
      (:func:`~particleShear.analysis.verdicts.oscillatory_checks`; docs/analysis.md, "Verdicts").

    Parameters
    ----------
    series : dict of numpy.ndarray
        ``SimulationResult.series``: "t" (s), "strain", "stress_surface", "stress_internal" (Pa).
    f : float
        Excitation frequency (Hz).
    strain_amplitude : float
        γ₀ (dimensionless).
    pre_periods, periods : float
        The protocol's baseline periods before the excitation and excitation periods.
    moduli : dict, optional
        Estimator → (G′, G″) in Pa, the run's reported moduli; without them the checks that
        compare moduli are not judged (None).

    Returns
    -------
    dict
        Column → value (float; checks bool or None; ``verdict`` str).
    """
    row = empty_measures()
    if not series or "t" not in series or len(series["t"]) == 0 or not f:
        return row
    t = np.asarray(series["t"], dtype=float)
    flags = []
    noise = {}
    window = measured_window(t, f, pre_periods, periods)
    for est, (_col, key) in ESTIMATOR_COLUMNS.items():
        if key not in series:
            continue
        stress = np.asarray(series[key], dtype=float)
        noise[est] = baseline_noise(t, stress, f, pre_periods)
        try:
            # each estimator at half the run's false-alarm level: the run's flag errs with <= 5 %
            pm = period_moduli(t, stress, f, strain_amplitude, pre_periods, periods, false_alarm=FALSE_ALARM / 2)
        except ValueError:
            pm = None
        if pm is not None:
            row[f"Gp_{est}_se"], row[f"Gpp_{est}_se"] = float(pm.Gp_se), float(pm.Gpp_se)
            flags.append(pm.steady)
        try:
            m = laos(t[window], np.asarray(series["strain"], dtype=float)[window], stress[window], f,
                     n_max=MEASURE_N_MAX)
        except (ValueError, KeyError, np.linalg.LinAlgError):
            continue
        row[f"I3_I1_{est}"], row[f"S_{est}"], row[f"T_{est}"] = float(m.I3_I1), float(m.S), float(m.T)
    known = [x for x in flags if x is not None]
    row["steady_state"] = None if not known or len(known) < len(flags) else all(known)
    checks = oscillatory_checks(moduli or {}, row, strain_amplitude, noise)
    row.update(checks)
    row["verdict"] = verdict(checks)
    return row
