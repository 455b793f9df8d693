"""Output formats of a run and :func:`read_run`, which reads any of them back.

========== ============ ==========================================================================
format     file suffix  content
========== ============ ==========================================================================
"text"     ``.txt``     the reference text file (header blocks + 42-column TAB table), default
"text.gz"  ``.txt.gz``  the same text, gzip-compressed (R's ``read.table``/``readLines`` read it)
"npz"      ``.npz``     one array per table column + ``header`` (JSON: text header and metadata)
"parquet"  ``.parquet`` one column per table column, JSON in the schema metadata (needs pyarrow,
                        the optional extra ``particleShear[parquet]``)
========== ============ ==========================================================================

Every writer streams into an open binary file (bounded memory) and is used by
``runSimulation`` on an :class:`~particleShear.simulation.output.AtomicOutputFile`, so a file
is complete or absent; the JSON sidecar ``<stem>.json`` records the table's row count, the
file's size and its SHA-256.  :func:`verify_run` checks cheaply that a file is complete,
:func:`read_run` checks everything (hash, structure, row count) while reading; both raise one
:class:`RunFileError` (a ``ValueError``) naming the file and what is wrong.  See
``docs/output.md`` for sizes, load times and the checks.
"""
__docformat__ = "numpy"
import contextlib
import gzip
import hashlib
import io
import json
import os
import re
import zipfile

import numpy as np

from .output import (FORMAT_SUFFIXES, format_of, NO_TENSOR_DATA_TEXT, TABLE_COLUMNS, _quietly, iter_table_text,
                     iter_text_rows, sidecar_path)

__all__ = ["OUTPUT_FORMATS", "FORMAT_SUFFIXES", "read_run", "verify_run", "RunData", "RunFileError", "write_run",
           "write_columns", "check_output_format", "series_columns", "table_rows", "text_stream", "sidecar_path",
           "RHEOMETER_TITLE", "RHEOMETER_DETAILED", "RHEOMETER_EXTRA_COLUMNS"]

#: the accepted values of ``output_format`` (keys of :data:`FORMAT_SUFFIXES`)
OUTPUT_FORMATS = tuple(FORMAT_SUFFIXES)

#: series key of SimulationResult.series → table column (the five base series)
_NUMBER = r"([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)"
#: header patterns of the protocol values a RunData exposes (first pattern that matches wins)
_PROTOCOL_PATTERNS = {
    "frequency": (re.compile(r"\nFrequency = " + _NUMBER + "Hz"),),
    "strain_amplitude": (re.compile(r"[(,]amplitude=" + _NUMBER + r"[,)]"),
                         re.compile(r"\nStrain amplitude = " + _NUMBER + "%")),
    "pre_periods": (re.compile(r"baseline_pre_periods = " + _NUMBER), re.compile(r"Pre-measurement periods = " + _NUMBER)),
    "periods": (re.compile(r"runSimulation\(periods=" + _NUMBER + ","),
                re.compile(r"Oscillatory shear periods = " + _NUMBER)),
}
_SERIES_COLUMNS = (("t", "t"), ("strain", "strain"), ("strain_rate", "strain_rate"),
                   ("stress_surface", "stress_measured_at_surface"),
                   ("stress_internal", "shear_stress_internal_stress-tensor"))
_PARQUET_HINT = ("output_format='parquet' needs pyarrow, which is not installed: "
                 "pip install 'particleShear[parquet]' (or pip install pyarrow)")
#: rows per Parquet row group (about 5 MB of columns)
_PARQUET_ROWS = 16384
_DETAILED = re.compile(r"Detailed[a-zA-Z0-9\s].*data")
#: key of the JSON (header, metadata) in a Parquet file's schema metadata
_PARQUET_KEY = b"particleShear"
#: the title line of the experiment block of a rheometer protocol's file (particleShear.run.rheometer_files)
RHEOMETER_TITLE = "Rheometer protocol experiment"
#: the line after which a protocol file's table starts (the reference's "Detailed … data" pattern)
RHEOMETER_DETAILED = "Detailed rheometer protocol data"
#: the columns of a protocol file after the first six: N1 (Pa, "steady"), sweep_position (sweeps)
RHEOMETER_EXTRA_COLUMNS = ("N1", "sweep_position")


def _pyarrow():
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError as exc:
        raise ImportError(_PARQUET_HINT) from exc
    return pyarrow, pyarrow.parquet


