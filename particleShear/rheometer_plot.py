"""Figures of the virtual rheometer's protocols with matplotlib (optional extra ``[plot]``).

Install with ``pip install "particleShear[plot]"``.  Like :mod:`particleShear.plot`, every
figure is a :class:`matplotlib.figure.Figure` on an Agg canvas (no pyplot, headless-safe).
Every function checks its input (equal lengths, finite numbers) and, when ``path`` is given,
the figure path, before drawing; points that cannot be on a log axis (non-positive) are left
out and a text note on the figure says how many.

Functions
---------
plot_flow_curve
    Stress σ and viscosity η = σ/γ̇ against the shear rate γ̇ (log–log), optionally a fitted
    yield-stress curve (Herschel–Bulkley σ = σ_y + K γ̇^n).
plot_relaxation
    Relaxation modulus G(t) against time, optionally a plateau band.
plot_creep
    Creep compliance J(t) against time (log–log).
plot_amplitude_sweeps
    G′ and G″ against the strain amplitude, one packing swept amplitude after amplitude and
    independent packings (``x="relative_frequency"``: against f·τ, a frequency sweep).
plot_steady_run
    The stress of one steady-shear run against the strain, with its steady mean and the end of
    the transient.
plot_flow_curve_sweep
    The flow curve of a steady-shear sweep's table: seed means with standard errors and the
    Herschel–Bulkley fit with bootstrap intervals (``particleShear plot DIR`` of such a sweep).
plot_rheometer_result
    The figure of one protocol run's :class:`~particleShear.run.result.SimulationResult` (``result.plot()``
    and the command line's ``--plot``): one of the above, chosen by its protocol.
"""
__docformat__ = "numpy"
import numpy as np

from .plot_tools import _figure, check_figure_path, fit_title, made_by, save_figure
from .analysis.flow_curve import fit_flow_curve, flow_curve_table
from .analysis.sweep import _vector
from .sweep.schema import load_results

__all__ = ["plot_flow_curve", "plot_relaxation", "plot_creep", "plot_amplitude_sweeps", "plot_steady_run",
           "plot_rheometer_result", "plot_flow_curve_sweep"]


def _series(name, values, n=None):
    """``values`` as a 1-d finite float array (of length ``n`` if given); ValueError naming ``name``."""
    a = _vector(name, values)
    if n is not None and len(a) != n:
        raise ValueError(f"{name} is invalid: length {len(a)}, must equal the length {n} of the data")
    return a


def _note(ax, dropped, what):
    """Write on ``ax`` how many non-positive points were left out of a log axis."""
    if dropped:
        ax.text(0.02, 0.02, f"{dropped} non-positive point(s) of {what} dropped (log axes)",
                transform=ax.transAxes, ha="left", va="bottom", fontsize="small", gid="dropped-note")


def _finish(fig, path, title=None):
    if title:
        fit_title(fig, title)
    if path is not None:
        save_figure(fig, path)
    return fig


