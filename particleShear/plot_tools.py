"""Figure tools shared by the plot modules (optional extra ``[plot]``): the figure and its file, titles and labels,
and the rows of a sweep's ``results.csv`` that carry moduli.

:mod:`particleShear.plot` (runs, the sweep figure and its command line), :mod:`particleShear.sweep_plot`,
:mod:`particleShear.rheometer_plot`, :mod:`particleShear.analysis.figure` and
:mod:`particleShear.experiment.figure` draw with these; :mod:`particleShear.plot` re-exports the public ones.
Nothing here imports matplotlib before a figure is drawn.
"""
__docformat__ = "numpy"
import math
import os

import numpy as np

from .analysis.verdicts import is_flagged  # noqa: F401 - re-exported: the one rule of a flagged row
from .analysis.grouping import MODULI_PROTOCOLS, measured_row, row_protocol
from .run.validation import check_folder_writable
from .sweep.reader import read_table

__all__ = ["ESTIMATORS", "FIGURE_FORMATS", "FLAGGED_LABEL", "align_zeros", "check_figure_path", "dodge_factors",
           "fit_title", "group_of", "is_flagged", "made_by", "ok_moduli", "place_labels", "read_sweep_table",
           "save_figure"]

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