def check_output_format(output_format):
    """Check an output format before any work.

    Parameters
    ----------
    output_format : str
        One of :data:`OUTPUT_FORMATS` (``"text"``, ``"text.gz"``, ``"npz"``, ``"parquet"``;
        CLI ``--output-format``).

    Raises
    ------
    ValueError
        For an unknown format (the message lists the allowed ones).
    ImportError
        For ``"parquet"`` without pyarrow (the message names the extra to install).
    """
    if not isinstance(output_format, str) or output_format not in FORMAT_SUFFIXES:
        raise ValueError(f"output_format={output_format!r} is invalid: allowed "
                         + ", ".join(repr(k) for k in OUTPUT_FORMATS) + " (CLI --output-format)")
    if output_format == "parquet":
        _pyarrow()


def series_columns(series):
    """``{column name: 1-D array}`` of the table from a ``SimulationResult.series``-like dict.

    ``index`` and the five base series always; the 36 tensor columns when ``"tensors"`` is present.

    Parameters
    ----------
    series : dict
        ``t`` (s), ``strain`` (–), ``strain_rate`` (1/s), ``stress_surface`` and
        ``stress_internal`` (Pa) as 1-D sequences of equal length; optionally ``tensors``,
        shape (n, 9, 2, 2) in Pa.

    Returns
    -------
    dict
        Column name → 1-D ``numpy.ndarray``, in the order of the text table (docs/output.md).
    """
    n = len(series["t"])
    cols = {"index": np.arange(n, dtype=np.int64)}
    for key, col in _SERIES_COLUMNS:
        cols[col] = np.asarray(series[key], dtype=float)
    tensors = series.get("tensors")
    if tensors is not None:
        flat = np.asarray(tensors, dtype=float).reshape(n, 36)
        for j, name in enumerate(TABLE_COLUMNS[6:]):
            cols[name] = flat[:, j]
    return cols


def table_rows(output_format, n_steps, tensors_saved):
    """Rows of the table a file of ``output_format`` holds for a run of ``n_steps`` protocol steps.

    The text formats write the table only with the tensor columns (otherwise the reference's
    notice, no rows); npz and parquet always hold the six scalar columns, one row per step.

    Parameters
    ----------
    output_format : str
        One of :data:`OUTPUT_FORMATS`.
    n_steps : int
        Protocol steps recorded.
    tensors_saved : bool
        Whether the 36 tensor columns are written.

    Returns
    -------
    int
        The ``n_rows`` recorded in the sidecar and the embedded metadata.
    """
    if output_format in ("text", "text.gz") and not tensors_saved:
        return 0
    return int(n_steps)


@contextlib.contextmanager
def _closing(obj):
    """``obj.close()`` on leaving; after a failure quietly, so the first error is the one raised.

    The close of a zip file, zip member, gzip stream or Parquet writer writes a trailer, which
    fails again on a full disk; that second error must not replace the first.
    """
    try:
        yield obj
    except BaseException:
        _quietly(obj.close)
        raise
    obj.close()


@contextlib.contextmanager
def text_stream(fh, output_format):
    """The binary stream the text of a run is written to: ``fh`` itself, or gzip around it.

    Parameters
    ----------
    fh : binary file object
        The open output file (left open).
    output_format : str
        ``"text"`` or ``"text.gz"``.

    Yields
    ------
    binary file object
        ``fh`` (``"text"``) or a ``gzip.GzipFile`` on it whose trailer is written on leaving
        (``"text.gz"``; after a failure nothing more is attempted that could fail again).
    """
    if output_format == "text.gz":
        with _closing(gzip.GzipFile(fileobj=fh, mode="wb", compresslevel=6, mtime=0)) as gz:
            yield gz
    else:
        yield fh


