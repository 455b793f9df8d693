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
other groups of the folder.  Writes, atomically:

``DIR/analysis.csv``
    One row per group: ``group`` (a label), the parameters that differ between groups, the
    estimator, the bootstrap settings, ``n_runs``, ``n_amplitudes``, … and every characteristic of
    :data:`particleShear.analysis.sweep.CHARACTERISTICS` with ``_ci_low``, ``_ci_high`` and
    ``_defined``; ``note`` says what deserves a look (one seed, non-positive means, rows left out).
    An empty cell is an undefined value.
``DIR/analysis.schema.json``
    Column → type, unit, description.
``DIR/analysis.png``, ``DIR/analysis.pdf``
    With matplotlib (extra ``[plot]``): :func:`particleShear.analysis.figure.plot_analysis`.

Exit status: 0 written, 2 invalid input (no results.csv, no usable rows, a bad flag value), with a
one-line message on stderr.
"""
__docformat__ = "numpy"
import io
import json
import math
import sys
import warnings
import zlib

from ..run.guard import SuggestingParser

__all__ = [
    "OUTPUT_ONLY",
    "ANALYSIS_NAME",
    "FIGURE_NAME",
    "SCHEMA_NAME",
    "analyse_folder",
    "analysis_columns",
    "build_parser",
    "group_runs",
    "main",
]

#: the table written into the sweep folder
ANALYSIS_NAME = "analysis.csv"
#: its schema (column → type, unit, description)
SCHEMA_NAME = "analysis.schema.json"
#: the figure's file stem (``.png`` and ``.pdf``)
FIGURE_NAME = "analysis"

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
    "n_amplitudes": ("int", "1", "distinct strain amplitudes of the group"),
    "amplitude_min": ("float", "1", "smallest strain amplitude"),
    "amplitude_max": ("float", "1", "largest strain amplitude"),
    "n_seeds_min": ("int", "1", "fewest runs (seeds) at one amplitude"),
    "n_seeds_max": ("int", "1", "most runs (seeds) at one amplitude"),
    "confidence": ("float", "1", "level of the bootstrap percentile intervals"),
    "n_boot": ("int", "1", "bootstrap replicates (seeds resampled with replacement within each amplitude)"),
    "bootstrap_seed": ("int", "1", "--seed of the bootstrap (empty: fresh entropy, not reproducible)"),
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
        ``--confidence C``, ``--seed S`` (values checked by :func:`main`).
    """
    from ..plot import ESTIMATORS
    p = _Parser(prog=_PROG, description="Characteristics of a sweep folder's amplitude sweeps (plateau, linear "
                                        "limits, flow point, the R package's four points) with bootstrap intervals "
                                        "over the seeds. Reads DIR/results.csv, writes DIR/analysis.csv, "
                                        "DIR/analysis.schema.json and (with matplotlib) DIR/analysis.png and .pdf.")
    p.add_argument("folder", metavar="DIR", help="sweep folder containing results.csv")
    p.add_argument("--estimator", choices=ESTIMATORS, default="surface",
                   help="moduli from the plate forces (surface, default) or the overall stress tensor (internal)")
    p.add_argument("--json", action="store_true", help="print the rows of analysis.csv as JSON on stdout (NaN: null)")
    p.add_argument("--n-boot", metavar="N", default="2000", help="bootstrap replicates, integer >= 1 (default 2000)")
    p.add_argument("--confidence", metavar="C", default="0.95", help="interval level in (0, 1) (default 0.95)")
    p.add_argument("--seed", metavar="S", default=None,
                   help="seed of the bootstrap, integer >= 0 (default: fresh entropy, intervals not reproducible)")
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
    try:
        value = int(text)
    except ValueError:
        raise _UsageError(f"{flag}={text!r} is invalid: allowed an integer >= {low}") from None
    if value < low:
        raise _UsageError(f"{flag}={text!r} is out of range: allowed an integer >= {low}")
    return value


def _sort_key(text):
    try:
        return (0, float(text), "")
    except (TypeError, ValueError):
        return (1, 0.0, str(text))


