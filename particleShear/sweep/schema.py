"""The schema of a results table: every column's type, unit and description, defined once.

A sweep writes it as ``DIR/results.schema.json`` beside ``DIR/results.csv``
(:func:`~particleShear.sweep.table.write_schema`), :func:`load_results` applies it when it reads the table back, and
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

from ..run.columns import (COLUMN_TYPES, PROTOCOL_COLUMNS, RUN_COLUMNS, SCHEMA_NAME,  # noqa: F401 - re-exported
                           TABLE_NAME, cell_problem, column_spec, read_schema, table_columns, typed_value)
from .reader import read_table

__all__ = ["SCHEMA_NAME", "COLUMN_TYPES", "RUN_COLUMNS", "PROTOCOL_COLUMNS", "results_schema", "column_spec",
           "read_schema", "typed_value", "typed_row", "cell_problem", "arrow_schema", "arrow_table",
           "load_results"]


def results_schema(columns=None):
    """The schema of a results table: one entry per column, in table order.

    Parameters
    ----------
    columns : sequence of str, optional
        The table's columns (default: :func:`~particleShear.run.columns.table_columns`).

    Returns
    -------
    dict
        ``{"format": "particleShear results schema", "version": 1, "columns": [entry, ...]}``,
        each entry as :func:`column_spec`.
    """
    if columns is None:
        columns = table_columns()
    return {"format": "particleShear results schema", "version": 1, "table": "results.csv",
            "columns": [column_spec(c) for c in columns]}


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