def write_run(fh, output_format, header_text, scalars, tensors, metadata):
    """Stream one run into the open binary file ``fh`` in ``output_format``.

    After a failure (e.g. disk full) the exception of the failing write is raised: closing the
    container afterwards is attempted quietly.

    Parameters
    ----------
    fh : binary file object
    output_format : str
        One of :data:`OUTPUT_FORMATS`.
    header_text : str
        The text header up to and including "Detailed stress tensor data" (blocks 1–3).
    scalars : numpy.ndarray, shape (n, 5)
        t, strain, strain_rate, τ_surface, τ_internal per protocol step.
    tensors : numpy.ndarray, shape (n, 9, 2, 2), or None
        The nine stress tensors per step (None: no tensor columns; the text formats then write
        the reference's notice instead of the table).
    metadata : dict
        JSON-safe run description (the sidecar's content), stored inside npz/parquet together
        with ``n_rows`` (:func:`table_rows`).
    """
    if output_format in ("text", "text.gz"):
        with text_stream(fh, output_format) as out:
            out.write(header_text.encode("utf-8"))
            if tensors is not None:
                for piece in iter_table_text(scalars, tensors):
                    out.write(piece.encode("utf-8"))
            else:
                out.write(("\n" + NO_TENSOR_DATA_TEXT).encode("utf-8"))
        return
    if output_format not in FORMAT_SUFFIXES:
        raise ValueError(f"output_format={output_format!r} is invalid: allowed " + ", ".join(OUTPUT_FORMATS))
    series = {key: scalars[:, k] for k, (key, _) in enumerate(_SERIES_COLUMNS)}
    if tensors is not None:
        series["tensors"] = tensors
    cols = series_columns(series)
    write_columns(fh, output_format, header_text, cols,
                  dict(metadata, n_rows=table_rows(output_format, len(cols["index"]), tensors is not None)))


def write_columns(fh, output_format, header_text, cols, metadata):
    """Stream a table of named columns into the open binary file ``fh`` in ``output_format``.

    The writer of every table but the reference text (:func:`write_run`): npz and parquet of
    oscillatory runs, and the rheometer protocols' files in every format (the text formats:
    ``header_text``, then the names line and TAB-separated rows, ``str`` of each float).

    Parameters
    ----------
    fh : binary file object
    output_format : str
        One of :data:`OUTPUT_FORMATS`.
    header_text : str
        The text header, ending with its "Detailed … data" line.
    cols : dict
        Column name → 1-D array of one length; ``index`` (0 … n-1) first; integer columns are
        written as int64, the others as float64.
    metadata : dict
        JSON-safe run description with ``n_rows``, stored inside npz/parquet.
    """
    if output_format not in FORMAT_SUFFIXES:
        raise ValueError(f"output_format={output_format!r} is invalid: allowed " + ", ".join(OUTPUT_FORMATS))
    if output_format in ("text", "text.gz"):
        with text_stream(fh, output_format) as out:
            out.write(header_text.encode("utf-8"))
            for piece in iter_text_rows(list(cols), list(cols.values())):
                out.write(piece.encode("utf-8"))
        return
    n = len(cols["index"])
    meta = json.dumps({"header": header_text, "metadata": metadata})
    if output_format == "npz":
        # what numpy.savez writes, one column at a time (one column copy in memory, not the table)
        with _closing(zipfile.ZipFile(fh, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True)) as zf:
            arrays = [("header", np.array(meta))] + list(cols.items())
            for name, v in arrays:  # a strided column is copied when written, one at a time
                v = v if v.ndim == 0 else np.ascontiguousarray(v)
                with _closing(zf.open(name + ".npy", "w", force_zip64=True)) as member:
                    np.lib.format.write_array(member, v, allow_pickle=False)
        return
    pa, pq = _pyarrow()
    schema = pa.schema([(name, pa.int64() if np.asarray(v).dtype.kind in "iu" else pa.float64())
                        for name, v in cols.items()],
                       metadata={_PARQUET_KEY: meta.encode("utf-8")})
    with _closing(pq.ParquetWriter(fh, schema, use_dictionary=False, write_page_checksum=True)) as writer:
        for a in range(0, max(n, 1), _PARQUET_ROWS):  # row groups: bounded extra memory
            b = min(n, a + _PARQUET_ROWS)
            writer.write_table(pa.table({name: np.ascontiguousarray(v[a:b]) for name, v in cols.items()},
                                        schema=schema))


