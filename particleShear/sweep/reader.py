"""The one reader of results tables: ``load_results``, ``analyse``, ``plot`` and the sweep all read through it.

:func:`read_table` reads a table written by :func:`~particleShear.sweep.table.row_line` (a
``results.csv``, a job-array task table, ``analysis.csv``) into typed columns: one NumPy array per
column (float64 for ``float``, int64 for ``int``, int8 for ``bool``, dictionary-encoded text for
the other types), so a row costs a few bytes per column, not a dict of Python strings.  The same
object gives the rows as read-only mappings of cell text (:meth:`ResultsTable.rows`), typed dicts
(:meth:`ResultsTable.typed_rows`) and a pandas DataFrame (:meth:`ResultsTable.to_frame`, when
pandas is installed).

The rules, the same for every caller:

* **One row is one line.**  The package writes every row as one line ending with ``\\n`` (an error
  message has no line break, :func:`~particleShear.sweep.tasks.error_text`).  The header is the
  first line (a UTF-8 byte-order mark before it is ignored); it must be UTF-8 with distinct names.
* **Torn lines are set aside.**  A last line without its final newline is *torn* (what a killed
  writer leaves; even when it has the full column count, its last cell may be cut), and so is any
  line that is not a row of the table: another number of fields than the header, a quote left
  open, bytes that are not UTF-8.  Such lines are never rows; they are listed in
  :attr:`ResultsTable.set_aside` with their line number and said in :attr:`ResultsTable.notes`.
  The sweep moves them to ``<table>.rejected`` when it opens the table
  (:func:`~particleShear.sweep.table.check_table`); the readers that only read skip them.
* **Invalid values are refused.**  Every cell is checked against its column's type in the schema
  (:mod:`particleShear.sweep.schema`): a text such as ``=HYPERLINK(...)`` in a float column is
  never turned into a value or a group.  With ``invalid="raise"`` (``load_results``, ``analyse``,
  ``plot``) the first such cell raises one ``ValueError`` naming the file, the line and the
  column; with ``invalid="keep"`` (the sweep, which re-runs a run whose row is not trustworthy)
  the cell keeps its text and is listed in :attr:`ResultsTable.problems`.
* **No field-size limit.**  The ``csv`` module's limit (131,072 characters by default) is raised
  to the size of the file being read, so any cell a SPEC can produce (a 10,000-value
  ``sweep_amplitudes`` list) is read.
* **Duplicate rows are removed.**  Two rows with the same ``run_id`` and step (``sweep_position``,
  when the table has that column) are one row: the first ``ok`` row is kept, else the first row;
  the others are listed in :attr:`ResultsTable.duplicates` and said in the notes.
* **Formula cells are escaped.**  A cell written by the package that starts with ``=``, ``+``,
  ``-``, ``@``, a tab, a carriage return or ``'`` and is not a number is prefixed with a single
  quote ``'`` (:func:`escape_cell`, the usual CSV-injection defence: a spreadsheet shows the text
  and evaluates nothing); the reader removes that quote again (:func:`unescape_cell`), so values
  round-trip.  Numbers such as ``-0.5`` or ``-inf`` are written as they are.
* **Errors name the file.**  Every ``ValueError`` of the reader starts with the file's path; a
  cell is shown cut to 200 characters.
"""
__docformat__ = "numpy"
import collections.abc
import csv
import os
import sys

import numpy as np

from ..checks import cut_text
from ..run.columns import SCHEMA_NAME, cell_problem, column_spec, read_schema, typed_value

__all__ = ["read_table", "ResultsTable", "escape_cell", "unescape_cell", "TableRow", "TableRows"]

#: first characters that make a spreadsheet evaluate a cell (and the escape character itself)
_FORMULA_STARTS = "=+-@\t\r'"
#: rows parsed before their cells are converted to columns (bounds the text held at once)
_CHUNK = 8192


def _is_number(text):
    try:
        float(text)
    except (TypeError, ValueError):
        return False
    return True


