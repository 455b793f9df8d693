"""``python -m particleShear analyse DIR``: the characteristics of a sweep folder, with bootstrap intervals.

Reads ``DIR/results.csv`` (:func:`particleShear.plot.read_sweep_table`), keeps the rows with status
``ok`` and finite moduli (:func:`particleShear.plot.ok_moduli`), groups them by every parameter
column except the strain amplitude ``theAmplitude`` (the parameter columns are the keys of
:func:`particleShear.sweep.spec.sweep_parameter_defaults` present in the header; the inputs that
change neither the physics nor the output, :data:`particleShear.simulation.provenance.IDENTITY_EXCLUDED`
— ``doDrawing``, ``plotStress``, ``renderer``, ``strict_io`` — and those of :data:`OUTPUT_ONLY` (what is
saved, the backend) do not split groups; the runs of one group are its seeds), and summarises each
group with :func:`particleShear.analysis.sweep.sweep_summary`.  The runs of a group are taken in
the order (amplitude, run id) and each group's bootstrap stream is derived from ``--seed`` and the
group's parameters, so the intervals depend neither on the order the runs finished in nor on the
other groups of the folder; without ``--seed`` the seed is
:data:`particleShear.analysis.sweep.DEFAULT_SEED` (0, as ``plot``'s), so the same call gives the same
numbers, and ``bootstrap_seed`` records it.  Writes, atomically:

``DIR/analysis.csv``
    One row per group: ``group`` (a label), the parameters that differ between groups, the
    estimator, the bootstrap settings, ``n_runs``, ``n_amplitudes``, … and every characteristic of
    :data:`particleShear.analysis.sweep.CHARACTERISTICS` with ``_ci_low``, ``_ci_high``,
    ``_defined`` and ``_flag`` (:data:`particleShear.analysis.sweep.FLAGS`: a censored point is a bound,
    printed ``> 0.2``, with no interval); ``note`` says what deserves a look (one seed, non-positive
    means, fewer than 4 amplitudes, rows left out).
    An empty cell is an undefined value.
``DIR/analysis.schema.json``
    Column → type, unit, description.
``DIR/analysis.png``, ``DIR/analysis.pdf``
    With matplotlib (extra ``[plot]``) and without ``--no-figure``:
    :func:`particleShear.analysis.figure.plot_analysis`, at most
    :data:`~particleShear.analysis.figure.MAX_FIGURE_PANELS` groups drawn, the others named.
``DIR/analysis_protocols.csv``, ``DIR/analysis_protocols.schema.json``
    When the folder holds steady, relaxation or creep runs:
    :func:`particleShear.analysis.protocol_summary.protocol_summaries`.

Rows are read as what they measured (:func:`particleShear.analysis.grouping.measured_row`): a step
of a one-packing sweep at its own amplitude or frequency, an empty ``protocol`` cell as
"oscillatory"; the protocol and the parameters it reads are grouping columns like the others.
The files are checked before any work and published as one set
(:mod:`particleShear.analysis.outputs`).

Exit status: 0 written, 2 invalid input (no results.csv, no usable rows, a bad flag value, an
unwritable folder, a directory or read-only file at an output), 3 another analysis kept the
folder's lock, 130 interrupted, 143 terminated, with a one-line message on stderr.
"""
__docformat__ = "numpy"
import io
import json
import math
import sys
import warnings
import zlib

import numpy as np

from ..run.guard import SuggestingParser, command_line_names
from .sweep import CHARACTERISTICS, DEFAULT_SEED, FLAGS, MIN_POINT_AMPLITUDES, N_BOOT_MAX, sweep_summary
from ..experiment.measured import main as measured_main
from ..plot_tools import ESTIMATORS, _float, _has_matplotlib, is_flagged, ok_moduli, read_sweep_table
from ..run.rheometer import PROTOCOL_DEFAULTS
from ..signals import sigterm_raises, signals_held
from ..simulation.provenance import IDENTITY_EXCLUDED
from ..sweep.locks import FolderBusyError
from ..sweep.spec import sweep_parameter_defaults
from ..sweep.table import atomic_text, row_line
from .figure import MAX_FIGURE_PANELS, not_drawn_line, plot_analysis
from .grouping import MODULI_PROTOCOLS, SUMMARY_PROTOCOLS, measured_row, row_protocol, short_value
from .outputs import PublishInterrupted, check_targets, make_staging, publish
from .protocol_summary import protocol_summaries, summary_columns
from .verdicts import counts_note, verdict_counts

__all__ = [
    "OUTPUT_ONLY",
    "ANALYSIS_NAME",
    "FIGURE_NAME",
    "PROTOCOLS_NAME",
    "PROTOCOLS_SCHEMA_NAME",
    "SCHEMA_NAME",
    "SET_NAMES",
    "analyse_folder",
    "analysis_columns",
    "build_parser",
    "group_runs",
    "grouping_columns",
    "main",
]

