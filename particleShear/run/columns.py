"""The columns of a results table: their names and order, and each column's type, unit and description.

A run's row (:meth:`~particleShear.run.result.SimulationResult.to_dict`, the rheometer's rows) and a
sweep's ``results.csv`` (:mod:`particleShear.sweep.table`) have these columns; the schema file
``results.schema.json`` (:mod:`particleShear.sweep.schema`, which re-exports the names here) states
them, and :func:`typed_value` reads a cell back as its column's type (the types:
:mod:`particleShear.sweep.schema`'s docstring).  A parameter's column is the parameter table's entry
(:mod:`particleShear.parameters`).
"""
__docformat__ = "numpy"
import json

from ..analysis.measures import MEASURE_COLUMNS
from ..analysis.verdicts import CHECKS
from ..parameters import BY_NAME, spec_defaults
from ..protocols import PROTOCOLS, result_columns

__all__ = ["SCHEMA_NAME", "COLUMN_TYPES", "RUN_COLUMNS", "PROTOCOL_COLUMNS", "RESULT_COLUMNS", "TABLE_NAME",
           "column_spec", "table_columns", "read_schema", "typed_value", "cell_problem"]

#: file name of the schema beside ``results.csv``
SCHEMA_NAME = "results.schema.json"
#: the allowed column types (module docstring)
COLUMN_TYPES = ("float", "int", "bool", "string", "bigint", "int_list", "float_list")
#: the run's time scales and repetition, after the measures in the table (docs/sweeps.md)
RUN_COLUMNS = ("repetition", "frequency_Hz", "omega", "dt", "N_steps")

_G = "{} modulus G{} from the {} (Pa); empty for a failed run"
_CHECK = ("check {0}: True when it passes, False when it fails, empty when it cannot be judged (rule: "
          "particleShear.analysis.verdicts.CHECKS['{0}'], docs/analysis.md \"Verdicts\")")
_SE = "standard error of {} over the measured excitation periods (Pa); NaN with fewer than 2 periods"
#: column -> (type, unit, description, nullable) of every column that is not a parameter
_FIXED = {
    "run_id": ("string", "", "12 hex digits identifying the complete parameter set and seed", False),
    "status": ("string", "", "'ok' or 'failed'", False),
    "error": ("string", "", "exception type and message of a failed run; empty when ok", False),
    "Gp_surface": ("float", "Pa", _G.format("storage", "′", "plate (surface) forces"), True),
    "Gpp_surface": ("float", "Pa", _G.format("loss", "″", "plate (surface) forces"), True),
    "Gp_internal": ("float", "Pa", _G.format("storage", "′", "internal estimator (stress tensor, eq. S1-24)"), True),
    "Gpp_internal": ("float", "Pa", _G.format("loss", "″", "internal estimator (stress tensor, eq. S1-24)"), True),
    "Gp_surface_se": ("float", "Pa", _SE.format("Gp_surface"), True),
    "Gpp_surface_se": ("float", "Pa", _SE.format("Gpp_surface"), True),
    "Gp_internal_se": ("float", "Pa", _SE.format("Gp_internal"), True),
    "Gpp_internal_se": ("float", "Pa", _SE.format("Gpp_internal"), True),
    "steady_state": ("bool", "", "False when a modulus drifts from period to period beyond its error, True when "
                     "none does; empty with fewer than 3 measured periods (docs/analysis.md)", True),
    "I3_I1_surface": ("float", "1", "intensity ratio of the third to the first stress harmonic, surface stress", True),
    "I3_I1_internal": ("float", "1", "intensity ratio of the third to the first stress harmonic, internal stress",
                       True),
    "S_surface": ("float", "1", "Ewoldt-Hosoi-McKinley stiffening ratio S, surface stress", True),
    "T_surface": ("float", "1", "Ewoldt-Hosoi-McKinley thickening ratio T, surface stress", True),
    "S_internal": ("float", "1", "Ewoldt-Hosoi-McKinley stiffening ratio S, internal stress", True),
    "T_internal": ("float", "1", "Ewoldt-Hosoi-McKinley thickening ratio T, internal stress", True),
    "linear_response": ("bool", "", _CHECK.format("linear_response"), True),
    "estimators_agree": ("bool", "", _CHECK.format("estimators_agree"), True),
    "moduli_positive": ("bool", "", _CHECK.format("moduli_positive"), True),
    "excitation_resolved": ("bool", "", _CHECK.format("excitation_resolved"), True),
    "verdict": ("string", "", "'ok' when no check of the run failed, else 'flagged: ' and the failed checks' names "
                "(docs/analysis.md, \"Verdicts\"); empty for a failed run", True),
    "irreversibility": ("float", "1", "mean squared non-affine displacement per excitation cycle between stroboscopic "
                        "snapshots after the transient cycle, / mean radius²; empty unless stroboscopic "
                        "(docs/microstructure.md)", True),
    "moved_fraction": ("float", "1", "mean fraction of spheres whose non-affine displacement per cycle exceeds "
                       "0.1 of their radius, after the transient; empty unless stroboscopic", True),
    "Z_rattler_free": ("float", "1", "contacts per sphere with rattlers (< 3 contacts, iteratively) removed, at the "
                       "snapshots after the transient; empty unless stroboscopic", True),
    "rattler_fraction": ("float", "1", "fraction of spheres that are rattlers at the snapshots after the transient; "
                         "empty unless stroboscopic", True),
    "contact_change_rate": ("float", "1/cycle", "contacts made + broken per cycle per contact, after the transient; "
                            "empty unless stroboscopic", True),
    "repetition": ("int", "", "index of the run among the repetitions of its parameter point (0-based; "
                   "SweepRun.repetition)", False),
    "frequency_Hz": ("float", "Hz", "excitation frequency f; empty for a failed run", True),
    "omega": ("float", "rad/s", "angular excitation frequency 2πf; empty for a failed run", True),
    "dt": ("float", "s", "protocol time step; empty for a failed run", True),
    "N_steps": ("int", "", "number of protocol steps; empty for a failed run", True),
    "seed_entropy": ("bigint", "", "entropy of the run's numpy.random.SeedSequence (the SPEC's [seeds] root; "
                     "an integer below 2**128)", False),
    "spawn_key": ("int_list", "", "spawn key of the run's SeedSequence, a JSON list ([k] for run k of a sweep)",
                  False),
    "package_version": ("string", "", "particleShear version that measured the run", False),
    "wall_time_s": ("float", "s", "wall time of the run", False),
    "output_path": ("string", "", "the run's output file, relative to the sweep folder; empty when none", False),
}


