"""Figures of runs and sweeps with matplotlib (optional extra ``[plot]``).

Install with ``pip install "particleShear[plot]"``.  Nothing here touches pyplot's global
state: every figure is a :class:`matplotlib.figure.Figure` drawn on an Agg canvas, so
plotting works headless (no display, no GUI backend) and in worker processes.

Functions
---------
plot_result
    Strain and both stress estimators against time, baseline and excitation periods marked,
    and the Lissajous loop (stress against strain) of one :class:`~particleShear.run.api.SimulationResult`.
    Also available as ``result.plot(path)``.
plot_sweep
    G′ and G″ (log axes) from a sweep folder's ``results.csv`` against the amplitude or frequency,
    one panel per material and per value of any other varying parameter, colour by μ, means over
    seeds with bootstrap intervals (amplitude) or standard errors (:mod:`particleShear.sweep_plot`).
cli_main
    ``python -m particleShear plot DIR [--estimator internal] [--x NAME] [--no-split]``.

The estimators are defined in ``docs/output.md``: "surface" = shear stress from the forces on
the plate bands (the value :func:`doParticleShearSimulation` returns), "internal" = xy component
of the overall stress tensor (eq. S1-24).
"""
__docformat__ = "numpy"
import logging
import math
import os
import sys
import warnings

import numpy as np

from .messages import console_messages
from .run.guard import SuggestingParser, command_line_names
from .analysis.grouping import MODULI_PROTOCOLS, row_protocol
from .analysis.laos import laos
from .analysis.measures import measured_window
from .plot_tools import (ESTIMATORS, FLAGGED_LABEL, _figure, _has_matplotlib, align_zeros,  # noqa: F401 - re-exported
                         check_figure_path, dodge_factors, fit_title, is_flagged, made_by, ok_moduli, place_labels,
                         read_sweep_table, save_figure)
from .rheometer_plot import plot_flow_curve_sweep
from .sweep_plot import draw_sweep, sweep_panels

__all__ = ["plot_result", "plot_sweep", "read_sweep_table", "ok_moduli", "cli_main", "save_figure",
           "check_figure_path", "align_zeros", "fit_title", "dodge_factors", "place_labels", "is_flagged",
           "FLAGGED_LABEL", "made_by"]

