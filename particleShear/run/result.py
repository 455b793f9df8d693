"""What one run produced: :class:`SimulationResult`, the one result type of every protocol.

Every run — the oscillatory one (moduli, their errors and LAOS measures) and the rheometer's other
protocols (a summary, curves, a sweep's steps) — returns a :class:`SimulationResult` naming its
``protocol``; what differs between protocols (the results-table rows, the text summary, the
verdict, the values returned, the figure) is the protocol's summary module,
:mod:`~particleShear.run.moduli_summary` for "oscillatory" and
:mod:`~particleShear.run.protocol_summary` for the others (:func:`_summary_of`).  Made by
:func:`~particleShear.run.api.doParticleShearSimulation` and the batch; rebuilt from results-table
rows by a resumed series (:meth:`SimulationResult.from_rows`).
"""
__docformat__ = "numpy"
import dataclasses

import numpy as np

from ..hooks import entry
from ..simulation.microstructure_pictures import microstructure_pictures
from ..analysis.demodulation import ESTIMATOR_COLUMNS
from ..analysis.laos import laos
from ..analysis.measures import measured_window
from . import moduli_summary, protocol_summary

__all__ = ["SimulationResult"]

#: the summary module of a protocol that has its own (every other protocol: :mod:`.protocol_summary`)
_SUMMARIES = {"oscillatory": moduli_summary}


def _summary_of(protocol):
    """The module that summarises a run of ``protocol`` (module docstring)."""
    return _SUMMARIES.get(protocol, protocol_summary)