def _protocol_columns():
    """The outputs of the rheometer's protocols (docs/protocols.md), from their files
    (:func:`particleShear.protocols.result_columns`: the step columns of the sweeps, the summaries,
    then the checks in the order of :data:`~particleShear.analysis.verdicts.CHECKS`)."""
    values, checks = result_columns(CHECKS)
    out = dict(values)
    for c, names in checks.items():
        text = _CHECK.format(c) if c in CHECKS else PROTOCOLS[names[0]].columns[c][2]
        out[c] = ("bool", "", text + "; empty unless protocol is " + " or ".join(f"'{n}'" for n in names))
    return out


#: the outputs of the rheometer's protocols, after the run columns in a table whose SPEC sets a
#: protocol parameter: name -> (type, unit, description)
_PROTOCOL_FIXED = _protocol_columns()
#: the protocol columns, in table order
PROTOCOL_COLUMNS = tuple(_PROTOCOL_FIXED)
_FIXED.update({k: v + (True,) for k, v in _PROTOCOL_FIXED.items()})
def column_spec(name):
    """The schema entry of one column of a results table (a parameter or a fixed column).

    Parameters
    ----------
    name : str
        The column.

    Returns
    -------
    dict
        ``{"name", "type", "unit", "description", "nullable"}``; a column the package does not
        know is a nullable ``string`` without description.
    """
    if name not in _spec_cache:
        _spec_cache[name] = _column_spec(name)
    return dict(_spec_cache[name])


_spec_cache = {}


def _column_spec(name):
    if name in _FIXED:
        kind, unit, text, nullable = _FIXED[name]
        return {"name": name, "type": kind, "unit": unit, "description": text, "nullable": nullable}
    if name not in spec_defaults(True):
        return {"name": name, "type": "string", "unit": "", "description": "", "nullable": True}
    par = BY_NAME[name]
    kind = {"float_list": "float_list", "bool": "bool", "int": "int", "float": "float"}.get(par.kind, "string")
    unit = par.unit if kind in ("float", "int", "float_list") else ""
    text = par.doc
    if par.has_range:
        text += f"; allowed {par.range_text()}"
    return {"name": name, "type": kind, "unit": unit,
            "description": f"parameter {name} of doParticleShearSimulation: {text}" if text else
            f"parameter {name} of doParticleShearSimulation", "nullable": par.nullable}


