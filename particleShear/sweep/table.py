"""The results table of a sweep: ``DIR/results.csv``, one row per finished run.

Columns, in this order: ``run_id, status, error, Gp_surface, Gpp_surface, Gp_internal,
Gpp_internal`` (Pa), the measures of :data:`~particleShear.analysis.measures.MEASURE_COLUMNS`
(standard errors in Pa, ``steady_state``, LAOS ratios; docs/analysis.md), the run columns
:data:`~particleShear.sweep.schema.RUN_COLUMNS` (``repetition, frequency_Hz, omega, dt, N_steps``),
then — in a table whose sweep sets a protocol parameter (docs/protocols.md) — the protocol columns
:data:`~particleShear.sweep.schema.PROTOCOL_COLUMNS`, every parameter of the run (signature
order of ``doParticleShearSimulation``), ``seed_entropy``,
``spawn_key`` (JSON list), ``package_version``, ``wall_time_s``, ``output_path``.  Each column's
type, unit and description: :mod:`particleShear.sweep.schema` (``DIR/results.schema.json``).

A run of a one-packing sweep protocol has one row per step (``sweep_position`` 0, 1, ...), all
written in one append; every other run has one row.

Rows are appended by one writer (the sweep's driving process) with a single ``os.write`` of
complete lines on an ``O_APPEND`` descriptor followed by ``fsync``, so a killed sweep leaves at
most one torn last line.  Every table is read by :func:`~particleShear.sweep.reader.read_table`
(the one reader of the package: torn lines set aside, cells checked against the schema, no
field-size limit, duplicate rows removed); the sweep repairs its table once, when it opens it
(:func:`check_table`), and then only appends (:func:`append_row`: one write, no read of the table).
A cell that starts with ``=``, ``+``, ``-``, ``@`` and is not a number is written with a leading
``'`` (:func:`~particleShear.sweep.reader.escape_cell`), which the reader removes.
"""
__docformat__ = "numpy"
import contextlib
import csv
import io
import json
import numbers
import os
import secrets
import socket

import numpy as np

from .reader import escape_cell, read_table
from ..signals import dead_leftovers
from ..analysis.measures import MEASURE_COLUMNS
from ..parameters import BY_NAME, identity_excluded
from ..protocols import PROTOCOLS
from ..simulation.provenance import identity_parameters, same_input
from ..run.columns import (PROTOCOL_COLUMNS, RESULT_COLUMNS, RUN_COLUMNS, SCHEMA_NAME, TABLE_NAME,  # noqa: F401 - re-exported
                           cell_problem, column_spec, table_columns)
from .schema import arrow_table, results_schema

__all__ = ["RESULT_COLUMNS", "table_columns", "row_line", "append_row", "read_rows", "repair_table",
           "write_table", "write_parquet", "TABLE_NAME", "task_table_name", "check_table", "row_problem", "atomic_text",
           "reject_lines", "remove_dead_temporaries",
           "REJECTED_SUFFIX", "sort_table", "write_schema"]

#: lines of a table that cannot be rows (wrong number of fields) are moved to ``<table>`` + this suffix
REJECTED_SUFFIX = ".rejected"



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


def _cell(v):
    """Text of one value: lists as JSON, NumPy scalars as the Python number they are (``0.2``, not
    ``np.float64(0.2)``), floats with ``repr`` (round trip), other values with ``str``."""
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):   # a spawn key (integers) or a sweep's list of values (floats)
        ints = all(isinstance(x, numbers.Integral) and not isinstance(x, (bool, np.bool_)) for x in v)
        return json.dumps([int(x) if ints else float(x) for x in v])
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        return repr(float(v))
    return str(v)