def escape_cell(text):
    """A cell's text made safe for spreadsheets: a formula-like text gets a leading ``'``.

    Parameters
    ----------
    text : str
        The cell as the package formats it.

    Returns
    -------
    str
        ``"'" + text`` when ``text`` starts with ``=``, ``+``, ``-``, ``@``, a tab, a carriage
        return or ``'`` and is not a number; otherwise ``text`` unchanged.

    Examples
    --------
    >>> escape_cell("=HYPERLINK(1)"), escape_cell("-0.5"), escape_cell("ok")
    ("'=HYPERLINK(1)", '-0.5', 'ok')
    """
    if text and text[0] in _FORMULA_STARTS and (text[0] == "'" or not _is_number(text)):
        return "'" + text
    return text


def unescape_cell(text):
    """Undo :func:`escape_cell`: a ``'`` followed by a formula start is removed.

    Parameters
    ----------
    text : str
        A cell as read from the file.

    Returns
    -------
    str

    Examples
    --------
    >>> unescape_cell("'=HYPERLINK(1)"), unescape_cell("'abc")
    ('=HYPERLINK(1)', "'abc")
    """
    if len(text) > 1 and text[0] == "'" and text[1] in _FORMULA_STARTS:
        return text[1:]
    return text


def _allow_fields(size):
    """Raise the ``csv`` module's field-size limit to ``size`` (never lower it: the limit is process-wide)."""
    want = min(int(size) + 1, sys.maxsize)
    if csv.field_size_limit() < want:
        csv.field_size_limit(want)


def _parse_line(line, n):
    """The fields of one complete line, or the reason it is not a row of ``n`` columns."""
    try:
        got = list(csv.reader([line]))
    except csv.Error as exc:
        return None, f"not CSV ({exc})"
    fields = got[0] if len(got) == 1 else []
    if fields and (fields[-1].endswith("\n") or fields[-1].endswith("\r")):
        return None, "a quote left open"
    if len(fields) != n:
        return None, f"{len(fields)} field(s), the header has {n}"
    return fields, None


# ---------------------------------------------------------------------------------------------
# typed columns
# ---------------------------------------------------------------------------------------------
class _Column:
    """One column: values in NumPy arrays, the text of cells not written canonically kept aside."""

    def __init__(self, name, kind):
        self.name, self.kind = name, kind
        self.chunks = []
        self.odd = {}             # row -> text of a cell whose canonical text differs (or an invalid cell)

    def finish(self, keep=None):
        raise NotImplementedError

    def _remap_odd(self, keep):
        if keep is None or not self.odd:
            return
        new = np.cumsum(keep) - 1
        self.odd = {int(new[i]): t for i, t in self.odd.items() if keep[i]}