#: the table written into the sweep folder
ANALYSIS_NAME = "analysis.csv"
#: its schema (column → type, unit, description)
SCHEMA_NAME = "analysis.schema.json"
#: the figure's file stem (``.png`` and ``.pdf``)
FIGURE_NAME = "analysis"
#: the summaries of the steady, relaxation and creep runs, and their schema
PROTOCOLS_NAME = "analysis_protocols.csv"
PROTOCOLS_SCHEMA_NAME = "analysis_protocols.schema.json"
#: every file of an analysis's set (published together, :mod:`particleShear.analysis.outputs`)
SET_NAMES = (ANALYSIS_NAME, SCHEMA_NAME, FIGURE_NAME + ".png", FIGURE_NAME + ".pdf", PROTOCOLS_NAME,
             PROTOCOLS_SCHEMA_NAME)

_PROG = "particleShear analyse"
_AMPLITUDE = "theAmplitude"
#: parameters that change what is written, not the moduli: they do not split groups
OUTPUT_ONLY = frozenset({"saveData", "saveStressTensorData", "saveOutputImages", "saveOutputMovie", "imageFileType",
                         "output_format", "backend", "root_folder"})

#: columns before the characteristics: name → (type, unit, description)
_HEAD_COLUMNS = {
    "group": ("str", "", ("the group: its parameters that differ between the groups of the folder ('all runs' "
                          "for one group)")),
    "estimator": ("str", "", "the moduli used: surface (plate forces) or internal (overall stress tensor)"),
    "n_runs": ("int", "1", "runs (rows with status ok and finite moduli) of the group"),
    "n_flagged": ("int", "1", "runs of the group whose verdict is flagged (counted in n_runs; docs/analysis.md "
                              "\"Verdicts\")"),
    "n_failed": ("int", "1", "rows of the group's parameters whose status is not ok (not in n_runs)"),
    "n_amplitudes": ("int", "1", "distinct strain amplitudes of the group"),
    "amplitude_min": ("float", "1", "smallest strain amplitude"),
    "amplitude_max": ("float", "1", "largest strain amplitude"),
    "n_seeds_min": ("int", "1", "fewest runs (seeds) at one amplitude"),
    "n_seeds_max": ("int", "1", "most runs (seeds) at one amplitude"),
    "confidence": ("float", "1", "level of the bootstrap percentile intervals"),
    "n_boot": ("int", "1", "bootstrap replicates (seeds resampled with replacement within each amplitude)"),
    "bootstrap_seed": ("int", "1", ("--seed of the bootstrap (default 0, analysis.sweep.DEFAULT_SEED; empty: fresh "
                                    "entropy, analyse_folder(seed=None) only)")),
}
_NOTE = ("note", ("str", "", ("what deserves a look: one seed at some amplitude (degenerate intervals), "
                              "non-positive means (no log-log characteristics there)")))


class _UsageError(Exception):
    """A bad command line (one line for stderr)."""


class _Parser(SuggestingParser):
    """Argument parser whose usage errors become :class:`_UsageError` (one line, status 2); no prefix
    abbreviations, an unknown flag named with the closest flags."""

    def error(self, message):
        raise _UsageError(" ".join(message.split()))


def build_parser():
    """Parser of ``python -m particleShear analyse``.

    Returns
    -------
    particleShear.run.guard.SuggestingParser
        Positional ``DIR``; options ``--estimator {surface,internal}``, ``--json``, ``--n-boot N``,
        ``--confidence C``, ``--seed S`` (values checked by :func:`main`), ``--no-figure``.
    """
    p = _Parser(prog=_PROG, description="Characteristics of a sweep folder's amplitude sweeps (plateau, linear "
                                        "limits, flow point, the R package's four points) with bootstrap intervals "
                                        "over the seeds. Reads DIR/results.csv, writes DIR/analysis.csv, "
                                        "DIR/analysis.schema.json and (with matplotlib) DIR/analysis.png and .pdf.")
    p.add_argument("folder", metavar="DIR", help="sweep folder containing results.csv")
    p.add_argument("--estimator", choices=ESTIMATORS, default="surface",
                   help="moduli from the plate forces (surface, default) or the stress tensor (internal)")
    p.add_argument("--json", action="store_true", help="print the rows of analysis.csv as JSON on stdout (NaN: null)")
    p.add_argument("--n-boot", metavar="N", default="2000",
                   help=f"bootstrap replicates, integer 1 ... {N_BOOT_MAX} (default 2000)")
    p.add_argument("--confidence", metavar="C", default="0.95", help="interval level in (0, 1) (default 0.95)")
    p.add_argument("--seed", metavar="S", default=str(DEFAULT_SEED),
                   help=f"seed of the bootstrap, integer >= 0 (default {DEFAULT_SEED}, as plot's: the same call prints "
                        "the same intervals)")
    p.add_argument("--no-figure", dest="figure", action="store_false",
                   help=f"write no analysis.png/.pdf (the figure draws at most {MAX_FIGURE_PANELS} groups, the others "
                        "named in one line)")
    return p