class RunData(dict):
    """The per-step columns of one run (``{column name: numpy array}``) with its header.

    Keys are the table's column names (``index``, ``t``, ``strain``, ``strain_rate``,
    ``stress_measured_at_surface``, ``shear_stress_internal_stress-tensor`` and the 36
    ``stress_tensor_*`` columns when saved); empty for a text file written with
    ``saveStressTensorData=False`` (the reference writes no table then).  A rheometer
    protocol's file (docs/protocols.md) has the first six columns and ``N1`` (steady) or
    ``sweep_position`` (sweeps); its ``protocol``, ``parameters``, ``f``, ``summary``, ``steps``,
    ``curves`` and ``series`` are properties, named as those of a
    :class:`~particleShear.run.result.SimulationResult`.

    Made by :func:`read_run`; the parameters are also its attributes.

    Parameters
    ----------
    columns : dict
        Column name → 1-D array (the dict's items).
    header : str
        The text header, blocks 1–3, up to and including "Detailed stress tensor data".
    metadata : dict
        Parameters and provenance (run id, seed, version, ``n_rows``): stored in npz/parquet,
        read from the sidecar ``<stem>.json`` (or the older ``<file>.json``) for text files
        (empty when there is none).
    path : str
        The file read.
    output_format : str
        Its format, one of :data:`OUTPUT_FORMATS`.
    """

    def __init__(self, columns, header, metadata, path, output_format):
        super().__init__(columns)
        self.header = header
        self.metadata = metadata
        self.path = path
        self.output_format = output_format

    def _header_value(self, name):
        for pattern in _PROTOCOL_PATTERNS[name]:
            m = pattern.search(self.header)
            if m:
                return float(m.group(1)) / (100.0 if m.group(0).endswith("%") else 1.0)
        raise RunFileError(f"{self.path}: its header records no {name.replace('_', ' ')}")

    @property
    def frequency(self):
        """The excitation frequency f (Hz), from the header line ``Frequency = …Hz``."""
        return self._header_value("frequency")

    @property
    def f(self):
        """The excitation frequency f (Hz), as ``SimulationResult.f``: :attr:`frequency`."""
        return self.frequency

    @property
    def parameters(self):
        """The run's parameters as the file's metadata records them (``SimulationResult.parameters``;
        {} when absent)."""
        return dict(self.metadata.get("parameters") or {})

    @property
    def strain_amplitude(self):
        """The strain amplitude γ₀ (dimensionless), from the call's ``amplitude=…`` in the header
        (exactly the value given), else ``Strain amplitude = …%`` / 100."""
        return self._header_value("strain_amplitude")

    @property
    def pre_periods(self):
        """Baseline periods before the excitation, from ``Pre-measurement periods = …``."""
        return self._header_value("pre_periods")

    @property
    def periods(self):
        """Excitation periods, from ``Oscillatory shear periods = …``."""
        return self._header_value("periods")

    @property
    def protocol(self):
        """The run's protocol: "oscillatory", or the rheometer protocol the file records."""
        if RHEOMETER_TITLE not in self.header:
            return "oscillatory"
        m = re.search(r"\nProtocol = (\w+)\n", self.header)
        return m.group(1) if m else self.metadata.get("protocol", "")

    @property
    def summary(self):
        """A protocol file's scalar results (``SimulationResult.summary``, from the metadata; {} when absent)."""
        return dict(self.metadata.get("summary") or {})

    @property
    def steps(self):
        """A sweep file's steps (``SimulationResult.steps``, from the metadata; [] when absent)."""
        return [dict(st) for st in self.metadata.get("steps") or []]

    @property
    def curves(self):
        """A protocol file's log-grid curves ``name -> (t, y, y_spread)`` as arrays (from the
        metadata; {} when absent — :func:`particleShear.analysis.rheometry.log_grid` of the
        series gives them again)."""
        return {name: tuple(np.asarray(v, dtype=float) for v in c)
                for name, c in (self.metadata.get("curves") or {}).items()}

    @property
    def series(self):
        """The columns under the keys of ``SimulationResult.series`` (tensors as (n, 9, 2, 2)), and
        of another protocol's ``SimulationResult.series`` for a protocol file (``N1``, ``sweep_position``)."""
        out = {key: self[col] for key, col in _SERIES_COLUMNS if col in self}
        out.update({col: self[col] for col in RHEOMETER_EXTRA_COLUMNS if col in self})
        names = TABLE_COLUMNS[6:]
        if all(name in self for name in names):
            out["tensors"] = np.stack([self[name] for name in names], axis=1).reshape(-1, 9, 2, 2)
        return out

    def to_dataframe(self):
        """A ``pandas.DataFrame`` of the columns (needs pandas); header and metadata in ``.attrs``."""
        try:
            import pandas as pd
        except ImportError as exc:
            raise ImportError("RunData.to_dataframe needs pandas: pip install \"particleShear[tables]\" (from this "
                              "source, see README 'Install')") from exc
        df = pd.DataFrame(dict(self))
        df.attrs["header"] = self.header
        df.attrs["metadata"] = self.metadata
        return df


class RunFileError(ValueError):
    """A run file that is missing, incomplete, damaged or not a particleShear file.

    The message starts with the file's path and says what is wrong.  A ``ValueError``, so
    ``except ValueError`` catches it.
    """