def plot_result(result, path=None):
    """Trace, Lissajous loop and Lissajous–Bowditch curves of one run.

    Top left: strain γ (right axis, dimensionless) and the shear stresses τ_surface and τ_internal
    (Pa) against time in excitation periods t·f (the excitation starts at t·f = ``pre_periods``);
    the zeros of the two y axes are at the same height (:func:`align_zeros`); the baseline
    periods before and after the excitation are shaded grey and the excitation window is bounded
    by dotted lines.  Top right: the Lissajous loop
    τ(γ) of both estimators during the excitation (an elastic solid gives a line of slope G′,
    a viscous response opens it into an ellipse of area π·G″·A²).  Bottom: the elastic
    (σ′ against γ) and viscous (σ″ against γ̇) Lissajous–Bowditch curves of the measured periods
    (:meth:`SimulationResult.laos`, docs/analysis.md) over the measured stress, and their LAOS
    ratios; a straight σ′(γ) is a linear elastic response, an upturn at large |γ| strain
    stiffening (S > 0).

    Parameters
    ----------
    result : SimulationResult
        The outcome of ``doParticleShearSimulation(..., return_result=True)``; needs
        ``result.series`` (t, strain, stress_surface, stress_internal), ``result.f`` (Hz) and
        the parameters ``pre_periods`` and ``periods``.
    path : str or os.PathLike, optional
        Write the figure there too (PNG, PDF, SVG or EPS by extension).

    Returns
    -------
    matplotlib.figure.Figure
        Axes in order: trace, Lissajous loop, the trace's strain axis, elastic and viscous
        Lissajous–Bowditch curves.
    """
    s = result.series
    for key in ("t", "strain", "stress_surface", "stress_internal"):
        if key not in s:
            raise ValueError(f"result.series has no {key!r}: plot needs a recorded run")
    t = np.asarray(s["t"])
    strain = np.asarray(s["strain"])
    tau_s = np.asarray(s["stress_surface"])
    tau_i = np.asarray(s["stress_internal"])
    f = float(result.f)
    pre = float(result.parameters.get("pre_periods", 0))
    P = float(result.parameters.get("periods", 0))
    t_on, t_off = pre / f, (pre + P) / f
    periods = t * f                        # time in excitation periods

    fig = _figure(12, 7.5)
    grid = fig.add_gridspec(2, 3)
    ax = fig.add_subplot(grid[0, :2])
    lj = fig.add_subplot(grid[0, 2])
    ax.axvspan(periods[0] if len(t) else 0, pre, color="0.92", label="baseline")
    ax.axvspan(pre + P, periods[-1] if len(t) else pre + P, color="0.92")
    ax.axvline(pre, color="0.4", ls=":", lw=1)
    ax.axvline(pre + P, color="0.4", ls=":", lw=1)
    ax.plot(periods, tau_s, color="C0", lw=1, label="surface (plate forces)")
    ax.plot(periods, tau_i, color="C1", lw=1, label="internal (stress tensor)")
    ax.set_xlabel("time t·f (periods)")
    ax.set_ylabel("shear stress τ (Pa)")
    ax2 = ax.twinx()
    ax2.plot(periods, strain, color="k", lw=1, ls="--", label="strain γ")
    ax2.set_ylabel("strain γ (–)")
    align_zeros(ax, ax2)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper left", fontsize="small", framealpha=0.85)
    A = result.parameters.get("theAmplitude", "?")
    mu = result.parameters.get("theMu", "?")
    ax.set_title(f"A = {A}, μ = {mu}, f = {f:.3g} Hz: excitation between the dotted lines", fontsize="medium")

    on = (t >= t_on) & (t <= t_off)
    lj.plot(strain[on], tau_s[on], color="C0", lw=1,
            label=f"surface: G′={result.G_surface[0]:.3g} Pa, G″={result.G_surface[1]:.3g} Pa")
    lj.plot(strain[on], tau_i[on], color="C1", lw=1,
            label=f"internal: G′={result.G_internal[0]:.3g} Pa, G″={result.G_internal[1]:.3g} Pa")
    lj.set_xlabel("strain γ (–)")
    lj.set_ylabel("shear stress τ (Pa)")
    lj.set_title("Lissajous loop (excitation)", fontsize="medium")
    lj.legend(loc="upper left", fontsize="x-small", framealpha=0.85)
    _lissajous_bowditch(result, fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1]),
                        fig.add_subplot(grid[1, 2]))
    p = result.parameters
    N = p.get("N")
    seed = result.seed
    rate = f"f·τ = {float(p['relative_frequency']):g}" if "relative_frequency" in p else None
    line = made_by(N=int(N) if N is not None else None, seeds=1, rate=rate,
                   amplitude=float(A) if isinstance(A, (int, float)) else None)
    fit_title(fig, f"One oscillatory run: {line}{'' if seed is None else f' (seed {seed})'}; "
                   "surface (plate forces) and internal (stress tensor) estimators")
    if path is not None:
        save_figure(fig, path)
    return fig