def _number_flag(flag, text, kind):
    """``text`` of ``flag`` as an int (``kind="n_boot"``, ``"seed"``) or float in (0, 1) (``"confidence"``)."""
    if kind == "confidence":
        try:
            value = float(text)
        except ValueError:
            raise _UsageError(f"{flag}={text!r} is invalid: allowed a number in (0, 1)") from None
        if not 0 < value < 1:
            raise _UsageError(f"{flag}={text!r} is out of range: allowed a number in (0, 1)")
        return value
    low = 1 if kind == "n_boot" else 0
    allowed = f"allowed an integer >= {low}" + (f" and <= {N_BOOT_MAX} (n_boot)" if kind == "n_boot" else "")
    try:
        value = int(text)
    except ValueError:
        raise _UsageError(f"{flag}={_short(text)!r} is invalid: {allowed}") from None
    if value < low or (kind == "n_boot" and value > N_BOOT_MAX):
        raise _UsageError(f"{flag}={_short(text)!r} is out of range: {allowed}")
    return value


def _short(text):
    return short_value(text, 40)


def _sort_key(text):
    try:
        return (0, float(text), "")
    except (TypeError, ValueError):
        return (1, 0.0, str(text))


def grouping_columns(header):
    """The parameter columns of a table that split groups (module docstring).

    Parameters
    ----------
    header : list of str
        The table's columns.

    Returns
    -------
    list of str
        The parameters of :func:`particleShear.sweep.spec.sweep_parameter_defaults` (protocol
        parameters included) in the header, less ``theAmplitude``, the inputs that change neither
        the physics nor the output and :data:`OUTPUT_ONLY`.
    """
    return [c for c in sweep_parameter_defaults(protocols=True) if c in header and c != _AMPLITUDE
            and c not in IDENTITY_EXCLUDED and c not in OUTPUT_ONLY]


def group_runs(rows, estimator="surface"):
    """The runs of a sweep table grouped by their parameters except the amplitude.

    Rows are read as :func:`particleShear.analysis.grouping.measured_row` rewrites them: a step
    of a one-packing sweep is a run at its own amplitude (``sweep_amplitude``) or frequency
    (``sweep_relative_frequency``); an empty ``protocol`` cell is "oscillatory"; the protocol
    and the parameters it reads split groups.  Rows of the steady, relaxation and creep
    protocols hold no moduli and are not grouped here
    (:func:`particleShear.analysis.protocol_summary.protocol_summaries`).

    Parameters
    ----------
    rows : list of dict
        Rows of ``results.csv`` (:func:`particleShear.plot.read_sweep_table`); only rows with
        status ``ok`` and finite amplitude and moduli count (:func:`particleShear.plot.ok_moduli`).
    estimator : {"surface", "internal"}, optional
        Which moduli (default "surface").

    Returns
    -------
    groups : list of dict
        One per group, sorted by its parameter values (numbers numerically): ``"parameters"``
        (``{name: text}`` of every grouping column), ``"amplitude"``, ``"Gp"``, ``"Gpp"`` (lists of
        floats, one per run or step), ``"n_flagged"`` (runs of the group whose verdict is flagged),
        ``"n_failed"`` (rows of its parameters whose status is not ok), ``"flags"`` (check → count).
    varying : list of str
        The grouping columns whose value differs between groups (header order).
    skipped : int
        Rows with status ``ok`` left out for a missing or non-finite amplitude or modulus.

    Raises
    ------
    ValueError
        If ``estimator`` is not one of the two, or the table has no ``theAmplitude`` column.
    """
    kept, skipped = ok_moduli(rows, estimator)
    header = list(rows[0]) if rows else []
    if rows and _AMPLITUDE not in header:
        raise ValueError(f"results.csv has no {_AMPLITUDE} column: not a sweep table")
    names = grouping_columns(header)
    cells = {}
    # runs in a fixed order (amplitude, run id), not the order they finished in: the bootstrap draws
    # the same resamples from the same seed however the table was written
    for row, A, gp, gpp in sorted(kept, key=lambda k: (k[1], str(k[0].get("run_id", "")))):
        key = tuple(str(row.get(c, "")) for c in names)
        d = cells.setdefault(key, {"parameters": dict(zip(names, key)), "amplitude": [], "Gp": [], "Gpp": [],
                                   "flagged": []})
        d["amplitude"].append(A)
        d["Gp"].append(gp)
        d["Gpp"].append(gpp)
        d["flagged"].append(is_flagged(row))    # verdict "flagged: …" (False in tables without the column)
    _count_verdicts(rows, names, cells)
    keys = sorted(cells, key=lambda k: [_sort_key(v) for v in k])
    varying = [c for i, c in enumerate(names) if len({k[i] for k in keys}) > 1]
    return [cells[k] for k in keys], varying, skipped