def _bad(path, what):
    return RunFileError(f"{path}: {what}")


def _sidecar(path, fmt):
    """``(sidecar path, content)`` of the run file ``path``, or ``(None, {})`` when it has none.

    The sidecar is ``<stem>.json``, or ``<file>.json`` for files written before that name; a
    ``<stem>.json`` recording another ``output_format`` belongs to a file of the same stem in that
    format and is not this file's.
    """
    for candidate in (sidecar_path(path), path + ".json"):
        if not os.path.isfile(candidate):
            continue
        try:
            with open(candidate, "rb") as fh:
                meta = json.loads(fh.read().decode("utf-8"))
        except (OSError, ValueError) as exc:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
            raise _bad(candidate, f"the sidecar of {os.path.basename(path)} is unreadable ({exc})") from exc
        if not isinstance(meta, dict):
            raise _bad(candidate, f"the sidecar of {os.path.basename(path)} is not a JSON object")
        if meta.get("output_format", fmt) == fmt:
            return candidate, meta
    return None, {}


#: lines every particleShear text header holds (blocks 1–3, docs/output.md "Blocks"; a protocol
#: file has RHEOMETER_TITLE instead of the first)
_HEADER_LINES = ("Oscillatory shear experiment", "Summary data")


def _is_rheometer(header):
    return "\n" + RHEOMETER_TITLE + "\n" in header


def _tables(header):
    """The column sets a table under ``header`` may have."""
    base = tuple(TABLE_COLUMNS[:6])
    if _is_rheometer(header):
        return [base] + [base + (extra,) for extra in RHEOMETER_EXTRA_COLUMNS]
    return [base, tuple(TABLE_COLUMNS)]
#: what the first lines must contain (the header is < 10 kB; 256 kB leaves room for long calls)
_HEAD_CHARS = 1 << 18


def _check_text_header(path, header):
    lines = _HEADER_LINES[1:] if _is_rheometer(header) else _HEADER_LINES
    if not _DETAILED.search(header.rsplit("\n", 1)[-1]) or any("\n" + line + "\n" not in header for line in lines):
        raise _bad(path, "not a particleShear run file, or cut inside its header (the header lines "
                   + ", ".join(repr(x) for x in _HEADER_LINES + ("Detailed stress tensor data",))
                   + " are missing)")


_HEADER_NUMBER = {key: re.compile("\n" + label + r"([^\s\[]+) ?" + unit + "\n")
                  for key, label, unit in (("dt", "Time step = ", "s"), ("f", "Frequency = ", "Hz"),
                                           ("pre", "Pre-measurement periods = ", r"\[-\]"),
                                           ("P", "Oscillatory shear periods = ", r"\[-\]"),
                                           ("post", "Post-measurement periods = ", r"\[-\]"))}


def _header_steps(header):
    """Protocol steps the header records, or None when it records none.

    ``int((P + pre + post)/f/dt)`` from "Time step", "Frequency" and the three period lines, the
    formula of the protocol (``OscillatoryShearExperiment.run_protocol``); the numbers are
    written so that they read back exactly.  Only for headers with the provenance lines: a
    ``reference_header=True`` file prints the pre value as "Post-measurement periods" (reference
    defect #21), so its step count is not recorded.
    """
    if "\n\tRun id: " not in header:
        return None
    values = {}
    for key, pattern in _HEADER_NUMBER.items():
        m = pattern.search(header)
        if m is None:
            return None
        try:
            values[key] = float(m.group(1))
        except ValueError:
            return None
    if not (values["f"] > 0 and values["dt"] > 0):
        return None
    return int((values["P"] + values["pre"] + values["post"]) / values["f"] / values["dt"])


def _check_rows(path, cols, n_recorded, header, table_written):
    """Columns complete and of one length equal to the recorded row count (sidecar or header)."""
    names = list(cols)
    if table_written:
        allowed = _tables(header)
        if sorted(names) not in [sorted(a) for a in allowed]:
            missing = [c for c in allowed[0] if c not in cols] or [c for c in allowed[-1] if c not in cols]
            raise _bad(path, "the table's columns are incomplete (missing: " + ", ".join(missing[:5])
                       + (", …" if len(missing) > 5 else "") + ")")
        lengths = {len(v) for v in cols.values()}
        if len(lengths) != 1:
            raise _bad(path, f"the table's columns differ in length ({sorted(lengths)})")
        n = lengths.pop()
        if not np.array_equal(np.asarray(cols["index"]), np.arange(n)):
            raise _bad(path, "the table's index column is not 0, 1, …, n-1 (rows missing or damaged)")
    else:
        n = 0
    expected = n_recorded
    source = "its sidecar/metadata records"
    if expected is None and table_written and not _is_rheometer(header):
        expected, source = _header_steps(header), "its header records"
    if expected is not None and n != expected:
        raise _bad(path, f"incomplete: the table has {n} rows, {source} {expected}")


