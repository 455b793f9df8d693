"""The oscillatory protocol's summary of a :class:`~particleShear.run.result.SimulationResult`.

G′ and G″ of the two estimators with their standard errors, the measures and the verdict: the
results-table row (one per run), the text and HTML summaries, the values ``doParticleShearSimulation``
returns and the figure.  Every function takes the result; :mod:`particleShear.run.result` calls them
for ``protocol="oscillatory"`` (the other protocols: :mod:`particleShear.run.protocol_summary`).
"""
__docformat__ = "numpy"
import math

import numpy as np

from .._version import __version__
from ..analysis.measures import MEASURE_COLUMNS, NON_NUMERIC_MEASURES, empty_measures, run_measures
from ..analysis.microstructure import MICRO_COLUMNS, micro_measures
from ..analysis.verdicts import verdict_lines
from ..parameters import spec_defaults
from ..simulation.provenance import run_identity

__all__ = ["PLOT_ENTRY", "measures", "verdict", "values", "to_dict", "rows", "from_rows", "text_fields", "text_lines",
           "html_rows", "verdict_text"]

#: the figure of an oscillatory run (:data:`particleShear.hooks.ENTRY_POINTS`)
PLOT_ENTRY = "plot_result"

_ESTIMATORS = (("surface", "G_surface", "G_surface_se"), ("internal", "G_internal", "G_internal_se"))


def measures(result):
    """Standard errors, steady-state flag, LAOS ratios and checks of the run, from its ``series``
    (:func:`~particleShear.analysis.measures.run_measures`; the stroboscopic observer's measures
    too when it ran); empty, with a ``RuntimeWarning``, when they cannot be evaluated.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict
    """
    import warnings
    p = result.parameters or {}
    try:
        out = run_measures(result.series, result.f, p.get("theAmplitude", 0.0), p.get("pre_periods", 0),
                           p.get("periods", 0), moduli={"surface": result.G_surface, "internal": result.G_internal})
        if result.microstructure is not None:
            out.update(micro_measures(result.microstructure))
    except Exception as exc:  # noqa: BLE001 - a measure must never turn a finished run into a failure
        warnings.warn(f"the measures of run {result.run_id or '?'} could not be evaluated "
                      f"({type(exc).__name__}: {exc}); they are left empty", RuntimeWarning, stacklevel=3)
        out = empty_measures()
    return out


def verdict(result):
    """``"ok"`` or ``"flagged: …"`` of the run's checks (its :attr:`measures`).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    str
    """
    return result.measures["verdict"]


def values(result):
    """``[G′_surface, G″_surface]`` — what :func:`~particleShear.run.api.doParticleShearSimulation` returns.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of float
    """
    return [result.G_surface[0], result.G_surface[1]]


def to_dict(result):
    """The run's row of a results table (:meth:`SimulationResult.to_dict
    <particleShear.run.result.SimulationResult.to_dict>`).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict
    """
    params = spec_defaults()
    params.update({k: v for k, v in result.parameters.items() if k in params})
    row = {"run_id": run_identity(params, result.seed, result.spawn_key), "status": "ok", "error": "",
           "Gp_surface": float(result.G_surface[0]), "Gpp_surface": float(result.G_surface[1]),
           "Gp_internal": float(result.G_internal[0]), "Gpp_internal": float(result.G_internal[1])}
    row.update(result.measures)
    row.update(repetition=int(result.repetition), frequency_Hz=float(result.f), omega=2 * math.pi * float(result.f),
               dt=float(result.dt), N_steps=int(result.N_steps))
    row.update(params)
    row.update(seed_entropy=result.seed, spawn_key=list(result.spawn_key), package_version=__version__,
               wall_time_s=float(result.timings.get("total", 0.0)), output_path=result.output_path or "")
    return row


def rows(result):
    """``[to_dict(result)]``: one run, one row.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of dict
    """
    return [to_dict(result)]


