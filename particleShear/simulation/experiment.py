"""The oscillatory shear experiment: pre-equilibration, sinusoidal strain protocol, G′ and G″.

``OscillatoryShearExperiment.oscillatory_shear_experiment`` runs the fixed-boundary
pre-equilibration and the measurement protocol (strain ``A·sin(2π(f t − pre))`` during the
excitation periods, at rest during the baselines) with the engine's one step and its one
protocol loop on the ensemble's own state (:meth:`OscillatoryShearExperiment.engine_of_ensemble`;
docs/engine.md, "One step"), records every step, demodulates τ_internal and τ_surface
(:func:`~.evaluation.demodulation`) and returns ``[G′_surface, G″_surface]`` (Pa) as the reference
does.  ``pre_equilibrate`` and ``run_protocol`` run the two phases one by one.
"""
__docformat__ = "numpy"
import logging
import math
import os
import time
import warnings

import numpy as np

from ..base.stress import StressTensorEvaluation
from ..engine.loops import relaxation_levels
from ..base.engine_adapter import state_of_ensemble, untouched_on_failure, write_back
from ..base.register import KeptTerms
from .evaluation import EvaluationHandlerPlotter, demodulation
from .output import NO_TENSOR_DATA_TEXT, experiment_description_text, iter_table_text, output_summary_text
from .drawing import IMAGE_EXTENSIONS
from .driver import ENGINE_SKIN_FACTOR, _guarded, replica_record
from .evaluation import _FORCE, _RATE, _SHEAR, _STRAIN, _T
from .observers import LiveDrawing, SnapshotWriter, StressWindow, ReplicaScene
from ..engine.step import pre_equilibrate, protocol, BatchEngine

_log = logging.getLogger(__name__)

__all__ = ["OscillatoryShearExperiment", "image_cadence", "protocol_steps"]


def protocol_steps(periods, pre, post, f, dt):
    """Number of protocol steps ``int((periods + pre + post)/f / dt)`` (truncated, as the reference).

    Parameters
    ----------
    periods : float
        Excitation periods.
    pre : float
        Baseline periods before the excitation.
    post : float
        Baseline (recovery) periods after it.
    f : float
        Excitation frequency (Hz).
    dt : float
        Time step (s).

    Returns
    -------
    int
    """
    return int((periods + pre + post) / f / dt)


def image_cadence(n_steps):
    """Snapshot interval ``image_N``: ``int(n/200)`` if n > 200 else 1 (docs/output.md, "Snapshots").

    Parameters
    ----------
    n_steps : int
        Protocol steps of the run.

    Returns
    -------
    int
        Steps between two snapshots (the first is taken at step 0).
    """
    return int(n_steps / 200) if n_steps > 200 else 1


