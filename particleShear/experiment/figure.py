"""One figure for measured and simulated tests: G′/G″ against amplitude or frequency, flow curve, G(t), J(t).

:func:`plot_comparison` draws measured and simulated :class:`~particleShear.experiment.tables.MeasuredTest`
on the same axes, one panel per kind present: G′ (filled) and G″ (open) against the strain amplitude
(amplitude sweeps) or the angular frequency (frequency sweeps), the stress against the shear rate
(flow curves), G(t) (relaxation) and J(t) (creep).  The replicates of one series (tests of one
``meta["label"]``) are pooled: an amplitude sweep shows the mean and the bootstrap interval of
:func:`particleShear.analysis.sweep.sweep_summary`; the other kinds the mean over the replicates at
each x with the min–max band where they share their x values.  The simulated moduli are multiplied by
``scale`` (the modulus scale: G ∝ E, the title says which E it stands for).  Needs matplotlib (the
``[plot]`` extra).
"""
__docformat__ = "numpy"
import math

import numpy as np

from .tables import Calibration, MeasuredTest
from ..analysis.sweep import sweep_summary
from ..plot_tools import _figure, _has_matplotlib, check_figure_path, fit_title, save_figure

__all__ = ["plot_comparison", "plot_calibration"]

_PANELS = {  # kind → (x column, y columns, x label, y label)
    "amplitude_sweep": ("strain_amplitude", ("Gp", "Gpp"), "strain amplitude γ₀ (–)", "G′, G″ (Pa)"),
    "frequency_sweep": ("angular_frequency", ("Gp", "Gpp"), "angular frequency ω (rad/s)", "G′, G″ (Pa)"),
    "flow_curve": ("shear_rate", ("stress",), "shear rate γ̇ (1/s)", "shear stress σ (Pa)"),
    "relaxation": ("time", ("G",), "time t (s)", "G(t) (Pa)"),
    "creep": ("time", ("compliance",), "time t (s)", "J(t) (1/Pa)"),
}
_SCALED = ("Gp", "Gpp", "stress", "G")


def _need_matplotlib():
    if not _has_matplotlib():
        raise ImportError('particleShear.experiment.figure needs matplotlib: pip install "particleShear[plot]"')


def _series(tests):
    """label → list of tests (the replicates of one series), in first-seen order."""
    out = {}
    for t in tests:
        out.setdefault(str(t.meta.get("label") or t.meta.get("name") or t.meta.get("source") or t.origin), []).append(t)
    return out


def _column(t, name):
    if name == "compliance" and "compliance" not in t:
        return t["strain"] / float(t.meta.get("stress", math.nan))
    return t[name]


def _mean_band(tests, x, y, factor):
    """(x, mean, low, high) over the replicates at each x (a band only where every replicate has that x)."""
    xs = np.concatenate([_column(t, x) for t in tests])
    ys = np.concatenate([_column(t, y) * factor for t in tests])
    keep = np.isfinite(xs) & np.isfinite(ys)
    xs, ys = xs[keep], ys[keep]
    u = np.unique(xs)
    mean = np.array([ys[xs == v].mean() for v in u])
    lo = np.array([ys[xs == v].min() for v in u])
    hi = np.array([ys[xs == v].max() for v in u])
    return u, mean, lo, hi