def _lissajous_bowditch(result, elastic, viscous, text):
    """Elastic σ′(γ) and viscous σ″(γ̇) curves of both estimators, and a table of their LAOS ratios."""
    s = result.series
    try:
        w = measured_window(s["t"], result.f, result.parameters.get("pre_periods", 0),
                            result.parameters.get("periods", 0))
    except ValueError as exc:
        text.axis("off")
        import textwrap
        text.text(0.0, 1.0, "\n".join(textwrap.wrap(f"no LAOS measures: {exc}", 48)), va="top", ha="left",
                  fontsize="small", transform=text.transAxes)
        return
    rate = np.asarray(s.get("strain_rate", np.zeros(len(s["t"]))))
    lines = ["LAOS of the measured periods", "(± standard error over the periods)", ""]
    spread = _laos_period_spread(result, w)
    signs = {}
    for est, color in (("surface", "C0"), ("internal", "C1")):
        key = "stress_" + est
        try:
            m = result.laos(est)
        except (ValueError, KeyError) as exc:
            import textwrap
            lines += textwrap.wrap(f"{est}: no LAOS measures: {exc}", 48) + [""]
            continue
        c = m.lissajous(400)
        stress = np.asarray(s[key])[w]
        elastic.plot(np.asarray(s["strain"])[w], stress, color=color, lw=0.5, alpha=0.35)
        elastic.plot(c["strain"], c["elastic_stress"], color=color, lw=1.8, label=f"σ′ {est}")
        if np.any(rate[w]):
            viscous.plot(rate[w], stress, color=color, lw=0.5, alpha=0.35)
        viscous.plot(c["strain_rate"], c["viscous_stress"], color=color, lw=1.8, label=f"σ″ {est}")
        se = spread.get(est, {})
        signs[est] = (np.sign(m.S), np.sign(m.T))
        lines += [f"{est}:", f"  G_M = {m.G_M:.4g} Pa,  G_L = {m.G_L:.4g} Pa",
                  f"  S = {_with_error(m.S, se.get('S'))}",
                  f"  η_M = {m.eta_M:.4g} Pa·s,  η_L = {m.eta_L:.4g} Pa·s",
                  f"  T = {_with_error(m.T, se.get('T'))}",
                  f"  I₃/I₁ = {_with_error(m.I3_I1, se.get('I3_I1'))}", ""]
    if len(signs) == 2:
        differ = [name for k, name in enumerate(("S", "T")) if signs["surface"][k] * signs["internal"][k] < 0]
        if differ:
            lines += [f"{' and '.join(differ)}: surface and internal", "  differ in sign: not resolved", ""]
    elastic.set_xlabel("strain γ (–)")
    elastic.set_ylabel("elastic stress σ′ (Pa)")
    elastic.set_title("elastic Lissajous–Bowditch (thin: measured τ)", fontsize="medium")
    viscous.set_xlabel("strain rate γ̇ (1/s)")
    viscous.set_ylabel("viscous stress σ″ (Pa)")
    viscous.set_title("viscous Lissajous–Bowditch", fontsize="medium")
    for a in (elastic, viscous):
        if a.get_legend_handles_labels()[0]:
            a.legend(loc="upper left", fontsize="x-small", framealpha=0.85)
    text.axis("off")
    text.text(0.0, 1.0, "\n".join(lines), va="top", ha="left", fontsize="x-small", family="monospace",
              transform=text.transAxes)


def _with_error(v, se):
    """``v ± se``, the error to 2 significant figures (at most 4 decimals) and the value to the same
    decimal; ``v`` to 2 figures, with "(no error: < 2 periods)" when ``se`` is None."""
    if se is None or not math.isfinite(se) or se <= 0:
        return f"{v:.2g} (no error: < 2 periods)" if se is None else f"{v:.2g}"
    digits = min(4, max(0, 1 - int(math.floor(math.log10(se)))))
    return f"{v:.{digits}f} ± {se:.{digits}f}"


def _laos_period_spread(result, window):
    """Standard errors of S, T and I₃/I₁ over the measured periods, per estimator (empty: < 2 periods).

    Each whole measured period gets its own LAOS measures (:func:`particleShear.analysis.laos.laos`,
    5 harmonics, as :meth:`SimulationResult.laos`); the error is their standard deviation over √n.
    """
    s = result.series
    t, strain = np.asarray(s["t"]), np.asarray(s["strain"])
    f = float(result.f)
    pre = float(result.parameters.get("pre_periods", 0))
    k = np.floor(t * f - pre + 1e-9).astype(int)
    ids = [j for j in np.unique(k[window]) if np.sum(window & (k == j)) >= 8]
    out = {}
    if len(ids) < 2:
        return out
    for est in ("surface", "internal"):
        values = {"S": [], "T": [], "I3_I1": []}
        for j in ids:
            idx = np.flatnonzero(window & (k == j))
            sel = np.arange(idx[0], min(idx[-1] + 2, len(t)))   # and the next period's first sample: one whole period
            try:
                m = laos(t[sel], strain[sel], np.asarray(s["stress_" + est])[sel], f, n_max=5)
            except (ValueError, KeyError):
                continue
            for name in values:
                values[name].append(float(getattr(m, name)))
        out[est] = {name: float(np.std(v, ddof=1) / math.sqrt(len(v))) for name, v in values.items() if len(v) >= 2}
    return out


