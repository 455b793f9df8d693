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
from .analysis.verdicts import is_flagged  # noqa: F401 - re-exported: the one rule of a flagged row
from .run.guard import SuggestingParser, command_line_names
from .analysis.grouping import MODULI_PROTOCOLS, measured_row, row_protocol
from .analysis.laos import laos
from .analysis.measures import measured_window
from .run.validation import check_folder_writable
from .sweep.reader import read_table

__all__ = ["plot_result", "plot_sweep", "read_sweep_table", "ok_moduli", "cli_main", "save_figure",
           "check_figure_path", "align_zeros", "fit_title", "dodge_factors", "place_labels", "is_flagged",
           "FLAGGED_LABEL", "made_by"]

_INSTALL_HINT = 'particleShear.plot needs matplotlib: pip install "particleShear[plot]"'

#: file extensions a figure can be written as (matplotlib format names)
FIGURE_FORMATS = {".png": "png", ".pdf": "pdf", ".svg": "svg", ".eps": "eps"}

ESTIMATORS = ("surface", "internal")


def _figure(width, height):
    """A new Figure on an Agg canvas (no pyplot, headless-safe)."""
    try:
        from matplotlib.figure import Figure
        from matplotlib.backends.backend_agg import FigureCanvasAgg
    except ImportError as exc:  # pragma: no cover - exercised only without matplotlib
        raise ImportError(_INSTALL_HINT) from exc
    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


#: legend entry of the points drawn hollow because a run of theirs has a flagged verdict
#: (:func:`particleShear.analysis.verdicts.is_flagged`, re-exported here for the figures)
FLAGGED_LABEL = "flagged (see verdict)"


def made_by(N=None, seeds=None, estimator=None, rate=None, amplitude=None, stress=None):
    """The "what made it" line of a figure's title: N, seeds, estimator, rate, γ₀ or σ₀.

    Each argument is a value (written), a (low, high) pair (written as a range), or None (left
    out: it varies across the figure and is on an axis, a panel or the legend).

    Parameters
    ----------
    N : int or tuple, optional
        Spheres per run.
    seeds : int or tuple, optional
        Seeds (repetitions) per point.
    estimator : str, optional
        "surface" (plate forces) or "internal" (overall stress tensor).
    rate : str, optional
        The rate, already written with its name and unit (``"f·τ = 0.025"``, ``"γ̇·τ = 1e-3"``).
    amplitude : float or tuple, optional
        Strain amplitude or step strain γ₀ (–).
    stress : float, optional
        Imposed stress σ₀ (Pa).

    Returns
    -------
    str
    """
    def show(v, unit=""):
        if isinstance(v, tuple):
            lo, hi = v
            return f"{lo:g}{unit}" if lo == hi else f"{lo:g}–{hi:g}{unit}"
        return f"{v:g}{unit}"
    parts = []
    if N is not None:
        parts.append(f"N = {show(N)}")
    if seeds is not None:
        one = seeds == 1 or seeds == (1, 1)
        parts.append(f"{show(seeds)} seed{'' if one else 's'}{' per point' if isinstance(seeds, tuple) else ''}")
    if estimator is not None:
        parts.append(f"{estimator} estimator")
    if rate is not None:
        parts.append(rate)
    if amplitude is not None:
        parts.append(f"γ₀ = {show(amplitude)}")
    if stress is not None:
        parts.append(f"σ₀ = {show(stress, ' Pa')}")
    return ", ".join(parts)