class _NumberColumn(_Column):
    """float (float64, NaN) or int (int64) values and a mask of empty cells."""

    def __init__(self, name, kind):
        super().__init__(name, kind)
        self.dtype = np.float64 if kind == "float" else np.int64

    def add(self, texts, base, problems):
        n = len(texts)
        empty = np.fromiter((not t for t in texts), dtype=bool, count=n)
        intform = np.zeros(n, dtype=bool)
        if self.kind == "float":
            try:
                values = np.array([t or "nan" for t in texts], dtype=np.float64)
                exact = [not t or repr(x) == t for t, x in zip(texts, values.tolist())]
                for i, ok in enumerate(exact):     # "8000" in a float column: an integer's spelling
                    if not ok and texts[i].isdigit() and str(int(values[i])) == texts[i]:
                        exact[i] = intform[i] = True
            except (ValueError, OverflowError):      # a cell that is no float: one by one
                got = []
                for t in texts:
                    try:
                        got.append(float(t) if t else np.nan)
                    except (ValueError, OverflowError):
                        got.append(None)
                values = np.array([np.nan if x is None else x for x in got], dtype=np.float64)
                exact = [x is not None and (not t or repr(x) == t) for t, x in zip(texts, got)]
        else:
            values = np.zeros(n, dtype=np.int64)
            exact = [False] * n
            try:
                ints = [int(t) if t else 0 for t in texts]
                values = np.array(ints, dtype=np.int64)
                exact = [not t or str(v) == t for t, v in zip(texts, ints)]
            except (ValueError, OverflowError):
                pass
        for i, ok in enumerate(exact):
            if ok:
                continue
            text = unescape_cell(texts[i])
            self.odd[base + i] = text
            try:
                v = typed_value(text, self.kind)
                if v is not None and self.kind == "int" and not -2 ** 63 <= v < 2 ** 63:
                    raise ValueError(f"{v} is beyond the range of a 64-bit integer")
            except (TypeError, ValueError) as exc:
                problems.append((base + i, self.name, text, str(exc) or f"not a {self.kind}"))
                v = None
            empty[i] = v is None
            values[i] = (np.nan if self.kind == "float" else 0) if v is None else v
        self.chunks.append((values, empty, intform))

    def finish(self, keep=None):
        values = np.concatenate([c[0] for c in self.chunks]) if self.chunks else np.zeros(0, self.dtype)
        empty = np.concatenate([c[1] for c in self.chunks]) if self.chunks else np.zeros(0, bool)
        intform = np.concatenate([c[2] for c in self.chunks]) if self.chunks else np.zeros(0, bool)
        self.chunks = []
        self._remap_odd(keep)
        if keep is not None:
            values, empty, intform = values[keep], empty[keep], intform[keep]
        self.values, self.empty = values, empty
        self.intform = intform if intform.any() else None

    def text(self, i):
        t = self.odd.get(i)
        if t is not None:
            return t
        if self.empty[i]:
            return ""
        v = self.values[i]
        if self.kind != "float" or (self.intform is not None and self.intform[i]):
            return str(int(v))
        return repr(float(v))

    def typed(self, i):
        return None if self.empty[i] else (float(self.values[i]) if self.kind == "float" else int(self.values[i]))


class _BoolColumn(_Column):
    """bool values as int8: 1 True, 0 False, -1 empty."""
    _CODES = {"True": 1, "False": 0, "": -1}

    def add(self, texts, base, problems):
        codes = np.empty(len(texts), dtype=np.int8)
        for i, t in enumerate(texts):
            c = self._CODES.get(t)
            if c is None:
                text = unescape_cell(t)
                self.odd[base + i] = text
                try:
                    v = typed_value(text, "bool")
                except (TypeError, ValueError) as exc:
                    problems.append((base + i, self.name, text, str(exc)))
                    v = None
                c = -1 if v is None else int(v)
            codes[i] = c
        self.chunks.append(codes)

    def finish(self, keep=None):
        codes = np.concatenate(self.chunks) if self.chunks else np.zeros(0, np.int8)
        self.chunks = []
        self._remap_odd(keep)
        self.values = codes[keep] if keep is not None else codes
        self.empty = self.values < 0

    def text(self, i):
        t = self.odd.get(i)
        if t is not None:
            return t
        return ("", "False", "True")[int(self.values[i]) + 1]

    def typed(self, i):
        c = int(self.values[i])
        return None if c < 0 else bool(c)


class _TextColumn(_Column):
    """string, bigint and list cells: dictionary-encoded (int32 codes into the distinct texts), each
    distinct text checked once."""

    def __init__(self, name, kind):
        super().__init__(name, kind)
        self.uniques, self.index, self.why = [], {}, []

    def add(self, texts, base, problems):
        codes = np.empty(len(texts), dtype=np.int32)
        index, uniques = self.index, self.uniques
        for i, t in enumerate(texts):
            c = index.get(t)
            if c is None:
                c = index[t] = len(uniques)
                text = unescape_cell(t)
                uniques.append(text)
                self.why.append(None if self.kind == "string" else cell_problem(text, self.kind))
            if self.why[c] is not None:
                problems.append((base + i, self.name, uniques[c], self.why[c]))
            codes[i] = c
        self.chunks.append(codes)

    def finish(self, keep=None):
        codes = np.concatenate(self.chunks) if self.chunks else np.zeros(0, np.int32)
        self.chunks = []
        self.index = None
        self.values = codes[keep] if keep is not None else codes

    def text(self, i):
        return self.uniques[self.values[i]]

    def typed(self, i):
        if self.why[self.values[i]] is not None:
            return None
        return typed_value(self.uniques[self.values[i]], self.kind)


