"""Readers of measured rheometer files: :func:`read_rheometer` → a list of :class:`~.tables.MeasuredTest`.

Formats (detected from the content and the file name, or named by ``format=``):

``rheocompass``
    Anton Paar RheoCompass text exports: UTF-16 with BOM or UTF-8, CRLF or LF, tab-separated,
    decimal comma or point.  Each test is a block introduced by ``Test:``, ``Result:`` and
    ``Interval:`` lines, then a line of column names (``Point No.  Time  Shear Strain …``), an
    optional empty line, a units row (``[s] [%] [Pa] …``) and the points, up to an empty line or
    the next block.  Every interval with points is one test; an interval without points is left
    out (``meta["skipped"]`` of the file's first test names it).
``trios``
    TA Instruments TRIOS "Export to LIMS" text: header lines ``name<TAB>value``, then ``[step]``
    blocks, each with ``Step name``, ``Number of points``, a ``Variables`` line of column names, a
    units row and rows starting with ``Data point``.  One test per step.
``reptate``
    RepTate files (by extension): a first line ``param=value;param=value;…``, optional ``#``
    lines and a line of column names or units, then whitespace-separated numbers in the units
    of RepTate's applications: ``.osc``/``.tts`` ω (rad/s), G′, G″ (Pa); ``.gt`` t (s), G(t)
    (Pa); ``.creep`` t (s), γ (absolute), with ``stress=`` (Pa) in the header; ``.shear`` t (s),
    σ_xy (Pa), N1 (Pa), γ̇ (1/s); ``.laos`` time (s), γ (absolute), σ (Pa), with ``omega=``
    (rad/s) and ``gamma=`` in the header.
``table``
    Any other CSV/TSV (separator tab, ``;`` or ``,``; ``#`` lines skipped): a header line of
    column names, an optional units row, then numbers.  ``columns=`` maps the file's names to
    quantities (:data:`~.tables.QUANTITIES`); without it the names of :data:`COLUMN_NAMES` are
    recognised.  pyRheo's tab-separated tables (``Angular Frequency / Storage Modulus / Loss
    Modulus``, ``Time / Relaxation Modulus``, ``Time / Creep Compliance``, ``Shear Rate /
    Viscosity``) are read this way; they carry no units, so ``units=`` must give them.

Units are converted to the SI units of :data:`~.tables.QUANTITIES` (:data:`UNITS`: % → 1,
mPa/kPa/MPa → Pa, Hz ↔ rad/s, mPa·s → Pa·s, min → s, …) and stated per column in
``meta["units"]`` (``{quantity: "source name [source unit] -> SI unit"}``).  A column the test
uses with no unit, or a unit this module does not know for the quantity, is a ``ValueError``
that names the file, the line and the column and says how to give the unit
(``units={"Shear Strain": "%"}``) — never a guess.  Bad numbers, truncated rows, unknown
columns are ``ValueError`` naming file, line and column.

The kind of test (:data:`~.tables.KINDS`) is read from the columns, unless ``kind=`` is given:
G′ and G″ with a strain amplitude that varies at a fixed frequency → ``amplitude_sweep``; with a
frequency that varies → ``frequency_sweep``; a relaxation modulus → ``relaxation``; shear rate
and stress (or viscosity) → ``flow_curve``; time, strain and stress with a strain that changes
sign → ``laos``, otherwise time and strain → ``creep``.

Files larger than :data:`MAX_FILE_BYTES` (200 MiB) are refused before they are read.
NumPy only.
"""
__docformat__ = "numpy"
import math
import os
import re

import numpy as np

from .tables import KINDS, QUANTITIES, MeasuredTest

__all__ = ["COLUMN_NAMES", "FORMATS", "MAX_FILE_BYTES", "REPTATE_EXTENSIONS", "UNITS", "read_rheometer"]

#: largest file read (bytes): 200 MiB, some 10 million points of a few columns
MAX_FILE_BYTES = 200 * 1024 * 1024

#: the formats :func:`read_rheometer` reads (``format=``)
FORMATS = ("rheocompass", "trios", "reptate", "table")