def row_line(row, columns):
    """One CSV line (with newline) of ``row`` in ``columns`` order; a missing value is empty.

    A text that a spreadsheet would evaluate (it starts with ``=``, ``+``, ``-``, ``@``, a tab, a
    carriage return or ``'`` and is not a number) is written with a leading ``'``
    (:func:`~particleShear.sweep.reader.escape_cell`; the reader removes it).

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
    csv.writer(buf, lineterminator="\n").writerow([escape_cell(_cell(row.get(c))) for c in columns])
    return buf.getvalue()


def repair_table(path):
    """Cut a torn last line (no trailing newline) left by a killed writer; it is kept in ``<table>.rejected``.

    Reads only the end of the file (backwards from the end to the last newline), so its cost does
    not grow with the table.

    Parameters
    ----------
    path : str or os.PathLike
        The table; nothing happens when it does not exist.

    Returns
    -------
    bool
        True when the file was cut.
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        return False
    with open(path, "rb+") as fh:
        end = fh.seek(0, os.SEEK_END)
        if end == 0:
            return False
        fh.seek(end - 1)
        if fh.read(1) == b"\n":
            return False
        pos, cut = end, 0
        while pos > 0:                              # find the last newline, block by block from the end
            step = min(65536, pos)
            pos -= step
            fh.seek(pos)
            block = fh.read(step)
            k = block.rfind(b"\n")
            if k >= 0:
                cut = pos + k + 1
                break
        fh.seek(cut)
        torn = fh.read()
        if cut > 0:                                 # a torn header alone (cut == 0) is no line worth keeping
            _reject_bytes(path, [torn + b"\n"])
        fh.truncate(cut)
        fh.flush()
        os.fsync(fh.fileno())
    return True


def _reject_bytes(path, lines):
    """Append raw ``lines`` (bytes, each ending with a newline) to ``<table>.rejected``, fsynced."""
    if not lines:
        return
    with open(os.fspath(path) + REJECTED_SUFFIX, "ab") as fh:
        fh.writelines(lines)
        fh.flush()
        os.fsync(fh.fileno())


def check_table(path, columns):
    """Check a table before any work: repair what can be repaired, refuse what cannot.

    The table is read by the package's one reader (:func:`~particleShear.sweep.reader.read_table`).
    Repaired (and said in the returned notes): a UTF-8 byte-order mark before the header (an
    editor's), a torn last line (a killed writer), lines that are not rows of the table (another
    number of fields, a quote left open, bytes that are not UTF-8) and duplicate rows (same
    ``run_id`` and step; the first ``ok`` row is kept) — those lines are moved, unchanged, to
    ``<table>.rejected``, so nothing is lost.  Cells that are not values of their column's type
    stay: the sweep runs their run again (:func:`row_problem`).  Refused: a header that is not
    this sweep's columns (other package version, parameter set, edited by hand), a header that is
    not UTF-8 text.

    Parameters
    ----------
    path : str
        The table (nothing happens when it does not exist or is empty).
    columns : sequence of str
        This sweep's columns.

    Returns
    -------
    list of str
        What was repaired, one note each.

    Raises
    ------
    ValueError
        When the header differs from ``columns``, naming the missing and unknown columns, or the
        table cannot be read (naming the file).
    """
    notes = []
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return notes
    if repair_table(path):
        notes.append(f"cut a torn last line of {path} (kept in {path + REJECTED_SUFFIX})")
    if os.path.getsize(path) == 0:
        return notes
    with open(path, "rb") as fh:
        bom = fh.read(3) == b"\xef\xbb\xbf"
    added = add_result_columns(path, columns)
    if added:
        notes.append(f"added the column(s) {added} of this version to {path} (results empty in its earlier rows: "
                     "not evaluated when they ran; parameters at their defaults)")
    table = read_table(path, schema="package", invalid="keep")
    check_table_header(path, columns)
    aside = {k for k, _ in table.set_aside} | {k for k, _ in table.duplicates}
    if bom or aside:
        bad = []
        with open(path, "rb") as src, atomic_text(path) as out:
            for k, raw in enumerate(src, start=1):
                if k == 1 and raw.startswith(b"\xef\xbb\xbf"):
                    raw = raw[3:]
                if k in aside:
                    bad.append(raw)
                else:
                    out.buffer.write(raw)
            _reject_bytes(path, bad)
        other = len(table.set_aside)
        if other:
            notes.append(f"moved {other} line(s) that are not rows of {path} to {path + REJECTED_SUFFIX}")
        if table.duplicates:
            notes.append(f"moved {len(table.duplicates)} duplicate row(s) of {path} (same run_id and step; "
                         f"line(s) {', '.join(str(k) for k, _ in table.duplicates[:10])}) to "
                         f"{path + REJECTED_SUFFIX}")
        if bom:
            notes.append(f"removed a UTF-8 byte-order mark from {path}")
    return notes