def _column(name, kind):
    if kind in ("float", "int"):
        return _NumberColumn(name, kind)
    if kind == "bool":
        return _BoolColumn(name, kind)
    return _TextColumn(name, kind)


# ---------------------------------------------------------------------------------------------
# rows
# ---------------------------------------------------------------------------------------------
class TableRow(collections.abc.MutableMapping):
    """One row of a :class:`ResultsTable` as a mapping column → cell text, made on access.

    Behaves as the dict of strings that ``csv.DictReader`` gives (``row["theMu"]``,
    ``row.get(...)``, ``dict(row)``, ``row["x"] = "..."``) at the cost of a few references: the
    text comes from the table's typed columns; a value set or deleted is kept in the row only.

    Parameters
    ----------
    table : ResultsTable
        The table.
    i : int
        The row's index in it.
    """
    __slots__ = ("_table", "_i", "_over")

    def __init__(self, table, i):
        self._table, self._i, self._over = table, i, None

    def __getitem__(self, name):
        if self._over is not None and name in self._over:
            got = self._over[name]
            if got is _DELETED:
                raise KeyError(name)
            return got
        return self._table._cols[self._table._at[name]].text(self._i)

    def __setitem__(self, name, value):
        if self._over is None:
            self._over = {}
        self._over[name] = value

    def __delitem__(self, name):
        self[name]                       # KeyError when absent
        self[name] = _DELETED

    def __iter__(self):
        over = self._over or {}
        for c in self._table.columns:
            if over.get(c) is not _DELETED:
                yield c
        for c in over:
            if c not in self._table._at and over[c] is not _DELETED:
                yield c

    def __len__(self):
        return sum(1 for _ in self)

    def __contains__(self, name):
        try:
            self[name]
        except KeyError:
            return False
        return True

    @property
    def line(self):
        """int: the row's line number in the file (1 is the header)."""
        return int(self._table.lines[self._i])

    def __repr__(self):
        return f"TableRow({dict(self)!r})"


_DELETED = object()


class TableRows(collections.abc.Sequence):
    """The rows of a table as a sequence of :class:`TableRow`, each made once, when first accessed.

    Parameters
    ----------
    table : ResultsTable
        The table.
    """

    def __init__(self, table):
        self._table = table
        self._made = [None] * len(table)

    def __len__(self):
        return len(self._made)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        n = len(self._made)
        if not -n <= i < n:
            raise IndexError("row index out of range")
        i %= n
        row = self._made[i]
        if row is None:
            row = self._made[i] = TableRow(self._table, i)
        return row

    def __eq__(self, other):
        if not isinstance(other, collections.abc.Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other))

    __hash__ = None

    @property
    def notes(self):
        """list of str: the table's notes (:attr:`ResultsTable.notes`)."""
        return self._table.notes

    @property
    def table(self):
        """ResultsTable: the table the rows come from."""
        return self._table

    def __repr__(self):
        return f"TableRows({len(self)} rows of {self._table.path!r})"


