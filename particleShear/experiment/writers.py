"""Write rheometer tests (:class:`~particleShear.experiment.tables.MeasuredTest`) for RepTate and pyRheo.

Two targets, each by its own documented rules (docs/experiment.md):

RepTate (``RepTate.core.FileType.TXTColumnFile``)
    Latin-1 text (written as ASCII); first line ``param=value;param=value;`` (the file
    parameters), second line the column names the application declares, then whitespace
    (tab) separated numbers, one row per point.  By kind:

    ========================  ===========  ======================  =======================
    kind                      extension    columns                 header parameters
    ========================  ===========  ======================  =======================
    frequency_sweep           ``.osc``     ``w G' G''``            (``T`` when known)
    relaxation                ``.gt``      ``t Gt``                ``gamma`` (step strain)
    creep                     ``.creep``   ``t strain``            ``stress`` (Pa, needed)
    flow_curve with ``time``  ``.shear``   ``t sigma_xy N1 gdot``  ``gdot`` (1/s)
    laos                      ``.laos``    ``time gamma sigma``    ``omega`` (rad/s), ``gamma``
    ========================  ===========  ======================  =======================

    RepTate has no file type for an amplitude sweep or a steady flow curve (one stress per rate):
    those are refused (use pyRheo for a flow curve).  A ``.shear`` file is a start-up of shear at
    one rate: a flow-curve test with a ``time`` column and one shear rate.
pyRheo
    Tab-delimited text, decimal point, one header line with the exact column names pyRheo's
    readers select: ``Angular Frequency / Storage Modulus / Loss Modulus`` (frequency sweep),
    ``Time / Relaxation Modulus`` (relaxation), ``Time / Creep Compliance`` (creep),
    ``Shear Rate / Viscosity`` (flow curve).

Numbers are written with ``repr`` (the shortest text that reads back to the same float), in SI
units (rad/s, Pa, s, 1/s; strain absolute).  Rows whose required columns are not finite are left
out.  Every file is written atomically (a temporary file in the same folder, then a rename).

The converters :func:`tests_from_sweep` and :func:`tests_from_result` turn simulation results into
tests (``origin="simulated"``); :func:`export` writes a sweep folder's tests, and
``particleShear export DIR --format reptate|pyrheo`` is its command line (:func:`main`).
"""
__docformat__ = "numpy"
import math
import os
import re
import sys

import numpy as np

from .tables import KINDS, MeasuredTest
from ..analysis.grouping import measured_row, row_protocol
from ..run.guard import SuggestingParser
from ..simulation.formats import read_run
from ..sweep.table import atomic_text
from ..analysis.cli import grouping_columns
from ..plot_tools import ok_moduli, read_sweep_table

__all__ = ["FORMATS", "REPTATE_TYPES", "PYRHEO_COLUMNS", "reptate_text", "pyrheo_text", "write_reptate",
           "write_pyrheo", "tests_from_sweep", "tests_from_result", "export", "main"]

#: the export formats of :func:`export` and ``particleShear export --format``
FORMATS = ("reptate", "pyrheo")
#: kind → (extension, RepTate column names, MeasuredTest columns)
REPTATE_TYPES = {
    "frequency_sweep": ("osc", ("w", "G'", "G''"), ("angular_frequency", "Gp", "Gpp")),
    "relaxation": ("gt", ("t", "Gt"), ("time", "G")),
    "creep": ("creep", ("t", "strain"), ("time", "strain")),
    "flow_curve": ("shear", ("t", "sigma_xy", "N1", "gdot"), ("time", "stress", "N1", "shear_rate")),
    "laos": ("laos", ("time", "gamma", "sigma"), ("time", "strain", "stress")),
}
#: kind → the exact pyRheo column names (header line) of its table
PYRHEO_COLUMNS = {
    "frequency_sweep": ("Angular Frequency", "Storage Modulus", "Loss Modulus"),
    "relaxation": ("Time", "Relaxation Modulus"),
    "creep": ("Time", "Creep Compliance"),
    "flow_curve": ("Shear Rate", "Viscosity"),
}
_ESTIMATORS = ("surface", "internal")


