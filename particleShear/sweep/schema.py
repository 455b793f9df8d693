"""The schema of a results table: every column's type, unit and description, defined once.

A sweep writes it as ``DIR/results.schema.json`` beside ``DIR/results.csv``
(:func:`write_schema`), :func:`load_results` applies it when it reads the table back, and
``results.parquet`` carries it (:func:`arrow_schema`: the types as Arrow types, unit and
description as field metadata).  ``run_sweep`` returns rows typed by it (:func:`typed_row`).

Column types (``"type"`` in the JSON file):

==============  =========================  ======================  ====================
type            Python value (typed dict)  pandas dtype            Arrow type
==============  =========================  ======================  ====================
``float``       float (empty: None)        ``float64`` (NaN)       ``double``
``int``         int (empty: None)          ``int64`` / ``Int64``   ``int64``
``bool``        bool (empty: None)         ``bool`` / ``boolean``  ``bool``
``string``      str (empty: "")            ``str`` / ``object``    ``string``
``bigint``      int of any size            ``object``              ``string`` (decimal)
``int_list``    list of int (JSON text)    ``object``              ``list<int64>``
``float_list``  list of float (JSON text)  ``object``              ``list<double>``
==============  =========================  ======================  ====================

A column that may be empty (``"nullable": true``: the moduli, measures and run columns of a
failed row, ``steady_state`` when it cannot be judged, the columns of the protocols that a row's
protocol does not produce) gets pandas' nullable dtype for ints and
bools (``Int64``, ``boolean``); floats are NaN where empty.
"""
__docformat__ = "numpy"
import json
import os
import warnings
from ..analysis.verdicts import CHECKS
from ..parameters import BY_NAME
from ..protocols import PROTOCOLS, result_columns

__all__ = ["SCHEMA_NAME", "COLUMN_TYPES", "RUN_COLUMNS", "PROTOCOL_COLUMNS", "results_schema", "column_spec", "write_schema",
           "read_schema", "typed_value", "typed_row", "cell_problem", "arrow_schema", "arrow_table",
           "load_results"]

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
    from .spec import sweep_parameter_defaults
    if name not in sweep_parameter_defaults(protocols=True):
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


def results_schema(columns=None):
    """The schema of a results table: one entry per column, in table order.

    Parameters
    ----------
    columns : sequence of str, optional
        The table's columns (default: :func:`~particleShear.sweep.table.table_columns`).

    Returns
    -------
    dict
        ``{"format": "particleShear results schema", "version": 1, "columns": [entry, ...]}``,
        each entry as :func:`column_spec`.
    """
    if columns is None:
        from .table import table_columns
        columns = table_columns()
    return {"format": "particleShear results schema", "version": 1, "table": "results.csv",
            "columns": [column_spec(c) for c in columns]}