class ResultsTable:
    """A results table read by :func:`read_table`: typed columns, notes, lines set aside.

    Made by :func:`read_table`, not by hand.

    Parameters
    ----------
    path : str
        The file read.
    columns : list of str
        The header.
    schema : dict
        The schema applied.
    cols : list
        One typed column store per column.
    lines : numpy.ndarray
        Line number of each row.
    set_aside, duplicates, problems : list of tuple
        As the attributes.

    Attributes
    ----------
    path : str
        The file read.
    columns : list of str
        The header.
    schema : dict
        ``{"columns": [entry, ...]}``, one :func:`~particleShear.sweep.schema.column_spec` entry
        per column (from the schema file beside the table when there is one).
    lines : numpy.ndarray
        The line number (1 is the header) of each row.
    set_aside : list of tuple
        ``(line, reason)`` of each line that is not a row (torn, wrong field count, not UTF-8).
    duplicates : list of tuple
        ``(line, kept_line)`` of each row removed as a duplicate of the row at ``kept_line``.
    problems : list of tuple
        ``(line, column, text, reason)`` of each cell that is not a value of its column's type
        (only with ``invalid="keep"``; otherwise the first one raised).
    notes : list of str
        One sentence per kind of line set aside or removed, naming the file.
    """

    def __init__(self, path, columns, schema, cols, lines, set_aside, duplicates, problems):
        self.path, self.columns, self.schema = path, list(columns), schema
        self._cols, self.lines = cols, lines
        self._at = {c: j for j, c in enumerate(self.columns)}
        self.set_aside, self.duplicates, self.problems = set_aside, duplicates, problems
        self.notes = []
        if set_aside:
            torn = [k for k, why in set_aside if why.startswith("torn")]
            other = [k for k, why in set_aside if not why.startswith("torn")]
            if torn:
                self.notes.append(f"{path}: a torn last line (line {torn[0]}, no final newline) is no row")
            if other:
                self.notes.append(f"{path}: {len(other)} line(s) that are not rows set aside (line(s) "
                                  f"{_lines(other)}: {set_aside[[k for k, _ in set_aside].index(other[0])][1]})")
        if duplicates:
            self.notes.append(f"{path}: removed {len(duplicates)} duplicate row(s) (same run_id and step; "
                              f"line(s) {_lines([k for k, _ in duplicates])})")

    def __len__(self):
        return len(self.lines)

    def rows(self):
        """The rows as a sequence of :class:`TableRow` (mappings column → cell text, as written).

        Returns
        -------
        TableRows
        """
        return TableRows(self)

    def text_rows(self):
        """The rows as a list of plain dicts column → cell text (what ``csv.DictReader`` gave).

        Returns
        -------
        list of dict
        """
        cols = self._cols
        return [{c.name: c.text(i) for c in cols} for i in range(len(self))]

    def typed_row(self, i):
        """Row ``i`` typed by the schema (as :func:`~particleShear.sweep.schema.typed_row`).

        Parameters
        ----------
        i : int

        Returns
        -------
        dict
        """
        return {c.name: c.typed(i) for c in self._cols}

    def typed_rows(self):
        """Every row typed by the schema, a list of dicts.

        Returns
        -------
        list of dict
        """
        return [self.typed_row(i) for i in range(len(self))]

    def column(self, name):
        """The typed values of one column as a NumPy array.

        Parameters
        ----------
        name : str

        Returns
        -------
        numpy.ndarray
            float64 (NaN where empty) for ``float`` columns; int64 for ``int`` columns without an
            empty cell, else float64 with NaN; object (None where empty) for ``bool``; object for
            the others (``str``, ``int``, ``list``).

        Raises
        ------
        KeyError
            When the table has no such column.
        """
        c = self._cols[self._at[name]]
        if c.kind == "float":
            return np.where(c.empty, np.nan, c.values)
        if c.kind == "int":
            return c.values.copy() if not c.empty.any() else np.where(c.empty, np.nan, c.values.astype(float))
        out = np.empty(len(self), dtype=object)
        for i in range(len(self)):
            out[i] = c.typed(i)
        return out

    def to_frame(self):
        """The table as a pandas DataFrame with the schema's dtypes (needs pandas).

        Returns
        -------
        pandas.DataFrame
            float64 (NaN where empty), ``int64``/``Int64``, ``bool``/``boolean``, ``str``, object.

        Raises
        ------
        ImportError
            When pandas is not installed.
        """
        import pandas as pd
        data = {}
        for c, spec in zip(self._cols, self.schema["columns"]):
            nullable = bool(spec.get("nullable"))
            if c.kind == "float":
                data[c.name] = pd.Series(np.where(c.empty, np.nan, c.values), dtype=np.float64)
            elif c.kind == "int":
                data[c.name] = pd.Series(pd.arrays.IntegerArray(c.values.copy(), c.empty.copy())) \
                    if nullable or c.empty.any() else pd.Series(c.values.copy(), dtype=np.int64)
            elif c.kind == "bool":
                data[c.name] = pd.Series(pd.arrays.BooleanArray(c.values > 0, c.empty.copy())) \
                    if nullable or c.empty.any() else pd.Series(c.values > 0, dtype=bool)
            elif c.kind == "string":
                uniques = np.array(c.uniques + [""], dtype=object)
                data[c.name] = pd.Series(uniques[c.values], dtype=str)
            else:
                data[c.name] = pd.Series([c.typed(i) for i in range(len(self))], dtype=object)
        return pd.DataFrame(data, columns=self.columns)