def _made(rows, columns):
    """``{column: value}`` of the columns that hold one number in every ``ok`` row (for a figure's title)."""
    made = {}
    for c in columns:
        values = {_float(r.get(c)) for r in rows if r.get("status") == "ok" and c in r}
        if len(values) == 1 and all(v == v for v in values):
            made[c] = values.pop()
    return made


def _count_verdicts(rows, names, cells):
    """Each group's ``n_flagged``, ``n_failed`` and ``flags`` (check → count) over every row of its
    parameters, whatever its status (:func:`particleShear.analysis.verdicts.verdict_counts`)."""
    members = {}
    for row in rows:
        if row_protocol(row) not in MODULI_PROTOCOLS:
            continue
        row = measured_row(row)
        members.setdefault(tuple(str(row.get(c, "")) for c in names), []).append(row)
    for key, d in cells.items():
        d["n_failed"], d["n_flagged"], d["flags"] = verdict_counts(members.get(key, []))


def analysis_columns(varying):
    """Columns of ``analysis.csv`` with (type, unit, description), in table order.

    Parameters
    ----------
    varying : list of str
        The parameter columns that differ between groups (:func:`group_runs`).

    Returns
    -------
    dict
        ``{column: (type, unit, description)}``; type one of "str", "int", "float".
    """
    cols = {"group": _HEAD_COLUMNS["group"]}
    for name in varying:
        cols[name] = ("str", "", (f"parameter {name} of doParticleShearSimulation (docs/parameters.md), as in "
                                  "results.csv"))
    cols.update({k: v for k, v in _HEAD_COLUMNS.items() if k != "group"})
    q = "the bootstrap percentile interval (level: confidence)"
    for name, (unit, text) in CHARACTERISTICS.items():
        cols[name] = ("float", unit, text + " (empty: undefined)")
        cols[name + "_ci_low"] = ("float", unit, f"lower end of {q} of {name}")
        cols[name + "_ci_high"] = ("float", unit, f"upper end of {q} of {name}")
        cols[name + "_defined"] = ("float", "1", f"fraction of the bootstrap replicates in which {name} is defined")
        cols[name + "_flag"] = ("str", "", f"what {name} is: one of {', '.join(FLAGS)} (analysis.sweep.FLAGS, "
                                           "docs/analysis.md)")
    cols[_NOTE[0]] = _NOTE[1]
    return cols


def _label(parameters, varying):
    shown = ", ".join(f"{n}={short_value(parameters[n])}" for n in varying if parameters.get(n, "") != "")
    if shown:
        return shown
    protocol = parameters.get("protocol", "")      # a mixed table: its oscillatory rows say so
    return f"protocol={protocol}" if protocol not in ("", None) else "all runs"


def _stream_label(parameters):
    """The text a group's bootstrap stream is derived from: its parameters, less the protocol
    columns an oscillatory run does not have (its stream is that of a table without protocols)."""
    return "\x1f".join(f"{k}={v}" for k, v in sorted(parameters.items())
                        if not (k in PROTOCOL_DEFAULTS and v in ("", "oscillatory")))


def _summarise(group, n_boot, confidence, rng):
    """(SweepSummary or None, notes) of one group."""

    notes = []
    n_amp = len(set(group["amplitude"]))
    if n_amp < 2:
        why = f"{n_amp} amplitude only: no characteristics"
        if group["parameters"].get("protocol") == "frequency_sweep":
            why += " (a step of a frequency sweep: particleShear plot DIR draws G′, G″ against the frequency)"
        return None, [why]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        s = sweep_summary(group["amplitude"], group["Gp"], group["Gpp"], n_boot=n_boot, confidence=confidence,
                          rng=rng)
    single = s.amplitudes[s.n_seeds == 1]
    if n_amp < MIN_POINT_AMPLITUDES:
        notes.append(f"{n_amp} amplitudes: the characteristic points (linear limits, flow point, the R package's "
                     f"points) need >= {MIN_POINT_AMPLITUDES}; only the plateau and the mean curves are given")
    if len(caught) and len(single):
        notes.append(f"one seed at amplitude(s) {_floats(single)}: degenerate intervals there")
    for what, mean in (("G′", s.Gp_mean), ("G″", s.Gpp_mean)):
        bad = s.amplitudes[np.asarray(mean) <= 0]
        if len(bad):
            notes.append(f"mean {what} <= 0 at amplitude(s) {_floats(bad)}: not on the log axes, no interval and "
                         "no log-log characteristics there")
    return s, notes