#: RepTate extension → (kind, quantities of the columns in order, the unit of each)
REPTATE_EXTENSIONS = {
    ".osc": ("frequency_sweep", ("angular_frequency", "Gp", "Gpp"), ("rad/s", "Pa", "Pa")),
    ".tts": ("frequency_sweep", ("angular_frequency", "Gp", "Gpp"), ("rad/s", "Pa", "Pa")),
    ".gt": ("relaxation", ("time", "G"), ("s", "Pa")),
    ".creep": ("creep", ("time", "strain"), ("s", "1")),
    ".shear": ("flow_curve", ("time", "stress", "N1", "shear_rate"), ("s", "Pa", "Pa", "1/s")),
    ".laos": ("laos", ("time", "strain", "stress"), ("s", "1", "Pa")),
}

#: column names the readers recognise (lower case, spaces collapsed) → quantity.  In a test with
#: G′ and G″ a strain column is the strain amplitude and a stress column the stress amplitude.
COLUMN_NAMES = {
    "angular frequency": "angular_frequency", "ang. frequency": "angular_frequency", "omega": "angular_frequency",
    "w": "angular_frequency",
    "frequency": "frequency", "osc. frequency": "frequency", "oscillation frequency": "frequency",
    "storage modulus": "Gp", "g'": "Gp", "g′": "Gp", "gp": "Gp",
    "loss modulus": "Gpp", "g''": "Gpp", "g″": "Gpp", "gpp": "Gpp",
    "shear strain": "strain", "strain": "strain", "oscillation strain": "strain", "osc. strain": "strain",
    "gamma": "strain", "strain amplitude": "strain",
    "shear stress": "stress", "stress": "stress", "oscillation stress": "stress", "osc. stress": "stress",
    "sigma": "stress", "sigma_xy": "stress", "stress amplitude": "stress",
    "shear rate": "shear_rate", "gdot": "shear_rate",
    "viscosity": "viscosity", "shear viscosity": "viscosity",
    "relaxation modulus": "G", "g(t)": "G", "gt": "G",
    "time": "time", "step time": "time", "t": "time", "interval time": "time",
    "temperature": "temperature",
    "creep compliance": "compliance", "compliance": "compliance", "j(t)": "compliance",
    "normal stress difference": "N1", "first normal stress difference": "N1", "n1": "N1",
}

_PA = {"Pa": 1.0, "mPa": 1e-3, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "N/m²": 1.0, "N/m^2": 1.0, "N/m2": 1.0}
#: dimension → {unit as written: factor to the SI unit}; the units are matched exactly (mPa is not MPa),
#: after spaces are removed and ``·``, ``*``, ``.`` between Pa and s are read alike
UNITS = {
    "pressure": dict(_PA),
    "strain": {"%": 0.01, "1": 1.0, "-": 1.0, "abs": 1.0, "absolute": 1.0, "‰": 1e-3, "mm/mm": 1.0},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0},
    "angular_frequency": {"rad/s": 1.0, "1/s": 1.0, "s^-1": 1.0, "s-1": 1.0, "rad/min": 1 / 60},
    "frequency": {"Hz": 1.0, "1/s": 1.0, "s^-1": 1.0, "kHz": 1e3, "mHz": 1e-3},
    "rate": {"1/s": 1.0, "s^-1": 1.0, "s-1": 1.0, "1/min": 1 / 60},
    "viscosity": {"Pa·s": 1.0, "mPa·s": 1e-3, "kPa·s": 1e3, "MPa·s": 1e6, "Pas": 1.0, "mPas": 1e-3, "cP": 1e-3,
                  "P": 0.1},
    "compliance": {"1/Pa": 1.0, "Pa^-1": 1.0, "1/kPa": 1e-3, "1/MPa": 1e-6, "kPa^-1": 1e-3},
    "temperature": {"°C": 1.0, "C": 1.0, "degC": 1.0, "K": 1.0},
}
_DIMENSION = {"strain_amplitude": "strain", "strain": "strain", "Gp": "pressure", "Gpp": "pressure",
              "G": "pressure", "stress": "pressure", "stress_amplitude": "pressure", "N1": "pressure",
              "angular_frequency": "angular_frequency", "frequency": "frequency", "shear_rate": "rate",
              "viscosity": "viscosity", "time": "time", "compliance": "compliance", "temperature": "temperature"}