def _lines(numbers, shown=10):
    numbers = list(numbers)
    text = ", ".join(str(k) for k in numbers[:shown])
    return text + (f", ... ({len(numbers)} in all)" if len(numbers) > shown else "")


def _schema_for(path, header, schema):
    if schema == "package":
        schema = {"columns": []}
    elif schema is None:
        schema_path = os.path.join(os.path.dirname(path) or ".", SCHEMA_NAME)
        if os.path.isfile(schema_path):
            schema = read_schema(schema_path)
        else:
            schema = {"columns": []}
    by_name = {c["name"]: c for c in schema.get("columns", [])}
    return {"columns": [by_name.get(c) or column_spec(c) for c in header]}


def read_table(path, *, schema=None, invalid="raise", dedupe=True, label="results table"):
    """Read a results table by the rules of the module docstring.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    schema : dict or "package", optional
        ``{"columns": [entry, ...]}`` as :func:`~particleShear.sweep.schema.results_schema`
        (default: ``results.schema.json`` beside the table when present, else the
        package's entry of each column; ``"package"``: the package's entries, whatever file is
        beside the table — what the sweep uses).  Columns it does not name get the package's entry.
    invalid : {"raise", "keep"}, optional
        What a cell that is not a value of its column's type does: ``"raise"`` (default) a
        ``ValueError`` naming file, line and column; ``"keep"``: the row is kept with the cell's
        text and the cell listed in :attr:`ResultsTable.problems`.
    dedupe : bool, optional
        Remove duplicate rows (same ``run_id`` and step; default True).
    label : str, optional
        What the file is called in messages (default "results table").

    Returns
    -------
    ResultsTable

    Raises
    ------
    ValueError
        Naming the file: it cannot be opened, has no complete header line, its header is not UTF-8
        text or CSV or repeats a name, or (``invalid="raise"``) a cell is invalid — then with the
        line and the column.
    """
    if invalid not in ("raise", "keep"):
        raise ValueError(f"invalid={invalid!r} is invalid: allowed 'raise' or 'keep'")
    path = os.fspath(path)
    where = f"{label} {path!r}"
    try:
        fh = open(path, "rb")
    except OSError as exc:
        raise ValueError(f"{where} cannot be read ({exc.strerror or exc})") from None
    with fh:
        _allow_fields(os.fstat(fh.fileno()).st_size)
        first = fh.readline()
        if not first.endswith(b"\n"):
            raise ValueError(f"{where} has no complete header line (a torn or empty file): repair it or "
                             "remove it")
        if first.startswith(b"\xef\xbb\xbf"):
            first = first[3:]
        try:
            header_text = first.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ValueError(f"{where} is not a CSV table of UTF-8 text (line 1: {exc.reason} at byte "
                             f"{exc.start})") from None
        try:
            header = next(csv.reader([header_text]), [])
        except csv.Error as exc:
            raise ValueError(f"{where} is not a CSV table (line 1: {exc})") from None
        if not header or any(not h for h in header) or len(set(header)) != len(header) \
                or any(not h.isprintable() for h in header):
            raise ValueError(f"{where} has no valid header line (line 1: empty, repeated or unprintable column "
                             f"names: {cut_text(header_text.strip())!r})")
        schema = _schema_for(path, header, schema)
        kinds = [c["type"] for c in schema["columns"]]
        cols = [_column(name, kind) for name, kind in zip(header, kinds)]
        n = len(header)
        lines, set_aside, problems, pending = [], [], [], []

        def flush():
            base = len(lines) - len(pending)
            for j, texts in enumerate(zip(*pending)):
                cols[j].add(texts, base, problems)
            pending.clear()
            if problems and invalid == "raise":
                i, name, text, why_ = min(problems)
                raise ValueError(f"{where}, line {lines[i]}: column {name}={cut_text(text)!r} is not of type "
                                 f"{schema['columns'][header.index(name)]['type']} ({cut_text(why_)}): correct or "
                                 "remove that row") from None

        k = 1
        for raw in fh:
            k += 1
            if not raw.endswith(b"\n"):
                set_aside.append((k, "torn: no final newline"))
                break
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                set_aside.append((k, f"not UTF-8 text ({exc.reason})"))
                continue
            fields, why = _parse_line(line, n)
            if fields is None:
                set_aside.append((k, why))
                continue
            lines.append(k)
            pending.append(fields)
            if len(pending) >= _CHUNK:
                flush()
        if pending:
            flush()
    lines = np.array(lines, dtype=np.int64)
    keep, duplicates = None, []
    if dedupe and "run_id" in header and len(lines):
        keep, duplicates = _dedupe(cols, header, lines)
    for c in cols:
        c.finish(keep)
    if keep is not None:
        if problems:
            new = np.cumsum(keep) - 1
            problems = [(int(new[i]), *rest) for i, *rest in problems if keep[i]]
        lines = lines[keep]
    problems = [(int(lines[i]), name, text, why) for i, name, text, why in problems]
    return ResultsTable(path, header, schema, cols, lines, set_aside, duplicates, problems)