def reject_lines(path, lines):
    """Append ``lines`` (complete text lines) to ``<table>.rejected``, fsynced: set aside, never lost.

    Parameters
    ----------
    path : str
        The table.
    lines : iterable of str
        Lines, each ending with a newline (nothing is written for none).
    """
    lines = list(lines)
    if not lines:
        return
    with open(path + REJECTED_SUFFIX, "a", encoding="utf-8", newline="") as fh:
        fh.writelines(lines)
        fh.flush()
        os.fsync(fh.fileno())


#: columns a newer version may add to a table of an older one: what a run measured, and the
#: parameters whose default leaves a run's identity unchanged (those of laws and protocols the run
#: does not use, options, parameters added after 2.0.0: particleShear.parameters.identity_excluded)
ADDABLE_COLUMNS = frozenset(MEASURE_COLUMNS) | frozenset(PROTOCOL_COLUMNS) | identity_excluded({})


def add_result_columns(path, columns):
    """Give a table of an earlier version this version's new columns: results empty, parameters at their default.

    Only when the header is ``columns`` less some of :data:`ADDABLE_COLUMNS` (measures, checks,
    protocol outputs, parameters whose default changes no run id), in the same order: the rows
    keep every cell, a new result column is empty ("not evaluated"), a new parameter column holds
    the parameter's default (what the run used), and the file is replaced atomically.  Any other difference is left for
    :func:`check_table_header` to refuse.

    Parameters
    ----------
    path : str
        The table.
    columns : sequence of str
        This sweep's columns.

    Returns
    -------
    list of str
        The columns added (empty when nothing was done).
    """
    header = _header_of(path)
    columns = list(columns)
    missing = [c for c in columns if c not in header]
    if not header or not missing or any(c not in ADDABLE_COLUMNS for c in missing) \
            or [c for c in columns if c in header] != header:
        return []
    where = [header.index(c) if c in header else None for c in columns]
    fill = [escape_cell(_cell(BY_NAME[c].default)) if i is None and c in BY_NAME else ""
            for c, i in zip(columns, where)]
    csv.field_size_limit(max(csv.field_size_limit(), os.path.getsize(path) + 1))
    try:
        with open(path, newline="", encoding="utf-8", errors="strict") as src, atomic_text(path) as out:
            w = csv.writer(out, lineterminator="\n")
            for k, cells in enumerate(csv.reader(src)):
                if k == 0:
                    w.writerow(columns)
                else:   # a line that is no row keeps its cells (check_table sets it aside next)
                    w.writerow(cells if len(cells) != len(header) else
                               [f if i is None else cells[i] for i, f in zip(where, fill)])
    except (UnicodeDecodeError, csv.Error):
        return []       # the file is left as it was (atomic_text); check_table says what is wrong with it
    return missing


def check_table_header(path, columns):
    """Refuse a table whose header is not ``columns`` (read only; a byte-order mark is tolerated).

    Parameters
    ----------
    path : str
        A table (nothing happens when it is absent or empty).
    columns : sequence of str
        The sweep's columns.

    Raises
    ------
    ValueError
        Naming the table and the missing and unknown columns.
    """
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return
    header = _header_of(path)
    if header != list(columns):
        missing = [c for c in columns if c not in header]
        unknown = [c for c in header if c not in columns]

        def names(a):                               # at most 10 names, each cut to 40 characters
            shown = [n if len(n) <= 40 else n[:40] + "..." for n in a[:10]]
            return f"{shown}" + (f" and {len(a) - 10} more" if len(a) > 10 else "")

        what = "; ".join(x for x in (f"missing {names(missing)}" if missing else "",
                                     f"unknown {names(unknown)}" if unknown else "",
                                     "columns in another order" if not (missing or unknown) else "") if x)
        raise ValueError(f"results table {path!r} does not have this sweep's columns ({what}): repair it, or use "
                         "another --out DIR")


