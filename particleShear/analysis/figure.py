"""The figure of ``python -m particleShear analyse``: mean G′, G″ against amplitude with bootstrap bands.

One panel per group of the sweep folder, log-log axes: the mean G′ (solid, filled circles) and G″
(dashed, open squares) over the seeds with their bootstrap intervals as bands, the characteristic
points of :class:`~particleShear.analysis.sweep.SweepSummary` marked, labelled and drawn with their
intervals as error bars, the number of seeds in the panel title, one legend for all panels below
them (never over the data).  A mean that is zero or negative cannot be drawn on a log axis: it is
marked by an open triangle on the lower edge of the panel at its amplitude and said in a note
under the panel; band ends at or below zero are drawn at the lower edge (said too).  Drawn on an Agg canvas
(:func:`particleShear.plot._figure`), headless; written with :func:`particleShear.plot.save_figure`.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..plot_tools import FLAGGED_LABEL, _figure, fit_title, made_by, place_labels, save_figure

__all__ = ["MARKERS", "MAX_FIGURE_PANELS", "not_drawn_line", "plot_analysis"]

#: most panels of the figure: the first groups (in table order) are drawn, the others named in one line
#: (a figure of thousands of panels would take gigabytes and hours; every group is a row of the table)
MAX_FIGURE_PANELS = 24

#: characteristic → (marker, short label, legend text, label offset in points)
MARKERS = {
    "linear_limit_5": ("v", "5 %", "linear limit: G′ 5 % below plateau", (3, 7)),
    "linear_limit_10": ("<", "10 %", "linear limit: G′ 10 % below plateau", (3, -12)),
    "flow_point": ("*", "flow", "flow point: G′ = G″ (log-log)", (5, 6)),
    "low_strain_plateau": ("D", "LSP", "low-strain plateau (R package)", (5, 6)),
    "softening": ("P", "soft.", "softening (R package)", (5, 6)),
    "soft_plateau": ("X", "SP", "soft plateau (R package)", (5, -12)),
    "yield": ("h", "yield", "yield (R package, linear)", (5, -12)),
}


def _loglog_at(A, y, a):
    """y at amplitude a, linear in log y against log A (NaN where a bracketing value is not positive)."""
    A, y = np.asarray(A, float), np.asarray(y, float)
    if not (math.isfinite(a) and A[0] <= a <= A[-1]):
        return math.nan
    j = int(np.clip(np.searchsorted(A, a), 1, len(A) - 1))
    y0, y1 = y[j - 1], y[j]
    if y0 <= 0 or y1 <= 0:
        return math.nan
    t = (math.log(a) - math.log(A[j - 1])) / (math.log(A[j]) - math.log(A[j - 1]))
    return math.exp(math.log(y0) + t * (math.log(y1) - math.log(y0)))


def _seeds_text(n_seeds):
    lo, hi = int(np.min(n_seeds)), int(np.max(n_seeds))
    return f"{lo} seed{'s' if lo != 1 else ''} per amplitude" if lo == hi else f"{lo}–{hi} seeds per amplitude"


def _panel(ax, title, s, notes, flagged=()):
    """Draw one group's panel; returns (the notes drawn into it, the point labels to place).

    The labels of the characteristic points are not drawn here: :func:`plot_analysis` places them
    after the layout, without overlap (:func:`particleShear.plot.place_labels`).
    """
    A = np.asarray(s.amplitudes, float)
    said = list(notes)
    positive = [v for arr in (s.Gp_mean, s.Gpp_mean, s.Gp_ci.ravel(), s.Gpp_ci.ravel()) for v in np.ravel(arr)
                if math.isfinite(v) and v > 0]
    floor = (min(positive) / 3) if positive else 1.0
    clipped = False
    for key, mean, ci, colour, style, marker, mfc in (("G′", s.Gp_mean, s.Gp_ci, "C0", "-", "o", "C0"),
                                                      ("G″", s.Gpp_mean, s.Gpp_ci, "C3", "--", "s", "white")):
        mean = np.asarray(mean, float)
        ok = mean > 0
        lo, hi = np.asarray(ci[:, 0], float), np.asarray(ci[:, 1], float)
        clipped |= bool(np.any((lo <= 0) & (hi > 0)))
        band_ok = hi > 0
        ax.fill_between(A[band_ok], np.maximum(lo[band_ok], floor), hi[band_ok], color=colour, alpha=0.18, lw=0,
                        label=f"{key}: {s.confidence:.0%} bootstrap interval of the mean (Student-t width)")
        ax.plot(A[ok], mean[ok], color=colour, ls=style, marker=marker, mfc=mfc, ms=4, lw=1.3,
                label=f"{key} mean over seeds")
        ring = ok & np.isin(A, np.asarray(list(flagged), float))
        if ring.any():     # a run of the point has a flagged verdict: ringed, never hidden
            ax.plot(A[ring], mean[ring], ls="none", marker="o", ms=10, mfc="none", mec="k", mew=1.1, zorder=4,
                    gid="flagged", label=FLAGGED_LABEL + ": ≥ 1 run at the amplitude")
        if (~ok).any():
            ax.plot(A[~ok], np.full((~ok).sum(), floor), ls="none", marker="v", ms=8, color=colour, mfc="none",
                    clip_on=False, label=f"{key} mean <= 0 (not on the log axis)")
            bad = ", ".join(f"{a:g}" for a in A[~ok])
            said = [n for n in said if not n.startswith(f"mean {key} <= 0")]   # said here, more precisely
            said.append(f"mean {key} <= 0 at A = {bad}: not on the log axis, marked ▽ on the lower edge")
    plateau = s.plateau
    marks = []
    for name, frac in (("linear_limit_5", 0.05), ("linear_limit_10", 0.10)):
        v, ci = s.value(name)
        marks.append((name, v, (1 - frac) * plateau if plateau > 0 else math.nan, ci, None))
    fp, fp_ci = s.value("flow_point")
    marks.append(("flow_point", fp, _loglog_at(A, s.Gp_mean, fp), fp_ci, None))
    for name in ("low_strain_plateau", "softening", "soft_plateau", "yield"):
        strain, gp, _ = s.points[name]
        ci = s.points_ci[name]
        marks.append((name, strain, gp, (ci[0, 0], ci[0, 1]), (ci[1, 0], ci[1, 1])))
    labels = []
    for name, x, y, xci, yci in marks:
        marker, short, legend, offset = MARKERS[name]
        flag = s.flags.get(name, s.flags.get(name + "_strain", "ok"))
        if flag in ("lower_bound", "upper_bound"):      # a bound is not a point of the curve: said, not drawn
            said.append(f"{short}: {'>' if flag == 'lower_bound' else '<'} {x:g} (beyond the measured amplitudes)")
            continue
        if not (math.isfinite(x) and math.isfinite(y) and x > 0 and y > 0):
            continue
        xerr = None
        if all(math.isfinite(c) and c > 0 for c in xci):
            xerr = [[max(x - xci[0], 0)], [max(xci[1] - x, 0)]]
        yerr = None
        if yci is not None and all(math.isfinite(c) and c > 0 for c in yci):
            yerr = [[max(y - yci[0], 0)], [max(yci[1] - y, 0)]]
        ax.errorbar([x], [y], xerr=xerr, yerr=yerr, ls="none", marker=marker, ms=8, color="k", mfc="gold",
                    ecolor="0.3", elinewidth=0.8, capsize=2, zorder=5, label=legend)
        labels.append((short, x, y))
    if clipped:
        said.append("interval ends <= 0 drawn at the lower edge")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("strain amplitude A (–)")
    ax.set_ylabel("G′, G″ (Pa)")
    ax.set_title(f"{title}\n{_seeds_text(s.n_seeds)}, {int(s.n_seeds.sum())} runs", fontsize="small")
    ax.grid(True, which="both", color="0.92", lw=0.5)
    if said:   # below the axis label, outside the data (constrained layout makes room for it)
        import textwrap
        ax.set_xlabel(ax.get_xlabel() + "\n" + "\n".join(textwrap.fill("note: " + n, 70) for n in said),
                      fontsize="small")
    return said, labels


def not_drawn_line(titles, limit=200):
    """One line naming the groups a figure leaves out, at most about ``limit`` characters of names.

    Parameters
    ----------
    titles : sequence of str
        The groups not drawn.
    limit : int, optional
        Characters of names shown; the rest are counted (default 200).

    Returns
    -------
    str
    """
    shown, size = [], 0
    for t in titles:
        if shown and size + len(t) > limit:
            break
        shown.append(t if len(t) <= limit else t[:limit - 1] + "…")
        size += len(t) + 2
    rest = len(titles) - len(shown)
    return "; ".join(shown) + (f"; … and {rest} more" if rest else "")


def plot_analysis(panels, estimator="surface", path=None, max_panels=MAX_FIGURE_PANELS, made=None):
    """One panel per group: mean G′, G″ with bootstrap bands and the characteristic points.

    At most ``max_panels`` panels are drawn (the first groups); a line at the foot of the figure
    names the others (:func:`not_drawn_line`).

    Parameters
    ----------
    panels : sequence of tuple
        ``(title, summary, notes)`` or ``(title, summary, notes, flagged)`` per group: a text, a
        :class:`~particleShear.analysis.sweep.SweepSummary` (None for a group that could not be
        summarised: the panel says so), a list of notes to print in the panel and the amplitudes
        at which a run has a flagged verdict (ringed, with a legend entry; default none).
    estimator : {"surface", "internal"}, optional
        Named in the figure's title (default "surface").
    path : str or os.PathLike, optional
        Also write the figure there (.png, .pdf, .svg or .eps), atomically.
    max_panels : int, optional
        Most panels drawn, 1 ... :data:`MAX_FIGURE_PANELS` (default).
    made : dict, optional
        ``N`` and ``relative_frequency`` where one value holds for every run: named in the title
        with the seeds and the estimator (:func:`particleShear.plot.made_by`).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        For no panels, or ``max_panels`` out of range.
    ImportError
        Without matplotlib (names the ``[plot]`` extra).
    """
    panels = list(panels)
    if not panels:
        raise ValueError("panels=[] is invalid: allowed at least one (title, summary, notes)")
    if isinstance(max_panels, bool) or not isinstance(max_panels, int) or not 1 <= max_panels <= MAX_FIGURE_PANELS:
        raise ValueError(f"max_panels={max_panels!r} is out of range: allowed an integer >= 1 and <= "
                         f"{MAX_FIGURE_PANELS}")
    panels = [tuple(p) + ((),) * (4 - len(p)) for p in panels]     # (title, summary, notes, flagged)
    left_out = [p[0] for p in panels[max_panels:]]
    panels = panels[:max_panels]
    n = len(panels)
    ncols = min(n, 3)
    nrows = math.ceil(n / ncols)
    legend_cols = max(1, min(3, ncols + 1))          # the shared legend must fit the figure's width
    fig = _figure(max(4.6 * ncols, 3.3 * legend_cols), 3.9 * nrows + 0.4 * math.ceil(12 / legend_cols) + 0.6)
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    handles = {}
    confidence = None
    to_label, seeds = [], []
    for ax, (title, summary, notes, flagged) in zip(axes, panels):
        if summary is None:
            ax.text(0.5, 0.5, "not summarised:\n" + "\n".join(notes), ha="center", va="center",
                    transform=ax.transAxes, fontsize="small", color="C3")
            ax.set_title(title, fontsize="small")
            ax.set_axis_off()
            continue
        confidence = summary.confidence
        seeds += [int(n) for n in np.ravel(summary.n_seeds)]
        _, labels = _panel(ax, title, summary, notes, flagged)
        to_label.append((ax, labels))
        for h, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, h)
    for ax in axes[n:]:
        ax.set_axis_off()
    what = f"{confidence:.0%} bootstrap intervals over seeds" if confidence is not None else "no summary"
    made = made or {}
    rate = f"f·τ = {made['relative_frequency']:g}" if "relative_frequency" in made else None
    line = made_by(N=int(made["N"]) if "N" in made else None, seeds=(min(seeds), max(seeds)) if seeds else None,
                   estimator=estimator, rate=rate)
    fit_title(fig, f"Mean G′, G″ against the strain amplitude: {line}; {what}")
    if left_out:
        import textwrap
        line = (f"{len(left_out)} more group(s) not drawn (the first {n} are; every group is a row of "
                f"analysis.csv): {not_drawn_line(left_out)}")
        fig.supxlabel("\n".join(textwrap.wrap(line, 160)), fontsize="x-small", color="0.3")
    if handles:
        try:
            fig.legend(list(handles.values()), list(handles), loc="outside lower center", ncol=legend_cols,
                       fontsize="x-small", frameon=False)
        except (ValueError, TypeError):   # matplotlib < 3.7: no "outside" locations
            fig.legend(list(handles.values()), list(handles), loc="lower center", ncol=legend_cols, fontsize="x-small",
                       frameon=False, bbox_to_anchor=(0.5, 0.0))
    fig.canvas.draw()        # the layout first: the labels are placed in the panels' final frames
    for ax, labels in to_label:
        place_labels(ax, labels)
    if path is not None:
        save_figure(fig, path)
    return fig
