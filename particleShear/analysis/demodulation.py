"""The downstream R evaluation of one run: measurement phases, jump correction, demodulation.

The paper behind the method did not publish the G′, G″ that :func:`doParticleShearSimulation`
returns but recomputed them from the saved files with the R package particleShearEvaluation:
it labels every sample by its phase of the protocol, keeps the excitation periods after the
first ("initiation"), removes steps of the stress (spheres entering or leaving the plate bands
or crossing the periodic boundary), and projects the stress on sine and cosine of the
excitation.  These functions are those definitions on arrays (docs/analysis.md); the package's
own estimate is :func:`particleShear.simulation.evaluation.demodulation`.
"""
__docformat__ = "numpy"
import math
import numbers

import numpy as np

from ..simulation.formats import read_run

__all__ = ["demodulate", "jump_corrected", "measurement_periods", "evaluate_run", "PHASES",
           "ESTIMATOR_COLUMNS"]

#: the labels of :func:`measurement_periods`, in protocol order
PHASES = ("pre", "initiation", "oscillatory_measurement", "post")

#: estimator → (column of a run file, key of ``SimulationResult.series``)
ESTIMATOR_COLUMNS = {"surface": ("stress_measured_at_surface", "stress_surface"),
                     "internal": ("shear_stress_internal_stress-tensor", "stress_internal")}


