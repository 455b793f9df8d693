"""What one run produced: :class:`SimulationResult` (moduli, their errors and LAOS measures, series, files).

Made by :func:`~particleShear.run.api.doParticleShearSimulation` and the batch; rebuilt from a
results-table row by a resumed series.
"""
__docformat__ = "numpy"
import dataclasses
import math

import numpy as np

from .._version import __version__
from ..hooks import entry
from ..parameters import spec_defaults
from ..simulation.microstructure_pictures import microstructure_pictures
from ..analysis.demodulation import ESTIMATOR_COLUMNS
from ..analysis.laos import laos
from ..analysis.measures import empty_measures, measured_window, run_measures
from ..analysis.microstructure import micro_measures
from ..analysis.verdicts import verdict_lines
from ..simulation.provenance import run_identity

__all__ = ["SimulationResult"]


@dataclasses.dataclass
class SimulationResult:
    """Everything a run of :func:`doParticleShearSimulation` produced.

    Parameters
    ----------
    G_surface : tuple of float
        (G′, G″) in Pa from the external (surface) forces on the plate bands — the
        reference's return value.
    G_internal : tuple of float
        (G′, G″) in Pa from the overall stress tensor (eq. S1-24) — the values the output
        header lists first.
    stress_surface, stress_internal : tuple of float
        (in-phase, out-of-phase) shear stress amplitudes in Pa of the two estimators.
    parameters : dict
        Every argument of the call (reference names), keyword-only options included.
    seed : int or None, default None
        Entropy of the ``numpy.random.SeedSequence`` that drove the run (None if a Generator
        was given).
    spawn_key : tuple of int, default ()
        Spawn key of that SeedSequence (non-empty for the runs of a series).
    timings : dict of float
        Wall time in s of "constitution", "pre_equilibration", "protocol", "demodulation",
        "output" and "total".
    output_path : str or None, default None
        The output file (when ``saveData``).
    image_folder : str or None, default None
        The folder of the snapshots (when ``saveOutputImages``).
    n_images : int, default 0
        Number of snapshots written.
    dt : float, default 0.0
        Protocol time step in s.
    f : float, default 0.0
        Excitation frequency in Hz.
    N_steps : int, default 0
        Number of protocol steps.
    repetition : int, default 0
        Index of the run among the repetitions of its parameter point in a sweep or series
        (0 for a single run).
    damping_factor : float, default 1.0
        Per-step velocity damping factor (``cool_factor`` per step), dimensionless.
    removed_fraction : float, default 0.0
        Actual fraction of removed non-essential bonds (``remove_link_fraction``).
    series : dict of numpy.ndarray
        Per protocol step: "t" (s), "strain", "strain_rate" (1/s), "stress_surface" and
        "stress_internal" (Pa), and "tensors" (n, 9, 2, 2) in Pa when the tensor history was kept
        (``saveData`` with ``saveStressTensorData``).
    run_id : str, default ""
        12 hex digits identifying parameters + seed
        (:func:`~particleShear.simulation.provenance.run_identity`).
    write_error : Exception or None, default None
        Why writing the output failed after the run (the moduli are valid); None when written.
    microstructure : dict or None, default None
        The per-cycle arrays of the stroboscopic observer (a run with ``stroboscopic=True``;
        :meth:`particleShear.engine.microstructure.Stroboscope.replica`, docs/microstructure.md);
        None for a run without it.

    Attributes
    ----------
    G : list of float
        ``[G′_surface, G″_surface]`` in Pa — what :func:`doParticleShearSimulation` returns.
    """

    G_surface: tuple
    G_internal: tuple
    stress_surface: tuple
    stress_internal: tuple
    parameters: dict
    seed: object = None
    spawn_key: tuple = ()
    timings: dict = dataclasses.field(default_factory=dict)
    output_path: object = None
    image_folder: object = None
    n_images: int = 0
    dt: float = 0.0
    f: float = 0.0
    N_steps: int = 0
    repetition: int = 0
    damping_factor: float = 1.0
    removed_fraction: float = 0.0
    series: dict = dataclasses.field(default_factory=dict, repr=False)
    run_id: str = ""
    write_error: object = None
    microstructure: object = dataclasses.field(default=None, repr=False, compare=False)
    _measures: dict = dataclasses.field(default=None, init=False, repr=False, compare=False)

    @property
    def G(self):
        """``[G′_surface, G″_surface]`` — what :func:`doParticleShearSimulation` returns."""
        return [self.G_surface[0], self.G_surface[1]]

    def _summary(self):
        """(estimator rows, run fields) of :meth:`__repr__` and :meth:`_repr_html_`.

        Rows: ``(name, G′, se G′, G″, se G″)`` with the standard errors None where not finite
        (fewer than 2 measured periods, or no recorded series); fields: ``(label, text)`` of N,
        A, μ, seed and run id as recorded.
        """
        rows = []
        for name, G, se_name in (("surface", self.G_surface, "G_surface_se"),
                                 ("internal", self.G_internal, "G_internal_se")):
            try:
                se = getattr(self, se_name)
            except Exception:  # noqa: BLE001 - a repr never fails: no error bars then
                se = (float("nan"), float("nan"))
            se = [float(v) if v is not None and np.isfinite(v) else None for v in se]
            rows.append((name, float(G[0]), se[0], float(G[1]), se[1]))
        p = self.parameters or {}
        seed = "None" if self.seed is None else str(self.seed)
        if self.spawn_key:
            seed += " spawn " + ",".join(str(k) for k in self.spawn_key)
        fields = [("N", str(p.get("N", "?"))), ("A", str(p.get("theAmplitude", "?"))),
                  ("μ", str(p.get("theMu", "?"))), ("seed", seed), ("run_id", self.run_id or "–")]
        return rows, fields

    @staticmethod
    def _modulus_text(value, se):
        return f"{value:.4g}" + ("" if se is None else f" ± {se:.2g}")

    def __repr__(self):
        """A short summary: G′, G″ of both estimators (± standard error over the measured periods where
        finite), N, A, μ, seed and run id — not the parameter dict (``result.parameters``).

        Returns
        -------
        str
        """
        rows, fields = self._summary()
        head = ", ".join(f"{k}={v}" for k, v in fields)
        lines = [f"SimulationResult({head}"]
        for name, g1, s1, g2, s2 in rows:
            lines.append(f"  {name + ':':<9} G′ = {self._modulus_text(g1, s1)} Pa, "
                         f"G″ = {self._modulus_text(g2, s2)} Pa")
        lines += ["  " + line for line in self._verdict_lines()]
        return "\n".join(lines) + ")"

    def _verdict_lines(self):
        """:func:`~particleShear.analysis.verdicts.verdict_lines` of the run; none when its measures fail."""
        try:
            return verdict_lines(self.measures)
        except Exception:  # noqa: BLE001 - a repr never fails
            return []

    def _repr_html_(self):
        """The summary of :meth:`__repr__` as a small HTML table (Jupyter); all text HTML-escaped.

        Returns
        -------
        str
        """
        import html
        rows, fields = self._summary()
        esc = html.escape
        cap = ", ".join(f"{esc(k)} = {esc(v)}" for k, v in fields)
        out = ["<table>", f"<caption>SimulationResult: {cap}</caption>",
               "<tr><th>estimator</th><th>G′ (Pa)</th><th>G″ (Pa)</th></tr>"]
        for name, g1, s1, g2, s2 in rows:
            out.append(f"<tr><td>{esc(name)}</td><td>{esc(self._modulus_text(g1, s1))}</td>"
                       f"<td>{esc(self._modulus_text(g2, s2))}</td></tr>")
        out += [f'<tr><td colspan="3">{esc(line.strip())}</td></tr>' for line in self._verdict_lines()]
        out.append("</table>")
        return "\n".join(out)

    @property
    def measures(self):
        """Standard errors, steady-state flag and LAOS ratios of the run (dict, the results-table columns
        :data:`~particleShear.analysis.measures.MEASURE_COLUMNS`), evaluated once from ``series``
        (:func:`~particleShear.analysis.measures.run_measures`; docs/analysis.md)."""
        if self._measures is None:
            import warnings
            p = self.parameters or {}
            try:
                self._measures = run_measures(self.series, self.f, p.get("theAmplitude", 0.0),
                                              p.get("pre_periods", 0), p.get("periods", 0),
                                              moduli={"surface": self.G_surface, "internal": self.G_internal})
                if self.microstructure is not None:
                    self._measures.update(micro_measures(self.microstructure))
            except Exception as exc:  # noqa: BLE001 - a measure must never turn a finished run into a failure
                warnings.warn(f"the measures of run {self.run_id or '?'} could not be evaluated "
                              f"({type(exc).__name__}: {exc}); they are left empty", RuntimeWarning, stacklevel=2)
                self._measures = empty_measures()
        return self._measures

    @property
    def G_surface_se(self):
        """(se G′, se G″) in Pa of the surface estimator: standard error over the measured periods."""
        return self.measures["Gp_surface_se"], self.measures["Gpp_surface_se"]

    @property
    def G_internal_se(self):
        """(se G′, se G″) in Pa of the internal estimator: standard error over the measured periods."""
        return self.measures["Gp_internal_se"], self.measures["Gpp_internal_se"]

    @property
    def verdict(self):
        """``"ok"`` when no check of the run failed, else ``"flagged: …"`` naming the failed checks
        (:mod:`particleShear.analysis.verdicts`; docs/analysis.md, "Verdicts")."""
        return self.measures["verdict"]

    @property
    def steady_state(self):
        """True when no modulus drifts from period to period beyond its error, False when one does,
        None with fewer than 3 measured periods (docs/analysis.md)."""
        return self.measures["steady_state"]

    def laos(self, estimator="surface", n_max=5):
        """Large-amplitude oscillatory shear measures of the measured excitation periods.

        Parameters
        ----------
        estimator : {"surface", "internal"}, default "surface"
            Which shear stress: plate forces or the overall stress tensor.
        n_max : int, default 5
            Highest harmonic order fitted (5, as the results table: higher orders of a run at
            N <= 150 are at its noise level; see docs/analysis.md).

        Returns
        -------
        particleShear.analysis.laos.LaosResult
            Harmonics G′_n, G″_n, Chebyshev e_n, v_n, G_M, G_L, η_M, η_L, S, T, I₃/I₁, Q.

        Raises
        ------
        ValueError
            For another estimator, a result without its series, or a measured span shorter than
            one period.
        """
        if estimator not in ESTIMATOR_COLUMNS:
            raise ValueError(f"estimator={estimator!r} is not allowed: use 'surface' or 'internal'")
        key = ESTIMATOR_COLUMNS[estimator][1]
        s = self.series
        if not s or key not in s:
            raise ValueError("laos needs the recorded series of the run (a result of this session, not one rebuilt "
                             "from a results table)")
        p = self.parameters
        w = measured_window(s["t"], self.f, p["pre_periods"], p["periods"])
        return laos(np.asarray(s["t"])[w], np.asarray(s["strain"])[w], np.asarray(s[key])[w], self.f, n_max=n_max)

    def plot(self, path=None):
        """Strain and stress traces against time plus the Lissajous loop (needs ``particleShear[plot]``).

        See :func:`particleShear.plot.plot_result`.

        Parameters
        ----------
        path : str or os.PathLike, optional
            File to write (PNG, PDF, SVG or EPS, chosen by the extension); None writes nothing.

        Returns
        -------
        matplotlib.figure.Figure
        """
        return entry("plot_result")(self, path)

    def microstructure_pictures(self, folder, colour_by="d2min", gif=True, **options):
        """One picture per excitation cycle (force chains, spheres coloured by D²_min) and a GIF.

        See :func:`particleShear.simulation.microstructure_pictures.microstructure_pictures` (Pillow
        only; docs/microstructure.md, "Pictures").

        Parameters
        ----------
        folder : str or os.PathLike
            Output folder (made when missing).
        colour_by : {"d2min", "non_affine"}, default "d2min"
            What fills the spheres.
        gif : bool, default True
            Also write ``folder/cycles.gif``.
        **options
            ``scale`` (pixels per µm), ``decades``, ``frame_duration_ms``.

        Returns
        -------
        dict
            ``"pictures"`` (PNG paths, one per cycle) and ``"gif"`` (path or None).

        Raises
        ------
        ValueError
            A run without ``stroboscopic=True``, or an option out of range.
        """
        return microstructure_pictures(self, folder, colour_by=colour_by, gif=gif, **options)

    def to_dict(self):
        """The row of this run in a sweep's results table (docs/sweeps.md), as a dict.

        Keys in table order: ``run_id`` (hash of the complete parameter set and seed),
        ``status`` ("ok"), ``error`` (""), ``Gp_surface, Gpp_surface, Gp_internal,
        Gpp_internal`` (Pa), the :attr:`measures` (standard errors, ``steady_state``, LAOS ratios),
        ``repetition``, ``frequency_Hz`` (f, Hz), ``omega`` (2πf, rad/s), ``dt`` (s), ``N_steps``,
        every parameter (defaults filled in for those not recorded), ``seed_entropy``,
        ``spawn_key``, ``package_version``, ``wall_time_s`` (s), ``output_path``.  Values are
        typed: float, int, bool (``steady_state`` None when it cannot be judged), str, the spawn
        key a list (types, units: :mod:`particleShear.sweep.schema`).

        Returns
        -------
        dict
        """
        params = spec_defaults()
        params.update({k: v for k, v in self.parameters.items() if k in params})
        row = {"run_id": run_identity(params, self.seed, self.spawn_key), "status": "ok", "error": "",
               "Gp_surface": float(self.G_surface[0]), "Gpp_surface": float(self.G_surface[1]),
               "Gp_internal": float(self.G_internal[0]), "Gpp_internal": float(self.G_internal[1])}
        row.update(self.measures)
        row.update(repetition=int(self.repetition), frequency_Hz=float(self.f), omega=2 * math.pi * float(self.f),
                   dt=float(self.dt), N_steps=int(self.N_steps))
        row.update(params)
        row.update(seed_entropy=self.seed, spawn_key=list(self.spawn_key), package_version=__version__,
                   wall_time_s=float(self.timings.get("total", 0.0)), output_path=self.output_path or "")
        return row

    #: the protocol of the run: a SimulationResult is an oscillatory run (a
    #: :class:`~particleShear.run.rheometer.RheometerResult` names its own)
    protocol = "oscillatory"

    @property
    def curves(self):
        """Empty: an oscillatory run has no G(t) or J(t) curve (the interface of
        :class:`~particleShear.run.rheometer.RheometerResult`, so that callers need not ask which
        result they hold)."""
        return {}

    @property
    def steps(self):
        """Empty: an oscillatory run is one step (sweeps have one entry per step; the interface of
        :class:`~particleShear.run.rheometer.RheometerResult`)."""
        return []

    def rows(self):
        """The rows of this run in a sweep's results table: ``[self.to_dict()]`` (one run, one row;
        the interface of :meth:`particleShear.run.rheometer.RheometerResult.rows`).

        Returns
        -------
        list of dict
        """
        return [self.to_dict()]

    def to_dataframe(self):
        """:meth:`to_dict` as a pandas Series (index: the column names, table order; needs pandas).

        Returns
        -------
        pandas.Series
            Object dtype, named by the run id: each value keeps its Python type (float, int,
            bool, str, list).
        """
        import pandas as pd
        row = self.to_dict()
        return pd.Series(row, dtype=object, name=row["run_id"])