def group_runs(rows, estimator="surface"):
    """The runs of a sweep table grouped by their parameters except the amplitude.

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
        floats, one per run).
    varying : list of str
        The grouping columns whose value differs between groups (header order).
    skipped : int
        Rows with status ``ok`` left out for a missing or non-finite amplitude or modulus.

    Raises
    ------
    ValueError
        If ``estimator`` is not one of the two, or the table has no ``theAmplitude`` column.
    """
    from ..plot import ok_moduli
    from ..simulation.provenance import IDENTITY_EXCLUDED
    from ..sweep.spec import sweep_parameter_defaults
    kept, skipped = ok_moduli(rows, estimator)
    header = list(rows[0]) if rows else []
    if rows and _AMPLITUDE not in header:
        raise ValueError(f"results.csv has no {_AMPLITUDE} column: not a sweep table")
    names = [c for c in sweep_parameter_defaults() if c in header and c != _AMPLITUDE and c not in IDENTITY_EXCLUDED
             and c not in OUTPUT_ONLY]
    cells = {}
    # runs in a fixed order (amplitude, run id), not the order they finished in: the bootstrap draws
    # the same resamples from the same seed however the table was written
    for row, A, gp, gpp in sorted(kept, key=lambda k: (k[1], str(k[0].get("run_id", "")))):
        key = tuple(str(row.get(c, "")) for c in names)
        d = cells.setdefault(key, {"parameters": dict(zip(names, key)), "amplitude": [], "Gp": [], "Gpp": []})
        d["amplitude"].append(A)
        d["Gp"].append(gp)
        d["Gpp"].append(gpp)
    keys = sorted(cells, key=lambda k: [_sort_key(v) for v in k])
    varying = [c for i, c in enumerate(names) if len({k[i] for k in keys}) > 1]
    return [cells[k] for k in keys], varying, skipped


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
    from .sweep import CHARACTERISTICS
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
    cols[_NOTE[0]] = _NOTE[1]
    return cols


def _label(parameters, varying):
    return ", ".join(f"{n}={parameters[n]}" for n in varying) or "all runs"


def _summarise(group, n_boot, confidence, rng):
    """(SweepSummary or None, notes) of one group."""
    import numpy as np

    from .sweep import sweep_summary
    notes = []
    n_amp = len(set(group["amplitude"]))
    if n_amp < 2:
        return None, [f"{n_amp} amplitude only: no characteristics"]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        s = sweep_summary(group["amplitude"], group["Gp"], group["Gpp"], n_boot=n_boot, confidence=confidence,
                          rng=rng)
    single = s.amplitudes[s.n_seeds == 1]
    if len(caught) and len(single):
        notes.append(f"one seed at amplitude(s) {_floats(single)}: degenerate intervals there")
    for what, mean in (("G′", s.Gp_mean), ("G″", s.Gpp_mean)):
        bad = s.amplitudes[np.asarray(mean) <= 0]
        if len(bad):
            notes.append(f"mean {what} <= 0 at amplitude(s) {_floats(bad)}: not on the log axes, no log-log "
                         "characteristics across them")
    return s, notes


def _floats(a):
    return "[" + ", ".join(f"{float(x):g}" for x in a) + "]"


def _row(group, varying, summary, notes, estimator, n_boot, confidence, seed):
    from .sweep import CHARACTERISTICS
    row = {"group": _label(group["parameters"], varying)}
    row.update({n: group["parameters"][n] for n in varying})
    row.update({"estimator": estimator, "n_runs": len(group["amplitude"]), "confidence": confidence,
                "n_boot": n_boot, "bootstrap_seed": seed})
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
    row["note"] = "; ".join(notes)
    return row