def _series(t, values, t_name="t", v_name="stress"):
    t = np.asarray(t, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.ndim != 1 or v.shape != t.shape:
        raise ValueError(f"{t_name} and {v_name} must be 1-D arrays of one length, got shapes {t.shape} and {v.shape}")
    return t, v


def _positive(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name}={value!r} is not allowed: a finite number > 0")
    return float(value)


def jump_corrected(stress, jump_threshold=0.15):
    """The stress with its jumps removed, by the R package's rule.

    The threshold is ``jump_threshold · (max − min)`` of the uncorrected series.  The list of
    positions i (0-based) with ``|m[i+1] − m[i]| > threshold`` is made once, before any
    correction; for each such i in increasing order with ``1 ≤ i ≤ n − 2`` every later sample
    ``m[i+1:]`` is shifted by ``−(m[i+1] − m[i]) + (m[i] − m[i−1])`` with the values as
    corrected so far: the step is replaced by the increment just before it.

    Parameters
    ----------
    stress : array_like
        A 1-D series (Pa).
    jump_threshold : float, default 0.15
        Fraction of the series' range above which an increment counts as a jump (> 0).

    Returns
    -------
    numpy.ndarray
        The corrected series (a new array; float).

    Raises
    ------
    ValueError
        For a series that is not 1-D or a threshold that is not a number > 0.
    """
    m = np.array(stress, dtype=float)
    if m.ndim != 1:
        raise ValueError(f"stress must be a 1-D array, got shape {m.shape}")
    jump_threshold = _positive("jump_threshold", jump_threshold)
    n = len(m)
    if n < 3:
        return m
    threshold = jump_threshold * (float(np.max(m)) - float(np.min(m)))
    inc = np.diff(m)
    jumps = np.flatnonzero(np.abs(inc) > threshold)
    jumps = jumps[(jumps >= 1) & (jumps <= n - 2)]
    if len(jumps) == 0:
        return m
    # every correction shifts a whole tail, so only the increments at the jumps change:
    # inc[i] becomes inc[i-1] as corrected so far (which differs from the original when i-1 is a jump)
    shift = np.zeros(n)
    corrected = {}
    for i in jumps.tolist():
        before = corrected.get(i - 1, inc[i - 1])
        corrected[i] = before
        shift[i + 1] = before - inc[i]
    return m + np.cumsum(shift)


def demodulate(t, stress, f, strain_amplitude=1.0, correct_jumps=True, jump_threshold=0.15):
    """G′ and G″ of a stress series, as the R package computes them.

    Times are shifted so that the first sample is at 0; the stress m is jump-corrected
    (:func:`jump_corrected`) when asked; then
    ``G′ = Σ sin(2πft)·m / Σ sin²(2πft) / γ₀`` and ``G″ = Σ cos(2πft)·m / Σ cos²(2πft) / γ₀``
    (least-squares amplitudes of the components in phase with the strain and with the strain
    rate).  Feed it the ``"oscillatory_measurement"`` samples of :func:`measurement_periods`.

    Parameters
    ----------
    t : array_like
        Sample times (s).
    stress : array_like
        Shear stress (Pa), same length.
    f : float
        Excitation frequency (Hz, > 0).
    strain_amplitude : float, default 1.0
        γ₀ (dimensionless, > 0); 1 returns the stress amplitudes in Pa.
    correct_jumps : bool, default True
        Remove jumps first.
    jump_threshold : float, default 0.15
        See :func:`jump_corrected`.

    Returns
    -------
    tuple of float
        ``(G′, G″)`` in Pa; NaN for an empty series.

    Raises
    ------
    ValueError
        For arrays of different shapes or non-positive ``f``, ``strain_amplitude`` or
        ``jump_threshold``.
    """
    t, m = _series(t, stress)
    f = _positive("f", f)
    strain_amplitude = _positive("strain_amplitude", strain_amplitude)
    if len(t) == 0:
        return math.nan, math.nan
    if correct_jumps:
        m = jump_corrected(m, jump_threshold)
    else:
        _positive("jump_threshold", jump_threshold)
    phase = 2 * math.pi * f * (t - t[0])
    a, b = np.sin(phase), np.cos(phase)
    saa, sbb = float(a @ a), float(b @ b)
    gp = float(a @ m) / saa / strain_amplitude if saa else math.nan
    gpp = float(b @ m) / sbb / strain_amplitude if sbb else math.nan
    return gp, gpp


def measurement_periods(t, f, pre_periods, periods):
    """The phase of the protocol each sample belongs to (the R package's labels).

    ``"pre"`` where ``t < pre/f``; ``"post"`` where ``t > (pre + periods)/f``; when
    ``periods > 1``, ``"initiation"`` where ``pre/f ≤ t < (pre + 1)/f`` (the first excitation
    period, a transient); ``"oscillatory_measurement"`` elsewhere.

    Parameters
    ----------
    t : array_like
        Sample times since the start of the protocol (s).
    f : float
        Excitation frequency (Hz, > 0).
    pre_periods : float
        Baseline periods before the excitation (≥ 0).
    periods : float
        Excitation periods (> 0).

    Returns
    -------
    numpy.ndarray of str
        One label of :data:`PHASES` per sample.

    Raises
    ------
    ValueError
        For a ``t`` that is not 1-D or parameters out of range.
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1:
        raise ValueError(f"t must be a 1-D array, got shape {t.shape}")
    f = _positive("f", f)
    periods = _positive("periods", periods)
    if isinstance(pre_periods, bool) or not isinstance(pre_periods, numbers.Real) or not pre_periods >= 0 \
            or not math.isfinite(pre_periods):
        raise ValueError(f"pre_periods={pre_periods!r} is not allowed: a finite number >= 0")
    labels = np.full(len(t), "oscillatory_measurement", dtype="<U23")
    if periods > 1:
        labels[(t >= pre_periods / f) & (t < (pre_periods + 1) / f)] = "initiation"
    labels[t > (pre_periods + periods) / f] = "post"
    labels[t < pre_periods / f] = "pre"
    return labels


def _protocol_of(run):
    """(series dict with 't' and both stresses, f, γ₀, pre, periods) of a result, RunData or path."""
    if isinstance(run, (str, bytes)) or hasattr(run, "__fspath__"):
        run = read_run(run)
    if hasattr(run, "strain_amplitude") and hasattr(run, "header"):       # RunData
        series = {"t": run["t"]} if "t" in run else {}
        for est, (col, _key) in ESTIMATOR_COLUMNS.items():
            if col in run:
                series[est] = run[col]
        return series, run.frequency, run.strain_amplitude, run.pre_periods, run.periods
    s = getattr(run, "series", None)
    if not s or "t" not in s:
        raise ValueError("evaluate_run needs a run with its recorded series (a SimulationResult of this session, "
                         "a RunData of read_run, or the path of a run file)")
    series = {"t": s["t"]}
    for est, (_col, key) in ESTIMATOR_COLUMNS.items():
        if key in s:
            series[est] = s[key]
    p = run.parameters
    return series, run.f, p["theAmplitude"], p["pre_periods"], p["periods"]


def evaluate_run(run, correct_jumps=True, jump_threshold=0.15):
    """The R package's G′ and G″ of one run, for both estimators.

    Labels the samples (:func:`measurement_periods`), keeps the ``"oscillatory_measurement"``
    ones and demodulates each stress column there (:func:`demodulate`, with the run's frequency
    and strain amplitude).

    Parameters
    ----------
    run : SimulationResult, RunData, str or os.PathLike
        A result with its ``series``, a :class:`~particleShear.simulation.formats.RunData`, or
        the path of a run file (read with :func:`~particleShear.simulation.formats.read_run`).
    correct_jumps : bool, default True
        Remove jumps first (:func:`jump_corrected`).
    jump_threshold : float, default 0.15
        Jump threshold as a fraction of the range.

    Returns
    -------
    dict
        ``{"surface": (G′, G″), "internal": (G′, G″)}`` in Pa, for the estimators the run
        recorded (a text file saved without tensor data has no table, hence neither).

    Raises
    ------
    ValueError
        When the run has no recorded series.
    """
    series, f, amplitude, pre, periods = _protocol_of(run)
    if "t" not in series:
        raise ValueError("evaluate_run: the run has no table of samples (saved with saveStressTensorData=False?)")
    keep = measurement_periods(series["t"], f, pre, periods) == "oscillatory_measurement"
    t = np.asarray(series["t"], dtype=float)[keep]
    return {est: demodulate(t, np.asarray(series[est], dtype=float)[keep], f, amplitude, correct_jumps,
                            jump_threshold)
            for est in ESTIMATOR_COLUMNS if est in series}