def _where(path, line=None, column=None):
    """``'FILE', line N, column 'X'`` for messages."""
    text = f"{os.fspath(path)!r}"
    if line is not None:
        text += f", line {line}"
    if column is not None:
        text += f", column {column!r}"
    return text


def _norm_name(name):
    return " ".join(str(name).strip().lower().split())


def _norm_unit(unit):
    u = str(unit).strip()
    if u.startswith("[") and u.endswith("]"):
        u = u[1:-1].strip()
    u = u.replace(" ", "")
    u = re.sub(r"Pa[*.·⋅]s", "Pa·s", u)
    return u


def _unit_factor(quantity, unit):
    """(SI quantity, factor, offset) of ``unit`` for ``quantity``; None when unknown."""
    u = _norm_unit(unit)
    dim = _DIMENSION[quantity]
    if quantity == "temperature":
        if u in ("K",):
            return quantity, 1.0, -273.15
        return (quantity, 1.0, 0.0) if u in UNITS["temperature"] else None
    if quantity == "frequency" and u in ("rad/s", "rad/min"):         # a frequency column in rad/s: ω
        return "angular_frequency", UNITS["angular_frequency"][u], 0.0
    if quantity == "angular_frequency" and u in ("Hz", "kHz", "mHz"):  # an ω column in Hz: f
        return "frequency", UNITS["frequency"][u], 0.0
    table = UNITS[dim]
    if u in table:
        return quantity, table[u], 0.0
    return None


