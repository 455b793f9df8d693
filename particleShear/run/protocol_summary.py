"""The summary of a :class:`~particleShear.run.result.SimulationResult` of a protocol other than "oscillatory".

A run of ``steady``, ``relaxation`` or ``creep`` holds its scalars in ``summary`` (with their
standard errors and checks) and its G(t) or J(t) in ``curves``; a sweep holds one entry per step
in ``steps`` (docs/protocols.md).  Here are the functions :mod:`particleShear.run.result` calls for
such a run: its results-table rows (one, or one per step of a sweep) and their inverse, the text
and HTML summaries, the verdict, the values ``doParticleShearSimulation`` returns and the figure;
and the columns they use.  The oscillatory run's: :mod:`particleShear.run.moduli_summary`.
"""
__docformat__ = "numpy"
import math

from .._version import __version__
from ..analysis.measures import MEASURE_COLUMNS, empty_measures
from ..analysis.verdicts import CHECKS, PROTOCOL_CHECKS, verdict as combined_verdict, verdict_lines
from ..parameters import BY_NAME, spec_defaults
from ..protocols import PROTOCOLS as REGISTRY, result_columns
from ..simulation.driver import dt_over_tau  # noqa: F401 - re-exported (moved to the driver)
from ..simulation.provenance import run_identity
from .moduli_summary import seed_text

__all__ = ["PLOT_ENTRY", "PROTOCOL_COLUMNS", "STEP_COLUMNS", "dt_over_tau", "unit", "measures", "verdict", "values", "to_dict",
           "rows", "from_rows", "text_fields", "text_lines", "html_rows", "verdict_text"]

#: the figure of a protocol run (:data:`particleShear.hooks.ENTRY_POINTS`)
PLOT_ENTRY = "plot_rheometer_result"

#: the result columns of the protocols, in table order (the summaries, the checks; the results
#: table's :data:`particleShear.sweep.schema.PROTOCOL_COLUMNS`), name → unit
_COLUMN_UNITS = {name: spec[1] for name, spec in result_columns(CHECKS)[0].items()}
_COLUMN_UNITS.update((name, "") for name in result_columns(CHECKS)[1])
PROTOCOL_COLUMNS = tuple(_COLUMN_UNITS)

#: key of a sweep step (``SimulationResult.steps``) -> its column in a results table (the other keys,
#: the moduli and measures, are columns of the same name)
STEP_COLUMNS = {"position": "sweep_position", "amplitude": "sweep_amplitude",
                "relative_frequency": "sweep_relative_frequency", "f": "frequency_Hz", "dt": "dt", "N_steps": "N_steps"}


def unit(name):
    """The unit of a summary number: its result column's, or its parameter's ("" when none).

    Parameters
    ----------
    name : str

    Returns
    -------
    str
    """
    if name in _COLUMN_UNITS:
        return _COLUMN_UNITS[name]
    par = BY_NAME.get(name)
    return par.unit if par is not None and par.kind in ("float", "int", "float_list") else ""


def measures(result):
    """The oscillatory measures of the run: empty (the checks of another protocol are in its
    ``summary``, a sweep's measures in each of its ``steps``).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict
    """
    return empty_measures()


def verdict(result):
    """``"ok"`` or ``"flagged: …"`` (:mod:`particleShear.analysis.verdicts`); a sweep's is that of its
    steps together (None when not judged).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    str or None
    """
    if not result.steps:
        return result.summary.get("verdict")
    names = PROTOCOL_CHECKS[result.protocol]
    return combined_verdict({n: (False if any(st.get(n) is False for st in result.steps) else None) for n in names})


def values(result):
    """The protocol's main numbers: steady ``[σ, η]`` (surface), relaxation ``[G_plateau]``, creep
    ``[final creep rate, σ₀/γ̇]``, sweeps ``[[G′, G″], …]`` per step (surface).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list
    """
    of_summary = REGISTRY[result.protocol].values
    if of_summary is not None:
        return of_summary(result.summary)
    return [[st["Gp_surface"], st["Gpp_surface"]] for st in result.steps]


def rows(result):
    """The rows of the run in a sweep's results table: one, or one per step of a sweep.

    Keys as :func:`particleShear.sweep.table.table_columns` of a protocol sweep: ``run_id``,
    ``status`` ("ok"), ``error``, the moduli and measures (sweep steps), the run columns
    (``repetition``, ``frequency_Hz`` and ``omega`` of a sweep step, ``dt``, ``N_steps``), the
    protocol columns (:data:`PROTOCOL_COLUMNS`: the summary, or ``sweep_position``,
    ``sweep_amplitude``, ``sweep_relative_frequency`` of a step), every parameter,
    ``seed_entropy``, ``spawn_key``, ``package_version``, ``wall_time_s`` (s), ``output_path``.
    Columns a protocol does not produce are absent (empty cells).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of dict
    """
    params = spec_defaults(protocols=True)
    params.update({k: v for k, v in result.parameters.items() if k in params})
    base = {"run_id": run_identity(params, result.seed, result.spawn_key), "status": "ok", "error": "",
            "repetition": int(result.repetition), "dt": float(result.dt)}
    base.update({k: v for k, v in result.summary.items() if k in PROTOCOL_COLUMNS or k == "verdict"})
    if REGISTRY[result.protocol].recorded:
        base["N_steps"] = int(len(result.series["t"])) if "t" in result.series else None
    base.update(params)
    base.update(seed_entropy=result.seed, spawn_key=list(result.spawn_key), package_version=__version__,
                wall_time_s=float(sum(result.timings.values())), output_path=result.output_path or "")
    if not result.steps:
        return [base]
    out = []
    for st in result.steps:
        row = dict(base, **{STEP_COLUMNS.get(k, k): v for k, v in st.items()})
        row["omega"] = 2 * math.pi * float(st["f"])
        out.append(row)
    return out


