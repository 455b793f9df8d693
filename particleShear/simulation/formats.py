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
is complete or absent.  See ``docs/output.md`` for sizes and load times.
"""
__docformat__ = "numpy"
import gzip
import io
import json
import os
import re
import zipfile

import numpy as np

from .output import NO_TENSOR_DATA_TEXT, TABLE_COLUMNS, iter_table_text

__all__ = ["OUTPUT_FORMATS", "FORMAT_SUFFIXES", "read_run", "RunData", "write_run", "check_output_format",
           "series_columns"]

#: the accepted values of ``output_format`` and their file suffixes
FORMAT_SUFFIXES = {"text": ".txt", "text.gz": ".txt.gz", "npz": ".npz", "parquet": ".parquet"}
OUTPUT_FORMATS = tuple(FORMAT_SUFFIXES)

#: series key of SimulationResult.series → table column (the five base series)
_SERIES_COLUMNS = (("t", "t"), ("strain", "strain"), ("strain_rate", "strain_rate"),
                   ("stress_surface", "stress_measured_at_surface"),
                   ("stress_internal", "shear_stress_internal_stress-tensor"))
_PARQUET_HINT = ("output_format='parquet' needs pyarrow, which is not installed: "
                 "pip install 'particleShear[parquet]' (or pip install pyarrow)")
#: rows per Parquet row group (about 5 MB of columns)
_PARQUET_ROWS = 16384
_DETAILED = re.compile(r"Detailed[a-zA-Z0-9\s].*data")


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


def write_run(fh, output_format, header_text, scalars, tensors, metadata):
    """Stream one run into the open binary file ``fh`` in ``output_format``.

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
        JSON-safe run description (the sidecar's content), stored inside npz/parquet.
    """
    if output_format in ("text", "text.gz"):
        gz = gzip.GzipFile(fileobj=fh, mode="wb", compresslevel=6, mtime=0) if output_format == "text.gz" else None
        out = gz if gz is not None else fh
        out.write(header_text.encode("utf-8"))
        if tensors is not None:
            for piece in iter_table_text(scalars, tensors):
                out.write(piece.encode("utf-8"))
        else:
            out.write(("\n" + NO_TENSOR_DATA_TEXT).encode("utf-8"))
        if gz is not None:
            gz.close()  # writes the gzip trailer; fh stays open
        return
    series = {key: scalars[:, k] for k, (key, _) in enumerate(_SERIES_COLUMNS)}
    if tensors is not None:
        series["tensors"] = tensors
    cols = series_columns(series)
    meta = json.dumps({"header": header_text, "metadata": metadata})
    if output_format == "npz":
        # what numpy.savez writes, one column at a time (one column copy in memory, not the table)
        with zipfile.ZipFile(fh, mode="w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
            arrays = [("header", np.array(meta))] + list(cols.items())
            for name, v in arrays:  # a strided column is copied when written, one at a time
                v = v if v.ndim == 0 else np.ascontiguousarray(v)
                with zf.open(name + ".npy", "w", force_zip64=True) as member:
                    np.lib.format.write_array(member, v, allow_pickle=False)
        return
    if output_format == "parquet":
        pa, pq = _pyarrow()
        schema = pa.schema([(name, pa.int64() if name == "index" else pa.float64()) for name in cols],
                           metadata={b"particleShear": meta.encode("utf-8")})
        n = len(cols["index"])
        with pq.ParquetWriter(fh, schema, use_dictionary=False) as writer:
            for a in range(0, max(n, 1), _PARQUET_ROWS):  # row groups: bounded extra memory
                b = min(n, a + _PARQUET_ROWS)
                writer.write_table(pa.table({name: np.ascontiguousarray(v[a:b]) for name, v in cols.items()},
                                            schema=schema))
        return
    raise ValueError(f"output_format={output_format!r} is invalid: allowed " + ", ".join(OUTPUT_FORMATS))


class RunData(dict):
    """The per-step columns of one run (``{column name: numpy array}``) with its header.

    Keys are the table's column names (``index``, ``t``, ``strain``, ``strain_rate``,
    ``stress_measured_at_surface``, ``shear_stress_internal_stress-tensor`` and the 36
    ``stress_tensor_*`` columns when saved); empty for a text file written with
    ``saveStressTensorData=False`` (the reference writes no table then).

    Made by :func:`read_run`; the parameters are also its attributes.

    Parameters
    ----------
    columns : dict
        Column name → 1-D array (the dict's items).
    header : str
        The text header, blocks 1–3, up to and including "Detailed stress tensor data".
    metadata : dict
        Parameters and provenance (run id, seed, version): stored in npz/parquet, read from the
        ``<file>.json`` sidecar for text files (empty when there is none).
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

    @property
    def series(self):
        """The columns under the keys of ``SimulationResult.series`` (tensors as (n, 9, 2, 2))."""
        out = {key: self[col] for key, col in _SERIES_COLUMNS if col in self}
        names = TABLE_COLUMNS[6:]
        if all(name in self for name in names):
            out["tensors"] = np.stack([self[name] for name in names], axis=1).reshape(-1, 9, 2, 2)
        return out

    def to_dataframe(self):
        """A ``pandas.DataFrame`` of the columns (needs pandas); header and metadata in ``.attrs``."""
        try:
            import pandas as pd
        except ImportError as exc:
            raise ImportError("RunData.to_dataframe needs pandas: pip install pandas") from exc
        df = pd.DataFrame(dict(self))
        df.attrs["header"] = self.header
        df.attrs["metadata"] = self.metadata
        return df


def _format_of(path):
    p = str(path)
    for fmt in ("text.gz", "text", "npz", "parquet"):
        if p.endswith(FORMAT_SUFFIXES[fmt]):
            return fmt
    raise ValueError(f"path={p!r} is not a run file: allowed suffixes "
                     + ", ".join(FORMAT_SUFFIXES.values()))


def _split_text(text):
    """(header up to and including the "Detailed … data" line, rest) as the R package splits them."""
    pos = 0
    for k, line in enumerate(text.split("\n", 200)[:200]):
        end = pos + len(line)
        if _DETAILED.search(line):
            return text[:end], text[end:]
        pos = end + 1
    return text, ""


def _read_table(body):
    lines = body.lstrip("\n")
    if not lines.startswith("index\t"):
        return {}
    first_nl = lines.find("\n")
    names = lines[:first_nl if first_nl >= 0 else None].split("\t")
    if first_nl < 0:
        return {name: np.empty(0) for name in names}
    data = np.loadtxt(io.StringIO(lines[first_nl + 1:]), delimiter="\t", ndmin=2)
    cols = {name: data[:, j] for j, name in enumerate(names)}
    cols["index"] = cols["index"].astype(np.int64)
    return cols


def read_run(path):
    """Read a run file of any :data:`OUTPUT_FORMATS` into a :class:`RunData`.

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
    """
    path = os.fspath(path)
    fmt = _format_of(path)
    if fmt in ("text", "text.gz"):
        opener = gzip.open if fmt == "text.gz" else open
        with opener(path, "rt", encoding="utf-8", newline="") as fh:
            text = fh.read()
        header, body = _split_text(text)
        metadata = {}
        if os.path.exists(path + ".json"):
            with open(path + ".json", encoding="utf-8") as fh:
                metadata = json.load(fh)
        return RunData(_read_table(body), header, metadata, path, fmt)
    if fmt == "npz":
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["header"]))
            cols = {name: z[name] for name in z.files if name != "header"}
        ordered = {name: cols[name] for name in TABLE_COLUMNS if name in cols}
        return RunData(ordered, meta["header"], meta["metadata"], path, fmt)
    _, pq = _pyarrow()
    table = pq.read_table(path)
    meta = json.loads(table.schema.metadata[b"particleShear"].decode("utf-8"))
    cols = {name: table.column(name).to_numpy() for name in table.column_names}
    return RunData(cols, meta["header"], meta["metadata"], path, fmt)