def fit_title(fig, text, fontsize="medium", **kw):
    """Set ``text`` as the figure's title, wrapped so that every line fits the figure's width.

    The text is broken at ``"; "``, then ``", "``, then spaces, and each line's width is measured
    with the figure's renderer (not estimated from a character count), so no title is clipped
    however few panels the figure has.  With constrained layout the panels move down to make room.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    text : str
        The title (explicit newlines are kept).
    fontsize : str or float, optional
    **kw
        Passed to ``fig.suptitle``.

    Returns
    -------
    matplotlib.text.Text
    """
    renderer = fig.canvas.get_renderer()
    room = 0.96 * fig.bbox.width
    title = fig.suptitle("", fontsize=fontsize, **kw)

    def width(line):
        title.set_text(line)
        return title.get_window_extent(renderer).width

    lines = []
    for paragraph in str(text).split("\n"):
        current = ""
        tokens = [t for t in paragraph.replace("; ", ";\0").replace(", ", ",\0").replace(" ", " \0").split("\0")]
        for tok in tokens:
            trial = current + (" " if current and current.endswith((";", ",")) else "") + tok
            if current and width(trial.rstrip()) > room:
                lines.append(current.rstrip())
                current = tok
            else:
                current = trial
        lines.append(current.rstrip())
    title.set_text("\n".join(lines))
    return title


def dodge_factors(n, xs):
    """Multiplicative offsets that set ``n`` series at the same x side by side on a log x axis.

    Series k of n is drawn at ``x · factor[k]``: centred on the true x, a step of 6 % of the
    smallest gap between neighbouring x values (in log x; a 4 % step where there is one x), so
    that markers and error bars do not overlap and never cross into the next x value.

    Parameters
    ----------
    n : int
        Number of series.
    xs : array_like
        The x values (> 0) the series share.

    Returns
    -------
    numpy.ndarray
        ``n`` factors, 1 for a single series.
    """
    u = np.unique(np.log10(np.asarray(xs, dtype=float)))
    step = 0.06 * float(np.min(np.diff(u))) if len(u) > 1 else 0.04
    step = min(step, 0.9 / max(n, 1) * (float(np.min(np.diff(u))) if len(u) > 1 else 1.0))
    return 10.0 ** (step * (np.arange(n) - (n - 1) / 2))


def place_labels(ax, items, fontsize="x-small", gid="mark-label"):
    """Label points without overlap: each label at the first of 8 offsets whose box meets no other.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    items : sequence of tuple
        ``(text, x, y)`` in data coordinates, in order of priority (the first labels are placed first).
    fontsize : str or float, optional
    gid : str, optional
        The gid of the labels.

    Returns
    -------
    list of matplotlib.text.Annotation
        The labels, each at the first offset whose box meets no label placed before and lies in
        the panel; else at the first free one; else the first in the panel.  Call it after the
        figure's layout is done (``fig.canvas.draw()``): the labels are left out of the layout.
    """
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    offsets = [(5, 6), (5, -12), (-5, 6), (-5, -12), (10, 16), (10, -22), (-10, 16), (-10, -22), (0, 26),
               (0, -32), (16, 0), (-16, 0)]
    frame = ax.get_window_extent(renderer)
    placed, boxes = [], []
    for text, x, y in items:
        best = None
        for dx, dy in offsets:
            a = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=fontsize,
                            ha="left" if dx >= 0 else "right", zorder=6, gid=gid)
            a.set_in_layout(False)     # placed after the layout: it must not move the panels
            box = a.get_window_extent(renderer)
            inside = (box.x0 >= frame.x0 and box.x1 <= frame.x1 and box.y0 >= frame.y0 and box.y1 <= frame.y1)
            free = not any(box.overlaps(b) for b in boxes)
            score = 2 * free + inside
            if best is None or score > best[0]:
                if best is not None:
                    best[1].remove()
                best = (score, a, box)
            else:
                a.remove()
            if score == 3:
                break
        boxes.append(best[2])
        placed.append(best[1])
    return placed


def _figure_format(name, path):
    """The matplotlib format of ``path`` from its extension; ValueError naming ``name`` for any other."""
    ext = os.path.splitext(str(path))[1].lower()
    if ext not in FIGURE_FORMATS:
        raise ValueError(f"{name}={str(path)!r} is invalid: allowed extensions {sorted(FIGURE_FORMATS)}")
    return FIGURE_FORMATS[ext]