def plot_comparison(measured=(), simulated=(), scale=1.0, path=None, title=None, scale_text=None, n_boot=1000,
                    seed=0):
    """Measured and simulated tests on the same axes (module docstring).

    Parameters
    ----------
    measured, simulated : sequence of MeasuredTest
        The tests; those of one ``meta["label"]`` are replicates of one series.
    scale : float, optional
        Factor on the simulated moduli and stresses (Pa) — the modulus scale (default 1); J(t) is
        divided by it.
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps), atomically.
    title : str, optional
        What made the figure (default: the number of measured and simulated series).
    scale_text : str, optional
        How the scale was chosen, shown in the title (default ``"simulated moduli × scale"``).
    n_boot : int, optional
        Bootstrap replicates of the amplitude-sweep intervals (default 1000).
    seed : int, optional
        Their seed (default 0).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No test, a test that is not a MeasuredTest, a kind without a panel (LAOS waveform), a scale
        that is not finite and > 0, a bad path — before anything is drawn.
    ImportError
        Without matplotlib (naming the ``[plot]`` extra).
    """
    tests = list(measured) + list(simulated)
    if not tests:
        raise ValueError("measured=() and simulated=() are invalid: allowed at least one MeasuredTest")
    for t in tests:
        if not isinstance(t, MeasuredTest):
            raise ValueError(f"test={type(t).__name__} is invalid: allowed particleShear.experiment.MeasuredTest")
        if t.kind not in _PANELS:
            raise ValueError(f"test kind={t.kind!r} is invalid: allowed one of {sorted(_PANELS)}")
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise ValueError(f"scale={scale!r} is invalid: allowed a finite number > 0")
    if path is not None:
        check_figure_path(path)
    _need_matplotlib()
    kinds = [k for k in _PANELS if any(t.kind == k for t in tests)]
    fig = _figure(max(6.5, 4.6 * len(kinds)), 4.4)
    axes = fig.subplots(1, len(kinds), squeeze=False)[0]
    colours = {}
    palette = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7", "C8", "C9"]
    for ax, kind in zip(axes, kinds):
        x, ys, xl, yl = _PANELS[kind]
        for origin, group in (("measured", measured), ("simulated", simulated)):
            for label, reps in _series([t for t in group if t.kind == kind]).items():
                c = colours.setdefault((origin, label), palette[len(colours) % len(palette)])
                factor = scale if origin == "simulated" else 1.0
                name = f"{origin}: {label}" + (f" ({len(reps)} replicates)" if len(reps) > 1 else "")
                for y, marker in zip(ys, ("o", "s")):
                    f = (1.0 / factor if y == "compliance" else factor)
                    open_ = y == "Gpp"
                    kw = dict(color=c, marker=marker if origin == "measured" else "^",
                              mfc="none" if open_ else c, ls="-" if origin == "simulated" else "none", ms=5)
                    if kind == "amplitude_sweep":
                        u, mean, lo, hi = _sweep_band(reps, y, f, n_boot, seed)
                    else:
                        u, mean, lo, hi = _mean_band(reps, x, y, f)
                    sym = {"Gp": "G′", "Gpp": "G″"}.get(y, "")
                    ax.plot(u, mean, label=f"{sym} {name}".strip(), **kw)
                    if len(reps) > 1:
                        ax.fill_between(u, lo, hi, color=c, alpha=0.15, lw=0)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.legend(fontsize="x-small")
    stated = scale_text or f"simulated moduli × {scale:.4g}"
    head = title or f"{len(_series(measured))} measured, {len(_series(simulated))} simulated series"
    fit_title(fig, f"{head}\n{stated}; bands: bootstrap interval (amplitude sweeps) or replicate range")
    fig.set_label("experiment_comparison")
    if path is not None:
        save_figure(fig, path)
    return fig


def _sweep_band(reps, y, factor, n_boot, seed):
    """Mean and sweep_summary interval of G′ or G″ of replicate amplitude sweeps (pooled per amplitude)."""
    import warnings

    A = np.concatenate([t["strain_amplitude"] for t in reps])
    gp = np.concatenate([t["Gp"] * factor for t in reps])
    gpp = np.concatenate([t["Gpp"] * factor for t in reps])
    keep = np.isfinite(A) & np.isfinite(gp) & np.isfinite(gpp) & (A > 0)
    if len(np.unique(A[keep])) < 2 or len(reps) < 2:
        u = np.unique(A[keep])
        v = gp if y == "Gp" else gpp
        mean = np.array([v[keep][A[keep] == a].mean() for a in u])
        return u, mean, mean, mean
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        s = sweep_summary(A[keep], gp[keep], gpp[keep], n_boot=n_boot, rng=np.random.default_rng(seed))
    ci = s.Gp_ci if y == "Gp" else s.Gpp_ci
    return s.amplitudes, (s.Gp_mean if y == "Gp" else s.Gpp_mean), ci[:, 0], ci[:, 1]


def plot_calibration(calibration, path=None, top=1):
    """The overlay of a calibration: the measured sweep and the best grid point(s), scaled.

    Parameters
    ----------
    calibration : particleShear.experiment.calibration.Calibration
    path : str or os.PathLike, optional
        Write the figure there.
    top : int, optional
        How many of the best grid points to draw (default 1), each scaled by its own scale.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(calibration, Calibration):
        raise ValueError(f"calibration={type(calibration).__name__} is invalid: allowed a Calibration")
    if isinstance(top, bool) or not isinstance(top, int) or top < 1:
        raise ValueError(f"top={top!r} is invalid: allowed an integer >= 1")
    best = calibration.rows[:top]
    sim = []
    for r in best:
        c = calibration.simulated[r["label"]]
        sim.append(MeasuredTest("amplitude_sweep", {"strain_amplitude": c["A"], "Gp": c["Gp"] * r["scale"] /
                                                    best[0]["scale"], "Gpp": c["Gpp"] * r["scale"] / best[0]["scale"]},
                                {"label": f"#{r['rank']} {r['label']} (mean over seeds)"}, "simulated"))
    r = best[0]
    scale_text = (f"simulated moduli × {r['scale']:.4g} [{r['scale_ci_low']:.3g}, {r['scale_ci_high']:.3g}]: "
                  f"E = {r['E_to_use']:.4g} Pa (simulated with {r['Young_modulus_spheres']:.4g} Pa)")
    head = (f"calibration: {len(calibration.rows)} grid points of {calibration.settings['sweep_dir']}, "
            f"{calibration.settings['estimator']} estimator, best {r['label']} (mismatch {r['mismatch']:.3g}, "
            f"p_best {r['p_best']:.2f})")
    return plot_comparison(calibration.measured["tests"], sim, scale=r["scale"], path=path, title=head,
                           scale_text=scale_text)