def _parse_text(path, text):
    """``(header, columns, table_written)`` of the text of a run file, structure checked."""
    header, body = _split_text(text)
    _check_text_header(path, header)
    if body == "\n" + NO_TENSOR_DATA_TEXT:
        return header, {}, False
    columns = [c for c in _tables(header) if len(c) > 6 or _is_rheometer(header)]
    for names in sorted(columns, key=len, reverse=True):
        names_line = "\n" + "\t".join(names)
        if body.startswith(names_line) and (len(body) == len(names_line) or body[len(names_line)] == "\n"):
            break
    else:
        raise _bad(path, "incomplete: after its 'Detailed … data' line neither the table's names line "
                   "nor the no-table notice is complete")
    rows = body[len(names_line) + 1:]
    if not rows:
        return header, {name: np.empty(0) for name in names}, True
    last = rows[rows.rfind("\n") + 1:]
    if last == "":
        raise _bad(path, "incomplete: the table ends with a line break, which a complete file does not have "
                   "after its last row (the file is cut at a row boundary)")
    if last.count("\t") != len(names) - 1:
        raise _bad(path, f"incomplete: the last row has {last.count(chr(9)) + 1} of {len(names)} fields "
                   "(the file is cut inside a row)")
    try:
        data = np.loadtxt(io.StringIO(rows), delimiter="\t", ndmin=2)
    except ValueError as exc:
        raise _bad(path, f"the table is damaged ({exc})") from exc
    if data.shape[1] != len(names):
        raise _bad(path, f"the table has {data.shape[1]} columns, not {len(names)}")
    cols = {name: data[:, j] for j, name in enumerate(names)}
    for name in ("index", "sweep_position"):
        if name in cols:
            cols[name] = cols[name].astype(np.int64)
    return header, cols, True


def _embedded(path, blob):
    """``(header, metadata)`` from the JSON stored inside an npz/parquet file."""
    meta = json.loads(blob)
    if not (isinstance(meta, dict) and isinstance(meta.get("header"), str) and isinstance(meta.get("metadata"), dict)):
        raise _bad(path, "the embedded particleShear metadata is incomplete")
    return meta["header"], meta["metadata"]


def _split_text(text):
    """(header up to and including the "Detailed … data" line, rest) as the R package splits them."""
    pos = 0
    for k, line in enumerate(text.split("\n", 200)[:200]):
        end = pos + len(line)
        if _DETAILED.search(line):
            return text[:end], text[end:]
        pos = end + 1
    return text, ""


def verify_run(path):
    """Check cheaply that a run file is complete: what a resume asks of every finished run.

    Checks, without reading the table: the file exists and is not empty; its size equals the
    sidecar's ``size_bytes`` (when it has a sidecar that records one); the container is readable
    where that is cheap — the central directory of an npz (member names), the footer of a
    Parquet file (columns, and its row count against the embedded ``n_rows``), the particleShear
    header at the start of a text file and, for a plain text file without a recorded size, a
    complete last row.  A few kB are read per file, whatever its size.  :func:`read_run` does
    the full check (SHA-256, every row).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.txt``, ``.txt.gz``, ``.npz`` or ``.parquet`` run file.

    Returns
    -------
    dict
        The content of the file's sidecar (``{}`` when it has none).

    Raises
    ------
    RunFileError
        (a ``ValueError``) naming the file and what is wrong: missing, empty, size differing
        from the sidecar's, unreadable container, not a particleShear file, cut inside a row.
    ValueError
        For a path without a run-file suffix.
    """
    path = os.fspath(path)
    fmt = format_of(path)
    meta, size = _check_file(path, fmt)
    _check_container(path, fmt, meta, size)
    return meta


_PROVENANCE = {key: re.compile(r"\n\t" + label + r": ([^\n]*)\n")
               for key, label in (("run_id", "Run id"), ("seed_entropy", "Seed entropy"),
                                  ("spawn_key", "Seed spawn key"))}