class OscillatoryShearExperiment:
    """Pre-equilibration with fixed plates, sinusoidal strain protocol, recording and demodulation.

    Parameters
    ----------
    theEnsemble : ensemble
        A Lees-Edwards ensemble with the step API (``setShearRate``, ``mechanical_simulation_step_*``).
    dt : float
        Time step of the protocol (s).
    f : float
        Excitation frequency (Hz).
    amplitude : float
        Strain amplitude A.
    output_file : file-like or False
        Where the experiment description and the results are written (False: nothing written).
    dt_max : float
        Coarsest step of the pre-equilibration; ``10·dt`` unless larger than ``dt``.
    TkSimulation, theTkOutput : optional
        Live windows (kept for API compatibility; see ``renderer`` and ``stress_window``).
    force_scale : float
        Plot scale of the stresses (pixels per Pa).
    imageOutputFolder : str or False
        Folder of the snapshots (docs/output.md, "Snapshots"); False: none.
    imageBaseFileName : str or False
        File name before the 7-digit step index (``"image"`` in the simulations); False: none.
    imageFileType : str
        ``"jpg"`` (default), ``"png"`` or ``"ps"``; snapshots are saved when a folder and a
        base name are given and a renderer exists.
    plotStress : bool
        Live stress/strain plot (needs a display).
    saveStressTensorData : bool
        Write the 42-column table (and keep the per-step tensor history for it).

    Attributes
    ----------
    correct_drift_sign : bool
        Beyond the reference, as the attributes below.  False (reference quirk, default) /
        True: sign of the drift correction of the demodulation (defect #1 in docs/output.md).
    reference_header : bool
        True reproduces the header defects #21–22 of docs/output.md ("Post-measurement periods"
        printing the pre value, "Simulated time" = excitation time only).  Default False.
    renderer : Renderer or None
        Drawing backend used for snapshots (and live updates); see :mod:`.drawing`.
    stress_window : StressPlotWindow or None
    image_N : int or None
        Snapshot interval; None = reference rule :func:`image_cadence`.
    save_movie : bool
        Also write the snapshots as ``movie.gif`` (see :meth:`observers`).
    progress : callable or None
        ``progress(phase, step, total, elapsed_s)`` called about 10 times per second.
    verbose : bool
        Print the reference console messages.
    timings : dict
        Wall time (s) of "pre_equilibration", "protocol", "demodulation", "output".
    results : dict
        After the run: "internal" and "surface" demodulation results ``[SA, SB, G', G'']``.
    """

    def __init__(self, theEnsemble, dt, f, amplitude, output_file, dt_max=0, TkSimulation=False, force_scale=1,
                 theTkOutput=False, imageOutputFolder=False, imageBaseFileName=False, imageFileType="jpg",
                 plotStress=True, saveStressTensorData=True):
        self.plotStress = plotStress
        self.theEnsemble = theEnsemble
        self.amplitude = amplitude
        self.dt = dt
        self.f = f
        self.theTk = theTkOutput
        self.external_output_Tk = bool(theTkOutput)
        self.width = 1000
        self.height = 500
        self.outputCanvas = False
        self.output_file = output_file
        self.dt_max = dt_max if dt_max > dt else 10 * dt
        self.theTkSimulation = TkSimulation
        self.plotter = None
        self.theEvaluator = None
        self.baseline_pre_periods = 0
        self.baseline_post_periods = 0
        self.periods = 2
        self.force_scale = force_scale
        self.final_cool_factor = 1
        self.cool_factor = 1
        self.do_preequilibration_with_fixed_boundaries = True
        self.imageOutputFolder = imageOutputFolder
        self.imageBaseFileName = imageBaseFileName
        self.imageFileType = imageFileType
        self.saveStressTensorData = saveStressTensorData
        # beyond the reference
        self.correct_drift_sign = False
        self.reference_header = False
        self.renderer = None
        self.stress_window = None
        self.image_N = None
        self.progress = None
        self.save_movie = False
        self.verbose = False
        self.keep_tensor_history = None
        self.timings = {}
        self.results = {}
        self.n_images_saved = 0
        self.N_steps = 0
        #: block 2 of the header as it was at the start of the run (kept for writers after the run)
        self.description_text = None
        #: (phase, step, total) of the running loop: where an interrupt stopped the run
        self.position = ("set-up", 0, 0)

    # -- signals ---------------------------------------------------------------------------------
    def in_phase_signal(self, t):
        """``sin(2π(t f − pre))``: the strain shape (the strain is A times it during the excitation).

        Parameters
        ----------
        t : float
            Time since the start of the protocol (s).

        Returns
        -------
        float
        """
        return math.sin(2 * math.pi * (t * self.f - self.baseline_pre_periods))

    def out_of_phase_signal(self, t):
        """``cos(2π(t f − pre))``: the strain-rate shape (the rate is 2πf·A times it).

        Parameters
        ----------
        t : float
            Time since the start of the protocol (s).

        Returns
        -------
        float
        """
        return math.cos(2 * math.pi * (t * self.f - self.baseline_pre_periods))

    def _say(self, *args):
        if self.verbose:
            _log.info(" ".join(str(a) for a in args))

    def _report(self, phase, step, total, t0, state):
        """Call the progress callback at most ~10 times per second (and at the end)."""
        if self.progress is None:
            return
        now = time.perf_counter()
        if step == total or now - state[0] >= 0.1:
            state[0] = now
            self.progress(phase, step, total, now - t0)

    # -- pre-equilibration -----------------------------------------------------------------------
    def pre_equilibrate(self, N=25, cool_factor=0.99):
        """Relax with the plates fixed: coarse levels from ``dt_max``, 2N steps at dt, N steps at dt.

        Stepped by the engine's one step on the ensemble's own state
        (:func:`particleShear.engine.step.pre_equilibrate` on :meth:`engine_of_ensemble`), the
        ensemble left in the final state (its clock, strain, relations and step count updated), for
        scripts that run the phases one by one; :meth:`oscillatory_shear_experiment` runs both.

        Runs with ``applyingShear = True`` (the plate band is immobile, the plates rest).  Each
        coarse level (step halved from ``dt_max`` down to ``dt``) takes ``int(N/2)`` steps with a
        damping factor rising from 0.5 towards 1; then 2N steps at dt with damping 0.98.  The
        last N steps use ``cool_factor`` and reset γ̇ to 0 by direct assignment before each step.
        The live particle window (if any) is redrawn after every step.

        Parameters
        ----------
        N : int, optional
            Step count unit (default 25; the simulations use ``25 · adjustment factor``).
        cool_factor : float, optional
            Per-step damping factor of the last N steps: fraction of the peculiar velocity kept
            per step (default 0.99).

        Raises
        ------
        SimulationInstabilityError
            If the ensemble's stability guard finds the run unstable.
        """
        with untouched_on_failure(self.theEnsemble):     # (also the predictor the engine drops)
            engine = self.engine_of_ensemble(carry_predictor=False)
            observers = self.observers(self._scene(engine), None, protocol=False)
            steps = self._pre_equilibrate_in(engine, N, cool_factor, observers)
        self._write_back(engine, steps)

    def _pre_equilibrate_in(self, engine, N, cool_factor, observers):
        """The pre-equilibration in ``engine`` (timed, guarded, reported); returns the steps run."""
        t0 = time.perf_counter()
        steps = _guarded(pre_equilibrate, engine, N, self.dt, self.dt_max, cool_factor, self._say,
                         self._reporter("pre-equilibration"), observers, dt=self.dt)
        self.timings["pre_equilibration"] = time.perf_counter() - t0
        return steps

    def free_pre_equilibration(self):
        """Unused by the reference protocol: relaxation without plates (kept for the reference API)."""
        ens = self.theEnsemble
        ens.applyingShear = False
        mu = getattr(ens, "mu", 0)
        N = int(20 * (2 - math.log10(mu))) if mu > 0 else 10
        for level_dt, cf in relaxation_levels(self.dt, self.dt_max):
            ens.mechanical_relaxation(N, cf, level_dt)
            ens.correct_linear_drift()
        ens.mechanical_relaxation(N, 1, self.dt)

    # -- images ----------------------------------------------------------------------------------
    def image_path(self, index):
        """``<folder>/<base><index padded to 7 digits>.<ext>`` (docs/output.md, "Snapshots").

        Parameters
        ----------
        index : int
            Protocol step of the snapshot.

        Returns
        -------
        str
        """
        ext = IMAGE_EXTENSIONS.get(self.imageFileType, IMAGE_EXTENSIONS["ps"])[0]
        return os.path.join(str(self.imageOutputFolder), str(self.imageBaseFileName) + f"{index:07d}" + ext)

    def save_canvas_image(self, index, scene=None):
        """Save a snapshot of the particle picture for protocol step ``index`` (if a renderer exists).

        Parameters
        ----------
        index : int
            Protocol step, used in the file name (:meth:`image_path`).
        scene : ensemble or ReplicaView, optional
            What is drawn (default :attr:`theEnsemble`; the engine's runs pass the
            :class:`~.observers.ReplicaView` of their replica).
        """
        if not self.saves_images():
            return
        scene = self.theEnsemble if scene is None else scene
        self.renderer.save(scene, self.image_path(index), self.imageFileType, step=index)
        self.n_images_saved += 1

    def saves_images(self):
        """Whether snapshots are saved: a renderer, an image folder and a base name exist.

        Returns
        -------
        bool
        """
        return self.renderer is not None and bool(self.imageOutputFolder) and bool(self.imageBaseFileName)

    def observers(self, scene, samples, live=True, protocol=True):
        """The observers of this experiment's drawing (:mod:`.observers`), for the loops of a measurement.

        A live particle window (with ``live`` and a live renderer), the snapshots and the movie
        (:meth:`saves_images`, ``save_movie``; the renderer starts collecting movie frames) and
        the live stress window (``plotStress`` and an open :attr:`stress_window`; its axes are
        drawn now).  Call once per measurement.

        Parameters
        ----------
        scene : callable
            ``scene(engine)``: what is drawn (a :class:`~.observers.ReplicaScene`).
        samples : callable
            ``samples(engine, lo, hi)``: t, γ, τ_surface, τ_internal of protocol steps
            ``lo … hi − 1`` (:meth:`~.observers.ReplicaScene.samples`).
        live : bool, default True
            Include the live particle window.
        protocol : bool, default True
            Include the observers of the protocol (snapshots, movie, live stress window); False
            for a pre-equilibration alone.

        Returns
        -------
        list of Observer
        """
        out = []
        r = self.renderer
        if live and r is not None and r.live:
            out.append(LiveDrawing(r, scene))
        if not protocol:
            return out
        T_total = (self.periods + self.baseline_pre_periods + self.baseline_post_periods) / self.f
        if self.saves_images():
            movie = None
            if self.save_movie:
                r.collect_movie = True
                folder = str(self.imageOutputFolder)
                movie = lambda: r.write_movie(os.path.join(folder, "movie.gif"))  # noqa: E731
            n = protocol_steps(self.periods, self.baseline_pre_periods, self.baseline_post_periods, self.f, self.dt)
            out.append(SnapshotWriter(self.save_canvas_image, scene, self.image_N or image_cadence(n), movie))
        if self.plotStress and self.stress_window is not None:
            out.append(StressWindow(self._make_plotter(T_total, self.stress_window), self.stress_window, samples))
        return out

    # -- the protocol ----------------------------------------------------------------------------
    def _make_plotter(self, T_total, window=None):
        """The recording plotter (``window`` None: draws nothing), or the plotter of the live stress
        ``window``, whose axes it draws (the :class:`~.observers.StressWindow` plots with it)."""
        canvas = window.canvas if window is not None else False
        plotter = EvaluationHandlerPlotter(window.tk if canvas else False, canvas,
                                           x_scale=self.width / T_total, y_scale_strain=30 / self.amplitude,
                                           y_scale_force=self.force_scale, r=2, offset_x=0,
                                           offset_y=self.height / 2, plotStress=bool(canvas))
        if canvas:
            self.outputCanvas = canvas
            window.draw_axes(T_total, plotter.x_scale, plotter.y_scale_force, plotter.y_scale_strain,
                             self.amplitude, self.baseline_pre_periods / self.f,
                             (self.baseline_pre_periods + self.periods) / self.f)
        return plotter

    def prepare_recording(self):
        """Create the evaluator and the plotter and preallocate the recording for the whole protocol."""
        ens = self.theEnsemble
        pre, P, post = self.baseline_pre_periods, self.periods, self.baseline_post_periods
        T_total = (P + pre + post) / self.f
        N_steps = int(T_total / self.dt)
        self.theEvaluator = StressTensorEvaluation(ens.size_x, ens.size_y)
        self.plotter = self._make_plotter(T_total)
        self.plotter.allocate(N_steps, keep_tensor_history=self._keeps_tensors())
        return N_steps

    def _keeps_tensors(self):
        """Whether the tensor history is recorded: ``keep_tensor_history``, or (None) when a file
        with the tensor table is written (``output_file`` and ``saveStressTensorData``)."""
        keep = self.keep_tensor_history
        if keep is None:
            keep = bool(self.output_file) and bool(self.saveStressTensorData)
        return bool(keep)

    def run_protocol(self, cool_factor, n_steps=None):
        """The measurement protocol, stepped by the engine's one step and its one protocol loop
        (:func:`particleShear.engine.step.protocol` on :meth:`engine_of_ensemble`), for scripts that
        run the phases one by one; :meth:`oscillatory_shear_experiment` runs both.

        Each step: set the shear rate (``A·2πf·cos(2π(f t − pre))`` during the excitation, else
        0), forces, recording, acceleration with damping, movement, then the experiment's
        observers (:meth:`observers`: live particle window, snapshots every ``image_N`` steps,
        movie, live stress window).  The clock starts at 0.  Afterwards the recording
        (:attr:`plotter`: series, tensor history when kept, first and last tensors;
        :attr:`theEvaluator`: the tensors of the last step) holds the steps run and the ensemble
        is in the final state.

        Parameters
        ----------
        cool_factor : float
            Per-step damping factor of the peculiar velocity (fraction kept per step).
        n_steps : int, optional
            Stop after that many steps (default: the whole protocol,
            ``int((P + pre + post)/f/dt)`` steps).

        Returns
        -------
        int
            Steps run.

        Raises
        ------
        SimulationInstabilityError
            If the ensemble's stability guard finds the run unstable.
        """
        engine = self.engine_of_ensemble(carry_predictor=True)
        scene = self._scene(engine)
        with untouched_on_failure(self.theEnsemble):
            record = self._protocol_in(engine, cool_factor, self.observers(scene, scene.samples), n_steps)
        self._write_back(engine, len(record["t"]))
        self._record(record)
        return self.N_steps

    def _protocol_in(self, engine, cool_factor, observers, n_steps=None):
        """The protocol in ``engine`` (timed, guarded, reported); returns the replica's record."""
        keep = self._keeps_tensors()
        t0 = time.perf_counter()
        out = _guarded(protocol, engine, self.dt, self.f, [self.amplitude], cool_factor, self.baseline_pre_periods,
                       self.periods, self.baseline_post_periods, keep, self._say, self._reporter("protocol"),
                       observers, dt=self.dt, stop=n_steps)
        self.timings["protocol"] = time.perf_counter() - t0
        return replica_record(out, 0, keep)

    def oscillatory_shear_experiment(self, cool_factor=1, N_pre_equilibration_fixed_boundaries=25):
        """Run pre-equilibration and protocol; return ``[G′_surface, G″_surface]`` (Pa).

        Measured by the engine's one step (:meth:`measure_in_engine`, as ``runSimulation`` and
        ``doParticleShearSimulation`` measure), the ensemble left in the final state.  Both
        demodulations are kept in ``results`` ("internal": overall tensor, eq. S1-24; "surface":
        external forces on the plates).

        Parameters
        ----------
        cool_factor : float, optional
            Per-step damping factor (default 1: none): the peculiar velocity ``v − γ̇ (y − Ly/2)``
            and the spin are multiplied by it every step.  The simulations pass
            ``cool_factor_per_period ** (f·dt)``.
        N_pre_equilibration_fixed_boundaries : int, optional
            ``N`` of :meth:`pre_equilibrate` (default 25); the pre-equilibration is skipped
            when ``do_preequilibration_with_fixed_boundaries`` is False.

        Returns
        -------
        list of float
            ``[G′_surface, G″_surface]`` in Pa.
        """
        self.describe(cool_factor)
        if self.output_file:
            self.write_experiment_description_information_to_file()
        record, timings = self.measure_in_engine(cool_factor, N_pre_equilibration_fixed_boundaries)
        return self.adopt_measurement(cool_factor, record, timings)

    def measure_in_engine(self, cool_factor, N_pre=25):
        """Pre-equilibration and protocol of this experiment in the engine, on the ensemble's own
        state; the ensemble is left in the engine's final state.

        The one step and the one protocol loop of every run (:func:`particleShear.engine.step.pre_equilibrate`,
        :func:`~particleShear.engine.step.protocol`) in one engine (:meth:`engine_of_ensemble`),
        observed by this experiment's drawing (:meth:`observers`).  The recording (:attr:`plotter`,
        :attr:`theEvaluator`) is made from the engine's record when the run is complete
        (:meth:`adopt_measurement`).  Afterwards the ensemble's clock, strain, shear rate and
        relations are the engine's (the spheres were stepped in place).

        Parameters
        ----------
        cool_factor : float
            Per-step damping factor of the peculiar velocity (fraction kept per step).
        N_pre : int, optional
            ``N`` of the pre-equilibration (skipped when ``do_preequilibration_with_fixed_boundaries``
            is False).

        Returns
        -------
        record : dict of ndarray
            The replica's record of :func:`~particleShear.engine.step.protocol` (tensors only when
            ``keep_tensor_history``; see :meth:`adopt_measurement`).
        timings : dict
            Wall times of "pre_equilibration" and "protocol" (s).
        """
        self.timings["pre_equilibration"] = 0.0
        with untouched_on_failure(self.theEnsemble):     # (also the predictor the engine drops)
            engine = self.engine_of_ensemble(carry_predictor=False)
            scene = self._scene(engine)
            observers = self.observers(scene, scene.samples)
            if self.do_preequilibration_with_fixed_boundaries:
                self._pre_equilibrate_in(engine, N_pre, cool_factor, observers)
            record = self._protocol_in(engine, cool_factor, observers)
        self._write_back(engine, len(record["t"]))
        return record, {k: self.timings[k] for k in ("pre_equilibration", "protocol")}

    def engine_of_ensemble(self, carry_predictor=True):
        """A batch of one on the ensemble's own state (:func:`~particleShear.base.engine_adapter.state_of_ensemble`,
        on the default backend: compiled where Numba is installed): the ensemble's integrator, stability guard (its interval and the thresholds of a
        :class:`~particleShear.base.stability.StabilityGuard`; a guard's own ``check`` is not
        called) and contact-law callbacks; it numbers the relations as they form (as every engine on
        an ensemble's own state does), for the write-back.

        Parameters
        ----------
        carry_predictor : bool, default True
            With velocity Verlet, continue the ensemble's predictor, which its state holds (the
            protocol after a pre-equilibration; :mod:`particleShear.engine.predictor`); False drops
            it first, as every measurement does at its pre-equilibration (the half kick of a
            constitution predates its crosslinking).

        Returns
        -------
        BatchEngine
            Its ``terms_to`` is a :class:`~particleShear.base.register.KeptTerms`: the terms of its
            last force phase, for the ensemble's force register.
        """
        ens = self.theEnsemble
        guard = getattr(ens, "stability_guard", None)
        state = state_of_ensemble(ens, backend="auto")      # (holds the ensemble's Verlet predictor)
        if not carry_predictor:
            state.predictor.drop()
        thresholds = ({} if guard is None else     # the thresholds of the ensemble's guard
                      dict(min_distance_ratio=guard.min_distance_ratio, max_kinetic_energy=guard.max_kinetic_energy))
        # keep_terms: the last step's terms, handed to a KeptTerms for the ensemble's force register;
        # "auto": compiled where Numba is installed (the same numbers, terms included)
        return BatchEngine(state, skin_factor=ENGINE_SKIN_FACTOR, guard=guard is not None,
                           check_interval=getattr(guard, "interval", 4), integrator=getattr(ens, "integrator", "euler"),
                           keep_terms=True, terms_to=KeptTerms(), numbers_relations=True, **thresholds)

    def _scene(self, engine):
        scene = ReplicaScene(getattr(self.theEnsemble, "graphical_output_configuration", None))
        scene.bind(engine, 0)
        return scene

    def _reporter(self, phase):
        """The engine's ``report(step, total)`` of ``phase``: :attr:`position` and the progress callback."""
        t0, state = time.perf_counter(), [0.0]

        def report(step, total):
            self.position = (phase, step, total)
            self._report(phase, step, total, t0, state)
        return report

    def _write_back(self, engine, steps):
        """The engine's plates and relations into the ensemble (its clock, strain, rate, μ and Verlet
        predictor are the ensemble's own already: :func:`~particleShear.base.engine_adapter.write_back`),
        and its last force phase into the ensemble's force register (the six lists, the totals), as
        the documented step loop leaves them."""
        ens = self.theEnsemble
        if engine.phase == "protocol":
            ens.step_count = 0        # the protocol's steps, as the documented loop counts them
        write_back(engine, 0, ens, steps, constitution=False, dt=self.dt)
        ens.phase = engine.phase
        ens.force_register.set_from_engine(ens, engine, engine.terms_to.last)

    def _conclude(self, G_int, G_surf, t0):
        """Keep the demodulations, say them (verbose), write block 3 to ``output_file``; return G_surface."""
        self.results = {"internal": G_int, "surface": G_surf}
        self.timings["demodulation"] = time.perf_counter() - t0
        if self.verbose:
            p = self.plotter
            if p.last_tensors is not None:
                _log.info("Overall stress tensor, last step: %s", p.last_tensors[-1].tolist())
                _log.info("Overall stress tensor, first step: %s", p.first_tensors[-1].tolist())
            for label, v in (("G'", G_int[2]), ("G''", G_int[3]), ("G'(by surface force)", G_surf[2]),
                             ("G''(by surface force)", G_surf[3])):
                _log.info("%s", label)
                _log.info("%s", v)
                _log.info("Pa")
        t0 = time.perf_counter()
        if self.output_file:
            self.write_output_information_to_file()
        self.timings["output"] = time.perf_counter() - t0
        return [G_surf[2], G_surf[3]]

    def adopt_measurement(self, cool_factor, record, timings=None):
        """Take the measurement of this experiment from the engine's record instead of running it.

        The engine (:mod:`particleShear.engine`, used by :func:`particleShear.simulation.driver.measure_sessions`)
        pre-equilibrates and shears the same ensemble with the same schedule; this fills the
        recording (:attr:`plotter`: series, tensor history when kept, first and last tensors),
        demodulates the recorded series exactly as :meth:`oscillatory_shear_experiment` does and
        keeps block 2 of the header, so the output writers see the same thing either way.

        Parameters
        ----------
        cool_factor : float
            The per-step damping factor the engine used.
        record : dict of ndarray
            One replica's record of :func:`particleShear.engine.step.protocol`: "t", "strain",
            "strain_rate", "stress_surface", "stress_internal" (n,), "first_tensors",
            "last_tensors" (9, 2, 2) and, when kept, "tensors" (n, 9, 2, 2).
        timings : dict, optional
            Wall times of "pre_equilibration" and "protocol" (s).

        Returns
        -------
        list of float
            ``[G′_surface, G″_surface]`` in Pa.
        """
        if self.description_text is None or self.cool_factor != cool_factor:
            self.describe(cool_factor)
        self._record(record)
        self.timings.update(timings or {})
        t0 = time.perf_counter()
        # the contiguous series of the record, demodulated as the batch driver always did
        G_int = self.demodulation(record["t"], record["stress_internal"])
        G_surf = self.demodulation(record["t"], record["stress_surface"])
        return self._conclude(G_int, G_surf, t0)

    def describe(self, cool_factor):
        """What the recording takes from the ensemble, read before a measurement at ``cool_factor``:
        block 2 of the file (:attr:`description_text`: model, ensemble and protocol parameters) and
        the evaluator of the tensors (:attr:`theEvaluator`, of the ensemble's cell).

        Called by :meth:`oscillatory_shear_experiment` and by the driver's hand-over
        (:meth:`~particleShear.simulation.oscillatory.RunSession.hand_over`), after which a
        measurement and :meth:`adopt_measurement` read nothing of the ensemble.

        Parameters
        ----------
        cool_factor : float
            The per-step damping factor of the measurement (written in block 2).
        """
        self.cool_factor = cool_factor
        self.description_text = experiment_description_text(self, reference_header=self.reference_header)
        if self.theEvaluator is None:
            self.theEvaluator = StressTensorEvaluation(self.theEnsemble.size_x, self.theEnsemble.size_y)

    def _record(self, record):
        """The recording of a replica's record: :attr:`plotter` (series, tensor history when kept,
        first and last tensors), :attr:`theEvaluator` (the tensors of the last step), :attr:`N_steps`."""
        n = len(record["t"])
        T_total = (self.periods + self.baseline_pre_periods + self.baseline_post_periods) / self.f
        if self.theEvaluator is None:         # a prepared recording (prepare_recording) is filled
            self.theEvaluator = StressTensorEvaluation(self.theEnsemble.size_x, self.theEnsemble.size_y)
        if self.plotter is None:
            self.plotter = self._make_plotter(T_total)
        p = self.plotter
        keep = self._keeps_tensors() and "tensors" in record
        p.keep_tensor_history = keep
        scal = np.empty((n, 5))
        for col, key in ((_T, "t"), (_STRAIN, "strain"), (_RATE, "strain_rate"), (_FORCE, "stress_surface"),
                         (_SHEAR, "stress_internal")):
            scal[:, col] = record[key]
        p._scal, p._tens, p._n, p._planned = scal, (record["tensors"] if keep else None), n, n
        if n:
            p.first_tensors = np.array(record["first_tensors"])
            p.last_tensors = np.array(record["last_tensors"])
            self.theEvaluator.tensors[...] = p.last_tensors
        self.N_steps = n
        self.position = ("protocol", n, n)

    # -- evaluation ------------------------------------------------------------------------------
    def demodulation(self, t, shear_stress):
        """``[in-phase stress, out-of-phase stress, G′, G″]`` of a series, with this protocol's settings.

        Parameters
        ----------
        t : array_like
            Sample times since the start of the protocol (s).
        shear_stress : array_like
            Shear stress samples (Pa).

        Returns
        -------
        list of float
            See :func:`~.evaluation.demodulation` (Pa).
        """
        return demodulation(t, shear_stress, self.f, self.amplitude, self.baseline_pre_periods, self.periods,
                            self.baseline_post_periods, correct_drift_sign=self.correct_drift_sign)

    def evaluateStressAndG(self, useExternalForce=False):
        """Demodulate τ_surface (``useExternalForce=True``) or τ_internal (False) of the recorded run.

        Parameters
        ----------
        useExternalForce : bool, optional
            True: the stress from the external (plate) forces; False (default): the xy
            component of the overall stress tensor (eq. S1-24).

        Returns
        -------
        list of float
            ``[SA, SB, G′, G″]`` in Pa.
        """
        p = self.plotter
        s = p.force_array if useExternalForce else p.shear_stress_array
        return self.demodulation(p.t_array, s)

    # -- output ----------------------------------------------------------------------------------
    def write_experiment_description_information_to_file(self):
        """Block 2 of the output file (docs/output.md); nothing without an output file (``False``/None)."""
        if not self.output_file:
            return
        text = self.description_text or experiment_description_text(self, reference_header=self.reference_header)
        self.output_file.write(text)

    def write_output_information_to_file(self):
        """Block 3 of the output file (docs/output.md): summary and (optionally) the 42-column table; nothing without
        an output file (``False``/None)."""
        if not self.output_file:
            return
        G_int = self.results.get("internal") or self.evaluateStressAndG(False)
        G_surf = self.results.get("surface") or self.evaluateStressAndG(True)
        out = self.output_file
        out.write(output_summary_text(G_int, G_surf, reference_header=self.reference_header))
        p = self.plotter
        if self.saveStressTensorData and p.tensor_history is not None:
            for piece in iter_table_text(p._scal[: len(p)], p.tensor_history):  # streamed: bounded memory
                out.write(piece)
        elif self.saveStressTensorData:
            warnings.warn("OscillatoryShearExperiment: tensor history was not kept; writing no table", RuntimeWarning,
                          stacklevel=2)
            out.write("\n" + NO_TENSOR_DATA_TEXT)
        else:
            out.write("\n" + NO_TENSOR_DATA_TEXT)
