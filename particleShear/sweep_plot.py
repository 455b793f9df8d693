"""The sweep figure: G′ and G″ against the parameter a sweep varies, nothing pooled that is not a seed.

:func:`sweep_panels` turns the rows of a sweep's ``results.csv`` into the numbers of the figure and
:func:`draw_sweep` draws them; :func:`particleShear.plot.plot_sweep` (``python -m particleShear plot
DIR``) does both and writes the files.

How the runs are arranged
-------------------------
The *parameter columns* are the keys of :func:`particleShear.sweep.spec.sweep_parameter_defaults`
present in the table, less the inputs that change neither the physics nor the output
(:data:`particleShear.simulation.provenance.IDENTITY_EXCLUDED`: ``seed``, ``doDrawing``, ...).  Only
rows with status ``ok`` and finite moduli count (:func:`particleShear.plot.ok_moduli`).  Of the
parameter columns whose value differs between those rows:

* the **x-axis** is the one chosen with ``x`` (CLI ``--x``); by default the strain amplitude
  ``theAmplitude`` if it varies, else the frequency ``relative_frequency`` if that varies, else the
  amplitude;
* the **colour** is μ (``theMu``);
* the **material** — crosslinked / uncrosslinked / bulk control, from ``do_permanent_links`` and
  ``cut_lines`` (:func:`particleShear.plot.group_of`) — gives one panel each; ``cut_lines`` splits
  the crosslinked panel further where it takes several positive values;
* **every other** varying parameter (the frequency of an amplitude sweep, N, ...) splits the panels
  further, one panel per combination of values, named in the panel title — or, with
  ``split=False`` or more than ``max_panels`` panels, is refused with a ValueError naming it.

What is left at one point of one curve are the repetitions (seeds) of one parameter set.

Rows are read as :func:`particleShear.analysis.grouping.measured_row` rewrites them: a step of a
one-packing sweep (protocol ``amplitude_sweep`` or ``frequency_sweep``) is a point at its own
amplitude or frequency, and in a table of several protocols the protocol and the parameters it
reads are parameter columns like the others (they split panels); rows of the steady, relaxation
and creep protocols hold no moduli and are not drawn here.

Intervals
---------
With the amplitude on the x-axis each curve's points carry the percentile bootstrap interval of
:func:`particleShear.analysis.sweep.sweep_summary` (seeds resampled within each amplitude, widened to
Student-t width on the log scale, so never below 0; 95 %; the resampling seed
:data:`particleShear.analysis.sweep.DEFAULT_SEED`, as ``analyse``'s, so the figure is reproducible); otherwise — or when a curve has a single
amplitude, which the bootstrap summary does not take — mean ± one standard error ``s/√n``
(``ddof = 1``; zero for one seed).  The legend says which.
"""
__docformat__ = "numpy"
import math
import numbers
import warnings

import numpy as np

from .analysis.sweep import DEFAULT_SEED, N_BOOT_MAX, sweep_summary
from .plot_tools import (ESTIMATORS, FLAGGED_LABEL, _figure, _float, dodge_factors, fit_title, group_of, is_flagged,
                   made_by, ok_moduli)
from .analysis.grouping import short_value
from .simulation.provenance import IDENTITY_EXCLUDED
from .sweep.spec import sweep_parameter_defaults

__all__ = ["sweep_panels", "draw_sweep", "figure_stem", "X_ALIASES", "MIN_SEEDS", "MAX_PANELS"]

_AMPLITUDE = "theAmplitude"
_FREQUENCY = "relative_frequency"
_MU = "theMu"
_MATERIAL_KEYS = ("do_permanent_links", "cut_lines")
_MATERIALS = ("crosslinked", "uncrosslinked", "bulk control")

#: short names accepted for ``x`` (CLI ``--x``)
X_ALIASES = {"amplitude": _AMPLITUDE, "frequency": _FREQUENCY}
_X_LABELS = {_AMPLITUDE: "strain amplitude A (–)", _FREQUENCY: "relative frequency f·τ (–)"}
_X_SYMBOLS = {_AMPLITUDE: "A", _FREQUENCY: "f·τ"}
_X_STEMS = {_AMPLITUDE: "G_vs_amplitude", _FREQUENCY: "G_vs_frequency"}
#: fewer seeds per point than this draws a warning
MIN_SEEDS = 3
#: default largest number of panels before the split is refused
MAX_PANELS = 12


