"""The results table of a sweep: ``DIR/results.csv``, one row per finished run.

Columns, in this order: ``run_id, status, error, Gp_surface, Gpp_surface, Gp_internal,
Gpp_internal`` (Pa), every parameter of the run (signature order of
``doParticleShearSimulation``), ``seed_entropy``, ``spawn_key`` (JSON list), ``package_version``,
``wall_time_s``, ``output_path``.

Rows are appended by one writer (the sweep's driving process) with a single ``os.write`` of a
complete line on an ``O_APPEND`` descriptor followed by ``fsync``, so a killed sweep leaves at
most one torn last line, which :func:`read_rows` drops and :func:`repair_table` cuts off.
"""
__docformat__ = "numpy"
import csv
import io
import json
import os

__all__ = ["RESULT_COLUMNS", "table_columns", "row_line", "append_row", "read_rows", "repair_table",
           "write_table", "write_parquet", "TABLE_NAME", "task_table_name"]

#: the first columns of every results table
RESULT_COLUMNS = ("run_id", "status", "error", "Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal")
_TAIL_COLUMNS = ("seed_entropy", "spawn_key", "package_version", "wall_time_s", "output_path")
TABLE_NAME = "results.csv"


def task_table_name(task_index, task_count):
    """Per-task table of a job-array task, merged by ``--merge``: ``results.task-0003-of-0010.csv``.

    Parameters
    ----------
    task_index : int
        The task's index, 0-based (``--task-index``).
    task_count : int
        Number of tasks sharing the sweep (``--task-count``).

    Returns
    -------
    str
        The file name (no folder).
    """
    return f"results.task-{task_index:04d}-of-{task_count:04d}.csv"


def table_columns(parameter_names=None):
    """All columns, given the parameter names (order of the module docstring).

    Parameters
    ----------
    parameter_names : iterable of str, optional
        The parameter columns, in order (default: every SPEC-settable parameter, signature
        order of ``doParticleShearSimulation``).

    Returns
    -------
    list of str
    """
    if parameter_names is None:
        from .spec import sweep_parameter_defaults
        parameter_names = list(sweep_parameter_defaults())
    return list(RESULT_COLUMNS) + list(parameter_names) + list(_TAIL_COLUMNS)


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):
        return json.dumps([int(x) for x in v])
    if isinstance(v, float):
        return repr(v)
    return str(v)


def row_line(row, columns):
    """One CSV line (with newline) of ``row`` in ``columns`` order; a missing value is empty.

    Parameters
    ----------
    row : dict
        Column name → value; lists and tuples are written as JSON, floats with ``repr``.
    columns : sequence of str
        The table's columns.

    Returns
    -------
    str
    """
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([_cell(row.get(c)) for c in columns])
    return buf.getvalue()


def repair_table(path):
    """Cut a torn last line (no trailing newline) left by a killed writer.

    Parameters
    ----------
    path : str or os.PathLike
        The table; nothing happens when it does not exist.

    Returns
    -------
    bool
        True when the file was cut.
    """
    if not os.path.exists(path):
        return False
    with open(path, "rb+") as fh:
        data = fh.read()
        if not data or data.endswith(b"\n"):
            return False
        fh.truncate(data.rfind(b"\n") + 1)
        fh.flush()
        os.fsync(fh.fileno())
    return True


def append_row(path, row, columns):
    """Append ``row`` to the table at ``path`` (header first when new); flushed and fsynced.

    Parameters
    ----------
    path : str or os.PathLike
        The table (created when absent); a torn last line is cut first (:func:`repair_table`).
    row : dict
        Column name → value (see :func:`row_line`).
    columns : sequence of str
        The table's columns; must equal the existing header.

    Raises
    ------
    ValueError
        When an existing table has other columns (another package version or parameter set).
    """
    repair_table(path)
    new = not os.path.exists(path) or os.path.getsize(path) == 0
    if not new:
        with open(path, newline="", encoding="utf-8") as fh:
            header = next(csv.reader(fh), None)
        if header != list(columns):
            raise ValueError(f"results table {path!r} has other columns than this sweep: use another --out DIR")
    text = (row_line({c: c for c in columns}, columns) if new else "") + row_line(row, columns)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    try:
        data = text.encode("utf-8")
        while data:  # one write in practice; bounded by the length of the line
            n = os.write(fd, data)
            data = data[n:]
        os.fsync(fd)
    finally:
        os.close(fd)


def read_rows(path):
    """Rows of a table as a list of dicts of strings (a torn last line is ignored); [] when absent.

    Parameters
    ----------
    path : str or os.PathLike
        The table.

    Returns
    -------
    list of dict
    """
    if not os.path.exists(path):
        return []
    with open(path, newline="", encoding="utf-8") as fh:
        text = fh.read()
    if text and not text.endswith("\n"):
        text = text[:text.rfind("\n") + 1]
    return list(csv.DictReader(io.StringIO(text)))


def write_table(path, rows, columns):
    """Write a complete table atomically (temporary file in the same folder, fsync, rename).

    Parameters
    ----------
    path : str or os.PathLike
        The table; replaced as a whole.
    rows : iterable of dict
        The rows (see :func:`row_line`).
    columns : sequence of str
        The header and column order.
    """
    tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".part")
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        fh.write(row_line({c: c for c in columns}, columns))
        for row in rows:
            fh.write(row_line(row, columns))
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def write_parquet(csv_path):
    """Write ``results.parquet`` next to ``csv_path`` when pyarrow is installed; its path, or None.

    Numeric columns are typed by pyarrow's CSV reader; ``error`` and ``output_path`` stay strings.

    Parameters
    ----------
    csv_path : str or os.PathLike
        The results table; ``results.parquet`` is written beside it (atomically).

    Returns
    -------
    str or None
        The Parquet file's path; None without pyarrow or without the CSV file.
    """
    try:
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq
        import pyarrow as pa
    except ImportError:
        return None
    if not os.path.exists(csv_path):
        return None
    with open(csv_path, newline="", encoding="utf-8") as fh:
        header = next(csv.reader(fh), [])
    strings = {c: pa.string() for c in ("run_id", "status", "error", "spawn_key", "package_version",
                                       "output_path") if c in header}
    table = pacsv.read_csv(csv_path, convert_options=pacsv.ConvertOptions(column_types=strings,
                                                                          strings_can_be_null=False))
    out = os.path.splitext(csv_path)[0] + ".parquet"
    tmp = os.path.join(os.path.dirname(out) or ".", "." + os.path.basename(out) + ".part")
    pq.write_table(table, tmp)
    os.replace(tmp, out)
    return out