def plot_sweep(folder_or_csv, estimator="surface", path=None, *, x=None, split=True, n_boot=2000, confidence=0.95,
               bootstrap_seed=0, max_panels=12):
    """G′ and G″ of a sweep against the parameter it varies; nothing but seeds pooled.

    Reads ``DIR/results.csv``; only ``status == "ok"`` rows with finite moduli count.  The x-axis is
    the strain amplitude ``theAmplitude`` or the frequency ``relative_frequency`` — whichever varies
    (the amplitude if both do), or ``x``.  One panel per material (crosslinked / uncrosslinked /
    bulk control, :func:`group_of`) and per value of every other parameter that varies (named in
    the panel titles; with ``split=False`` such a parameter is refused instead), one colour per μ,
    the legend beside the panels.  Each point is the mean over the seeds of one parameter set with
    the 95 % bootstrap interval of :func:`particleShear.analysis.sweep.sweep_summary` (amplitude
    x-axis) or ± one standard error (otherwise); the legend says which.  The number of seeds per
    point is in the panel titles (or beside the points); fewer than 3 warn.  A mean ≤ 0 cannot be
    drawn on the log axis: it is marked at the panel's lower edge, listed in a note and warned about.
    Details: :mod:`particleShear.sweep_plot`.  A step of a one-packing sweep is a point at its own
    amplitude or frequency, and the protocol splits panels
    (:func:`particleShear.analysis.grouping.measured_row`).  A steady-shear sweep (every row of
    protocol "steady") gives its flow curve instead
    (:func:`particleShear.rheometer_plot.plot_flow_curve_sweep`, ``DIR/flow_curve.png``); a folder
    of relaxation or creep runs only is refused, naming ``analyse``, which summarises them.

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder or its ``results.csv``.
    estimator : {"surface", "internal"}
        Which moduli to plot (default the surface estimator, as ``doParticleShearSimulation`` returns).
    path : str, os.PathLike or None
        None (default): write ``DIR/G_vs_amplitude.png`` and ``.pdf`` (``G_vs_frequency`` for a
        frequency x-axis, ``G_vs_<x>`` for another) beside the CSV.  A path: write only that file
        (format by extension).  False: write nothing.
    x : str, optional
        The x-axis parameter column (``"amplitude"``, ``"frequency"`` or a column name such as
        ``"theAmplitude"``, ``"relative_frequency"``, ``"N"``; CLI ``--x``).  Default: chosen as above.
    split : bool, optional
        True (default): other varying parameters split the panels.  False: a ValueError names
        them (CLI ``--no-split``).
    n_boot : int, optional
        Bootstrap replicates of the intervals (amplitude x-axis), >= 1 (default 2000).
    confidence : float, optional
        Level of the bootstrap intervals, in (0, 1) (default 0.95).
    bootstrap_seed : int or None, optional
        Seed of the resampling, >= 0 (default 0, :data:`particleShear.analysis.sweep.DEFAULT_SEED`, as
        ``analyse``'s: the figure is reproducible); None: fresh entropy.
    max_panels : int, optional
        More panels than this are refused with a ValueError naming the parameters (default 12).

    Returns
    -------
    matplotlib.figure.Figure
        Labelled with its file stem; axes: one per panel, then the legend axes.  In each panel
        one errorbar container per modulus and μ, labelled ``"G′ μ=<μ>"`` and ``"G″ μ=<μ>"``.

    Raises
    ------
    ValueError
        Naming the parameter: an unknown ``estimator`` or ``x``, a varying parameter that can be
        neither the x-axis nor a panel, no usable rows, a setting out of range.

    Warns
    -----
    UserWarning
        Means ≤ 0 (marked, not drawn), fewer than 3 seeds at a point, ``ok`` rows left out.
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS} (CLI --estimator)")
    rows = read_sweep_table(folder_or_csv)
    for note in rows.notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    if rows and all(r.get("protocol") == "steady" for r in rows):   # a flow curve (docs/protocols.md)
        return plot_flow_curve_sweep(folder_or_csv, estimator, path, n_boot=n_boot, confidence=confidence,
                                     bootstrap_seed=bootstrap_seed)
    if rows and not any(row_protocol(r) in MODULI_PROTOCOLS for r in rows):
        found = sorted({row_protocol(r) for r in rows})
        raise ValueError(f"folder_or_csv={str(folder_or_csv)!r} holds runs of protocol(s) {found}, no G′ and G″ to "
                         "plot: particleShear analyse DIR summarises them (analysis_protocols.csv)")
    try:
        table = sweep_panels(rows, estimator, x=x, split=split, n_boot=n_boot, confidence=confidence,
                             bootstrap_seed=bootstrap_seed, max_panels=max_panels)
    except ValueError as exc:
        raise ValueError(f"folder_or_csv={str(folder_or_csv)!r}: {exc}") from None
    fig = draw_sweep(table)
    if path is None:
        src = str(folder_or_csv)
        folder = src if os.path.isdir(src) else os.path.dirname(os.path.abspath(src))
        for ext in (".png", ".pdf"):
            save_figure(fig, os.path.join(folder, fig.get_label() + ext))
    elif path is not False:
        save_figure(fig, path)
    return fig


# ---------------------------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------------------------
def build_parser():
    """Parser of ``python -m particleShear plot``.

    Returns
    -------
    particleShear.run.guard.SuggestingParser
        Positional ``DIR``, options ``--estimator {surface,internal}``, ``--output FILE``,
        ``--x NAME`` and ``--no-split``.
    """
    p = SuggestingParser(prog="particleShear plot",  # no prefix abbreviations; unknown flags get suggestions
                         description="Plot G' and G'' of a sweep folder against the parameter it varies "
                                     "(amplitude or frequency), one panel per material and per value of any "
                                     "other varying parameter (reads DIR/results.csv, writes "
                                     "DIR/G_vs_amplitude.png and .pdf, or G_vs_frequency.*).")
    p.add_argument("folder", metavar="DIR", help="sweep folder containing results.csv (or the CSV file)")
    p.add_argument("--estimator", choices=ESTIMATORS, default="surface",
                   help="moduli from the plate forces (surface, default) or the stress tensor (internal)")
    p.add_argument("--output", metavar="FILE", default=None,
                   help="write this file instead of DIR/G_vs_amplitude.png and .pdf")
    p.add_argument("--x", metavar="NAME", default=None,
                   help="x-axis parameter: amplitude (theAmplitude), frequency (relative_frequency) or another "
                        "numeric parameter column (default: the one of amplitude and frequency that varies)")
    p.add_argument("--no-split", dest="split", action="store_false",
                   help="refuse (exit 2) instead of splitting the panels by a parameter that varies besides the "
                        "x-axis, mu and the material")
    return p


#: plot_sweep's arguments whose command-line names differ (:func:`~particleShear.run.guard.command_line_names`)
_CLI_ALIASES = {"folder_or_csv": "folder", "path": "output"}


def cli_main(argv=None):
    """``python -m particleShear plot DIR [--estimator internal] [--output FILE] [--x NAME] [--no-split]``.

    The warnings of :func:`plot_sweep` (means ≤ 0, few seeds) are printed on stderr.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``plot`` (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 written, 1 matplotlib missing, 2 invalid input (message on stderr).
    """
    import warnings
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fig = plot_sweep(args.folder, estimator=args.estimator, path=args.output, x=args.x, split=args.split)
        for w in caught:
            print(f"particleShear plot: warning: {w.message}", file=sys.stderr)
    except ImportError as exc:
        print(f"particleShear plot: {exc}", file=sys.stderr)
        return 1
    except ValueError as exc:   # named as the user typed it: DIR, --x, --output
        print(f"particleShear plot: {command_line_names(exc, parser, _CLI_ALIASES)}", file=sys.stderr)
        return 2
    folder = args.folder if os.path.isdir(args.folder) else os.path.dirname(os.path.abspath(args.folder))
    written = [args.output] if args.output else [os.path.join(folder, fig.get_label() + e) for e in (".png", ".pdf")]
    with console_messages(stream=sys.stdout):
        for w in written:
            logging.getLogger(__name__).info("wrote %s", w)
    return 0