def figure_stem(x):
    """File stem of the sweep figure for x-axis parameter ``x``.

    Parameters
    ----------
    x : str
        The x-axis parameter column.

    Returns
    -------
    str
        ``"G_vs_amplitude"`` for ``theAmplitude``, ``"G_vs_frequency"`` for ``relative_frequency``,
        ``"G_vs_<x>"`` otherwise.
    """
    return _X_STEMS.get(x, "G_vs_" + x)


def _value(text):
    """Comparable value of a cell: the float if it reads as one, else the stripped text."""
    v = _float(text)
    return v if math.isfinite(v) else str(text).strip()


def _show(v):
    return f"{v:g}" if isinstance(v, float) else short_value(v)


def _sort_key(v):
    return (0, v, "") if isinstance(v, float) else (1, 0.0, str(v))


def _parameter_columns(header):
    # the protocol parameters too: in a table of several protocols the protocol (and what it reads) splits
    # panels; rows are read as particleShear.analysis.grouping.measured_row rewrites them
    return [c for c in sweep_parameter_defaults(protocols=True) if c in header and c not in IDENTITY_EXCLUDED]


def _check_settings(n_boot, confidence, bootstrap_seed, max_panels):
    if isinstance(n_boot, bool) or not isinstance(n_boot, numbers.Integral) or not 1 <= n_boot <= N_BOOT_MAX:
        raise ValueError(f"n_boot={n_boot!r} is out of range: allowed an integer >= 1 and <= {N_BOOT_MAX}")
    if isinstance(confidence, bool) or not isinstance(confidence, numbers.Real) or not 0 < confidence < 1:
        raise ValueError(f"confidence={confidence!r} is out of range: allowed a number in (0, 1)")
    if bootstrap_seed is not None and (isinstance(bootstrap_seed, bool) or not isinstance(
            bootstrap_seed, numbers.Integral) or bootstrap_seed < 0):
        raise ValueError(f"bootstrap_seed={bootstrap_seed!r} is out of range: allowed None or an integer >= 0")
    if isinstance(max_panels, bool) or not isinstance(max_panels, numbers.Integral) or max_panels < 1:
        raise ValueError(f"max_panels={max_panels!r} is out of range: allowed an integer >= 1")


def _resolve_x(x, params, varying, kept):
    allowed = (f"allowed {_AMPLITUDE!r} ('amplitude'), {_FREQUENCY!r} ('frequency') or another numeric parameter "
               f"column of the table except {list(_MATERIAL_KEYS)} (CLI --x)")
    if x is None:
        if _AMPLITUDE in varying or _FREQUENCY not in varying:
            return _AMPLITUDE
        return _FREQUENCY
    if not isinstance(x, str):
        raise ValueError(f"x={x!r} is invalid: {allowed}")
    name = X_ALIASES.get(x, x)
    if name in _MATERIAL_KEYS or (name not in params and name != _AMPLITUDE):
        raise ValueError(f"x={x!r} is invalid: {allowed}; the table's parameter columns: {params}")
    bad = [row.get(name) for row, *_ in kept if not math.isfinite(_float(row.get(name)))]
    if bad:
        raise ValueError(f"x={x!r} is invalid: column {name!r} holds {bad[0]!r}, not a finite number; {allowed}")
    return name


def _interval_label(kind, n_boot, confidence, bootstrap_seed, why=""):
    if kind == "bootstrap":
        seed = "fresh entropy" if bootstrap_seed is None else f"seed {bootstrap_seed}"
        return (f"bars: {100 * confidence:g} % bootstrap interval of the mean\nover seeds, Student-t width "
                f"(analysis.sweep_summary,\n{n_boot} resamples, {seed})")
    return "bars: mean ± 1 standard error\nover seeds (s/√n, ddof = 1)" + (f"\n{why}" if why else "")


def _mean_se(values):
    v = np.asarray(values, dtype=float)
    m = float(v.mean())
    se = float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else 0.0
    return m, m - se, m + se