#: the columns an ``ok`` row of each protocol must hold a number in (each protocol's ``required``,
#: :mod:`particleShear.protocols`, and the wall time)
_OK_NUMBERS = {name: p.required_numbers + ("wall_time_s",) for name, p in PROTOCOLS.items()}


def row_problem(row, run):
    """Why ``row`` is not a trustworthy row of ``run`` (None when it is).

    A row counts only when its status is ``ok`` or ``failed``, its id, seed and every parameter
    are those of the run (as :func:`row_line` writes them), every cell is a value of its
    column's type (:mod:`~particleShear.sweep.schema`), and — for an ``ok`` row — the numbers
    its protocol produces (the moduli of an oscillatory run) and the wall time are not empty.

    Parameters
    ----------
    row : dict
        A row as read back (strings).
    run : SweepRun
        The run it claims to be.

    Returns
    -------
    str or None
    """
    if row.get("run_id") != run.run_id:
        return f"run_id={row.get('run_id')!r} is not {run.run_id}"
    status = row.get("status")
    if status not in ("ok", "failed"):
        return f"status={status!r} (allowed ok, failed)"
    if row.get("seed_entropy") != _cell(run.seed_entropy) or row.get("spawn_key") != _cell(list(run.spawn_key)):
        return "its seed is not the run's"
    compared = identity_parameters(run.parameters)   # the one rule of "the same run"
    for name, v in run.parameters.items():
        if name in compared and not same_input(row.get(name), v, name):
            return f"{name}={row.get(name)!r} is not the run's {_cell(v)!r}"
    numbers = _OK_NUMBERS.get(run.parameters.get("protocol", "oscillatory"), _OK_NUMBERS["oscillatory"]) \
        if status == "ok" else ("wall_time_s",)
    for name in numbers:
        try:
            float(row.get(name))
        except (TypeError, ValueError):
            return f"{name}={row.get(name)!r} is not a number"
    for name, text in row.items():
        kind = column_spec(name)["type"]
        why = cell_problem(text, kind)
        if why is not None:
            return f"{name}={text!r} is not of type {kind} ({why})"
    return None


def append_row(path, row, columns, *, checked=False):
    """Append ``row`` to the table at ``path`` (header first when new) in one write; flushed and fsynced.

    The cost does not depend on the table's length: nothing of the table is read but its last
    byte and its header line (and not even those when ``checked``).

    Parameters
    ----------
    path : str or os.PathLike
        The table (created when absent).
    row : dict or list of dict
        Column name → value (see :func:`row_line`); a list: the rows of one run (the steps of a
        one-packing sweep), appended together.
    columns : sequence of str
        The table's columns; must equal the existing header.
    checked : bool, optional
        True when the caller has checked the table (:func:`check_table`) and is its only writer
        (the sweep, under the table's lock): the row is only written.  False (default): a torn last
        line is cut first (:func:`repair_table`) and the header line is compared with ``columns``.

    Raises
    ------
    ValueError
        When an existing table has other columns (another package version or parameter set).
    """
    if not checked:
        repair_table(path)
        if os.path.exists(path) and os.path.getsize(path) > 0:
            if _header_of(path) != list(columns):
                raise ValueError(f"results table {os.fspath(path)!r} has other columns than this sweep: use another "
                                 "--out DIR")
    rows = row if isinstance(row, list) else [row]
    body = "".join(row_line(r, columns) for r in rows)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    try:
        new = os.fstat(fd).st_size == 0
        data = ((row_line({c: c for c in columns}, columns) if new else "") + body).encode("utf-8")
        while data:  # one write in practice; bounded by the length of the line
            n = os.write(fd, data)
            data = data[n:]
        os.fsync(fd)
    finally:
        os.close(fd)