def _floats(a):
    return "[" + ", ".join(f"{float(x):g}" for x in a) + "]"


def _row(group, varying, summary, notes, estimator, n_boot, confidence, seed):
    row = {"group": _label(group["parameters"], varying)}
    row.update({n: group["parameters"][n] for n in varying})
    row.update({"estimator": estimator, "n_runs": len(group["amplitude"]), "n_flagged": group.get("n_flagged", 0),
                "n_failed": group.get("n_failed", 0), "confidence": confidence, "n_boot": n_boot,
                "bootstrap_seed": seed})
    if summary is not None:
        row.update(summary.to_dict())
    else:
        amps = sorted(set(group["amplitude"]))
        row.update({"n_amplitudes": len(amps), "amplitude_min": amps[0], "amplitude_max": amps[-1],
                    "n_seeds_min": len(group["amplitude"]), "n_seeds_max": len(group["amplitude"])})
        for name in CHARACTERISTICS:
            for suffix in ("", "_ci_low", "_ci_high"):
                row[name + suffix] = math.nan
            row[name + "_defined"] = 0.0
            row[name + "_flag"] = "too_few_amplitudes"
    counted = counts_note(len(group["amplitude"]), group.get("n_failed", 0), group.get("n_flagged", 0),
                          group.get("flags", {}))
    row["note"] = "; ".join(([counted] if counted else []) + list(notes))
    return row


def _check_settings(estimator, n_boot, confidence, seed, figure, max_figure_panels):
    """The arguments of :func:`analyse_folder`, before any work (ValueError naming the parameter and its flag)."""
    import numbers

    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS} (CLI --estimator)")
    if isinstance(n_boot, bool) or not isinstance(n_boot, numbers.Integral) or not 1 <= n_boot <= N_BOOT_MAX:
        raise ValueError(f"n_boot={n_boot!r} is out of range: allowed an integer >= 1 and <= {N_BOOT_MAX} "
                         "(CLI --n-boot)")
    if isinstance(confidence, bool) or not isinstance(confidence, numbers.Real) or not 0 < confidence < 1:
        raise ValueError(f"confidence={confidence!r} is out of range: allowed a number in (0, 1) (CLI --confidence)")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0):
        raise ValueError(f"seed={seed!r} is out of range: allowed None or an integer >= 0 (CLI --seed)")
    if not isinstance(figure, bool):
        raise ValueError(f"figure={figure!r} is invalid: allowed True or False (CLI --no-figure)")
    if isinstance(max_figure_panels, bool) or not isinstance(max_figure_panels, numbers.Integral) \
            or not 1 <= max_figure_panels <= MAX_FIGURE_PANELS:
        raise ValueError(f"max_figure_panels={max_figure_panels!r} is out of range: allowed an integer >= 1 and "
                         f"<= {MAX_FIGURE_PANELS}")


def _write_csv(path, columns, rows):
    with atomic_text(path) as fh:
        fh.write(row_line({c: c for c in columns}, list(columns)))
        for r in rows:
            fh.write(row_line({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                               for k, v in r.items()}, list(columns)))


def _write_schema(path, name, description, columns, generation, settings):
    schema = {"file": name, "description": description, "empty_cell": "undefined value (NaN)",
              "generation": generation, "settings": settings,
              "columns": {c: {"type": t, "unit": u, "description": d} for c, (t, u, d) in columns.items()}}
    with atomic_text(path) as fh:
        json.dump(schema, fh, indent=1, ensure_ascii=False)
        fh.write("\n")