def _dedupe(cols, header, lines):
    """Mask of the rows kept (first ``ok`` row of each run and step, else the first) and the removed ones."""
    run = cols[header.index("run_id")]
    run_codes = np.concatenate(run.chunks) if run.chunks else np.zeros(0, np.int32)
    if len(np.unique(run_codes)) == len(run_codes):
        return None, []
    status = cols[header.index("status")] if "status" in header else None
    ok = None
    if isinstance(status, _TextColumn):
        okc = status.index.get("ok") if status.index is not None else None
        codes = np.concatenate(status.chunks)
        ok = codes == okc if okc is not None else np.zeros(len(codes), bool)
    step = cols[header.index("sweep_position")] if "sweep_position" in header else None
    step_values = None
    if step is not None:
        step_values = [c for c in step.chunks]
    if isinstance(step, _NumberColumn):
        values = np.concatenate([c[0] for c in step_values])
        empty = np.concatenate([c[1] for c in step_values])
        step_key = np.where(empty, -1, values).tolist()
        for i, t in step.odd.items():
            step_key[i] = t
    elif step is not None:
        step_key = np.concatenate(step_values).tolist()
    else:
        step_key = [None] * len(run_codes)
    first = {}
    keep = np.ones(len(run_codes), dtype=bool)
    for i, key in enumerate(zip(run_codes.tolist(), step_key)):
        j = first.get(key)
        if j is None:
            first[key] = i
        elif ok is not None and ok[i] and not ok[j]:
            keep[j] = False
            first[key] = i
        else:
            keep[i] = False
    if keep.all():
        return None, []
    kept_line = {}
    for key, i in first.items():
        kept_line[key] = int(lines[i])
    duplicates = [(int(lines[i]), kept_line[key]) for i, key in enumerate(zip(run_codes.tolist(), step_key))
                  if not keep[i]]
    return keep, duplicates