def read_rows(path):
    """Rows of a table (:func:`~particleShear.sweep.reader.read_table`, cells kept as text); [] when absent.

    Lines that are not rows (a torn last line, another number of fields) are skipped, duplicate
    rows (same ``run_id`` and step) removed; a cell that is not a value of its column's type keeps
    its text (:func:`row_problem` judges it).

    Parameters
    ----------
    path : str or os.PathLike
        The table.

    Returns
    -------
    TableRows
        A sequence of mappings column → text (as ``csv.DictReader`` rows), made on access from the
        table's typed columns; [] when the file is absent or has no complete line.

    Raises
    ------
    ValueError
        Naming the file, when its header cannot be read.
    """
    if not os.path.exists(path):
        return []
    with open(path, "rb") as fh:
        if b"\n" not in fh.read(1 << 16) and fh.read(1) == b"":
            return []                               # empty, or a torn header alone
    return read_table(path, schema="package", invalid="keep").rows()


@contextlib.contextmanager
def atomic_text(path):
    """A text file (UTF-8, ``newline=""``) that replaces ``path`` only when the block completes.

    Written under a hidden name unique to the process in the same folder, fsynced, then moved
    into place with ``os.replace``; an exception removes it and leaves ``path`` as it was.  Every
    whole-file write of a sweep folder (tables, the record, a published sidecar) goes through it.

    Parameters
    ----------
    path : str
        The file to replace.

    Yields
    ------
    file object
    """
    tmp = os.path.join(os.path.dirname(path) or ".",
                       f".{os.path.basename(path)}.{socket.gethostname()}-{os.getpid()}-{secrets.token_hex(4)}.part")
    try:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


def remove_dead_temporaries(folder):
    """Remove the temporary files of :func:`atomic_text` left in ``folder`` by dead processes of this host.

    Parameters
    ----------
    folder : str
        The sweep folder.

    Returns
    -------
    list of str
        The names removed.
    """
    removed = []
    for name in dead_leftovers(folder):
        with contextlib.suppress(OSError):
            os.remove(os.path.join(folder, name))
            removed.append(name)
    return removed


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
    with atomic_text(path) as fh:
        fh.write(row_line({c: c for c in columns}, columns))
        for row in rows:
            fh.write(row_line(row, columns))


def sort_table(path, columns, index_of):
    """Rewrite the table at ``path`` atomically with its rows in sweep order; True when it changed.

    Rows for which ``index_of(row)`` is an integer come first, sorted by it (stable: rows of
    one run keep their order); the others (rows of other SPEC segments, or of no run of the
    sweep) follow in their order.  Every row is kept.  Call it under the table's lock.

    Parameters
    ----------
    path : str
        The table (nothing happens when it is absent).
    columns : sequence of str
        Its columns (its header).
    index_of : callable
        ``index_of(row) -> int or None``: the run's index in the SPEC.

    Returns
    -------
    bool
    """
    rows = read_rows(path)
    keys = [index_of(r) for r in rows]
    ours = sorted((k, i) for i, k in enumerate(keys) if k is not None)
    order = [i for _, i in ours] + [i for i, k in enumerate(keys) if k is None]
    if order == list(range(len(rows))):
        return False
    write_table(path, [rows[i] for i in order], columns)
    return True


def write_parquet(csv_path):
    """Write ``results.parquet`` next to ``csv_path`` when pyarrow is installed; its path, or None.

    The columns are typed by the table's schema (:func:`~particleShear.sweep.schema.results_schema`):
    Arrow types, with each column's unit and description as field metadata and the whole schema
    as the schema metadata ``particleShear.schema``.

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
        import pyarrow.parquet as pq
    except ImportError:
        return None
    if not os.path.exists(csv_path):
        return None
    read = read_table(csv_path, schema=results_schema(_header_of(csv_path)), invalid="keep")
    table = arrow_table(read.typed_rows(), read.schema)
    out = os.path.splitext(csv_path)[0] + ".parquet"
    tmp = os.path.join(os.path.dirname(out) or ".", "." + os.path.basename(out) + ".part")
    pq.write_table(table, tmp)
    os.replace(tmp, out)
    return out


def _header_of(path):
    """The header line's names (undecodable bytes replaced); a line that is not CSV is no header: []."""
    with open(path, "rb") as fh:
        first = fh.readline().decode("utf-8", errors="replace").lstrip("\ufeff")
    csv.field_size_limit(max(csv.field_size_limit(), len(first) + 1))
    try:
        return next(csv.reader([first]), [])
    except csv.Error:
        return []


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