def from_rows(cls, rows, parameters, seed, spawn_key, output_path=None):
    """The result of a finished run rebuilt from its typed row: moduli, measures, time scales (no series).

    Parameters
    ----------
    cls : type
        The result type.
    rows : list of dict
        The run's one typed row.
    parameters : dict
        The run's parameters.
    seed, spawn_key
        The run's seed entropy and spawn key.
    output_path : str, optional
        The run's file.

    Returns
    -------
    SimulationResult
    """
    row = rows[0]
    g = tuple(_number(row.get(c)) for c in ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal"))
    result = cls(G_surface=g[:2], G_internal=g[2:], stress_surface=(), stress_internal=(),
                 parameters=dict(parameters), seed=seed, spawn_key=tuple(spawn_key),
                 timings={"total": _number(row.get("wall_time_s"))}, output_path=output_path,
                 dt=_number(row.get("dt")), f=_number(row.get("frequency_Hz")),
                 N_steps=int(row.get("N_steps") or 0), repetition=int(row.get("repetition") or 0),
                 run_id=row["run_id"])
    # (an empty microstructure cell stays None: not evaluated, as the run without the observer reports it)
    result._measures = {c: (row.get(c) if c in NON_NUMERIC_MEASURES or (c in MICRO_COLUMNS and row.get(c) is None)
                            else _number(row.get(c))) for c in MEASURE_COLUMNS}
    return result


def _number(value):
    """A typed cell as float: None (empty) is NaN."""
    return float("nan") if value is None else float(value)


def _estimator_rows(result):
    """``(name, G′, se G′, G″, se G″)`` of both estimators, the standard errors None where not finite."""
    out = []
    for name, attr, se_name in _ESTIMATORS:
        G = getattr(result, attr)
        try:
            se = getattr(result, se_name)
        except Exception:  # noqa: BLE001 - a repr never fails: no error bars then
            se = (float("nan"), float("nan"))
        se = [float(v) if v is not None and np.isfinite(v) else None for v in se]
        out.append((name, float(G[0]), se[0], float(G[1]), se[1]))
    return out


def _modulus_text(value, se):
    return f"{value:.4g}" + ("" if se is None else f" ± {se:.2g}")


def text_fields(result):
    """``(label, text)`` of N, A, μ, seed and run id as recorded (the head of the summary).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of tuple
    """
    p = result.parameters or {}
    return [("N", str(p.get("N", "?"))), ("A", str(p.get("theAmplitude", "?"))), ("μ", str(p.get("theMu", "?"))),
            ("seed", seed_text(result)), ("run_id", result.run_id or "–")]


def seed_text(result):
    """The seed entropy and spawn key as the summary shows them.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    str
    """
    seed = "None" if result.seed is None else str(result.seed)
    if result.spawn_key:
        seed += " spawn " + ",".join(str(k) for k in result.spawn_key)
    return seed


def text_lines(result):
    """The summary's lines: G′, G″ of each estimator (± standard error over the measured periods where finite).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of str
    """
    return [f"  {name + ':':<9} G′ = {_modulus_text(g1, s1)} Pa, G″ = {_modulus_text(g2, s2)} Pa"
            for name, g1, s1, g2, s2 in _estimator_rows(result)]


def html_rows(result):
    """The summary as table cells: the header ``(estimator, G′ (Pa), G″ (Pa))`` and one row per estimator.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    header : tuple of str
    rows : list of tuple of str
    """
    return (("estimator", "G′ (Pa)", "G″ (Pa)"),
            [(name, _modulus_text(g1, s1), _modulus_text(g2, s2)) for name, g1, s1, g2, s2 in _estimator_rows(result)])


def verdict_text(result):
    """:func:`~particleShear.analysis.verdicts.verdict_lines` of the run; none when its measures fail.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of str
    """
    try:
        return verdict_lines(result.measures)
    except Exception:  # noqa: BLE001 - a repr never fails
        return []