def write_schema(folder, columns):
    """Write ``folder/results.schema.json`` (atomically) for a table of ``columns``; its path.

    Parameters
    ----------
    folder : str
        The sweep folder.
    columns : sequence of str
        The table's columns.

    Returns
    -------
    str
    """
    from .table import atomic_text
    path = os.path.join(folder, SCHEMA_NAME)
    text = json.dumps(results_schema(columns), indent=1, ensure_ascii=False) + "\n"
    try:
        with open(path, encoding="utf-8") as fh:
            if fh.read() == text:
                return path
    except OSError:
        pass
    with atomic_text(path) as fh:
        fh.write(text)
    return path


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
    """The value of one table cell as its column's type (module docstring); empty text is None.

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


def typed_row(row, schema=None):
    """A table row (dict of strings) with every value typed by the schema.

    Parameters
    ----------
    row : dict
        Column -> text (as :func:`~particleShear.sweep.table.read_rows` gives).
    schema : dict, optional
        As :func:`results_schema` (default: the package's entry of each column).

    Returns
    -------
    dict
        Same keys and order; values as the module docstring's "Python value".

    Raises
    ------
    ValueError
        Naming the column and the text, when a cell is not a value of its type.
    """
    kinds = {c["name"]: c["type"] for c in schema["columns"]} if schema else {}
    out = {}
    for name, text in row.items():
        kind = kinds.get(name) or column_spec(name)["type"]
        try:
            out[name] = typed_value(text, kind)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"column {name}={text!r} is not of type {kind} ({exc})") from None
    return out


def arrow_schema(schema):
    """The ``pyarrow.Schema`` of a results schema: Arrow types, unit and description as field metadata.

    Parameters
    ----------
    schema : dict
        As :func:`results_schema`.

    Returns
    -------
    pyarrow.Schema
        Field metadata ``type`` (the schema's type), ``unit``, ``description``; schema metadata
        ``particleShear.schema``: the schema as JSON.
    """
    import pyarrow as pa
    arrow = {"float": pa.float64(), "int": pa.int64(), "bool": pa.bool_(), "string": pa.string(),
             "bigint": pa.string(), "int_list": pa.list_(pa.int64()), "float_list": pa.list_(pa.float64())}
    fields = [pa.field(c["name"], arrow[c["type"]], nullable=True,
                       metadata={"type": c["type"], "unit": c.get("unit", ""),
                                 "description": c.get("description", "")}) for c in schema["columns"]]
    return pa.schema(fields, metadata={"particleShear.schema": json.dumps(schema, ensure_ascii=False)})


def arrow_table(rows, schema):
    """A ``pyarrow.Table`` of typed rows (:func:`typed_row`) under :func:`arrow_schema`.

    Parameters
    ----------
    rows : list of dict
        Typed rows.
    schema : dict
        As :func:`results_schema`.

    Returns
    -------
    pyarrow.Table
    """
    import pyarrow as pa
    sch = arrow_schema(schema)
    cols = []
    for c in schema["columns"]:
        values = [r.get(c["name"]) for r in rows]
        if c["type"] == "bigint":
            values = [None if v is None else str(v) for v in values]
        cols.append(pa.array(values, type=sch.field(c["name"]).type))
    return pa.Table.from_arrays(cols, schema=sch)


def load_results(folder_or_csv, as_frame=None):
    """A sweep's results table, typed by its schema: a pandas DataFrame, or a list of typed dicts.

    Reads ``DIR/results.csv`` with the package's one table reader
    (:func:`~particleShear.sweep.reader.read_table`) and applies ``DIR/results.schema.json`` (the
    package's schema of the table's columns when the file is absent).  Every row is kept, ``ok``
    and ``failed``, in the table's order (SPEC order once a sweep has finished), except lines
    that are not rows (a torn last line, another number of fields) and duplicate rows (same
    ``run_id`` and step): those are left out with a ``UserWarning`` each (also in the
    DataFrame's ``attrs["notes"]``).

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder, or a results table (``.csv``) itself (its schema is looked for beside it).
    as_frame : bool, optional
        True: a DataFrame (needs pandas, the extra ``[tables]``); False: a list of dicts; None
        (default): a DataFrame when pandas is installed, else the list.  Code that indexes the
        result as a DataFrame should pass True, so a missing pandas is an error saying so.

    Returns
    -------
    pandas.DataFrame or list of dict
        Columns typed as the schema says (module docstring): moduli float64, ``N`` int64,
        ``steady_state`` boolean (nullable), ``N_steps`` Int64, parameters of their type,
        strings as strings.

    Raises
    ------
    ValueError
        When there is no table, the table cannot be read (naming the file), a cell is not a value
        of its column's type (naming the file, the line and the column), or ``as_frame`` is not
        None, True or False.
    ImportError
        When ``as_frame=True`` and pandas is not installed (naming the extra ``[tables]``), before
        the table is read.
    """
    from .reader import read_table
    from .table import TABLE_NAME
    if as_frame not in (None, True, False):
        raise ValueError(f"as_frame={as_frame!r} is invalid: allowed None, True or False")
    if as_frame:
        try:
            __import__("pandas")            # checked before the table is read
        except ImportError:
            raise ImportError("load_results(as_frame=True) needs pandas: pip install \"particleShear[tables]\" "
                              "(from this source, see README 'Install'), or pass as_frame=False for a list of "
                              "typed dicts") from None
    path = os.fspath(folder_or_csv)
    if os.path.isdir(path):
        path = os.path.join(path, TABLE_NAME)
    if not os.path.isfile(path):
        raise ValueError(f"folder_or_csv={os.fspath(folder_or_csv)!r} is invalid: no results table there")
    table = read_table(path)
    for note in table.notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    if as_frame is False:
        return table.typed_rows()
    try:
        frame = table.to_frame()
    except ImportError:
        if as_frame:
            raise
        return table.typed_rows()
    frame.attrs["notes"] = list(table.notes)
    return frame