def run_file_identity(path):
    """The run a run file says it is, from its own header: what a resume checks without the sidecar.

    Reads a few kB: the start of a text file, the ``header`` member of an npz, the footer of a
    Parquet file.  The provenance lines of block 1 (docs/output.md) give the run id, the seed
    entropy and the spawn key.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.txt``, ``.txt.gz``, ``.npz`` or ``.parquet`` run file (verified first with :func:`verify_run`).

    Returns
    -------
    dict
        ``{"run_id": str, "seed_entropy": str, "spawn_key": str}`` as the header writes them
        (``"[3]"`` for spawn key 3); a key is absent when the header has no such line (a file
        without provenance lines).

    Raises
    ------
    RunFileError
        (a ``ValueError``) naming the file when its header cannot be read.
    """
    path = os.fspath(path)
    fmt = format_of(path)
    try:
        if fmt in ("text", "text.gz"):
            opener = gzip.open if fmt == "text.gz" else open
            with opener(path, "rb") as fh:
                header = _split_text(fh.read(_HEAD_CHARS).decode("utf-8", errors="replace"))[0]
        elif fmt == "npz":
            with zipfile.ZipFile(path) as zf, zf.open("header.npy") as fh:
                header, _ = _embedded(path, str(np.lib.format.read_array(fh, allow_pickle=False)))
        else:
            _, pq = _pyarrow()
            kv = pq.ParquetFile(path).metadata.metadata or {}
            header, _ = _embedded(path, kv[_PARQUET_KEY].decode("utf-8"))
    except (RunFileError, ImportError, MemoryError):
        raise
    except Exception as exc:  # KeyError (no header member), zip/gzip/Arrow errors
        raise _bad(path, f"its header cannot be read ({type(exc).__name__}: {exc})") from exc
    found = {key: rx.search(header) for key, rx in _PROVENANCE.items()}
    return {key: m.group(1).strip() for key, m in found.items() if m}


def _check_file(path, fmt):
    """``(sidecar content, size)``: the file exists, is not empty and has the size its sidecar records."""
    try:
        size = os.stat(path).st_size
    except FileNotFoundError:
        raise _bad(path, "does not exist") from None
    except OSError as exc:
        raise _bad(path, f"cannot be read ({exc})") from exc
    if not os.path.isfile(path):
        raise _bad(path, "is not a regular file")
    if size == 0:
        raise _bad(path, "is empty (0 bytes)")
    side_path, meta = _sidecar(path, fmt)
    recorded = meta.get("size_bytes")
    if recorded is not None and size != recorded:
        raise _bad(path, f"incomplete or changed: {size} bytes, its sidecar {os.path.basename(side_path)} "
                   f"records {recorded}")
    return meta, size


def _check_container(path, fmt, meta, size):
    """The cheap structure checks of :func:`verify_run` (a few kB read)."""
    recorded = meta.get("size_bytes")
    try:
        if fmt in ("text", "text.gz"):
            opener = gzip.open if fmt == "text.gz" else open
            with opener(path, "rb") as fh:
                head = fh.read(_HEAD_CHARS).decode("utf-8", errors="replace")
            header, _ = _split_text(head)
            _check_text_header(path, header)
            if fmt == "text" and recorded is None:  # no recorded size: a complete last line
                with open(path, "rb") as fh:
                    fh.seek(max(0, size - 4096))
                    last = fh.read().decode("utf-8", errors="replace").rsplit("\n", 1)[-1]
                n_fields = max(len(c) for c in _tables(header)) if not _is_rheometer(header) else \
                    len(head[len(header):].lstrip("\n").split("\n", 1)[0].split("\t"))
                if last != NO_TENSOR_DATA_TEXT.rsplit("\n", 1)[-1] and last.count("\t") != n_fields - 1:
                    raise _bad(path, "incomplete: the last row is cut")
        elif fmt == "npz":
            with zipfile.ZipFile(path) as zf:
                names = {n[:-4] for n in zf.namelist() if n.endswith(".npy")}
            missing = [c for c in ("header",) + tuple(TABLE_COLUMNS[:6]) if c not in names]
            if missing:
                raise _bad(path, "incomplete: members missing: " + ", ".join(missing))
        else:
            _, pq = _pyarrow()
            md = pq.ParquetFile(path).metadata
            kv = md.metadata or {}
            if _PARQUET_KEY not in kv:
                raise _bad(path, "not a particleShear Parquet file (no particleShear metadata)")
            _, embedded = _embedded(path, kv[_PARQUET_KEY].decode("utf-8"))
            names = [md.schema.column(j).name for j in range(md.num_columns)]
            missing = [c for c in TABLE_COLUMNS[:6] if c not in names]
            if missing:
                raise _bad(path, "incomplete: columns missing: " + ", ".join(missing))
            if embedded.get("n_rows") is not None and md.num_rows != embedded["n_rows"]:
                raise _bad(path, f"incomplete: {md.num_rows} rows, its metadata records {embedded['n_rows']}")
    except (RunFileError, ImportError, MemoryError):
        raise
    except Exception as exc:  # BadZipFile, EOFError, zlib/gzip/Arrow errors: an unreadable container
        raise _bad(path, f"unreadable {fmt} file ({type(exc).__name__}: {exc})") from exc