def analyse_folder(folder, estimator="surface", n_boot=2000, confidence=0.95, seed=DEFAULT_SEED, figure=True,
                   max_figure_panels=None):
    """Analyse a sweep folder: write ``analysis.csv``, ``analysis.schema.json`` and the figure.

    Every argument and the folder are checked before any work; the files are written into a
    staging folder and published as one set (:mod:`particleShear.analysis.outputs`).

    Parameters
    ----------
    folder : str or os.PathLike
        The sweep folder (with ``results.csv``).
    estimator : {"surface", "internal"}, optional
        Which moduli (default "surface").
    n_boot : int, optional
        Bootstrap replicates, 1 ... :data:`particleShear.analysis.sweep.N_BOOT_MAX` (100,000;
        default 2000).
    confidence : float, optional
        Level of the intervals, in (0, 1) (default 0.95).
    seed : int or None, optional
        Seed of the bootstrap (>= 0): each group's stream is derived from it and the group's
        parameters; default 0 (:data:`particleShear.analysis.sweep.DEFAULT_SEED`, as ``plot``'s), so
        the same call gives the same intervals; None draws fresh entropy (not reproducible).
    figure : bool, optional
        Write ``analysis.png`` and ``analysis.pdf`` when matplotlib is installed (default True;
        CLI ``--no-figure``).  The figure draws the first ``max_figure_panels`` groups and names
        the others in one line.
    max_figure_panels : int, optional
        Most panels of the figure, 1 ... :data:`particleShear.analysis.figure.MAX_FIGURE_PANELS`
        (24, the default).

    Returns
    -------
    dict
        ``"rows"`` (the rows of ``analysis.csv``, numbers as floats/ints, NaN where undefined),
        ``"columns"`` (:func:`analysis_columns`), ``"protocol_rows"`` and ``"protocol_columns"``
        (``analysis_protocols.csv``, :mod:`particleShear.analysis.protocol_summary`; empty
        without steady, relaxation or creep rows), ``"written"`` (paths), ``"removed"`` (files
        of an earlier set that this one does not hold), ``"notes"`` (messages about the folder:
        rows left out, groups not drawn, no figure without matplotlib).

    Raises
    ------
    ValueError
        An invalid argument, no ``results.csv``, no row with status ``ok`` and finite moduli or
        protocol summary, an unwritable folder, a directory or read-only file in the place of
        an output — all before the bootstrap.
    particleShear.sweep.locks.FolderBusyError
        Another analysis of the folder held its lock for a minute.
    particleShear.analysis.outputs.PublishInterrupted
        SIGINT or SIGTERM during the publication, which completed first.
    """
    import os
    import shutil
    import signal


    if max_figure_panels is None:
        max_figure_panels = MAX_FIGURE_PANELS
    _check_settings(estimator, n_boot, confidence, seed, figure, max_figure_panels)
    folder = os.fspath(folder)
    if not os.path.isfile(os.path.join(folder, "results.csv")):
        raise ValueError(f"folder={folder!r} is invalid: no results.csv there")
    check_targets(folder, SET_NAMES)
    rows = read_sweep_table(folder)
    groups, varying, skipped = group_runs(rows, estimator)
    header = list(rows[0]) if rows else []
    protocol_rows, protocol_varying = protocol_summaries(rows, grouping_columns(header) + (
        [_AMPLITUDE] if _AMPLITUDE in header else []), estimator, n_boot, confidence, seed)
    if not groups and not protocol_rows:
        raise ValueError(f"folder={folder!r} has no rows with status 'ok' and finite {estimator} moduli "
                         f"({len(rows)} row(s) in results.csv)")
    notes = list(getattr(rows, "notes", []))
    if skipped:
        notes.append(f"left out {skipped} row(s) with status ok but a missing or non-finite amplitude or "
                     f"{estimator} modulus")
    if any(row_protocol(r) in SUMMARY_PROTOCOLS for r in rows) and not groups:
        notes.append("no oscillatory runs or sweep steps: the steady, relaxation and creep runs are summarised in "
                     f"{PROTOCOLS_NAME}")
    if rows and all(row_protocol(r) == "steady" for r in rows):
        notes.append("the flow curve with its fit is drawn by: particleShear plot DIR (flow_curve.png)")
    generation = f"{os.getpid()}-{np.random.default_rng().integers(1 << 62):x}"
    settings = {"estimator": estimator, "n_boot": n_boot, "confidence": confidence, "bootstrap_seed": seed}
    staging = None
    try:
        with signals_held() as got:     # (the staging folder is made and named at once: the finally removes it)
            staging = make_staging(folder)
        for signum in got[:1]:          # a signal that came while it was made, acted on now
            signal.raise_signal(signum)
        out_rows, panels, names = [], [], []
        for g in groups:
            # each group its own stream, from the seed and the group's parameters: a group's intervals do not
            # depend on which other groups the folder holds
            label = _stream_label(g["parameters"])
            rng = np.random.default_rng(None if seed is None else [int(seed), zlib.crc32(label.encode("utf-8"))])
            summary, group_notes = _summarise(g, n_boot, confidence, rng)
            out_rows.append(_row(g, varying, summary, group_notes, estimator, n_boot, confidence, seed))
            flagged = sorted({A for A, fl in zip(g["amplitude"], g["flagged"]) if fl})
            panels.append((out_rows[-1]["group"], summary, group_notes, flagged))
        columns = analysis_columns(varying)
        if groups:
            _write_csv(os.path.join(staging, ANALYSIS_NAME), columns, out_rows)
            _write_schema(os.path.join(staging, SCHEMA_NAME), ANALYSIS_NAME,
                          "characteristics of the amplitude sweeps of a sweep folder (python -m particleShear "
                          "analyse; docs/analysis.md)", columns, generation, settings)
            names += [ANALYSIS_NAME, SCHEMA_NAME]
        p_columns = summary_columns(protocol_varying)
        if protocol_rows:
            _write_csv(os.path.join(staging, PROTOCOLS_NAME), p_columns, protocol_rows)
            _write_schema(os.path.join(staging, PROTOCOLS_SCHEMA_NAME), PROTOCOLS_NAME,
                          "summaries of the steady (Herschel-Bulkley fit of the flow curve), relaxation and creep "
                          "runs of a sweep folder (python -m particleShear analyse; docs/analysis.md)", p_columns,
                          generation, settings)
            names += [PROTOCOLS_NAME, PROTOCOLS_SCHEMA_NAME]
        if figure and panels:
            if _has_matplotlib():
                fig = plot_analysis(panels, estimator=estimator, max_panels=max_figure_panels,
                                    made=_made(rows, ("N", "relative_frequency")))
                for ext in (".png", ".pdf"):
                    key = "Description" if ext == ".png" else "Subject"
                    fig.savefig(os.path.join(staging, FIGURE_NAME + ext), format=ext[1:], dpi=150,
                                metadata={key: f"particleShear analyse, generation {generation}"})
                    names.append(FIGURE_NAME + ext)
                if len(panels) > max_figure_panels:
                    notes.append(f"figure: the first {max_figure_panels} of {len(panels)} groups drawn; not drawn: "
                                 + not_drawn_line([p[0] for p in panels[max_figure_panels:]]))
            else:
                notes.append('no figure: matplotlib is not installed (pip install "particleShear[plot]")')
        removed = publish(folder, staging, names, SET_NAMES)
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    if removed:
        notes.append("removed " + ", ".join(os.path.basename(p) for p in removed) + " of an earlier analysis "
                     "(not part of this one)")
    return {"rows": out_rows, "columns": columns, "protocol_rows": protocol_rows, "protocol_columns": p_columns,
            "written": [os.path.join(folder, n) for n in names], "removed": removed, "notes": notes}