def sweep_panels(rows, estimator="surface", x=None, split=True, n_boot=2000, confidence=0.95,
                 bootstrap_seed=DEFAULT_SEED, max_panels=MAX_PANELS):
    """The numbers of the sweep figure: panels, curves per μ, points per x value (module docstring).

    Parameters
    ----------
    rows : list of dict
        Rows of ``results.csv`` (:func:`particleShear.plot.read_sweep_table`).
    estimator : {"surface", "internal"}, optional
        Which moduli: plate forces (default) or the overall stress tensor.
    x : str, optional
        The x-axis parameter column (``"amplitude"`` and ``"frequency"`` stand for ``theAmplitude``
        and ``relative_frequency``); default: the amplitude if it varies, else the frequency if it
        varies, else the amplitude.
    split : bool, optional
        True (default): any other varying parameter splits the panels.  False: refuse it.
    n_boot : int, optional
        Bootstrap replicates (amplitude x-axis), >= 1 (default 2000).
    confidence : float, optional
        Level of the bootstrap intervals, in (0, 1) (default 0.95).
    bootstrap_seed : int or None, optional
        Seed of the resampling, >= 0 (default 0, :data:`particleShear.analysis.sweep.DEFAULT_SEED`, as
        ``analyse``'s: reproducible); None draws fresh entropy.
    max_panels : int, optional
        Refuse a split into more panels than this (default :data:`MAX_PANELS`).

    Returns
    -------
    dict
        ``"x"`` (the x column), ``"x_label"``, ``"log_x"`` (all x > 0), ``"estimator"``,
        ``"made"`` (``N``, ``relative_frequency``, ``theAmplitude`` where one value holds for every
        point), ``"interval"`` ("bootstrap" or "se"), ``"interval_label"`` (legend text), ``"split_by"``
        (the parameters besides the material that split the panels), ``"varying"`` (every varying
        parameter column), ``"skipped"`` (``ok`` rows left out for a missing value), ``"panels"``: a
        list of ``{"material", "split": {name: value}, "title", "curves"}``, each curve
        ``{"mu", "label", "x", "n", "flagged", "Gp", "Gp_low", "Gp_high", "Gpp", "Gpp_low", "Gpp_high"}``
        (``flagged``: runs of the point whose ``verdict`` is "flagged: …") with
        NumPy arrays ordered by x (moduli and interval ends in Pa; ``mu`` None when μ is the x-axis).

    Raises
    ------
    ValueError
        Naming the parameter and its allowed values: an unknown ``estimator`` or ``x``, a varying
        parameter with ``split=False`` (or beyond ``max_panels`` panels), no usable rows, settings
        out of range.
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS} (CLI --estimator)")
    _check_settings(n_boot, confidence, bootstrap_seed, max_panels)
    kept, skipped = ok_moduli(rows, estimator)
    if not kept:
        raise ValueError("the table has no rows with status 'ok' and finite amplitude and moduli")
    params = _parameter_columns(list(rows[0]))
    varying = [c for c in params if len({_value(r.get(c, "")) for r, *_ in kept}) > 1]
    xname = _resolve_x(x, params, varying, kept)
    colour = _MU if xname != _MU else None
    crosslinked_cuts = {_value(r.get("cut_lines", 0)) for r, *_ in kept if group_of(r) == "crosslinked"}
    cut_split = len(crosslinked_cuts) > 1
    others = [c for c in varying if c not in (xname, colour) + _MATERIAL_KEYS]
    split_by = (["cut_lines"] if cut_split else []) + others
    if split_by and not split:
        raise ValueError(f"parameter(s) {split_by} vary between the runs besides the x-axis {xname!r}, μ and the "
                         "material: they are not pooled as seeds; plot with split=True (CLI: without --no-split) "
                         "for one panel per value, or choose them as the x-axis with x=NAME (CLI --x NAME)")
    cells = {}
    for row, _, gp, gpp in kept:
        if not math.isfinite(_float(row.get(xname))):
            skipped += 1
            continue
        material = group_of(row)
        key = tuple(_value(row.get(c, "")) for c in others)
        if cut_split and material == "crosslinked":
            key = (_value(row.get("cut_lines", 0)),) + key
        elif cut_split:
            key = (None,) + key
        mu = _value(row.get(colour, 0.0)) if colour else None
        cells.setdefault((material, key), {}).setdefault(mu, {}).setdefault(_float(row.get(xname)), []).append(
            (gp, gpp, is_flagged(row)))
    if not cells:
        raise ValueError(f"x={xname!r}: no row with status 'ok' has a finite value in that column")
    if len(cells) > max_panels:
        raise ValueError(f"the runs split into {len(cells)} panels (material × {split_by}), more than "
                         f"max_panels={max_panels}: parameter(s) {split_by} vary; plot a part of the table, "
                         "choose one of them as the x-axis (x=NAME, CLI --x NAME) or raise max_panels")
    single = [m for p in cells.values() for m in p.values() if len(m) < 2]
    kind = "bootstrap" if xname == _AMPLITUDE and not single else "se"
    why = "(the bootstrap needs >= 2 amplitudes per curve)" if xname == _AMPLITUDE and single else ""
    panels = []
    for material, key in sorted(cells, key=lambda k: (_MATERIALS.index(k[0]), [_sort_key(v) for v in k[1]])):
        names = split_by if cut_split else others
        split_values = {n: v for n, v in zip(names, key) if v is not None}
        title = material + "".join(f", {n} = {_show(v)}" for n, v in split_values.items())
        curves = []
        for mu in sorted(cells[(material, key)], key=_sort_key):
            pts = cells[(material, key)][mu]
            xs = np.array(sorted(pts))
            c = {"mu": mu, "label": "" if mu is None else f"μ={_show(mu)}", "x": xs,
                 "n": np.array([len(pts[v]) for v in xs]),
                 "flagged": np.array([sum(p[2] for p in pts[v]) for v in xs])}
            if kind == "bootstrap":
                long = [(v, gp, gpp) for v in xs for gp, gpp, _ in pts[v]]
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UserWarning)   # one seed: said by draw_sweep's warning
                    s = sweep_summary([t[0] for t in long], [t[1] for t in long], [t[2] for t in long],
                                      n_boot=n_boot, confidence=confidence, rng=bootstrap_seed)
                for name, mean, ci in (("Gp", s.Gp_mean, s.Gp_ci), ("Gpp", s.Gpp_mean, s.Gpp_ci)):
                    c[name], c[name + "_low"], c[name + "_high"] = (np.array(mean), np.array(ci[:, 0]),
                                                                     np.array(ci[:, 1]))
            else:
                for i, name in ((0, "Gp"), (1, "Gpp")):
                    m = np.array([_mean_se([p[i] for p in pts[v]]) for v in xs])
                    c[name], c[name + "_low"], c[name + "_high"] = m[:, 0], m[:, 1], m[:, 2]
            curves.append(c)
        panels.append({"material": material, "split": split_values, "title": title, "curves": curves})
    all_x = [v for p in panels for c in p["curves"] for v in c["x"]]
    made = {}      # what made the figure, where one value holds for every point (else it is on an axis or panel)
    for col in ("N", _FREQUENCY, _AMPLITUDE):
        values = {_value(r.get(col, "")) for r, *_ in kept}
        if col != xname and col not in split_by and len(values) == 1 and isinstance(next(iter(values)), float):
            made[col] = next(iter(values))
    return {"x": xname, "made": made, "x_label": _X_LABELS.get(xname, xname), "log_x": min(all_x) > 0, "estimator": estimator,
            "interval": kind, "interval_label": _interval_label(kind, n_boot, confidence, bootstrap_seed, why),
            "split_by": split_by, "varying": varying, "skipped": skipped, "panels": panels}


def draw_sweep(table):
    """Draw the numbers of :func:`sweep_panels`: one panel each, the legend and notes beside them.

    G′ solid lines with filled circles, G″ dashed with open squares, one colour per μ; log y axis
    (log x where every x > 0).  A mean ≤ 0 cannot be drawn on the log axis: it is marked with a
    triangle (▼ G′, ▽ G″) at the lower edge of its panel, listed in the note beside the legend and
    reported in a ``UserWarning``.  The number of seeds per point is in each panel title where it is
    one number, else written beside each point.  Fewer than :data:`MIN_SEEDS` seeds at a point (or
    ``ok`` rows left out) also warn.

    Parameters
    ----------
    table : dict
        The result of :func:`sweep_panels`.

    Returns
    -------
    matplotlib.figure.Figure
        Labelled :func:`figure_stem` of the x-axis; axes: the panels in order, then the legend
        axes (no data).  In each panel one errorbar container per modulus and μ, labelled
        ``"G′ μ=<μ>"`` / ``"G″ μ=<μ>"``; its data line holds the means (NaN where ≤ 0); the markers
        of non-positive means have gid ``"nonpositive"``; the note is the legend axes' text with gid
        ``"note"``.
    """
    from matplotlib.lines import Line2D
    from matplotlib.ticker import NullFormatter
    from matplotlib.transforms import blended_transform_factory
    panels, xname = table["panels"], table["x"]
    symbol = _X_SYMBOLS.get(xname, xname)
    ncols = min(3, len(panels))
    nrows = math.ceil(len(panels) / ncols)
    fig = _figure(4.0 * ncols + 3.0, 3.3 * nrows + 0.9)
    fig.set_label(figure_stem(xname))
    grid = fig.add_gridspec(nrows, ncols + 1, width_ratios=[1.0] * ncols + [0.8])
    axes = []
    for i in range(len(panels)):   # one y scale for all panels: materials compare at a glance
        axes.append(fig.add_subplot(grid[i // ncols, i % ncols], sharey=axes[0] if axes else None))
    legend_ax = fig.add_subplot(grid[:, ncols])
    legend_ax.axis("off")
    mus = sorted({c["mu"] for p in panels for c in p["curves"]}, key=_sort_key)
    colours = {mu: f"C{k % 10}" for k, mu in enumerate(mus)}
    handles, nonpositive, few, total = {}, [], [], 0
    # one lower edge for all panels (they share y): a third of the smallest positive mean or bar end;
    # a bar whose lower end is at or below it (an interval reaching <= 0) is cut there and marked
    positive = [v for p in panels for c in p["curves"] for k in ("Gp", "Gpp", "Gp_low", "Gpp_low")
                for v in np.ravel(c[k]) if np.isfinite(v) and v > 0]
    means = [v for p in panels for c in p["curves"] for k in ("Gp", "Gpp") for v in np.ravel(c[k])
             if np.isfinite(v) and v > 0]
    floor = min(positive) / 3 if positive else 1.0
    if means and floor < min(means) / 1e3:      # a bar end far below every mean: cut it (marked), keep the data legible
        floor = min(means) / 1e3
    cut_any, flagged_any = False, False
    for ax, panel in zip(axes, panels):
        edge = blended_transform_factory(ax.transData, ax.transAxes)
        n_panel = sorted({int(n) for c in panel["curves"] for n in c["n"]})
        panel_x = [v for c in panel["curves"] for v in c["x"]]
        if table["log_x"]:     # series at the same x side by side (dodge_factors), x ticks at the true values
            shift = {id(c): c["x"] * f for c, f in zip(panel["curves"], dodge_factors(len(panel["curves"]), panel_x))}
        else:
            span = (max(panel_x) - min(panel_x)) or 1.0
            m = len(panel["curves"])
            shift = {id(c): c["x"] + 0.015 * span * (k - (m - 1) / 2) for k, c in enumerate(panel["curves"])}
        for c in panel["curves"]:
            col = colours[c["mu"]]
            xd = shift[id(c)]
            for name, sym, marker, ls, mfc in (("Gp", "G′", "o", "-", col), ("Gpp", "G″", "s", "--", "white")):
                mean, low, high = c[name], c[name + "_low"], c[name + "_high"]
                pos = mean > 0
                y = np.where(pos, mean, np.nan)
                cut = pos & ~(low > floor)
                err = np.vstack([np.where(pos, mean - np.where(cut, floor, low), np.nan),
                                 np.where(pos, high - mean, np.nan)])
                label = f"{sym} {c['label']}".strip()
                cont = ax.errorbar(xd, y, yerr=err, color=col, marker=marker, mfc=mfc, ls=ls, capsize=3,
                                   label=label)
                handles.setdefault(label, cont)
                if cut.any():
                    cut_any = True
                    ax.plot(xd[cut], np.full(int(cut.sum()), floor), ls="none", marker=7, ms=7, color=col,
                            clip_on=False, gid="interval-cut")
                fl = pos & (c["flagged"] > 0)
                if fl.any():
                    flagged_any = True
                    ax.plot(xd[fl], mean[fl], ls="none", marker="o", ms=13, mfc="none", mec="k", mew=1.2,
                            zorder=4, gid="flagged")
                if not pos.all():
                    ax.plot(xd[~pos], np.zeros(int((~pos).sum())), transform=edge, ls="none", clip_on=False,
                            marker="v", ms=8, color=col, mfc=col if name == "Gp" else "white", gid="nonpositive")
                    if (c["flagged"][~pos] > 0).any():
                        flagged_any = True
                        ax.plot(xd[~pos & (c["flagged"] > 0)], np.zeros(int((~pos & (c["flagged"] > 0)).sum())),
                                transform=edge, ls="none", clip_on=False, marker="o", ms=13, mfc="none", mec="k",
                                mew=1.2, gid="flagged")
                    for v, m in zip(c["x"][~pos], mean[~pos]):
                        nonpositive.append(f"{panel['title']} {c['label']}: {sym} = {m:.3g} Pa at {symbol} = {v:g}")
            if len(n_panel) > 1:
                for v, n, gp in zip(xd, c["n"], c["Gp"]):
                    if gp > 0:
                        ax.annotate(f"n={n}", (v, gp), xytext=(3, 4), textcoords="offset points", fontsize=6,
                                    color=col)
            total += len(c["x"])
            few += [f"{panel['title']} {c['label']} at {symbol} = {v:g}: {n}"
                    for v, n in zip(c["x"], c["n"]) if n < MIN_SEEDS]
        seeds = (f"n = {n_panel[0]} seed(s) per point" if len(n_panel) == 1
                 else f"n = {n_panel[0]}–{n_panel[-1]} seeds per point (beside the points)")
        ax.set_title(f"{panel['title']}\n{seeds}", fontsize="medium")
        ax.set_yscale("log", nonpositive="clip")
        ax.set_ylim(bottom=floor)
        if table["log_x"]:
            ax.set_xscale("log")
        xs = sorted({float(v) for c in panel["curves"] for v in c["x"]})
        if len(xs) <= 12:   # label the measured values themselves, no crowded minor labels
            ax.set_xticks(xs, [f"{v:g}" for v in xs])
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(table["x_label"])
        ax.set_ylabel(f"G′, G″ (Pa), {table['estimator']} estimator")
        ax.grid(True, which="both", color="0.9", lw=0.6)
    if nonpositive:
        handles["mean ≤ 0: not on the log axis,\nmarked at the lower edge"] = Line2D([], [], ls="none", marker="v", ms=8, color="0.3")
    if cut_any:
        handles["interval reaches below the axis (≤ 0, or\n1000× below the smallest mean): bar cut at ▼"] = Line2D(
            [], [], ls="none", marker=7, ms=7, color="0.3")
    if flagged_any:
        handles[FLAGGED_LABEL + ":\n≥ 1 run of the point flagged"] = Line2D([], [], ls="none", marker="o", ms=13,
                                                                          mfc="none", mec="k", mew=1.2)
    if any(len(p["curves"]) > 1 for p in panels):
        handles["series at one x drawn side by side\n(ticks at the measured values)"] = Line2D([], [], ls="none")
    legend_ax.legend(list(handles.values()), list(handles.keys()), loc="upper left", fontsize="small",
                     title=table["interval_label"], title_fontsize="x-small", frameon=False)
    split = ", ".join(["material (do_permanent_links, cut_lines)"] + [s for s in table["split_by"]
                                                                     if s != "cut_lines"])
    made = table.get("made", {})
    ns = [int(n) for p in panels for c in p["curves"] for n in c["n"]]
    rate = f"f·τ = {made[_FREQUENCY]:g}" if _FREQUENCY in made else None
    line = made_by(N=int(made["N"]) if "N" in made else None, seeds=(min(ns), max(ns)),
                   estimator=table["estimator"], rate=rate, amplitude=made.get(_AMPLITUDE))
    fit_title(fig, f"G′, G″ against {table['x_label']}: {line}; panels by {split}; colour: μ (theMu)")
    notes = []
    if nonpositive:
        notes.append("mean ≤ 0, marked at the lower edge:\n" + "\n".join("  " + s for s in nonpositive))
        warnings.warn("plot_sweep: mean(s) <= 0 cannot be drawn on the log axis, marked at the lower edge: "
                      + "; ".join(nonpositive), UserWarning, stacklevel=3)
    if few:
        notes.append(f"fewer than {MIN_SEEDS} seeds at {len(few)} of {total} point(s)")
        listed = "; ".join(few[:6]) + ("; ..." if len(few) > 6 else "")
        warnings.warn(f"plot_sweep: fewer than {MIN_SEEDS} seeds at {len(few)} of {total} point(s) (their intervals "
                      f"are unreliable; one seed gives a zero-width bar): {listed}", UserWarning, stacklevel=3)
    if table["skipped"]:
        notes.append(f"{table['skipped']} row(s) with status ok left out (missing or non-finite value)")
        warnings.warn(f"plot_sweep: {table['skipped']} row(s) with status ok left out for a missing or non-finite "
                      "amplitude, x value or modulus", UserWarning, stacklevel=3)
    if notes:
        legend_ax.text(0.0, 0.0, "\n".join(notes), transform=legend_ax.transAxes, va="bottom", ha="left",
                       fontsize="x-small", wrap=True, gid="note")
    return fig
