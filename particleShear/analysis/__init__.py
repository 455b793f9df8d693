"""Rheology analysis of runs and sweeps (NumPy only; figures with the ``[plot]`` extra).

* :mod:`~particleShear.analysis.demodulation` — the downstream R evaluation of one run:
  measurement phases, jump correction, demodulation (:func:`evaluate_run`).
* :mod:`~particleShear.analysis.curves` — the characteristic points of an amplitude sweep
  (yield point, the R package's four points).

Definitions, units and when to use which estimator: docs/analysis.md.
"""
__docformat__ = "numpy"
from .curves import CURVE_POINTS, stress_curve_points, yield_point
from .demodulation import ESTIMATOR_COLUMNS, PHASES, demodulate, evaluate_run, jump_corrected, measurement_periods

__all__ = ["demodulate", "jump_corrected", "measurement_periods", "evaluate_run", "PHASES", "ESTIMATOR_COLUMNS",
           "yield_point", "stress_curve_points", "CURVE_POINTS"]