def plot_flow_curve(rate, stress, stress_err=None, fit=None, path=None, *, title=None):
    """Flow curve: σ (Pa) and η = σ/γ̇ (Pa·s) against γ̇ (1/s), both log–log.

    Parameters
    ----------
    rate : array_like
        Shear rates γ̇ in 1/s.
    stress : array_like
        Steady shear stresses σ in Pa, same length as ``rate``.
    stress_err : array_like, optional
        Standard errors of ``stress`` in Pa (error bars; η's error is stress_err/rate).
    fit : object, optional
        A fitted flow law with attributes ``sigma_y`` (Pa), ``K`` (Pa·s^n), ``n`` and a method
        ``stress(rate)``; drawn on a log-spaced grid over the data range on both panels, with
        σ_y as a dashed horizontal line on the σ panel.
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).
    title : str, optional
        Keyword-only.  The figure's title: what made it (N, seeds, estimator, rate, γ₀ or σ₀;
        :func:`particleShear.plot.made_by`), fitted to the figure's width.

    Returns
    -------
    matplotlib.figure.Figure
        Axes 0: σ against γ̇; axes 1: η against γ̇.

    Raises
    ------
    ValueError
        Unequal lengths, non-finite numbers, or a bad ``path``.
    """
    rate = _series("rate", rate)
    stress = _series("stress", stress, len(rate))
    err = None if stress_err is None else _series("stress_err", stress_err, len(rate))
    if path is not None:
        check_figure_path(path, "path")
    keep = (rate > 0) & (stress > 0)
    r, s = rate[keep], stress[keep]
    e = None if err is None else err[keep]
    fig = _figure(9.0, 4.0)
    ax_s, ax_e = fig.subplots(1, 2)
    ax_s.errorbar(r, s, yerr=e, fmt="o", label="data")
    ax_e.errorbar(r, s / r, yerr=None if e is None else e / r, fmt="o", label="data")
    if fit is not None and len(r):
        grid = np.logspace(np.log10(r.min()), np.log10(r.max()), 200)
        fs = np.asarray(fit.stress(grid), dtype=float)
        label = f"fit: σ_y={fit.sigma_y:.3g} Pa, K={fit.K:.3g} Pa·s^n, n={fit.n:.3g}"
        ax_s.plot(grid, fs, "-", label=label, gid="fit")
        ax_e.plot(grid, fs / grid, "-", label=label, gid="fit")
        if fit.sigma_y > 0:
            ax_s.axhline(fit.sigma_y, ls="--", color="grey", label="σ_y", gid="sigma_y")
    for ax in (ax_s, ax_e):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("shear rate γ̇ (1/s)")
        ax.legend(fontsize="small")
    ax_s.set_ylabel("stress σ (Pa)")
    ax_e.set_ylabel("viscosity η = σ/γ̇ (Pa·s)")
    _note(ax_s, int((~keep).sum()), "(γ̇, σ)")
    return _finish(fig, path, title)


def plot_relaxation(t, G, G_err=None, plateau=None, path=None, *, title=None, ramp=None):
    """Stress relaxation: G(t) (Pa) against t (s), log x; log y when all G > 0, else linear y.

    Parameters
    ----------
    t : array_like
        Times in s after the strain step; non-positive times are dropped (log x).
    G : array_like
        Relaxation modulus G(t) = (σ(t) − σ_res)/γ₀ in Pa, same length as ``t``.
    G_err : array_like, optional
        Error bars of ``G`` in Pa: for the curves of a run, the within-bin spread of
        :func:`~particleShear.analysis.rheometry.log_grid` about the bin's trend (std/√n of
        correlated samples: a spread, not an independent error; NaN, drawn without a bar, for a
        bin of fewer than 3 samples), said in the legend.
    plateau : tuple of float, optional
        (value, error) of the plateau modulus in Pa, drawn as a horizontal band.
    ramp : float, optional
        Keyword-only.  Duration of the strain ramp in s, drawn as a dotted vertical line: before
        about this time G(t) is the packing's release from the ramp, after it the stress waves
        of the stopped plates ring down (an oscillation of G about the plateau over a few tens of
        ramp times), then the plateau.
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).
    title : str, optional
        Keyword-only.  The figure's title: what made it (N, seeds, estimator, rate, γ₀ or σ₀;
        :func:`particleShear.plot.made_by`), fitted to the figure's width.

    Returns
    -------
    matplotlib.figure.Figure
        One axes.

    Raises
    ------
    ValueError
        Unequal lengths, non-finite numbers, a bad ``plateau``, or a bad ``path``.
    """
    t = _series("t", t)
    G = _series("G", G, len(t))
    err = None
    if G_err is not None:     # NaN: a bin without a spread (fewer than 3 samples), drawn without a bar
        err = np.asarray(G_err, dtype=float).reshape(-1)
        if len(err) != len(t) or np.any(np.isinf(err)) or np.any(err < 0):
            raise ValueError(f"G_err is invalid: allowed {len(t)} numbers >= 0 or NaN (no spread), one per time")
        err = np.nan_to_num(err, nan=0.0)
    if plateau is not None:
        plateau = _series("plateau", plateau, 2)
    if path is not None:
        check_figure_path(path, "path")
    keep = t > 0
    fig = _figure(6.0, 4.0)
    ax = fig.subplots()
    ax.errorbar(t[keep], G[keep], yerr=None if err is None else err[keep], fmt="o",
                label="G(t)" if err is None else "G(t): log-time bin means; bars: the samples' spread about\n"
                "the bin's trend (std/√n; none for fewer than 3 samples)")
    if plateau is not None:
        v, e = plateau
        ax.axhspan(v - e, v + e, alpha=0.3, color="grey", label=f"plateau {v:.3g} ± {e:.3g} Pa", gid="plateau")
    if ramp is not None and np.isfinite(ramp) and ramp > 0:
        ax.axvline(float(ramp), color="0.3", ls=":", lw=1, gid="ramp",
                   label=f"ramp duration {float(ramp):.3g} s: the release, then stress\nwaves ring down before the plateau")
    ax.set_xscale("log")
    if np.all(G[keep] > 0):
        ax.set_yscale("log")
    else:
        ax.text(0.98, 0.98, "linear G axis: some G ≤ 0", transform=ax.transAxes, ha="right", va="top",
                fontsize="small", gid="linear-note")
    ax.set_xlabel("time after the strain step t (s)")
    ax.set_ylabel("relaxation modulus G(t) (Pa)")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(0.0, -0.16), frameon=False)   # below: off the data
    _note(ax, int((~keep).sum()), "t")
    return _finish(fig, path, title)


