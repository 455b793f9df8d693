"""Rheology analysis of runs and sweeps (NumPy only; figures with the ``[plot]`` extra).

* :mod:`~particleShear.analysis.demodulation` — the downstream R evaluation of one run:
  measurement phases, jump correction, demodulation (:func:`evaluate_run`).
* :mod:`~particleShear.analysis.periods` — G′, G″ of each excitation period: standard errors and
  a steady-state check (:func:`period_moduli`).
* :mod:`~particleShear.analysis.laos` — large-amplitude oscillatory shear measures: harmonics,
  Chebyshev coefficients, G_M, G_L, η_M, η_L, S, T, I₃/I₁, Q (:func:`laos`).
* :mod:`~particleShear.analysis.measures` — what every run reports in ``SimulationResult.measures``
  and the results table (:func:`run_measures`).
* :mod:`~particleShear.analysis.curves` — the characteristic points of an amplitude sweep
  (yield point, the R package's four points).
* :mod:`~particleShear.analysis.sweep` — an amplitude sweep's mean curves and characteristics
  with bootstrap intervals over seeds (:func:`sweep_summary`).
* :mod:`~particleShear.analysis.flow_curve` — Herschel–Bulkley fit of a flow curve with bootstrap
  intervals over seeds (:func:`herschel_bulkley_bootstrap`; of a steady-shear sweep's table:
  :func:`fit_flow_curve`).
* :mod:`~particleShear.analysis.cli` — ``python -m particleShear analyse DIR``;
  :mod:`~particleShear.analysis.figure` its figure.

Definitions, units and when to use which estimator: docs/analysis.md.
"""
__docformat__ = "numpy"
from .curves import CURVE_POINTS, stress_curve_points, yield_point
from .demodulation import ESTIMATOR_COLUMNS, PHASES, demodulate, evaluate_run, jump_corrected, measurement_periods
from .flow_curve import (FlowCurveFit, HerschelBulkley, fit_flow_curve, flow_curve_table, herschel_bulkley_bootstrap,
                         herschel_bulkley_fit)
from .laos import LaosResult, laos
from .measures import MEASURE_COLUMNS, MeasurementWarning, run_measures
from .periods import PeriodModuli, measured_period_count, period_moduli
from .sweep import SweepSummary, sweep_summary

__all__ = ["demodulate", "jump_corrected", "measurement_periods", "evaluate_run", "PHASES", "ESTIMATOR_COLUMNS",
           "yield_point", "stress_curve_points", "CURVE_POINTS", "laos", "LaosResult", "period_moduli",
           "PeriodModuli", "measured_period_count", "run_measures", "MEASURE_COLUMNS", "MeasurementWarning",
           "sweep_summary", "SweepSummary",
           "herschel_bulkley_fit", "HerschelBulkley", "herschel_bulkley_bootstrap", "FlowCurveFit", "fit_flow_curve",
           "flow_curve_table"]
