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
    G′ and G″ against strain amplitude (log axes) from a sweep folder's ``results.csv``, one
    line per group (crosslinked / uncrosslinked / bulk control, per μ), mean ± standard error
    over seeds.
cli_main
    ``python -m particleShear plot DIR [--estimator internal]``.

The estimators are defined in ``docs/output.md``: "surface" = shear stress from the forces on
the plate bands (the value :func:`doParticleShearSimulation` returns), "internal" = xy component
of the overall stress tensor (eq. S1-24).
"""
__docformat__ = "numpy"
import csv
import logging
import math
import os
import sys

from .messages import console_messages
from .run.guard import SuggestingParser

__all__ = ["plot_result", "plot_sweep", "read_sweep_table", "ok_moduli", "sweep_groups", "cli_main", "save_figure",
           "check_figure_path"]

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
    from .run.validation import check_folder_writable
    _figure_format(name, path)
    check_folder_writable(f"{name} folder", os.path.dirname(os.path.abspath(str(path))))
    if not _has_matplotlib():
        raise ImportError(f"{name}={str(path)!r} needs matplotlib, which is not installed: "
                          "pip install 'particleShear[plot]'")


def save_figure(fig, path, dpi=150):
    """Write ``fig`` to ``path`` atomically; the format follows the extension (.png, .pdf, .svg, .eps).

    The figure is written to a temporary file in the same folder and renamed, so the file is
    complete or absent.

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
    fmt = _figure_format("path", path)
    folder = os.path.dirname(os.path.abspath(str(path)))
    tmp = os.path.join(folder, "." + os.path.basename(str(path)) + ".part")
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
def plot_result(result, path=None):
    """Trace, Lissajous loop and Lissajous–Bowditch curves of one run.

    Top left: strain γ (right axis, dimensionless) and the shear stresses τ_surface and τ_internal
    (Pa) against time t (s); the baseline periods before and after the excitation are shaded
    grey and the excitation window is bounded by dotted lines.  Top right: the Lissajous loop
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
    import numpy as np
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

    fig = _figure(12, 7.5)
    grid = fig.add_gridspec(2, 3)
    ax = fig.add_subplot(grid[0, :2])
    lj = fig.add_subplot(grid[0, 2])
    ax.axvspan(t[0] if len(t) else 0, t_on, color="0.92", label="baseline")
    ax.axvspan(t_off, t[-1] if len(t) else t_off, color="0.92")
    ax.axvline(t_on, color="0.4", ls=":", lw=1)
    ax.axvline(t_off, color="0.4", ls=":", lw=1)
    ax.plot(t, tau_s, color="C0", lw=1, label="τ surface (plate forces)")
    ax.plot(t, tau_i, color="C1", lw=1, label="τ internal (stress tensor)")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("shear stress τ (Pa)")
    ax2 = ax.twinx()
    ax2.plot(t, strain, color="k", lw=1, ls="--", label="strain γ")
    ax2.set_ylabel("strain γ (–)")
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
    if path is not None:
        save_figure(fig, path)
    return fig


def _lissajous_bowditch(result, elastic, viscous, text):
    """Elastic σ′(γ) and viscous σ″(γ̇) curves of both estimators, and a table of their LAOS ratios."""
    import numpy as np
    from .analysis.measures import measured_window
    s = result.series
    w = measured_window(s["t"], result.f, result.parameters.get("pre_periods", 0),
                        result.parameters.get("periods", 0))
    rate = np.asarray(s.get("strain_rate", np.zeros(len(s["t"]))))
    lines = ["LAOS of the measured periods", ""]
    for est, color in (("surface", "C0"), ("internal", "C1")):
        key = "stress_" + est
        try:
            m = result.laos(est)
        except ValueError as exc:
            lines.append(f"{est}: {exc}")
            continue
        c = m.lissajous(400)
        stress = np.asarray(s[key])[w]
        elastic.plot(np.asarray(s["strain"])[w], stress, color=color, lw=0.5, alpha=0.35)
        elastic.plot(c["strain"], c["elastic_stress"], color=color, lw=1.8, label=f"σ′ {est}")
        if np.any(rate[w]):
            viscous.plot(rate[w], stress, color=color, lw=0.5, alpha=0.35)
        viscous.plot(c["strain_rate"], c["viscous_stress"], color=color, lw=1.8, label=f"σ″ {est}")
        lines += [f"{est}:", f"  G_M = {m.G_M:.4g} Pa,  G_L = {m.G_L:.4g} Pa,  S = {m.S:.3g}",
                  f"  η_M = {m.eta_M:.4g} Pa·s,  η_L = {m.eta_L:.4g} Pa·s,  T = {m.T:.3g}",
                  f"  I₃/I₁ = {m.I3_I1:.3g},  Q = {m.Q:.3g}", ""]
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
    """Rows of a sweep's ``results.csv`` as dicts of strings (csv module; no pandas needed).

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder (its ``results.csv`` is read) or the CSV file itself.

    Returns
    -------
    list of dict
        One ``{column: text}`` dict per row, in file order.

    Raises
    ------
    ValueError
        If there is no such CSV file.
    """
    path = str(folder_or_csv)
    if os.path.isdir(path):
        path = os.path.join(path, "results.csv")
    if not os.path.isfile(path):
        raise ValueError(f"folder_or_csv={folder_or_csv!r} is invalid: no results.csv there")
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


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
    skipped : int
        Rows with status ``ok`` left out because the amplitude or a modulus is missing or not
        finite (rows of any other status are not counted).

    Raises
    ------
    ValueError
        If ``estimator`` is not "surface" or "internal".
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS}")
    kept, skipped = [], 0
    for row in rows:
        if str(row.get("status", "")).strip() != "ok":
            continue
        gp, gpp = _float(row.get("Gp_" + estimator)), _float(row.get("Gpp_" + estimator))
        A = _float(row.get("theAmplitude"))
        if not (math.isfinite(gp) and math.isfinite(gpp) and math.isfinite(A)):
            skipped += 1
            continue
        kept.append((row, A, gp, gpp))
    return kept, skipped


def sweep_groups(rows, estimator="surface"):
    """Mean and standard error over seeds of G′ and G″ per (group, μ) and amplitude.

    Only rows with ``status == "ok"`` and finite moduli count.  The standard error is
    ``s/√n`` with the sample standard deviation ``s`` (ddof = 1); 0 for a single seed.

    Parameters
    ----------
    rows : iterable of dict
        Rows of ``results.csv`` (as :func:`read_sweep_table` returns them).
    estimator : {"surface", "internal"}, optional
        Which moduli to average: ``Gp_surface``/``Gpp_surface`` (plate forces, default) or
        ``Gp_internal``/``Gpp_internal`` (overall stress tensor, eq. S1-24).

    Returns
    -------
    dict
        ``{(group, mu): {"A": [...], "Gp": [...], "Gp_err": [...], "Gpp": [...], "Gpp_err": [...],
        "n": [...]}}`` with amplitudes ascending; moduli in Pa.

    Raises
    ------
    ValueError
        If ``estimator`` is not "surface" or "internal".
    """
    cells = {}
    for row, A, gp, gpp in ok_moduli(rows, estimator)[0]:
        key = (group_of(row), _float(row.get("theMu", 0)))
        cells.setdefault(key, {}).setdefault(A, []).append((gp, gpp))
    out = {}
    for key in sorted(cells, key=lambda k: (k[0], k[1])):
        d = {"A": [], "Gp": [], "Gp_err": [], "Gpp": [], "Gpp_err": [], "n": []}
        for A in sorted(cells[key]):
            vals = cells[key][A]
            n = len(vals)
            d["A"].append(A)
            d["n"].append(n)
            for i, name in ((0, "Gp"), (1, "Gpp")):
                xs = [v[i] for v in vals]
                m = sum(xs) / n
                sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (n - 1)) if n > 1 else 0.0
                d[name].append(m)
                d[name + "_err"].append(sd / math.sqrt(n))
        out[key] = d
    return out


def plot_sweep(folder_or_csv, estimator="surface", path=None):
    """G′ and G″ against strain amplitude of a sweep, one line per group and μ.

    Reads ``DIR/results.csv`` (columns run_id, status, error, Gp_surface, Gpp_surface,
    Gp_internal, Gpp_internal, then the parameters: theAmplitude, theMu, do_permanent_links,
    cut_lines, ...).  Only ``status == "ok"`` rows are used; each point is the mean over seeds
    with an error bar of one standard error.  Both axes are logarithmic, so a non-positive mean
    (e.g. a negative G′ of a fluid-like group) is not shown; G′ is drawn with solid lines and filled
    circles, G″ with dashed lines and open squares, same colour per group.

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder or its ``results.csv``.
    estimator : {"surface", "internal"}
        Which moduli to plot (default the surface estimator, as ``doParticleShearSimulation`` returns).
    path : str, os.PathLike or None
        None (default): write ``DIR/G_vs_amplitude.png`` and ``DIR/G_vs_amplitude.pdf`` beside
        the CSV.  A path: write only that file (format by extension).  False: write nothing.

    Returns
    -------
    matplotlib.figure.Figure
        One Line2D per group for G′ (label "G′ <group>, μ=<μ>") and one for G″.
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of {ESTIMATORS} (CLI --estimator)")
    rows = read_sweep_table(folder_or_csv)
    groups = sweep_groups(rows, estimator)
    if not groups:
        raise ValueError(f"folder_or_csv={folder_or_csv!r} has no rows with status 'ok' and finite moduli")
    import numpy as np
    fig = _figure(6.4, 4.4)
    ax = fig.subplots()
    for k, ((group, mu), d) in enumerate(groups.items()):
        d = {key: np.asarray(v, dtype=float) for key, v in d.items()}
        colour = f"C{k % 10}"
        name = f"{group}, μ={mu:g}"
        ax.errorbar(d["A"], d["Gp"], yerr=d["Gp_err"], color=colour, marker="o", ls="-", capsize=3,
                    label="G′ " + name)
        ax.errorbar(d["A"], d["Gpp"], yerr=d["Gpp_err"], color=colour, marker="s", mfc="white", ls="--",
                    capsize=3, label="G″ " + name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    amplitudes = sorted({a for d in groups.values() for a in d["A"]})
    if len(amplitudes) <= 12:  # label the measured amplitudes themselves, no crowded minor labels
        from matplotlib.ticker import NullFormatter
        ax.set_xticks(amplitudes, [f"{a:g}" for a in amplitudes])
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("strain amplitude A (–)")
    ax.set_ylabel(f"G′, G″ (Pa), {estimator} estimator")
    n_seeds = sorted({n for d in groups.values() for n in d["n"]})
    ax.set_title(f"mean ± standard error over {n_seeds[0]}–{n_seeds[-1]} seeds" if len(n_seeds) > 1
                 else f"mean ± standard error over {n_seeds[0]} seed(s)", fontsize="medium")
    ax.grid(True, which="both", color="0.9", lw=0.6)
    ax.legend(fontsize="x-small", ncol=2 if len(groups) > 2 else 1)
    if path is None:
        src = str(folder_or_csv)
        folder = src if os.path.isdir(src) else os.path.dirname(os.path.abspath(src))
        for ext in (".png", ".pdf"):
            save_figure(fig, os.path.join(folder, "G_vs_amplitude" + ext))
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
        Positional ``DIR``, options ``--estimator {surface,internal}`` and ``--output FILE``.
    """
    p = SuggestingParser(prog="particleShear plot",  # no prefix abbreviations; unknown flags get suggestions
                         description="Plot G' and G'' against strain amplitude of a sweep folder "
                                     "(reads DIR/results.csv, writes DIR/G_vs_amplitude.png and .pdf).")
    p.add_argument("folder", metavar="DIR", help="sweep folder containing results.csv (or the CSV file)")
    p.add_argument("--estimator", choices=ESTIMATORS, default="surface",
                   help="moduli from the plate forces (surface, default) or the overall stress tensor (internal)")
    p.add_argument("--output", metavar="FILE", default=None,
                   help="write this file instead of DIR/G_vs_amplitude.png and .pdf")
    return p


def cli_main(argv=None):
    """``python -m particleShear plot DIR [--estimator internal] [--output FILE]``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``plot`` (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 written, 1 matplotlib missing, 2 invalid input (message on stderr).
    """
    args = build_parser().parse_args(argv)
    try:
        plot_sweep(args.folder, estimator=args.estimator, path=args.output)
    except ImportError as exc:
        print(f"particleShear plot: {exc}", file=sys.stderr)
        return 1
    except ValueError as exc:
        print(f"particleShear plot: {exc}", file=sys.stderr)
        return 2
    folder = args.folder if os.path.isdir(args.folder) else os.path.dirname(os.path.abspath(args.folder))
    written = [args.output] if args.output else [os.path.join(folder, "G_vs_amplitude" + e) for e in (".png", ".pdf")]
    with console_messages(stream=sys.stdout):
        for w in written:
            logging.getLogger(__name__).info("wrote %s", w)
    return 0