# ---------------------------------------------------------------------------------------------
# text of one file
# ---------------------------------------------------------------------------------------------
def _number(v):
    return repr(float(v))


def _param_value(v):
    """A header value RepTate reads back: a number, or ASCII text without ``;``, ``=`` or blanks."""
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, float, np.integer, np.floating)):
        return _number(v) if isinstance(v, (float, np.floating)) else str(int(v))
    text = str(v).encode("ascii", "replace").decode("ascii")
    return re.sub(r"[;=\s]+", "_", text)


def _header_parameters(test, required):
    """``{name: value}`` of the first line: the required ones first, then the scalar meta and parameters."""
    out = dict(required)
    items = list(test.meta.items()) + list((test.meta.get("parameters") or {}).items())
    for k, v in items:
        if k in out or k == "parameters" or isinstance(v, (dict, list, tuple, np.ndarray)) or v is None:
            continue
        if isinstance(v, str) and v == "":
            continue
        out[re.sub(r"[^A-Za-z0-9_.-]+", "_", str(k))] = v
    out.setdefault("origin", test.origin)
    return out


def _need_meta(test, name, what):
    v = test.meta.get(name)
    try:
        v = float(v)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        raise ValueError(f"test.meta[{name!r}]={test.meta.get(name)!r} is invalid: a RepTate .{what} file needs a "
                         f"finite {name} in its header")
    return v


def reptate_text(test):
    """The RepTate file of one test: its extension and text (module docstring).

    Parameters
    ----------
    test : MeasuredTest
        A frequency sweep, relaxation, creep (``meta["stress"]``, Pa), start-up of shear (a
        flow curve with a ``time`` column and one ``shear_rate``) or LAOS waveform
        (``meta["omega"]`` rad/s, ``meta["gamma"]`` absolute).

    Returns
    -------
    extension : str
        ``"osc"``, ``"gt"``, ``"creep"``, ``"shear"`` or ``"laos"``.
    text : str
        ASCII text, lines ending in ``\\n``.

    Raises
    ------
    ValueError
        A kind RepTate has no file type for (amplitude sweep, steady flow curve), or a missing
        header parameter.
    """
    if not isinstance(test, MeasuredTest):
        raise ValueError(f"test={type(test).__name__} is invalid: a particleShear.experiment.MeasuredTest")
    if test.kind not in REPTATE_TYPES or (test.kind == "flow_curve" and "time" not in test):
        raise ValueError(f"test.kind={test.kind!r} is invalid for RepTate: it has file types for a frequency sweep "
                         "(.osc), relaxation (.gt), creep (.creep), start-up of shear (.shear: a flow curve with a "
                         "time column) and a LAOS waveform (.laos); write a steady flow curve with format='pyrheo'")
    ext, names, columns = REPTATE_TYPES[test.kind]
    required = {}
    if test.kind == "creep":
        required["stress"] = _need_meta(test, "stress", ext)
    elif test.kind == "laos":
        required["omega"] = _need_meta(test, "omega", ext)
        required["gamma"] = _need_meta(test, "gamma", ext)
    elif test.kind == "relaxation" and test.meta.get("gamma") is not None:
        required["gamma"] = float(test.meta["gamma"])
    elif test.kind == "flow_curve":
        rates = np.unique(test["shear_rate"][np.isfinite(test["shear_rate"])])
        if len(rates) != 1:
            raise ValueError(f"test shear_rate has {len(rates)} distinct values: a RepTate .shear file is a start-up "
                             "at one shear rate")
        required["gdot"] = float(rates[0])
    if test.kind == "flow_curve" and "N1" not in test:
        test = MeasuredTest(test.kind, dict(test.columns, N1=np.full(len(test), np.nan)), test.meta, test.origin)
    params = _header_parameters(test, required)
    # the N1 of a .shear may be NaN (not sampled): only the kind's required columns must be finite
    lines = ["".join(f"{_param_value(k)}={_param_value(v)};" for k, v in params.items())]
    lines.append("\t".join(names))
    keep = np.ones(len(test), bool)
    for c in KINDS[test.kind]:
        keep &= np.isfinite(test[c])
    for i in np.flatnonzero(keep):
        lines.append("\t".join(_number(test[c][i]) for c in columns))
    return ext, "\n".join(lines) + "\n"