def _has_matplotlib():
    """Whether matplotlib can be imported here (found on the path; not imported)."""
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


def check_figure_path(path, name="path"):
    """Check, before any work, that a figure can be written to ``path``.

    The extension must be one of .png, .pdf, .svg, .eps, the folder of ``path`` must exist and
    be writable (probed with an empty temporary file), and matplotlib must be installed.

    Parameters
    ----------
    path : str or os.PathLike
        The figure file to be written.
    name : str, optional
        What the messages call ``path`` (a parameter name, or a flag such as ``"--plot"``).

    Raises
    ------
    ValueError
        An unsupported extension, or a folder that does not exist or is not writable.
    ImportError
        Without matplotlib (the message names ``name`` and the extra to install).
    """
    _figure_format(name, path)
    check_folder_writable(f"{name} folder", os.path.dirname(os.path.abspath(str(path))))
    if not _has_matplotlib():
        raise ImportError(f"{name}={str(path)!r} needs matplotlib, which is not installed: "
                          "pip install 'particleShear[plot]'")


def save_figure(fig, path, dpi=150):
    """Write ``fig`` to ``path`` atomically; the format follows the extension (.png, .pdf, .svg, .eps).

    The figure is written to a temporary file of a name unique to the call in the same folder
    and renamed, so the file is complete or absent (also when several processes write it at once).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure to write.
    path : str or os.PathLike
        Destination file; its extension (.png, .pdf, .svg or .eps) chooses the format.
    dpi : float, optional
        Resolution of raster output in dots per inch (default 150; PDF/SVG/EPS are vector).

    Returns
    -------
    str or os.PathLike
        ``path``, as given.

    Raises
    ------
    ValueError
        If the extension of ``path`` is none of .png, .pdf, .svg, .eps.
    """
    import secrets
    import socket
    fmt = _figure_format("path", path)
    folder = os.path.dirname(os.path.abspath(str(path)))
    # a name of its own per call (as sweep.table.atomic_text): two processes writing the same figure never
    # share a temporary
    tmp = os.path.join(folder, f".{os.path.basename(str(path))}.{socket.gethostname()}-{os.getpid()}-"
                               f"{secrets.token_hex(4)}.part")
    try:
        fig.savefig(tmp, format=fmt, dpi=dpi)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    return path


# ---------------------------------------------------------------------------------------------
# one run
# ---------------------------------------------------------------------------------------------
def align_zeros(ax, other):
    """Widen the y limits of two axes sharing an x axis so that y = 0 is at the same height on both.

    Each range is first extended to include 0; then the one whose zero lies lower is extended
    downwards or the other upwards (limits are only widened, never narrowed), so the fraction
    ``−lo / (hi − lo)`` is the same on both axes.

    Parameters
    ----------
    ax, other : matplotlib.axes.Axes
        The two axes (e.g. an axis and its ``twinx``).

    Returns
    -------
    float
        That common fraction of the height below 0.
    """
    limits = []
    for a in (ax, other):
        lo, hi = a.get_ylim()
        lo, hi = min(lo, 0.0), max(hi, 0.0)
        if hi == lo:
            lo, hi = -1.0, 1.0
        limits.append((lo, hi))
    fracs = [-lo / (hi - lo) for lo, hi in limits]
    target = min(max(max(fracs), 0.05), 0.95)   # a zero at the very edge would squash the other axis
    for a, (lo, hi), frac in zip((ax, other), limits, fracs):
        if frac < target:      # more room below 0
            lo = -hi * target / (1 - target)
        elif frac > target:    # more room above 0
            hi = -lo * (1 - target) / target
        a.set_ylim(lo, hi)
    return target


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
    seed = getattr(result, "seed", None)
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


# ---------------------------------------------------------------------------------------------
# sweeps
# ---------------------------------------------------------------------------------------------
def _truth(v):
    return str(v).strip().lower() in ("true", "1", "yes")