def _json_rows(rows, columns):
    def clean(v):
        return None if isinstance(v, float) and not math.isfinite(v) else v
    return json.dumps([{c: clean(r.get(c)) for c in columns} for r in rows], ensure_ascii=False)


def _fmt(v):
    return "–" if not (isinstance(v, (int, float)) and math.isfinite(v)) else f"{v:.4g}"


def _with_interval(row, name):
    """``value [low, high]`` of a characteristic as its flag says (:data:`particleShear.analysis.sweep.FLAGS`):
    a censored point as a bound (``> 0.2``), an open interval end as a bound, no interval without an estimate."""
    v, lo, hi, flag = row[name], row[name + "_ci_low"], row[name + "_ci_high"], row.get(name + "_flag", "ok")
    if flag == "lower_bound":
        return f"> {_fmt(v)}"
    if flag == "upper_bound":
        return f"< {_fmt(v)}"
    if flag in ("too_few_amplitudes", "undefined") or not math.isfinite(v):
        return "–"
    if flag == "non_positive":
        return f"{_fmt(v)} (<= 0, no interval)"
    low = ("< " if flag in ("open_below", "open_both") else "") + _fmt(lo)
    high = ("> " if flag in ("open_above", "open_both") else "") + _fmt(hi)
    return f"{_fmt(v)} [{low}, {high}]"


def _human(rows):
    """A short table: group, runs, plateau, linear limit 5 %, flow point, yield strain with intervals."""
    shown = (("plateau", "plateau (Pa)"), ("linear_limit_5", "linear limit 5 %"), ("flow_point", "flow point"),
             ("yield_strain", "yield strain"))
    head = ["group", "runs"] + [t for _, t in shown]
    body = [[r["group"], _runs_text(r)] +
            [_with_interval(r, n) for n, _ in shown] for r in rows]
    widths = [max(len(x[i]) for x in [head] + body) for i in range(len(head))]
    buf = io.StringIO()
    for line in [head] + body:
        buf.write("  ".join(x.ljust(w) for x, w in zip(line, widths)).rstrip() + "\n")
    if rows:
        r = rows[0]
        seed = "fresh entropy (not reproducible)" if r["bootstrap_seed"] is None else f"seed {r['bootstrap_seed']}"
        buf.write(f"intervals: {100 * r['confidence']:g} % bootstrap, {r['n_boot']} replicates, {seed}; "
                  "> x / < x: the point lies beyond the measured amplitudes (a bound)\n")
    for r in rows:
        if r["note"]:
            buf.write(f"note: {r['group']}: {r['note']}\n")
    return buf.getvalue()


def _runs_text(r):
    """``12`` or ``12 (2 flagged, 1 failed)``: a group's runs with its verdict counts."""
    extra = [f"{r[k]} {k[2:]}" for k in ("n_flagged", "n_failed") if r.get(k)]
    return str(r["n_runs"]) + (f" ({', '.join(extra)})" if extra else "")