def _pyrheo_columns(test):
    """The pyRheo table's arrays of a test, in :data:`PYRHEO_COLUMNS` order."""
    k = test.kind
    if k == "frequency_sweep":
        return [test["angular_frequency"], test["Gp"], test["Gpp"]]
    if k == "relaxation":
        return [test["time"], test["G"]]
    if k == "creep":
        if "compliance" in test:
            return [test["time"], test["compliance"]]
        return [test["time"], test["strain"] / _need_meta(test, "stress", "creep compliance")]
    if "viscosity" in test:
        return [test["shear_rate"], test["viscosity"]]
    with np.errstate(divide="ignore", invalid="ignore"):
        return [test["shear_rate"], test["stress"] / test["shear_rate"]]


def pyrheo_text(test):
    """The pyRheo table of one test (tab-delimited, exact header line; module docstring).

    Parameters
    ----------
    test : MeasuredTest
        A frequency sweep (ω rad/s, G′ G″ Pa), relaxation (t s, G Pa), creep (t s, J 1/Pa: the
        ``compliance`` column, else ``strain``/``meta["stress"]``) or flow curve (γ̇ 1/s,
        η Pa·s: the ``viscosity`` column, else ``stress``/``shear_rate``).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        For an amplitude sweep or a LAOS waveform (pyRheo reads neither).
    """
    if not isinstance(test, MeasuredTest):
        raise ValueError(f"test={type(test).__name__} is invalid: a particleShear.experiment.MeasuredTest")
    if test.kind not in PYRHEO_COLUMNS:
        raise ValueError(f"test.kind={test.kind!r} is invalid for pyRheo: allowed one of {sorted(PYRHEO_COLUMNS)}")
    cols = _pyrheo_columns(test)
    keep = np.ones(len(test), bool)
    for c in cols:
        keep &= np.isfinite(c)
    lines = ["\t".join(PYRHEO_COLUMNS[test.kind])]
    lines += ["\t".join(_number(c[i]) for c in cols) for i in np.flatnonzero(keep)]
    return "\n".join(lines) + "\n"


def _write(path, text):
    path = os.fspath(path)
    folder = os.path.dirname(path)
    if folder:
        os.makedirs(folder, exist_ok=True)
    with atomic_text(path) as fh:
        fh.write(text)
    return path


def write_reptate(test, path):
    """Write one test as a RepTate file (atomically); the extension is set by the kind.

    Parameters
    ----------
    test : MeasuredTest
    path : str or os.PathLike
        The file; its extension is replaced by the kind's (``.osc``, ``.gt``, ...).

    Returns
    -------
    str
        The path written.
    """
    ext, text = reptate_text(test)
    return _write(os.path.splitext(os.fspath(path))[0] + "." + ext, text)


def write_pyrheo(test, path):
    """Write one test as a pyRheo table (atomically).

    Parameters
    ----------
    test : MeasuredTest
    path : str or os.PathLike
        The file (``.csv`` or ``.txt``, as pyRheo's demos name them).

    Returns
    -------
    str
        The path written.
    """
    return _write(path, pyrheo_text(test))