#: the first columns of every results table
RESULT_COLUMNS = ("run_id", "status", "error", "Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal") \
    + MEASURE_COLUMNS + RUN_COLUMNS
_TAIL_COLUMNS = ("seed_entropy", "spawn_key", "package_version", "wall_time_s", "output_path")
TABLE_NAME = "results.csv"


def table_columns(parameter_names=None):
    """All columns, given the parameter names (order of :mod:`particleShear.sweep.table`'s docstring).

    Parameters
    ----------
    parameter_names : iterable of str, optional
        The parameter columns, in order (default: every SPEC-settable parameter of the
        oscillatory protocol, signature order of ``doParticleShearSimulation``).  When they hold
        ``protocol``, the protocol columns come before them.

    Returns
    -------
    list of str
    """
    if parameter_names is None:
        parameter_names = list(spec_defaults(False))
    parameter_names = list(parameter_names)
    extra = list(PROTOCOL_COLUMNS) if "protocol" in parameter_names else []
    return list(RESULT_COLUMNS) + extra + parameter_names + list(_TAIL_COLUMNS)


def read_schema(path):
    """The schema in ``path`` (a ``results.schema.json``), checked.

    Parameters
    ----------
    path : str
        The schema file.

    Returns
    -------
    dict
        As :func:`results_schema`.

    Raises
    ------
    ValueError
        When the file is not JSON or an entry has no name or an unknown type.
    """
    try:
        with open(path, encoding="utf-8") as fh:
            doc = json.load(fh)
    except (OSError, ValueError) as exc:
        raise ValueError(f"schema {path!r} cannot be read ({exc}): delete it to use the package's schema") from None
    cols = doc.get("columns") if isinstance(doc, dict) else None
    if not isinstance(cols, list) or not all(isinstance(c, dict) and isinstance(c.get("name"), str)
                                             and c.get("type") in COLUMN_TYPES for c in cols):
        raise ValueError(f"schema {path!r} is invalid: allowed 'columns', a list of entries with a name and a type "
                         f"in {list(COLUMN_TYPES)}")
    return doc


def typed_value(text, kind):
    """The value of one table cell as its column's type (:mod:`particleShear.sweep.schema`); empty text is None.

    Parameters
    ----------
    text : str or None
        The cell as read back (a value already typed is returned converted).
    kind : str
        One of :data:`COLUMN_TYPES`.

    Returns
    -------
    object

    Raises
    ------
    ValueError
        When the text is not a value of that type.
    """
    if kind == "string":
        return "" if text is None else str(text)
    if text is None or text == "":
        return None
    if not isinstance(text, str):
        if kind == "float":
            return float(text)
        if kind in ("int", "bigint"):
            return _integer(text)
        if kind == "bool":
            return bool(text)
        return [float(x) for x in text] if kind == "float_list" else [int(x) for x in text]
    if kind == "float":
        return float(text)
    if kind in ("int", "bigint"):
        return _integer(text)
    if kind == "bool":
        if text in ("True", "true", "1"):
            return True
        if text in ("False", "false", "0"):
            return False
        raise ValueError(f"{text!r} is not True or False")
    value = json.loads(text)
    if kind == "float_list":
        if not isinstance(value, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                  for x in value):
            raise ValueError(f"{text!r} is not a JSON list of numbers")
        return [float(x) for x in value]
    if not isinstance(value, list) or not all(isinstance(x, int) and not isinstance(x, bool) for x in value):
        raise ValueError(f"{text!r} is not a JSON list of integers")
    return value


def _integer(v):
    if isinstance(v, bool):
        raise ValueError(f"{v!r} is not an integer")
    if isinstance(v, int):
        return v
    try:
        return int(v)
    except (TypeError, ValueError):
        x = float(v)
        if not x.is_integer():
            raise ValueError(f"{v!r} is not an integer") from None
        return int(x)


def cell_problem(text, kind):
    """Why ``text`` is not a value of type ``kind`` (None when it is, or when it is empty).

    Parameters
    ----------
    text : str or None
        A cell as read back.
    kind : str
        One of :data:`COLUMN_TYPES`.

    Returns
    -------
    str or None
    """
    try:
        typed_value(text, kind)
    except (TypeError, ValueError) as exc:
        return str(exc) or f"{text!r} is not a {kind}"
    return None