class _Terminated(BaseException):
    """SIGTERM during an analysis (status 143); a BaseException, so no ``except Exception`` swallows it."""


def _human_protocols(rows):
    """A short table of the protocol summaries: group, quantity, runs, value [interval] unit."""
    head = ["group", "quantity", "runs", "value [interval]", "unit", "flag"]
    body = [[r["group"], r["quantity"], str(r["n_runs"]),
             f"{_fmt(r['value'])} [{_fmt(r['ci_low'])}, {_fmt(r['ci_high'])}]"
             if math.isfinite(r["value"]) and math.isfinite(r["ci_low"]) else _fmt(r["value"]),
             r["unit"], r.get("flag", "ok")] for r in rows]
    widths = [max(len(x[i]) for x in [head] + body) for i in range(len(head))]
    buf = io.StringIO()
    for line in [head] + body:
        buf.write("  ".join(x.ljust(w) for x, w in zip(line, widths)).rstrip() + "\n")
    for note in dict.fromkeys(f"note: {r['group']}: {r['note']}" for r in rows if r["note"]):
        buf.write(note + "\n")
    return buf.getvalue()


def _measured_files(argv):
    """Whether the command line names files, not a sweep folder: a positional argument that is an existing file
    other than a sweep's ``results.csv`` (read by :func:`particleShear.experiment.measured.main`)."""
    import os
    return any(not a.startswith("-") and os.path.isfile(a) and os.path.basename(a) != "results.csv" for a in argv)


def main(argv=None):
    """``python -m particleShear analyse DIR [--estimator surface|internal] [--json] [--n-boot N]
    [--confidence C] [--seed S] [--no-figure]``.

    A command line whose paths are measured rheometer files (not a folder) is handed to
    :func:`particleShear.experiment.measured.main` (``analyse FILE… [--out DIR]``).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``analyse`` (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 written; 2 invalid input, an unwritable folder or output (message on
        stderr, before any work); 3 another analysis of the folder kept its lock; 130
        interrupted (Ctrl-C), 143 terminated (SIGTERM) — the earlier files or the new set are
        on disk, never a mix, and one line says which.
    """
    import signal
    argv = sys.argv[1:] if argv is None else list(argv)
    if _measured_files(argv):       # particleShear analyse FILE…: measured rheometer files
        return measured_main(argv)
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        n_boot = _number_flag("--n-boot", args.n_boot, "n_boot")
        confidence = _number_flag("--confidence", args.confidence, "confidence")
        seed = _number_flag("--seed", args.seed, "seed")
    except _UsageError as exc:
        print(f"{_PROG}: invalid parameter: {exc}", file=sys.stderr)
        return 2
    try:
        with sigterm_raises(_Terminated):
            result = analyse_folder(args.folder, estimator=args.estimator, n_boot=n_boot, confidence=confidence,
                                    seed=seed, figure=args.figure)
    except ValueError as exc:   # named as the user typed it: DIR, --seed, --n-boot
        text = command_line_names(exc, parser, {"folder_or_csv": "folder", "bootstrap_seed": "seed"})
        print(f"{_PROG}: {' '.join(text.split())}", file=sys.stderr)
        return 2
    except FolderBusyError:
        print(f"{_PROG}: another analysis of {args.folder!r} kept its lock (analysis.lock) for a minute: nothing "
              "written; try again", file=sys.stderr)
        return 3
    except PublishInterrupted as exc:
        print(f"{_PROG}: interrupted: the new analysis files were written whole before stopping", file=sys.stderr)
        return 143 if exc.signum == signal.SIGTERM else 130
    except (KeyboardInterrupt, _Terminated) as exc:
        print(f"{_PROG}: {'interrupted' if isinstance(exc, KeyboardInterrupt) else 'terminated'}: nothing written, "
              "the files of an earlier analysis are kept as they were", file=sys.stderr)
        return 130 if isinstance(exc, KeyboardInterrupt) else 143
    for note in result["notes"]:
        print(f"{_PROG}: {note}", file=sys.stderr)
    if args.json:
        if result["protocol_rows"]:
            print(json.dumps({"analysis": json.loads(_json_rows(result["rows"], result["columns"])),
                              "protocols": json.loads(_json_rows(result["protocol_rows"],
                                                                 result["protocol_columns"]))},
                             ensure_ascii=False))
        else:
            print(_json_rows(result["rows"], result["columns"]))
    else:
        if result["rows"]:
            sys.stdout.write(_human(result["rows"]))
        if result["protocol_rows"]:
            sys.stdout.write(_human_protocols(result["protocol_rows"]))
        for w in result["written"]:
            print(f"wrote {w}")
    return 0