# ---------------------------------------------------------------------------------------------
# simulation results → tests
# ---------------------------------------------------------------------------------------------
def _f(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def _check_estimator(estimator, name="estimator"):
    if estimator not in _ESTIMATORS:
        raise ValueError(f"{name}={estimator!r} is invalid: allowed one of {_ESTIMATORS}")


def _label(params, names):
    shown = [f"{n}={params[n]}" for n in names if params.get(n, "") != ""]
    return ",".join(shown) or "all runs"


def _group(items, key_columns, x_name):
    """``{key: {"parameters", "runs": [(x, repetition, row)]}}`` grouped by ``key_columns``."""
    cells = {}
    for row, x in items:
        key = tuple(str(row.get(c, "")) for c in key_columns)
        d = cells.setdefault(key, {"parameters": dict(zip(key_columns, key)), "runs": []})
        d["runs"].append((x, str(row.get("repetition", "0")), row))
    return cells


def _varying(cells, key_columns):
    keys = list(cells)
    return [c for i, c in enumerate(key_columns) if len({k[i] for k in keys}) > 1]


def _tests_per_replicate(cells, varying, make):
    """One test per group and repetition (the seeds of a group are its replicates)."""
    out = []
    for key in sorted(cells, key=lambda k: [(0, _f(v), "") if math.isfinite(_f(v)) else (1, 0.0, v) for v in k]):
        d = cells[key]
        reps = sorted({r for _, r, _ in d["runs"]}, key=lambda r: (_f(r), r))
        for rep in reps:
            runs = sorted((x, row) for x, r, row in d["runs"] if r == rep)
            label = _label(d["parameters"], varying)
            meta = {"name": label, "label": label, "replicate": rep, "parameters": dict(d["parameters"])}
            out.append(make([row for _, row in runs], meta))
    return out


def tests_from_sweep(folder, estimator="surface"):
    """The tests of a sweep folder's ``results.csv`` (``origin="simulated"``).

    Rows are grouped as ``particleShear analyse`` groups them (the grouping columns of
    :func:`particleShear.analysis.cli.grouping_columns`, rows rewritten by
    :func:`particleShear.analysis.grouping.measured_row`, only the ``ok`` rows of
    :func:`particleShear.plot.ok_moduli`), and each group's seeds (``repetition``) are its
    replicates: one test per group and repetition.

    * amplitude sweeps: groups over every grouping column (the amplitude excepted) with >= 2
      amplitudes: ``strain_amplitude``, ``Gp``, ``Gpp`` (Pa) of the estimator;
    * frequency sweeps: groups over every grouping column but ``relative_frequency`` (the amplitude
      included) with >= 2 frequencies — ``frequency_sweep`` protocol steps and oscillatory runs:
      ``angular_frequency`` = 2π·``frequency_Hz`` (rad/s of the simulation's clock, f = (f·τ)/τ);
    * flow curves: ``steady`` rows grouped over every grouping column but ``relative_rate``:
      ``shear_rate`` (``strain_rate``, 1/s), ``stress``, ``viscosity``, ``N1``;
    * relaxation and creep: one test per run whose file (``output_path``) is there, from its
      log-grid curves (:func:`particleShear.simulation.formats.read_run`): ``G`` (Pa) of the
      estimator, or ``compliance`` J (1/Pa) and ``strain`` = J·σ₀ with ``meta["stress"]`` = σ₀;
    * LAOS waveforms: one test per oscillatory run whose file is there: ``time`` (s),
      ``strain``, ``stress`` (Pa) with ``meta["omega"]`` (rad/s) and ``meta["gamma"]``.

    Parameters
    ----------
    folder : str or os.PathLike
        The sweep folder (or its ``results.csv``).
    estimator : {"surface", "internal"}, optional
        Which moduli and stresses (plate forces, default, or stress tensor).

    Returns
    -------
    tests : list of MeasuredTest
    notes : list of str
        What was left out (a run file missing or unreadable).

    Raises
    ------
    ValueError
        An unknown estimator, no ``results.csv``.
    """
    _check_estimator(estimator)
    rows = read_sweep_table(folder)
    notes = list(getattr(rows, "notes", []) or [])
    header = list(rows[0]) if rows else []
    names = grouping_columns(header)
    tests = []
    kept = ok_moduli(rows, estimator)[0]

    def sweep_test(kind, xname, xfun):
        def make(runs, meta):
            cols = {xname: [xfun(r) for r in runs], "Gp": [_f(r["Gp_" + estimator]) for r in runs],
                    "Gpp": [_f(r["Gpp_" + estimator]) for r in runs]}
            meta = dict(meta, estimator=estimator)
            return MeasuredTest(kind, cols, meta, "simulated")
        return make

    # amplitude sweeps
    cells = _group([(row, A) for row, A, _, _ in kept], names, "theAmplitude")
    cells = {k: d for k, d in cells.items() if len({x for x, _, _ in d["runs"]}) >= 2}
    tests += _tests_per_replicate(cells, _varying(cells, names),
                                  sweep_test("amplitude_sweep", "strain_amplitude", lambda r: _f(r["theAmplitude"])))
    # frequency sweeps
    fnames = [c for c in names if c != "relative_frequency"] + (["theAmplitude"] if "theAmplitude" in header else [])
    cells = _group([(row, _f(row.get("relative_frequency"))) for row, _, _, _ in kept], fnames, "relative_frequency")
    cells = {k: d for k, d in cells.items() if len({x for x, _, _ in d["runs"]}) >= 2}
    tests += _tests_per_replicate(cells, _varying(cells, fnames),
                                  sweep_test("frequency_sweep", "angular_frequency",
                                             lambda r: 2 * math.pi * _f(r.get("frequency_Hz"))))
    # flow curves, relaxation, creep, waveforms
    steady, files = [], []
    for row in rows:
        if str(row.get("status", "")).strip() != "ok":
            continue
        row = measured_row(row)
        proto = row_protocol(row)
        if proto == "steady":
            steady.append((row, _f(row.get("strain_rate"))))
        elif proto in ("relaxation", "creep", "oscillatory") and row.get("output_path"):
            files.append(row)
    snames = [c for c in names if c != "relative_rate"]
    cells = _group(steady, snames, "strain_rate")

    def flow(runs, meta):
        cols = {"shear_rate": [_f(r.get("strain_rate")) for r in runs],
                "stress": [_f(r.get("stress_" + estimator)) for r in runs],
                "viscosity": [_f(r.get("viscosity_" + estimator)) for r in runs],
                "N1": [_f(r.get("N1")) for r in runs]}
        return MeasuredTest("flow_curve", cols, dict(meta, estimator=estimator), "simulated")
    tests += _tests_per_replicate(cells, _varying(cells, snames), flow)
    base = os.fspath(folder)
    base = base if os.path.isdir(base) else os.path.dirname(os.path.abspath(base))
    for row in files:
        path = row["output_path"]
        path = path if os.path.isabs(path) else os.path.join(base, path)
        if not os.path.exists(path):
            notes.append(f"run {row.get('run_id', '')}: its file {row['output_path']} is not there: left out")
            continue
        try:
            data = read_run(path)
            tests += tests_from_result(data, estimator=estimator,
                                       meta={"name": os.path.basename(path), "run_id": row.get("run_id", ""),
                                             "replicate": row.get("repetition", "0"),
                                             "parameters": {c: row.get(c, "") for c in names}})
        except ValueError as exc:
            notes.append(f"run {row.get('run_id', '')}: {exc}: left out")
    return tests, notes


def _series_stress(series, estimator):
    return np.asarray(series["stress_" + estimator], dtype=float)


def tests_from_result(result, estimator="surface", meta=None):
    """The tests of one simulation result (``origin="simulated"``).

    Parameters
    ----------
    result : SimulationResult or RunData
        An oscillatory run (its LAOS waveform from ``series``: ``time`` s, ``strain``, ``stress``
        Pa with ``omega`` = 2πf rad/s and ``gamma`` = the amplitude), a protocol run (steady:
        the start-up as a flow curve with ``time``; relaxation: G(t) of the estimator's log-grid
        curve; creep: J(t) and γ = J·σ₀; a sweep: its steps as an amplitude or frequency sweep),
        or a run file read by :func:`particleShear.simulation.formats.read_run`.
    estimator : {"surface", "internal"}, optional
    meta : dict, optional
        Added to each test's meta.

    Returns
    -------
    list of MeasuredTest

    Raises
    ------
    ValueError
        An unknown estimator or result type, or a result without what its kind needs.
    """
    _check_estimator(estimator)
    meta = dict(meta or {}, estimator=estimator)
    try:   # one interface: a result of any protocol, or a run file (RunData)
        params, protocol, series, curves, steps = (dict(result.parameters), result.protocol, result.series,
                                                   result.curves, result.steps)
    except AttributeError:
        raise ValueError(f"result={type(result).__name__} is invalid: a SimulationResult or RunData") from None
    if protocol == "oscillatory":
        f = result.f
        gamma = params["theAmplitude"] if "theAmplitude" in params else result.strain_amplitude
    E = params.get("Young_modulus_spheres")
    meta.setdefault("parameters", {k: v for k, v in params.items() if isinstance(v, (int, float, str, bool))})
    if E is not None:
        meta.setdefault("Young_modulus_spheres", E)
    if protocol == "oscillatory":
        if "t" not in series:
            raise ValueError("result.series is empty: the LAOS waveform needs the run's series (t, strain, stress)")
        return [MeasuredTest("laos", {"time": series["t"], "strain": series["strain"],
                                      "stress": _series_stress(series, estimator)},
                             dict(meta, omega=2 * math.pi * float(f), gamma=float(gamma)), "simulated")]
    if protocol == "steady":
        if "t" not in series:
            raise ValueError("result.series is empty: the start-up needs the run's series")
        cols = {"time": series["t"], "shear_rate": series["strain_rate"], "stress": _series_stress(series, estimator)}
        if "N1" in series:
            cols["N1"] = series["N1"]
        return [MeasuredTest("flow_curve", cols, meta, "simulated")]
    if protocol == "relaxation":
        key = "G_" + estimator if "G_" + estimator in curves else "G"
        if key not in curves:
            raise ValueError("result.curves has no G(t): the relaxation test needs the run's curves")
        t, g = curves[key][0], curves[key][1]
        return [MeasuredTest("relaxation", {"time": t, "G": g}, dict(meta, gamma=_f(params.get("theAmplitude"))),
                             "simulated")]
    if protocol == "creep":
        if "J" not in curves:
            raise ValueError("result.curves has no J(t): the creep test needs the run's curves")
        t, J = np.asarray(curves["J"][0], float), np.asarray(curves["J"][1], float)
        s0 = _f(params.get("creep_stress"))
        return [MeasuredTest("creep", {"time": t, "compliance": J, "strain": J * s0}, dict(meta, stress=s0),
                             "simulated")]
    if protocol in ("amplitude_sweep", "frequency_sweep") and steps:
        gp = [_f(st.get("Gp_" + estimator)) for st in steps]
        gpp = [_f(st.get("Gpp_" + estimator)) for st in steps]
        if protocol == "amplitude_sweep":
            cols = {"strain_amplitude": [_f(st.get("amplitude")) for st in steps], "Gp": gp, "Gpp": gpp}
        else:
            cols = {"angular_frequency": [2 * math.pi * _f(st.get("f")) for st in steps], "Gp": gp, "Gpp": gpp}
        return [MeasuredTest(protocol, cols, meta, "simulated")]
    raise ValueError(f"result protocol={protocol!r} has nothing to export (no series, curves or steps)")


# ---------------------------------------------------------------------------------------------
# a folder → files
# ---------------------------------------------------------------------------------------------
def _file_stem(test, index):
    label = str(test.meta.get("label") or test.meta.get("name") or "test")
    label = re.sub(r"[^A-Za-z0-9.=,-]+", "_", label).strip("_")[:80] or "test"
    rep = test.meta.get("replicate")
    return f"{index:03d}_{test.kind}_{label}" + (f"_rep{rep}" if rep not in (None, "") else "")


def export(folder, format="reptate", out=None, estimator="surface"):
    """Write the tests of a sweep folder (:func:`tests_from_sweep`) as RepTate or pyRheo files.

    Parameters
    ----------
    folder : str or os.PathLike
        The sweep folder (with ``results.csv``).
    format : {"reptate", "pyrheo"}, optional
        RepTate files (``.osc``, ``.gt``, ``.creep``, ``.shear``, ``.laos``) or pyRheo tables
        (``.csv``, tab-delimited).  The kinds a format has no file type for (an amplitude sweep
        in either; a steady flow curve in RepTate; a LAOS waveform in pyRheo) are left out, and
        said in the notes.
    out : str or os.PathLike, optional
        The folder to write into (default ``FOLDER/export_<format>``); made when missing.
    estimator : {"surface", "internal"}, optional

    Returns
    -------
    written : list of str
        The files written (each atomically).
    notes : list of str
        What was left out and why.

    Raises
    ------
    ValueError
        An unknown format or estimator, or no ``results.csv`` — before anything is written.
    """
    if format not in FORMATS:
        raise ValueError(f"format={format!r} is invalid: allowed one of {FORMATS}")
    _check_estimator(estimator)
    tests, notes = tests_from_sweep(folder, estimator)
    base = os.fspath(folder)
    base = base if os.path.isdir(base) else os.path.dirname(os.path.abspath(base))
    out = os.fspath(out) if out is not None else os.path.join(base, f"export_{format}")
    written, skipped = [], {}
    for i, test in enumerate(tests):
        stem = os.path.join(out, _file_stem(test, i))
        try:
            if format == "reptate":
                written.append(write_reptate(test, stem))
            else:
                written.append(write_pyrheo(test, stem + ".csv"))
        except ValueError:
            kind = test.kind + (" (steady)" if test.kind == "flow_curve" and "time" not in test else "")
            skipped[kind] = skipped.get(kind, 0) + 1
    for kind, n in skipped.items():
        notes.append(f"{n} {kind} test(s) left out: {format} has no file type for them")
    return written, notes


def build_parser():
    """Parser of ``particleShear export``."""
    p = SuggestingParser(prog="particleShear export",
                         description="Write a sweep folder's results as RepTate files (.osc per frequency sweep, .gt, "
                                     ".creep, .shear, .laos per run waveform) or pyRheo tables (tab-delimited, "
                                     "pyRheo's column names); SI units, seeds as replicates (docs/experiment.md).")
    p.add_argument("folder", metavar="DIR", help="sweep folder containing results.csv")
    p.add_argument("--format", choices=FORMATS, required=True, help="reptate or pyrheo")
    p.add_argument("--out", metavar="OUT", default=None, help="folder to write into (default DIR/export_FORMAT)")
    p.add_argument("--estimator", choices=_ESTIMATORS, default="surface",
                   help="moduli and stresses from the plate forces (surface, default) or the stress tensor (internal)")
    return p


def main(argv=None):
    """``particleShear export DIR --format reptate|pyrheo [--out OUT] [--estimator surface|internal]``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``export``.

    Returns
    -------
    int
        0 written, 2 invalid input (one line on stderr).
    """
    args = build_parser().parse_args(argv)
    try:
        written, notes = export(args.folder, args.format, args.out, args.estimator)
    except ValueError as exc:
        msg = str(exc).replace("folder_or_csv=", "DIR=").replace("format=", "--format=")
        print(f"particleShear export: {msg}".splitlines()[0], file=sys.stderr)
        return 2
    for n in notes:
        print(f"particleShear export: note: {n}", file=sys.stderr)
    print(f"wrote {len(written)} {args.format} file(s)" + (f" to {os.path.dirname(written[0])}" if written else ""))
    return 0