def plot_creep(t, J, path=None, *, title=None):
    """Creep: compliance J(t) = γ(t)/σ₀ (1/Pa) against t (s), log–log on the positive points.

    Parameters
    ----------
    t : array_like
        Times in s after the stress step.
    J : array_like
        Creep compliance in 1/Pa, same length as ``t``.
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).
    title : str, optional
        Keyword-only.  The figure's title: what made it (N, seeds, estimator, rate, γ₀ or σ₀;
        :func:`particleShear.plot.made_by`), fitted to the figure's width.

    Returns
    -------
    matplotlib.figure.Figure
        One axes.

    Raises
    ------
    ValueError
        Unequal lengths, non-finite numbers, or a bad ``path``.
    """
    t = _series("t", t)
    J = _series("J", J, len(t))
    if path is not None:
        check_figure_path(path, "path")
    keep = (t > 0) & (J > 0)
    fig = _figure(6.0, 4.0)
    ax = fig.subplots()
    ax.plot(t[keep], J[keep], "o-", label="J(t)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("creep compliance J(t) (1/Pa)")
    _note(ax, int((~keep).sum()), "(t, J)")
    return _finish(fig, path, title)


#: legend names of the two series, by the swept quantity (the legend says what was swept)
_SWEEP_NAMES = {"amplitude": {"one_packing": "one packing (amplitude after amplitude)",
                              "independent": "independent packings"},
                "relative_frequency": {"one_packing": "one packing (frequency after frequency)",
                                       "independent": "independent packings"}}


def _sweep(name, data, x="amplitude"):
    """Validate one sweep mapping; returns dict of arrays (errors None when absent)."""
    try:
        keys = set(data)
    except TypeError as exc:
        raise ValueError(f"{name}={data!r} is invalid: must be a mapping with keys {x}, Gp, Gpp") from exc
    missing = {x, "Gp", "Gpp"} - keys
    if missing:
        raise ValueError(f"{name} is invalid: missing keys {sorted(missing)}")
    a = _series(f"{name}[{x!r}]", data[x])
    out = {"amplitude": a}
    for k in ("Gp", "Gpp", "Gp_err", "Gpp_err"):
        out[k] = None if data.get(k) is None else _series(f"{name}[{k!r}]", data[k], len(a))
    return out


def plot_amplitude_sweeps(one_packing, independent=None, path=None, *, x="amplitude", title=None):
    """G′ (filled markers) and G″ (open markers) in Pa against the strain amplitude, log–log.

    Parameters
    ----------
    one_packing : mapping
        One packing swept step after step (amplitude after amplitude, or frequency after
        frequency): keys ``x``, "Gp", "Gpp" (Pa) and optional "Gp_err", "Gpp_err" (standard
        errors, Pa).
    independent : mapping, optional
        A fresh packing per amplitude, same keys.
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).
    title : str, optional
        Keyword-only.  The figure's title: what made it (N, seeds, estimator, rate, γ₀ or σ₀;
        :func:`particleShear.plot.made_by`), fitted to the figure's width.
    x : {"amplitude", "relative_frequency"}, default "amplitude"
        Keyword-only.  The abscissa's key: the strain amplitude γ₀, or the relative frequency
        f·τ of a frequency sweep.

    Returns
    -------
    matplotlib.figure.Figure
        One axes; line labels start with the series name.

    Raises
    ------
    ValueError
        A missing key, unequal lengths, non-finite numbers, or a bad ``path``.
    """
    if x not in ("amplitude", "relative_frequency"):
        raise ValueError(f"x={x!r} is invalid: allowed 'amplitude', 'relative_frequency'")
    sweeps = {"one_packing": _sweep("one_packing", one_packing, x)}
    if independent is not None:
        sweeps["independent"] = _sweep("independent", independent, x)
    if path is not None:
        check_figure_path(path, "path")
    fig = _figure(6.0, 4.5)
    ax = fig.subplots()
    dropped = 0
    for (key, d), colour in zip(sweeps.items(), ("C0", "C1")):
        for k, face in (("Gp", colour), ("Gpp", "none")):
            keep = (d["amplitude"] > 0) & (d[k] > 0)
            dropped += int((~keep).sum())
            err = d[k + "_err"]
            ax.errorbar(d["amplitude"][keep], d[k][keep], yerr=None if err is None else err[keep], fmt="o-",
                        color=colour, mfc=face, label=f"{_SWEEP_NAMES[x][key]}: {'G′' if k == 'Gp' else 'G″'}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("strain amplitude γ₀" if x == "amplitude" else "relative frequency f·τ")
    ax.set_ylabel("G′, G″ (Pa)")
    ax.legend(fontsize="small")
    _note(ax, dropped, "G′/G″")
    return _finish(fig, path, title)


def plot_steady_run(strain, stress, steady=None, strain_transient=None, path=None, *, title=None, is_steady=True):
    """One steady-shear run: the shear stress σ (Pa) against the strain γ, linear axes.

    Parameters
    ----------
    strain : array_like
        Strain of every step.
    stress : array_like
        Shear stress in Pa, same length.
    steady : tuple of float, optional
        (mean, standard error) of the steady stress in Pa, drawn as a band after the transient.
    strain_transient : float, optional
        Strain at the detected end of the start-up transient (a vertical line).
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).
    title : str, optional
        Keyword-only.  The figure's title: what made it (N, seeds, estimator, rate, γ₀ or σ₀;
        :func:`particleShear.plot.made_by`), fitted to the figure's width.
    is_steady : bool, default True
        Keyword-only.  False when the run failed ``plateau_reached``
        (:mod:`particleShear.analysis.verdicts`): the band is then hatched and labelled the mean
        after the transient, "not steady", never a steady stress.

    Returns
    -------
    matplotlib.figure.Figure
        One axes.

    Raises
    ------
    ValueError
        Unequal lengths, non-finite numbers, a bad ``steady``, or a bad ``path``.
    """
    g = _series("strain", strain)
    s = _series("stress", stress, len(g))
    if steady is not None:
        steady = _series("steady", steady, 2)
    if strain_transient is not None:
        strain_transient = float(_series("strain_transient", [strain_transient])[0])
    if path is not None:
        check_figure_path(path, "path")
    fig = _figure(6.0, 4.0)
    ax = fig.subplots()
    ax.plot(g, s, "-", lw=0.8, label="σ (plate)")
    if steady is not None:
        v, e = steady
        if is_steady:
            ax.axhspan(v - e, v + e, alpha=0.3, color="grey", label=f"steady {v:.3g} ± {e:.3g} Pa", gid="steady")
        else:
            ax.axhspan(v - e, v + e, alpha=0.3, facecolor="none", edgecolor="tab:red", hatch="//",
                       label=f"mean after transient {v:.3g} ± {e:.3g} Pa: not steady (no plateau)", gid="steady")
    if strain_transient is not None:
        ax.axvline(strain_transient, color="k", ls=":", label="end of transient", gid="transient")
    ax.set_xlabel("strain γ")
    ax.set_ylabel("shear stress σ (Pa)")
    ax.legend(fontsize="small")
    return _finish(fig, path, title)


#: what each protocol's title names besides N, the seed and the estimator
_PROTOCOL_TITLES = {"steady": "steady shear", "relaxation": "stress relaxation", "creep": "creep",
                    "amplitude_sweep": "amplitude sweep (one packing)", "frequency_sweep": "frequency sweep (one packing)"}


def _result_title(result):
    """The title of a protocol run's figure: the protocol, then N, seeds, estimator, rate, γ₀ or σ₀."""
    p = result.parameters or {}

    def num(name):
        try:
            v = float(p[name])
        except (KeyError, TypeError, ValueError):
            return None
        return v if np.isfinite(v) else None
    proto = result.protocol
    N = num("N")
    kw = {"N": int(N) if N is not None else None, "seeds": 1, "estimator": "surface"}
    if proto == "steady" and num("relative_rate") is not None:
        kw["rate"] = f"γ̇·τ = {num('relative_rate'):g}"
    if proto in ("relaxation", "frequency_sweep") and num("theAmplitude") is not None:
        kw["amplitude"] = num("theAmplitude")
    if proto == "relaxation" and num("ramp_time") is not None:
        kw["rate"] = f"ramp time {num('ramp_time'):g} τ"
    if proto == "creep" and num("creep_stress") is not None:
        kw["stress"] = num("creep_stress")
    if proto == "amplitude_sweep" and num("relative_frequency") is not None:
        kw["rate"] = f"f·τ = {num('relative_frequency'):g}"
    seed = result.seed
    tail = f" (seed {seed})" if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) else ""
    return f"{_PROTOCOL_TITLES.get(proto, proto)}: {made_by(**kw)}{tail}"


def plot_rheometer_result(result, path=None):
    """The figure of one protocol run, chosen by ``result.protocol``.

    steady: :func:`plot_steady_run` (plate stress against strain, steady band, transient);
    relaxation: :func:`plot_relaxation` of the curve ``G_surface`` with the plateau;
    creep: :func:`plot_creep` of ``J``; sweeps: :func:`plot_amplitude_sweeps` of the steps
    (against γ₀, or f·τ for a frequency sweep) with their standard errors.

    Parameters
    ----------
    result : SimulationResult
        A run of this session (the series and curves are needed; a result rebuilt from a
        results table has the steps only, enough for the sweeps).
    path : str or os.PathLike, optional
        Write the figure there (.png, .pdf, .svg, .eps).

    Returns
    -------
    matplotlib.figure.Figure
        Titled with the protocol, N, the seed, the estimator and the rate, γ₀ or σ₀, and the verdict
        when the run is flagged.

    Raises
    ------
    ValueError
        A result without the data its figure needs, a protocol without a figure (one not shipped), or
        a bad ``path``.
    """
    proto, summ = result.protocol, result.summary
    title = _result_title(result)
    verdict = result.verdict
    if verdict and verdict != "ok":
        title += f"; {verdict}"           # flags are drawn, never hidden (docs/analysis.md, "Verdicts")
    if proto in ("amplitude_sweep", "frequency_sweep"):
        x = "amplitude" if proto == "amplitude_sweep" else "relative_frequency"
        st = result.steps
        data = {x: [s[x] for s in st], "Gp": [s["Gp_surface"] for s in st], "Gpp": [s["Gpp_surface"] for s in st]}
        for k in ("Gp", "Gpp"):
            errs = [s.get(f"{k}_surface_se") for s in st]
            if all(e is not None and np.isfinite(e) for e in errs):
                data[k + "_err"] = errs
        return plot_amplitude_sweeps(data, path=path, x=x, title=title)
    if proto == "steady":
        if "strain" not in result.series:
            raise ValueError("plot needs the recorded series of the run (a result of this session or read_run "
                             "of its file, not one rebuilt from a results table)")
        return plot_steady_run(result.series["strain"], result.series["stress_surface"],
                               (summ["stress_surface"], summ["stress_surface_se"]), summ.get("strain_transient"),
                               path, title=title, is_steady=summ.get("plateau_reached") is not False)
    if proto not in ("relaxation", "creep"):
        raise ValueError(f"plot has no figure of protocol={proto!r}: the figures are those of the shipped protocols "
                         "(plot result.series, the record of every step, yourself)")
    name = "G_surface" if proto == "relaxation" else "J"
    if name not in result.curves:
        raise ValueError(f"plot needs the curve {name!r} of the run (a result of this session, not one rebuilt "
                         "from a results table)")
    t, y, err = result.curves[name]
    if proto == "relaxation":
        plateau = (summ["G_plateau_surface"], summ["G_plateau_surface_se"])
        return plot_relaxation(t, y, err, plateau if all(np.isfinite(plateau)) else None, path, title=title,
                               ramp=summ.get("ramp_time_s"))
    return plot_creep(t, y, path, title=title)


def plot_flow_curve_sweep(folder_or_csv, estimator="surface", path=None, n_boot=2000, confidence=0.95,
                          bootstrap_seed=0):
    """The flow curve of a steady-shear sweep with its Herschel–Bulkley fit (log–log).

    Each point is the mean over the repetitions at one ``relative_rate`` with ± one standard error
    (failed runs left out); the fit is :func:`particleShear.analysis.fit_flow_curve`, its
    bootstrap interval of σ_y in the legend.

    Parameters
    ----------
    folder_or_csv : str or os.PathLike
        The sweep folder or its ``results.csv``.
    estimator : {"surface", "internal"}, default "surface"
        Which stress.
    path : str, os.PathLike, None or False
        None (default): write ``DIR/flow_curve.png`` and ``.pdf``; a path: that file; False: nothing.
    n_boot, confidence, bootstrap_seed
        As :func:`particleShear.analysis.flow_curve.herschel_bulkley_bootstrap` (``rng``).

    Returns
    -------
    matplotlib.figure.Figure
        Labelled "flow_curve"; axes as :func:`plot_flow_curve`.

    Raises
    ------
    ValueError
        No steady rows, mixed materials, or fewer than three rates with a finished run.
    """
    import os
    import warnings

    src = os.fspath(folder_or_csv)
    table = load_results(src, as_frame=False)
    rate, stress = flow_curve_table(table, estimator)
    have = np.isfinite(stress).sum(axis=1)
    if (have > 0).sum() < 3:
        raise ValueError(f"folder_or_csv={src!r}: a flow curve needs finished runs at >= 3 rates, "
                         f"it has {(have > 0).sum()}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mean = np.nanmean(stress, axis=1)
        sem = np.where(have > 1, np.nanstd(stress, axis=1, ddof=1) / np.sqrt(np.maximum(have, 1)), 0.0)
    keep = have > 0
    fc = fit_flow_curve(table, estimator, n_boot=n_boot, confidence=confidence, rng=bootstrap_seed)
    if path not in (None, False):
        check_figure_path(path, "path")
    fig = plot_flow_curve(rate[keep], mean[keep], np.nan_to_num(sem[keep]), fit=fc.fit)
    lo, hi = fc.intervals["sigma_y"]
    Ns = sorted({int(r["N"]) for r in table if r.get("N") is not None and str(r.get("status")) == "ok"})
    N = (Ns[0] if len(Ns) == 1 else (Ns[0], Ns[-1])) if Ns else None
    fig.axes[0].set_title(f"flow curve: {made_by(N=N, seeds=stress.shape[1], estimator=estimator)}; σ_y "
                          f"{100 * confidence:g} % interval [{lo:.3g}, {hi:.3g}] Pa", fontsize="small")
    fig.set_label("flow_curve")
    if path not in (None, False):      # written with its title
        save_figure(fig, path)
    if path is None:
        folder = src if os.path.isdir(src) else os.path.dirname(os.path.abspath(src))
        for ext in (".png", ".pdf"):
            save_figure(fig, os.path.join(folder, "flow_curve" + ext))
    return fig