@dataclasses.dataclass
class SimulationResult:
    """Everything a run of :func:`doParticleShearSimulation` produced, whatever its protocol.

    The fields G_surface … microstructure are those of the oscillatory protocol (empty or at their
    defaults for another); protocol … steps those of the others (docs/protocols.md; empty for the
    oscillatory run, which is one step).  A run of another protocol is made by
    :meth:`of_protocol`.

    Parameters
    ----------
    G_surface : tuple of float
        (G′, G″) in Pa from the external (surface) forces on the plate bands — the
        reference's return value; () for another protocol.
    G_internal : tuple of float
        (G′, G″) in Pa from the overall stress tensor (eq. S1-24) — the values the output
        header lists first; () for another protocol.
    stress_surface, stress_internal : tuple of float
        (in-phase, out-of-phase) shear stress amplitudes in Pa of the two estimators.
    parameters : dict
        Every argument of the call (reference names), keyword-only options included (another
        protocol: normalized, a sweep's first value in ``theAmplitude`` or ``relative_frequency``).
    seed : int or None, default None
        Entropy of the ``numpy.random.SeedSequence`` that drove the run (None if a Generator
        was given).
    spawn_key : tuple of int, default ()
        Spawn key of that SeedSequence (non-empty for the runs of a series).
    timings : dict of float
        Wall time in s of "constitution", "pre_equilibration", "protocol", "demodulation",
        "output" and "total" (another protocol: "constitution", "pre_equilibration",
        "protocol", "analysis" and "output").
    output_path : str or None, default None
        The output file (when ``saveData``).
    image_folder : str or None, default None
        The folder of the snapshots (when ``saveOutputImages``).
    n_images : int, default 0
        Number of snapshots written.
    dt : float, default 0.0
        Protocol time step in s (of the first step for sweeps).
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
        (``saveData`` with ``saveStressTensorData``); for "steady" also "N1" (Pa, NaN where not
        sampled); for sweeps the steps' records one after the other with "sweep_position" (each
        step's clock from 0).
    run_id : str, default ""
        12 hex digits identifying parameters + seed
        (:func:`~particleShear.simulation.provenance.run_identity`).
    write_error : Exception or None, default None
        Why writing the output failed after the run (the moduli are valid); None when written.
    microstructure : dict or None, default None
        The per-cycle arrays of the stroboscopic observer (a run with ``stroboscopic=True``;
        :meth:`particleShear.engine.microstructure.Stroboscope.replica`, docs/microstructure.md);
        None for a run without it.
    protocol : str, default "oscillatory"
        The protocol of the run (:data:`particleShear.protocols.PROTOCOLS`).
    tau : float or None, default None
        Model time constant τ (s) of another protocol's run (its rates and times are in units of τ).
    summary : dict, default {}
        Another protocol's scalar results by name (units in docs/protocols.md), its checks and verdict.
    curves : dict, default {}
        ``name -> (t, y, y_sem)`` on log-spaced grids: "G" (relaxation, Pa), "J" (creep, 1/Pa).
    steps : list of dict, default []
        Sweeps: one dict per step (position, amplitude, relative_frequency, f, G′/G″ of both
        estimators with standard errors, LAOS measures).

    Attributes
    ----------
    G : list of float
        ``[G′_surface, G″_surface]`` in Pa — what :func:`doParticleShearSimulation` returns.
    values : list
        What :func:`doParticleShearSimulation` returns without ``return_result``, for every protocol.
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
    protocol: str = "oscillatory"
    tau: object = None
    summary: dict = dataclasses.field(default_factory=dict)
    curves: dict = dataclasses.field(default_factory=dict, repr=False)
    steps: list = dataclasses.field(default_factory=list)
    _measures: dict = dataclasses.field(default=None, init=False, repr=False, compare=False)

    def __setstate__(self, state):
        """Unpickle a result of an earlier version: the fields it lacks take their defaults (a 2.x
        ``RheometerResult`` has no moduli, a 2.x ``SimulationResult`` no protocol summary)."""
        for field in dataclasses.fields(self):
            if field.name not in state:
                if field.default_factory is not dataclasses.MISSING:
                    state[field.name] = field.default_factory()
                else:
                    state[field.name] = () if field.default is dataclasses.MISSING else field.default
        self.__dict__.update(state)

    @property
    def G(self):
        """``[G′_surface, G″_surface]`` — what :func:`doParticleShearSimulation` returns for the
        oscillatory protocol (another protocol's numbers: :attr:`values`).

        Raises
        ------
        AttributeError
            For a run of another protocol, which has no G′, G″ of its own.
        """
        if len(self.G_surface) < 2:
            raise AttributeError(f"a run of protocol={self.protocol!r} has no G: its numbers are result.values "
                                 "(a sweep's moduli per step: result.steps)")
        return moduli_summary.values(self)

    @classmethod
    def of_protocol(cls, protocol, parameters, seed, spawn_key, run_id, tau, dt, series, summary, curves, steps,
                    timings, output_path=None):
        """The result of a run of a protocol other than "oscillatory" (the arguments of 2.x's
        ``RheometerResult``, which now names this constructor).

        Parameters
        ----------
        protocol, parameters, seed, spawn_key, run_id, tau, dt, series, summary, curves, steps, timings
            The fields of the same names (class docstring).
        output_path : str, optional
            The run's file.

        Returns
        -------
        SimulationResult
        """
        return cls(G_surface=(), G_internal=(), stress_surface=(), stress_internal=(), parameters=parameters,
                   seed=seed, spawn_key=tuple(spawn_key), timings=timings, output_path=output_path, dt=dt,
                   series=series, run_id=run_id, protocol=protocol, tau=tau, summary=summary, curves=curves,
                   steps=steps)

    @classmethod
    def from_rows(cls, rows, parameters, seed, spawn_key, output_path=None):
        """The result of a finished run rebuilt from its results-table rows (no series, no curves).

        Used when a series or a sweep resumes: the moduli and measures, the protocol's summary, or
        the steps of a sweep, are the rows' values (the inverse of :meth:`rows`).

        Parameters
        ----------
        rows : list of dict
            The run's typed rows (:func:`particleShear.sweep.schema.typed_row`), in step order.
        parameters : dict
            The run's parameters (``protocol`` among them, or "oscillatory").
        seed, spawn_key
            The run's seed entropy and spawn key.
        output_path : str, optional
            The run's file.

        Returns
        -------
        SimulationResult
        """
        return _summary_of(parameters.get("protocol", "oscillatory")).from_rows(cls, rows, parameters, seed,
                                                                                spawn_key, output_path)

    @property
    def _form(self):
        """The module that summarises this run's protocol (:func:`_summary_of`)."""
        return _summary_of(self.protocol)

    def __repr__(self):
        """A short summary — the oscillatory protocol's G′, G″ of both estimators (± standard error
        over the measured periods where finite) with N, A, μ, seed and run id; another protocol's
        name, N, μ, seed, run id and each summary number with its standard error and unit (sweeps:
        G′, G″ per step and estimator); then the verdict — not the parameters nor the records.

        Returns
        -------
        str
        """
        form = self._form
        head = ", ".join(f"{k}={v}" for k, v in form.text_fields(self))
        lines = [f"SimulationResult({head}"] + form.text_lines(self)
        lines += ["  " + line for line in self._verdict_lines()]
        return "\n".join(lines) + ")"

    def _verdict_lines(self):
        """The verdict of the summary, as lines (the protocol's ``verdict_text``; none when not evaluable)."""
        return self._form.verdict_text(self)

    def _repr_html_(self):
        """The summary of :meth:`__repr__` as a small HTML table (Jupyter); all text HTML-escaped.

        Returns
        -------
        str
        """
        import html
        esc = html.escape
        form = self._form
        cap = ", ".join(f"{esc(k)} = {esc(v)}" for k, v in form.text_fields(self))
        header, cells = form.html_rows(self)
        out = ["<table>", f"<caption>SimulationResult: {cap}</caption>",
               "<tr>" + "".join(f"<th>{esc(h)}</th>" for h in header) + "</tr>"]
        out += ["<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in cells]
        out += [f'<tr><td colspan="3">{esc(line.strip())}</td></tr>' for line in self._verdict_lines()]
        out.append("</table>")
        return "\n".join(out)

    @property
    def measures(self):
        """Standard errors, steady-state flag and LAOS ratios of the run (dict, the results-table columns
        :data:`~particleShear.analysis.measures.MEASURE_COLUMNS`), evaluated once from ``series``
        (:func:`~particleShear.analysis.measures.run_measures`; docs/analysis.md)."""
        if self._measures is None:
            self._measures = self._form.measures(self)
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
        return self._form.verdict(self)

    @property
    def values(self):
        """The protocol's main numbers — what :func:`doParticleShearSimulation` returns without
        ``return_result``: oscillatory ``[G′, G″]`` (surface, :attr:`G`), steady ``[σ, η]``
        (surface), relaxation ``[G_plateau]``, creep ``[final creep rate, σ₀/γ̇]``, sweeps
        ``[[G′, G″], …]`` per step (surface)."""
        return self._form.values(self)

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
        """The protocol's figure (needs ``particleShear[plot]``): strain and stress traces against time
        plus the Lissajous loop of an oscillatory run (:func:`particleShear.plot.plot_result`); the
        stress against strain of a steady run, G(t), J(t), or G′/G″ of a sweep's steps
        (:func:`particleShear.rheometer_plot.plot_rheometer_result`).

        Parameters
        ----------
        path : str or os.PathLike, optional
            File to write (PNG, PDF, SVG or EPS, chosen by the extension); None writes nothing.

        Returns
        -------
        matplotlib.figure.Figure
        """
        return entry(self._form.PLOT_ENTRY)(self, path)

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
        key a list (types, units: :mod:`particleShear.sweep.schema`).  Another protocol: its one
        row of :meth:`rows`.

        Returns
        -------
        dict

        Raises
        ------
        ValueError
            For a sweep protocol, which has a row per step (:meth:`rows`).
        """
        return self._form.to_dict(self)

    def rows(self):
        """The rows of this run in a sweep's results table: ``[self.to_dict()]`` (one run, one row),
        or one per step of a sweep protocol (:func:`particleShear.run.protocol_summary.rows`).

        Returns
        -------
        list of dict
        """
        return self._form.rows(self)

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