def read_run(path):
    """Read a run file of any :data:`OUTPUT_FORMATS` into a :class:`RunData`, verifying it.

    Besides :func:`verify_run`'s checks: the SHA-256 of the file against the sidecar's
    ``sha256``; the container's own checks (gzip CRC, the CRC-32 of each npz member, Parquet page
    checksums); for text the header blocks and a complete table (every row with 42 fields,
    index 0…n-1); every column present and of one length, equal to the ``n_rows`` recorded in
    the sidecar or embedded metadata — or, without one, to the protocol steps the header
    records (``int((P + pre + post)/f/dt)``; headers with the provenance lines only).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.txt``, ``.txt.gz``, ``.npz`` or ``.parquet`` file written by particleShear.

    Returns
    -------
    RunData
        ``{column: array}`` plus ``header`` (text), ``metadata`` (dict) and ``to_dataframe()``.
        Values are exactly those of ``SimulationResult.series`` (the text formats write
        ``str()`` of each float, which reads back bit for bit).

    Raises
    ------
    RunFileError
        (a ``ValueError``) naming the file and what is wrong: missing, empty, incomplete,
        damaged (checksum mismatch), not a particleShear file, columns missing.
    ValueError
        For a path without a run-file suffix.
    ImportError
        For a Parquet file without pyarrow.
    """
    path = os.fspath(path)
    fmt = format_of(path)
    side, _ = _check_file(path, fmt)  # the container is checked by parsing it, after the hash
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise _bad(path, f"cannot be read ({exc})") from exc
    if side.get("sha256") is not None and hashlib.sha256(data).hexdigest() != side["sha256"]:
        raise _bad(path, "damaged: its SHA-256 differs from the one its sidecar records")
    try:
        if fmt in ("text", "text.gz"):
            raw = gzip.decompress(data) if fmt == "text.gz" else data
            # a foreign file is named as such, also when it is not UTF-8
            _check_text_header(path, _split_text(raw[:_HEAD_CHARS].decode("utf-8", errors="replace"))[0])
            header, cols, table = _parse_text(path, raw.decode("utf-8"))
            metadata = side
        elif fmt == "npz":
            with np.load(io.BytesIO(data), allow_pickle=False) as z:
                if "header" not in z.files:
                    raise _bad(path, "incomplete: the member 'header' is missing")
                header, metadata = _embedded(path, str(z["header"]))
                cols = {name: z[name] for name in z.files if name != "header"}
            table = True
        else:
            pa, pq = _pyarrow()
            t = pq.read_table(pa.BufferReader(data), page_checksum_verification=True)
            kv = t.schema.metadata or {}
            if _PARQUET_KEY not in kv:
                raise _bad(path, "not a particleShear Parquet file (no particleShear metadata)")
            header, metadata = _embedded(path, kv[_PARQUET_KEY].decode("utf-8"))
            cols = {name: t.column(name).to_numpy() for name in t.column_names}
            table = True
        n_recorded = side.get("n_rows", metadata.get("n_rows"))
        _check_rows(path, cols, n_recorded, header, table)
    except (RunFileError, ImportError, MemoryError):
        raise
    except Exception as exc:  # EOFError, BadZipFile (CRC), zlib/gzip/Arrow errors, UnicodeDecodeError, KeyError …
        raise _bad(path, f"damaged or unreadable {fmt} file ({type(exc).__name__}: {exc})") from exc
    ordered = {name: cols[name] for name in tuple(TABLE_COLUMNS) + RHEOMETER_EXTRA_COLUMNS if name in cols}
    return RunData(ordered, header, metadata, path, fmt)