def to_dict(result):
    """The run's one row (:func:`rows`).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        For a sweep, which has a row per step (use :meth:`~particleShear.run.result.SimulationResult.rows`).
    """
    out = rows(result)
    if len(out) != 1:
        raise ValueError(f"to_dict() is invalid for protocol={result.protocol!r}: the run has {len(out)} rows, one "
                         "per step; use rows()")
    return out[0]


def from_rows(cls, rows, parameters, seed, spawn_key, output_path=None):
    """The result of a finished run rebuilt from its table rows (no series, no curves): the summary,
    or the steps of a sweep, are the rows' values (the inverse of :func:`rows`).

    Parameters
    ----------
    cls : type
        The result type.
    rows : list of dict
        The run's typed rows (:func:`particleShear.sweep.schema.typed_row`), in step order.
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
    first = rows[0]
    proto = parameters["protocol"]
    inverse = {c: k for k, c in STEP_COLUMNS.items()}
    moduli = ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal") + tuple(MEASURE_COLUMNS)
    steps = [{inverse.get(c, c): r.get(c) for c in tuple(STEP_COLUMNS.values()) + moduli}
             for r in rows] if REGISTRY[proto].segmented else []
    summary = {} if steps else {c: first[c] for c in PROTOCOL_COLUMNS + ("verdict",) if first.get(c) is not None}
    dt = float(first["dt"])
    return cls.of_protocol(proto, dict(parameters), seed, tuple(spawn_key), first["run_id"],
                           dt / dt_over_tau(parameters), dt, {}, summary, {}, steps,
                           {"total": float(first.get("wall_time_s") or 0.0)}, output_path=output_path)


def text_fields(result):
    """``(label, text)`` of protocol, N, μ, seed and run id (the head of the summary).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of tuple
    """
    p = result.parameters or {}
    return [("protocol", result.protocol), ("N", str(p.get("N", "?"))), ("μ", str(p.get("theMu", "?"))),
            ("seed", seed_text(result)), ("run_id", result.run_id or "–")]


def _number_text(v, se=None):
    text = f"{v:.4g}" if isinstance(v, (float, int)) and not isinstance(v, bool) else str(v)
    if isinstance(se, float) and math.isfinite(se):
        text += f" ± {se:.2g}"
    return text


def _quantities(result):
    """``(name, value text, unit)``: the summary's numbers with their standard errors (``name_se``)
    where finite and the units of the results-table columns of the same names; for sweeps one row
    per step and estimator (G′, G″ in Pa)."""
    out = []
    if result.steps:
        for st in result.steps:
            label = REGISTRY[result.protocol].label(st)
            for est in ("surface", "internal"):
                out.append((f"{label} ({est})",
                            f"G′ = {_number_text(st.get('Gp_' + est, float('nan')), st.get('Gp_' + est + '_se'))}, "
                            f"G″ = {_number_text(st.get('Gpp_' + est, float('nan')), st.get('Gpp_' + est + '_se'))}",
                            "Pa"))
        return out
    for name, v in result.summary.items():
        if name.endswith("_se") or name in CHECKS or name == "verdict":
            continue
        u = unit(name)
        out.append((name, _number_text(v, result.summary.get(name + "_se")), "" if u == "1" else u))
    return out


def text_lines(result):
    """The summary's lines: each summary number with its standard error and unit (sweeps: G′, G″ of
    both estimators per step) — not the records.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of str
    """
    return [f"  {name}: {text}" + (f" {u}" if u else "") for name, text, u in _quantities(result)]


def html_rows(result):
    """The summary as table cells: the header ``(quantity, value, unit)`` and one row per quantity.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    header : tuple of str
    rows : list of tuple of str
    """
    return ("quantity", "value", "unit"), _quantities(result)


def verdict_text(result):
    """The verdict of the run (:func:`~particleShear.analysis.verdicts.verdict_lines`); a sweep's per step.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    list of str
    """
    if not result.steps:
        return verdict_lines(result.summary, result.protocol) if "verdict" in result.summary else []
    return [f"step {st.get('position', j)}: {st.get('verdict') or 'not judged'}" for j, st in enumerate(result.steps)]