def analyse_folder(folder, estimator="surface", n_boot=2000, confidence=0.95, seed=None, figure=True):
    """Analyse a sweep folder: write ``analysis.csv``, ``analysis.schema.json`` and the figure.

    Parameters
    ----------
    folder : str or os.PathLike
        The sweep folder (with ``results.csv``).
    estimator : {"surface", "internal"}, optional
        Which moduli (default "surface").
    n_boot : int, optional
        Bootstrap replicates, >= 1 (default 2000).
    confidence : float, optional
        Level of the intervals, in (0, 1) (default 0.95).
    seed : int or None, optional
        Seed of the bootstrap (>= 0): one generator drives the groups in table order; None
        (default) draws fresh entropy.
    figure : bool, optional
        Write ``analysis.png`` and ``analysis.pdf`` when matplotlib is installed (default True).

    Returns
    -------
    dict
        ``"rows"`` (the rows of ``analysis.csv``, numbers as floats/ints, NaN where undefined),
        ``"columns"`` (:func:`analysis_columns`), ``"written"`` (paths), ``"notes"`` (messages
        about the folder: rows left out, no figure without matplotlib).

    Raises
    ------
    ValueError
        No ``results.csv``, no row with status ``ok`` and finite moduli, or an invalid argument.
    """
    import os

    import numpy as np

    from ..plot import _has_matplotlib, read_sweep_table
    from ..sweep.table import atomic_text, row_line
    folder = os.fspath(folder)
    if not os.path.isfile(os.path.join(folder, "results.csv")):
        raise ValueError(f"folder={folder!r} is invalid: no results.csv there")
    rows = read_sweep_table(folder)
    groups, varying, skipped = group_runs(rows, estimator)
    if not groups:
        raise ValueError(f"folder={folder!r} has no rows with status 'ok' and finite {estimator} moduli "
                         f"({len(rows)} row(s) in results.csv)")
    notes = list(getattr(rows, "notes", []))
    if skipped:
        notes.append(f"left out {skipped} row(s) with status ok but a missing or non-finite amplitude or "
                     f"{estimator} modulus")
    out_rows, panels = [], []
    for g in groups:
        # each group its own stream, from the seed and the group's parameters: a group's intervals do not
        # depend on which other groups the folder holds
        label = "\x1f".join(f"{k}={v}" for k, v in sorted(g["parameters"].items()))
        rng = np.random.default_rng(None if seed is None else [int(seed), zlib.crc32(label.encode("utf-8"))])
        summary, group_notes = _summarise(g, n_boot, confidence, rng)
        out_rows.append(_row(g, varying, summary, group_notes, estimator, n_boot, confidence, seed))
        panels.append((out_rows[-1]["group"], summary, group_notes))
    columns = analysis_columns(varying)
    path = os.path.join(folder, ANALYSIS_NAME)
    with atomic_text(path) as fh:
        fh.write(row_line({c: c for c in columns}, list(columns)))
        for r in out_rows:
            fh.write(row_line({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                               for k, v in r.items()}, list(columns)))
    schema = {"file": ANALYSIS_NAME, "description": "characteristics of the amplitude sweeps of a sweep folder "
                                                    "(python -m particleShear analyse; docs/analysis.md)",
              "empty_cell": "undefined value (NaN)",
              "columns": {c: {"type": t, "unit": u, "description": d} for c, (t, u, d) in columns.items()}}
    schema_path = os.path.join(folder, SCHEMA_NAME)
    with atomic_text(schema_path) as fh:
        json.dump(schema, fh, indent=1, ensure_ascii=False)
        fh.write("\n")
    written = [path, schema_path]
    if figure:
        if _has_matplotlib():
            from ..plot import save_figure
            from .figure import plot_analysis
            fig = plot_analysis(panels, estimator=estimator)
            for ext in (".png", ".pdf"):
                written.append(save_figure(fig, os.path.join(folder, FIGURE_NAME + ext)))
        else:
            notes.append('no figure: matplotlib is not installed (pip install "particleShear[plot]")')
    return {"rows": out_rows, "columns": columns, "written": written, "notes": notes}


def _json_rows(rows, columns):
    def clean(v):
        return None if isinstance(v, float) and not math.isfinite(v) else v
    return json.dumps([{c: clean(r.get(c)) for c in columns} for r in rows], ensure_ascii=False)


def _fmt(v):
    return "–" if not (isinstance(v, (int, float)) and math.isfinite(v)) else f"{v:.4g}"


def _human(rows):
    """A short table: group, runs, plateau, linear limit 5 %, flow point, yield strain with intervals."""
    shown = (("plateau", "plateau (Pa)"), ("linear_limit_5", "linear limit 5 %"), ("flow_point", "flow point"),
             ("yield_strain", "yield strain"))
    head = ["group", "runs"] + [t for _, t in shown]
    body = [[r["group"], str(r["n_runs"])] +
            [f"{_fmt(r[n])} [{_fmt(r[n + '_ci_low'])}, {_fmt(r[n + '_ci_high'])}]" for n, _ in shown] for r in rows]
    widths = [max(len(x[i]) for x in [head] + body) for i in range(len(head))]
    buf = io.StringIO()
    for line in [head] + body:
        buf.write("  ".join(x.ljust(w) for x, w in zip(line, widths)).rstrip() + "\n")
    for r in rows:
        if r["note"]:
            buf.write(f"note: {r['group']}: {r['note']}\n")
    return buf.getvalue()


def main(argv=None):
    """``python -m particleShear analyse DIR [--estimator surface|internal] [--json] [--n-boot N]
    [--confidence C] [--seed S]``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``analyse`` (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 written, 2 invalid input (message on stderr).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = build_parser().parse_args(argv)
        n_boot = _number_flag("--n-boot", args.n_boot, "n_boot")
        confidence = _number_flag("--confidence", args.confidence, "confidence")
        seed = None if args.seed is None else _number_flag("--seed", args.seed, "seed")
    except _UsageError as exc:
        print(f"{_PROG}: invalid parameter: {exc}", file=sys.stderr)
        return 2
    try:
        result = analyse_folder(args.folder, estimator=args.estimator, n_boot=n_boot, confidence=confidence,
                                seed=seed)
    except ValueError as exc:
        print(f"{_PROG}: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    for note in result["notes"]:
        print(f"{_PROG}: {note}", file=sys.stderr)
    if args.json:
        print(_json_rows(result["rows"], result["columns"]))
    else:
        sys.stdout.write(_human(result["rows"]))
        for w in result["written"]:
            print(f"wrote {w}")
    return 0