def _read_text(path):
    """The decoded text of ``path`` and its encoding (UTF-16 with a BOM, UTF-8, else Latin-1)."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"path={path!r} is not a file")
    size = os.path.getsize(path)
    if size > MAX_FILE_BYTES:
        raise ValueError(f"{path!r} has {size} bytes: larger than the {MAX_FILE_BYTES} bytes "
                         "(experiment.readers.MAX_FILE_BYTES) a rheometer file is read to; split the file")
    with open(path, "rb") as fh:
        raw = fh.read(MAX_FILE_BYTES + 1)
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        return raw.decode("utf-16"), "utf-16"
    if len(raw) >= 4 and raw[1:2] == b"\x00" and raw[3:4] == b"\x00":   # UTF-16-LE without a BOM
        return raw.decode("utf-16-le"), "utf-16-le"
    if raw.startswith(b"\xef\xbb\xbf"):
        return raw.decode("utf-8-sig"), "utf-8"
    try:
        return raw.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        return raw.decode("latin-1"), "latin-1"


def _detect_format(path, lines):
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext in REPTATE_EXTENSIONS:
        return "reptate"
    for line in lines[:10000]:
        s = line.strip()
        if s.lower() == "[step]":
            return "trios"
        if re.match(r"^(Test|Result|Interval):(\t|\s|$)", s):
            return "rheocompass"
    return "table"


def _number(text, decimal_comma, path, line, column):
    t = text.strip()
    if decimal_comma:
        if "." in t and "," in t:
            raise ValueError(f"{_where(path, line, column)}: {text!r} has both '.' and ',': not a number with a "
                             "decimal comma")
        t = t.replace(",", ".")
    if t == "" or t.lower() in ("nan", "--", "-", "n/a", "na", "inf", "-inf", "+inf"):
        if t.lower() in ("inf", "+inf", "-inf"):
            return float(t)
        return math.nan
    try:
        return float(t)
    except ValueError:
        raise ValueError(f"{_where(path, line, column)}: {text!r} is not a number") from None


def _user_unit(units, name, quantity):
    """The unit ``units=`` gives for a source column (by its name, case-insensitively, or its quantity)."""
    if not units:
        return None
    for key, value in units.items():
        if key == name or _norm_name(key) == _norm_name(name) or key == quantity:
            return value
    return None


def _user_quantity(columns, name, path, line):
    """(quantity, unit or None) that ``columns=`` gives a source column, or None when it does not name it."""
    if not columns:
        return None
    for key, value in columns.items():
        if key == name or _norm_name(key) == _norm_name(name):
            q, u = (value, None) if isinstance(value, str) else tuple(value)
            if q not in QUANTITIES:
                raise ValueError(f"columns={{{key!r}: {value!r}}}: {q!r} is not a known quantity: one of "
                                 f"{sorted(QUANTITIES)} ({_where(path, line)})")
            return q, u
    return None


def _split_name_unit(name):
    """``'Time [s]'`` or ``'Time (s)'`` → ('Time', 's'); otherwise (name, None)."""
    m = re.match(r"^(.*?)\s*[\[(]([^\])]*)[\])]\s*$", name)
    if m and m.group(1):
        return m.group(1), m.group(2)
    return name, None


def _decimal_comma(rows, separator):
    """Whether the numbers of ``rows`` (lists of cells) use a decimal comma (never with ',' as separator)."""
    if separator == ",":
        return False
    for cells in rows:
        for c in cells:
            if re.fullmatch(r"\s*[-+]?\d*,\d+([eE][-+]?\d+)?\s*", c):
                return True
    return False


def _build(path, names, unit_cells, rows, *, header_line, units_line, kind, columns, units, meta, fixed_units=None,
           fixed_quantities=None, decimal_comma=False):
    """One MeasuredTest from a block: names (source column names), their units, rows ``(line number, cells)``."""
    # which source columns are used, as what
    used = []                       # (index, source name, quantity, unit text, where the unit came from)
    ignored = []
    for i, name in enumerate(names):
        name = name.strip()
        if fixed_quantities is not None:
            if i >= len(fixed_quantities):
                ignored.append(name or f"column {i + 1}")
                continue
            q, u = fixed_quantities[i], fixed_units[i]
            used.append((i, name or q, q, u, "the format"))
            continue
        base, unit_in_name = _split_name_unit(name)
        given = _user_quantity(columns, name, path, header_line) or _user_quantity(columns, base, path, header_line)
        if given is not None:
            q, u = given
        elif columns:
            ignored.append(name)
            continue
        else:
            q, u = COLUMN_NAMES.get(_norm_name(base)), None
            if q is None:
                if name:
                    ignored.append(name)
                continue
        unit_row = unit_cells[i].strip() if unit_cells is not None and i < len(unit_cells) else ""
        for text, whence in ((u, "columns="), (_user_unit(units, name, q) or _user_unit(units, base, q), "units="),
                             (unit_in_name, "the column name"), (unit_row, "the units row")):
            if text not in (None, ""):
                used.append((i, name, q, text, whence))
                break
        else:
            used.append((i, name, q, None, None))
    if columns:
        present = {_norm_name(n) for n in names} | {_norm_name(_split_name_unit(n)[0]) for n in names}
        for key in columns:
            if _norm_name(key) not in present:
                raise ValueError(f"{_where(path, header_line, key)}: columns= names a column the file does not "
                                 f"have; its columns are {[n.strip() for n in names if n.strip()]}")
    quantities = [q for _, _, q, _, _ in used]
    dup = sorted({q for q in quantities if quantities.count(q) > 1})
    if dup:
        raise ValueError(f"{_where(path, header_line)}: several columns are {dup}: give columns= to say which to use")
    oscillatory = "Gp" in quantities and "Gpp" in quantities
    # values
    data = {}
    for i, name, q, _, _ in used:
        vals = np.empty(len(rows))
        for r, (ln, cells) in enumerate(rows):
            if i >= len(cells):
                raise ValueError(f"{_where(path, ln, name)} (column {i + 1}): the row is truncated: it has "
                                 f"{len(cells)} cells, the header (line {header_line}) names {len(names)} columns")
            vals[r] = _number(cells[i], decimal_comma, path, ln, name)
        data[i] = vals
    # units → SI
    out, stated = {}, {}
    for i, name, q, unit, whence in used:
        if oscillatory and q in ("strain", "stress"):
            q = q + "_amplitude"
        if unit is None:
            hint = "%" if _DIMENSION[q] == "strain" else sorted(UNITS[_DIMENSION[q]])[0]
            raise ValueError(f"{_where(path, units_line or header_line, name)}: the column has no unit "
                             f"({QUANTITIES[q][1]}): give it, e.g. units={{{name!r}: {hint!r}}}")
        conv = _unit_factor(q, unit)
        if conv is None:
            raise ValueError(f"{_where(path, units_line or header_line, name)}: unit {_norm_unit(unit)!r} (from {whence}) is not "
                             f"known for {q} ({QUANTITIES[q][1]}): allowed {sorted(UNITS[_DIMENSION[q]])}; give "
                             f"the right one, e.g. units={{{name!r}: {sorted(UNITS[_DIMENSION[q]])[0]!r}}}")
        q2, factor, offset = conv
        if q2 in out:
            raise ValueError(f"{_where(path, header_line, name)}: a second {q2} column: give columns= to say which "
                             "to use")
        out[q2] = data[i] * factor + offset
        stated[q2] = f"{name} [{_norm_unit(unit)}] -> {QUANTITIES[q2][0]}" + (f" (x{factor:g})" if factor != 1 else "") + \
            (f" ({offset:+g})" if offset else "")
    # derived columns
    if "angular_frequency" not in out and "frequency" in out:
        out["angular_frequency"] = 2 * math.pi * out["frequency"]
        stated["angular_frequency"] = "2π × frequency"
    if "frequency" not in out and "angular_frequency" in out:
        out["frequency"] = out["angular_frequency"] / (2 * math.pi)
        stated["frequency"] = "angular_frequency / 2π"
    if "stress" not in out and "viscosity" in out and "shear_rate" in out:
        out["stress"] = out["viscosity"] * out["shear_rate"]
        stated["stress"] = "viscosity × shear_rate"
    if "viscosity" not in out and "stress" in out and "shear_rate" in out:
        with np.errstate(divide="ignore", invalid="ignore"):
            out["viscosity"] = out["stress"] / out["shear_rate"]
        stated["viscosity"] = "stress / shear_rate"
    kind = _kind(path, header_line, out, kind)
    if kind == "creep" and "strain" not in out and "compliance" in out and "stress" in meta:
        out["strain"] = out["compliance"] * meta["stress"]
        stated["strain"] = "compliance × stress (header)"
    if kind == "creep" and "stress" in out and "stress" not in meta:
        s = out["stress"][np.isfinite(out["stress"])]
        if len(s):
            meta["stress"] = float(np.median(s))
    if kind == "creep" and "compliance" not in out and "strain" in out and meta.get("stress"):
        out["compliance"] = out["strain"] / meta["stress"]
        stated["compliance"] = "strain / stress"
    if kind == "laos" and "omega" not in meta and "angular_frequency" in out:
        w = out["angular_frequency"][np.isfinite(out["angular_frequency"])]
        if len(w):
            meta["omega"] = float(np.median(w))
    missing = [c for c in KINDS[kind] if c not in out]
    if missing:
        raise ValueError(f"{_where(path, header_line)}: a {kind} test needs the column(s) {missing}; the file's "
                         f"columns give {sorted(out)} (unused: {ignored}); map them with columns=")
    meta = dict(meta)
    meta.update({"source": os.fspath(path), "units": stated, "ignored_columns": ignored, "header_line": header_line})
    return MeasuredTest(kind, out, meta)


def _varies(x, rtol=0.05):
    x = x[np.isfinite(x)]
    if len(x) < 2:
        return False
    lo, hi = float(np.min(np.abs(x))), float(np.max(np.abs(x)))
    return hi - lo > rtol * max(hi, 1e-300)


def _kind(path, line, cols, kind):
    if kind is not None:
        if kind not in KINDS:
            raise ValueError(f"kind={kind!r} is not allowed: one of {sorted(KINDS)}")
        return kind
    if "Gp" in cols and "Gpp" in cols:
        amp = "strain_amplitude" in cols and _varies(cols["strain_amplitude"])
        freq = "angular_frequency" in cols and _varies(cols["angular_frequency"])
        if amp and not freq:
            return "amplitude_sweep"
        if freq and not amp:
            return "frequency_sweep"
        if "strain_amplitude" in cols and "angular_frequency" not in cols:
            return "amplitude_sweep"
        if "angular_frequency" in cols and "strain_amplitude" not in cols:
            return "frequency_sweep"
        what = "both vary" if amp and freq else "neither varies"
        raise ValueError(f"{_where(path, line)}: G′ and G″ with strain amplitude and frequency where {what}: "
                         "give kind='amplitude_sweep' or kind='frequency_sweep'")
    if "G" in cols and "time" in cols:
        return "relaxation"
    if "shear_rate" in cols and "stress" in cols:
        return "flow_curve"
    if "time" in cols and "strain" in cols:
        s = cols["strain"][np.isfinite(cols["strain"])]
        if "stress" in cols and len(s) and s.min() < 0 < s.max():
            return "laos"
        return "creep"
    if "time" in cols and "compliance" in cols:
        return "creep"
    raise ValueError(f"{_where(path, line)}: cannot tell the kind of test from the columns {sorted(cols)}: give "
                     f"kind= (one of {sorted(KINDS)}) and columns=")


# ------------------------------------------------------------------------------------------------------------------
def _blank(line):
    return line.strip() == ""


def _read_rheocompass(path, lines, kind, columns, units, encoding):
    tests, skipped = [], []
    block = {}
    n = len(lines)
    i = 0
    while i < n:
        s = lines[i].strip()
        m = re.match(r"^(Test|Result|Interval):\s*(.*)$", s)
        if not m:
            if not _blank(lines[i]) and not block:
                raise ValueError(f"{_where(path, i + 1)}: {s[:60]!r} before the first Test:/Result:/Interval: line "
                                 "of a RheoCompass export")
            i += 1
            continue
        key, value = m.group(1), m.group(2).strip()
        if key == "Test":
            block = {"Test": value}
        else:
            block[key] = value
        i += 1
        if key != "Interval":
            continue
        # the column names
        while i < n and _blank(lines[i]):
            i += 1
        if i >= n:
            break
        header_line = i + 1
        names = lines[i].split("\t")
        i += 1
        while i < n and _blank(lines[i]):
            i += 1
        unit_cells, units_line = None, None
        if i < n and re.match(r"^\s*(\[[^\]]*\]\s*)*$", lines[i].replace("\t", " ")) and "[" in lines[i]:
            unit_cells, units_line = lines[i].split("\t"), i + 1
            i += 1
        rows = []
        while i < n and not re.match(r"^(Test|Result|Interval):", lines[i].strip()):
            line = lines[i]
            if line.strip("\t\r\n ") == "":
                if line.strip() == "" and "\t" not in line and rows:
                    i += 1
                    break      # an empty line ends the points
                i += 1
                continue
            rows.append((i + 1, line.split("\t")))
            i += 1
        name = " / ".join(f"{k} {block[k]}" for k in ("Test", "Result", "Interval") if k in block)
        if not rows:
            skipped.append(name)
            continue
        meta = {"format": "rheocompass", "encoding": encoding, "name": name, "sample": block.get("Test", ""),
                "result": block.get("Result", ""), "interval": block.get("Interval", "")}
        dc = _decimal_comma([c for _, c in rows[:200]], "\t")
        tests.append(_build(path, names, unit_cells, rows, header_line=header_line, units_line=units_line, kind=kind,
                            columns=columns, units=units, meta=meta, decimal_comma=dc))
    if not tests:
        raise ValueError(f"{_where(path)}: no interval with points in this RheoCompass export"
                         + (f" (empty: {skipped})" if skipped else ""))
    if skipped:
        tests[0].meta["skipped"] = skipped
    return tests


def _read_trios(path, lines, kind, columns, units, encoding):
    head, tests = {}, []
    i, n = 0, len(lines)
    while i < n and lines[i].strip().lower() != "[step]":
        cells = [c.strip() for c in lines[i].split("\t") if c.strip()]
        if len(cells) >= 2:
            head[cells[0]] = cells[1]
        i += 1
    while i < n:
        step_line = i + 1
        i += 1
        step, names, unit_cells, header_line, units_line, rows = {}, None, None, None, None, []
        while i < n and lines[i].strip().lower() != "[step]":
            line = lines[i]
            cells = line.split("\t")
            first = cells[0].strip()
            if first.lower() == "variables":
                names, header_line = cells[1:], i + 1
                if i + 1 < n and lines[i + 1].split("\t")[0].strip() == "" and not _blank(lines[i + 1]):
                    unit_cells, units_line = lines[i + 1].split("\t")[1:], i + 2
                    i += 1
            elif first.lower() == "data point":
                if names is None:
                    raise ValueError(f"{_where(path, i + 1)}: a 'Data point' row before the step's 'Variables' line")
                rows.append((i + 1, cells[1:]))
            elif first and len(cells) >= 2 and names is None:
                step[first] = cells[1].strip()
            i += 1
        if names is None:
            raise ValueError(f"{_where(path, step_line)}: a [step] without a 'Variables' line")
        declared = step.get("Number of points")
        if declared is not None:
            try:
                declared = int(float(declared))
            except ValueError:
                raise ValueError(f"{_where(path, step_line)}: 'Number of points' {declared!r} is not a number") \
                    from None
            if declared != len(rows):
                raise ValueError(f"{_where(path, header_line)}: the step declares {declared} points "
                                 f"('Number of points'), the file holds {len(rows)} 'Data point' rows (truncated?)")
        if not rows:
            continue
        meta = {"format": "trios", "encoding": encoding, "name": step.get("Step name", f"step at line {step_line}"),
                "sample": head.get("Sample name", ""), "header": dict(head)}
        m = re.search(r"\(([-+\d.,]+)\s*°C\)", meta["name"])
        if m:
            meta["temperature"] = float(m.group(1).replace(",", "."))
        dc = _decimal_comma([c for _, c in rows[:200]], "\t")
        tests.append(_build(path, names, unit_cells, rows, header_line=header_line, units_line=units_line, kind=kind,
                            columns=columns, units=units, meta=meta, decimal_comma=dc))
    if not tests:
        raise ValueError(f"{_where(path)}: no [step] with 'Data point' rows in this TRIOS export")
    return tests


def _header_params(path, line):
    params = {}
    for part in line.strip().split(";"):
        part = part.strip()
        if not part:
            continue
        if "=" not in part:
            raise ValueError(f"{_where(path, 1)}: {part!r} in the RepTate header is not param=value")
        k, v = part.split("=", 1)
        try:
            params[k.strip()] = float(v)
        except ValueError:
            params[k.strip()] = v.strip()
    return params


def _read_reptate(path, lines, kind, columns, units, encoding):
    ext = os.path.splitext(os.fspath(path))[1].lower()
    rkind, quantities, si = REPTATE_EXTENSIONS[ext]
    if not lines or "=" not in lines[0]:
        raise ValueError(f"{_where(path, 1)}: a RepTate file starts with a line param=value;param=value;…")
    params = _header_params(path, lines[0])
    rows, header_line = [], 2
    for k, line in enumerate(lines[1:], start=2):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = s.split()
        if not rows and not re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", cells[0]):
            header_line = k          # a line of column names or units before the numbers
            continue
        rows.append((k, cells))
    if not rows:
        raise ValueError(f"{_where(path)}: no numbers in this RepTate file")
    need = len(quantities)
    meta = {"format": "reptate", "encoding": encoding, "name": os.path.basename(os.fspath(path)),
            "parameters": params}
    if rkind == "creep":
        if "stress" in params and isinstance(params["stress"], float):
            meta["stress"] = params["stress"]
    if rkind == "laos":
        for key in ("omega", "gamma"):
            if key not in params or not isinstance(params[key], float):
                raise ValueError(f"{_where(path, 1)}: a RepTate .laos file needs {key}=… in its first line")
        meta["omega"], meta["gamma"] = params["omega"], params["gamma"]
    for ln, cells in rows:
        if len(cells) < need:
            raise ValueError(f"{_where(path, ln, quantities[len(cells)])} (column {len(cells) + 1}): the row is "
                             f"truncated: {len(cells)} numbers, a RepTate {ext} file has {need} columns "
                             f"({', '.join(quantities)})")
    names = [f"{q}" for q in quantities]
    return [_build(path, names, None, rows, header_line=header_line, units_line=None, kind=kind or rkind,
                   columns=None, units=None, meta=meta, fixed_units=si, fixed_quantities=quantities)]


def _read_table(path, lines, kind, columns, units, encoding):
    body = [(k + 1, line) for k, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    if not body:
        raise ValueError(f"{_where(path)}: no header line and no numbers")
    header_line, header = body[0]
    sep = "\t" if "\t" in header else (";" if ";" in header else ("," if "," in header else None))
    split = (lambda s: s.split(sep)) if sep else (lambda s: s.split())
    names = [c.strip().strip('"') for c in split(header)]
    rest = body[1:]
    unit_cells, units_line = None, None
    if rest:
        cells = [c.strip().strip('"') for c in split(rest[0][1])]
        if not any(re.fullmatch(r"[-+]?[\d.,]+([eE][-+]?\d+)?", c) for c in cells):
            unit_cells, units_line = cells, rest[0][0]
            rest = rest[1:]
    rows = [(ln, [c.strip().strip('"') for c in split(line)]) for ln, line in rest]
    dc = _decimal_comma([c for _, c in rows[:200]], sep)
    if not rows:
        raise ValueError(f"{_where(path)}: no rows of numbers after the header (line {header_line})")
    meta = {"format": "table", "encoding": encoding, "name": os.path.basename(os.fspath(path)),
            "separator": sep or "whitespace", "decimal": "," if dc else "."}
    return [_build(path, names, unit_cells, rows, header_line=header_line, units_line=units_line, kind=kind,
                   columns=columns, units=units, meta=meta, decimal_comma=dc)]


_READERS = {"rheocompass": _read_rheocompass, "trios": _read_trios, "reptate": _read_reptate, "table": _read_table}


def read_rheometer(path, kind=None, columns=None, units=None, format=None):
    """Read a measured rheometer file into typed tables, one per test (interval, step).

    Parameters
    ----------
    path : str or os.PathLike
        The file (at most :data:`MAX_FILE_BYTES` bytes): a RheoCompass export, a TRIOS "Export to
        LIMS" text, a RepTate file (``.osc``, ``.tts``, ``.gt``, ``.creep``, ``.shear``,
        ``.laos``) or a CSV/TSV table (module docstring).
    kind : str, optional
        The kind of every test of the file (:data:`~.tables.KINDS`); default: read from the
        columns (module docstring).
    columns : dict, optional
        Source column name → quantity (:data:`~.tables.QUANTITIES`) or ``(quantity, unit)``; only
        the columns named are used.  Default: the names of :data:`COLUMN_NAMES`.
    units : dict, optional
        Source column name (or quantity) → unit as written (``{"Shear Strain": "%"}``), for
        columns whose file gives no unit or to override it.
    format : {"rheocompass", "trios", "reptate", "table"}, optional
        Default: detected (RepTate by extension, ``[step]`` lines → TRIOS, ``Test:``/``Interval:``
        lines → RheoCompass, otherwise a table).

    Returns
    -------
    list of MeasuredTest
        Columns in SI units (strain absolute, moduli and stresses in Pa, ω in rad/s, f in Hz,
        rates in 1/s, viscosity in Pa·s, time in s, temperature in °C); ``meta`` holds
        ``source``, ``format``, ``encoding``, ``name``, ``units`` (what each column was and how
        it was converted), ``ignored_columns``, ``header_line`` and what the format says of the
        test (``sample``, ``interval``; ``stress`` in Pa of a creep, ``omega`` in rad/s and
        ``gamma`` of a LAOS waveform).

    Raises
    ------
    ValueError
        Naming the file, the line and the column: a file that is missing or too large, a column
        without a unit or with an unknown one (asking for ``units=``), a cell that is not a
        number, a truncated row, a ``columns=`` name the file lacks, a kind that cannot be told
        or whose columns are missing.

    Examples
    --------
    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "sweep.csv")
    >>> _ = open(p, "w").write("Strain [%],G' [kPa],G'' [kPa]\\n1,2.0,0.1\\n10,1.5,0.3\\n100,0.2,0.4\\n")
    >>> t, = read_rheometer(p)
    >>> t.kind, t["strain_amplitude"].tolist(), t["Gp"].tolist()
    ('amplitude_sweep', [0.01, 0.1, 1.0], [2000.0, 1500.0, 200.0])
    """
    if format is not None and format not in FORMATS:
        raise ValueError(f"format={format!r} is not allowed: one of {FORMATS}")
    if kind is not None and kind not in KINDS:
        raise ValueError(f"kind={kind!r} is not allowed: one of {sorted(KINDS)}")
    text, encoding = _read_text(path)
    lines = text.splitlines()
    fmt = format or _detect_format(path, lines)
    if fmt == "reptate" and os.path.splitext(os.fspath(path))[1].lower() not in REPTATE_EXTENSIONS:
        raise ValueError(f"{_where(path)}: format='reptate' needs one of the extensions {sorted(REPTATE_EXTENSIONS)}")
    return _READERS[fmt](path, lines, kind, columns, units, encoding)