def _float(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def read_sweep_table(folder_or_csv):
    """Rows of a sweep's ``results.csv`` as mappings column → text (no pandas needed).

    Read by the package's one table reader (:func:`particleShear.sweep.reader.read_table`): lines
    that are not rows (a torn last line) and duplicate rows are left out (said in the result's
    ``notes``), a cell that is not a value of its column's type is refused.

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder (its ``results.csv`` is read) or the CSV file itself.

    Returns
    -------
    particleShear.sweep.reader.TableRows
        A sequence of one ``{column: text}`` mapping per row, in file order; ``.notes``: what was
        left out.

    Raises
    ------
    ValueError
        If there is no such CSV file, or it cannot be read (naming the file; a bad cell also its
        line and column).
    """
    path = str(folder_or_csv)
    if os.path.isdir(path):
        path = os.path.join(path, "results.csv")
    if not os.path.isfile(path):
        raise ValueError(f"folder_or_csv={folder_or_csv!r} is invalid: no results.csv there")
    return read_table(path).rows()


def group_of(row):
    """Group name of a result row: "crosslinked", "uncrosslinked" or "bulk control".

    crosslinked = ``do_permanent_links`` and ``cut_lines > 0``; uncrosslinked = not
    ``do_permanent_links``; bulk control = ``do_permanent_links`` and ``cut_lines == 0``.

    Parameters
    ----------
    row : dict
        A row of ``results.csv`` (values as text or numbers); a missing ``do_permanent_links``
        counts as True, a missing ``cut_lines`` as 0.

    Returns
    -------
    str
        The group name.
    """
    if not _truth(row.get("do_permanent_links", True)):
        return "uncrosslinked"
    return "crosslinked" if _float(row.get("cut_lines", 0)) > 0 else "bulk control"


def ok_moduli(rows, estimator="surface"):
    """The rows of a sweep that count: status ``ok`` and finite amplitude and moduli, with those numbers.

    Parameters
    ----------
    rows : iterable of dict
        Rows of ``results.csv`` (as :func:`read_sweep_table` returns them).
    estimator : {"surface", "internal"}, optional
        Which moduli: ``Gp_surface``/``Gpp_surface`` (plate forces, default) or
        ``Gp_internal``/``Gpp_internal`` (overall stress tensor, eq. S1-24).

    Returns
    -------
    kept : list of tuple
        ``(row, amplitude, G′, G″)`` for each row that counts, in input order (floats; Pa).
        ``row`` is the row as :func:`particleShear.analysis.grouping.measured_row` rewrites it:
        a step of a one-packing sweep carries its own amplitude (``sweep_amplitude``) or
        frequency (``sweep_relative_frequency``) in ``theAmplitude`` / ``relative_frequency``, an
        empty ``protocol`` cell reads as "oscillatory".
    skipped : int
        Rows with status ``ok`` left out because the amplitude or a modulus is missing or not
        finite (rows of any other status, and rows of the steady, relaxation and creep protocols,
        which hold no moduli, are not counted).

    Raises
    ------
    ValueError
        If ``estimator`` is not "surface" or "internal".
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS}")
    kept, skipped = [], 0
    for row in rows:
        if str(row.get("status", "")).strip() != "ok" or row_protocol(row) not in MODULI_PROTOCOLS:
            continue
        row = measured_row(row)
        gp, gpp = _float(row.get("Gp_" + estimator)), _float(row.get("Gpp_" + estimator))
        A = _float(row.get("theAmplitude"))
        if not (math.isfinite(gp) and math.isfinite(gpp) and math.isfinite(A)):
            skipped += 1
            continue
        kept.append((row, A, gp, gpp))
    return kept, skipped


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
    from .sweep_plot import draw_sweep, sweep_panels
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS} (CLI --estimator)")
    rows = read_sweep_table(folder_or_csv)
    for note in rows.notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    if rows and all(r.get("protocol") == "steady" for r in rows):   # a flow curve (docs/protocols.md)
        from .rheometer_plot import plot_flow_curve_sweep
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
