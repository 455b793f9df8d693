"""The oscillatory simulation class: ensemble construction + experiment + output file (docs/output.md).

The fragmentation classes of :mod:`.fragmentation` subclass :class:`OscillatorySimulation`;
:mod:`.simulations` gathers all of them.

``runSimulation`` (inherited by every class) validates the output settings (and probes the
folder) before any work, builds the ensemble (``initEnsemble``), reserves the file number,
drives the :class:`OscillatoryShearExperiment`, then streams the file (format
``output_format``) and its JSON sidecar to disk and renames them into place; it returns
``[G′_surface, G″_surface]`` (Pa).  The full outcome (both moduli pairs, timings, output path,
write error) is kept in ``self.result_info`` after the run.  See ``docs/output.md``.
"""
__docformat__ = "numpy"
import io
import json
import logging
import os
import shutil
import sys
import time
from collections import namedtuple

from ..base.engine_adapter import state_from_ensembles
from ..linkable.builders import relax_constitution
from ..base.stability import StabilityGuard
from ..engine.relax import RELAX_SKIN
from .drawing import make_renderer, open_stress_plot
from .driver import measure_sessions
from .experiment import OscillatoryShearExperiment
from .formats import FORMAT_SUFFIXES, check_output_format, table_rows, text_stream, write_run
from .output import (IMAGE_FOLDER_SUFFIX, REFERENCE_IMAGE_FOLDER_SUFFIX, number_is_free, output_summary_text,
                     probe_writable, reserve_numbered_path, run_file_stem, sidecar_path)
from .provenance import json_safe, package_version

_log = logging.getLogger(__name__)

__all__ = ["MeasurementSchedule", "RunSession", "OscillatorySimulation", "check_output_folder"]


def check_output_folder(root_folder, saveData, saveOutputImages, doDrawing=True):
    """Raise ValueError when output is requested without a usable ``root_folder``.

    The reference crashed or wrote to file descriptor 0 here (defect #26 in docs/output.md).

    Parameters
    ----------
    root_folder : str or os.PathLike
        The output folder; must exist and be writable (probed) when anything is saved.
    saveData : bool
        Whether the text file is written.
    saveOutputImages : bool
        Whether snapshots are saved (rendered off-screen, with or without ``doDrawing``).
    doDrawing : bool, optional
        Accepted for the reference signature; snapshots do not depend on it (default True).

    Raises
    ------
    ValueError
        Naming ``root_folder`` when output is requested and the folder is empty, missing or
        not writable.
    """
    wants = []
    if saveData:
        wants.append("saveData=True")
    if saveOutputImages:  # snapshots are rendered off-screen, with or without doDrawing
        wants.append("saveOutputImages=True")
    if not wants:
        return
    if not root_folder or not isinstance(root_folder, (str, os.PathLike)):
        raise ValueError(f"root_folder={root_folder!r} is invalid: {' and '.join(wants)} needs an existing "
                         "output folder (a non-empty path)")
    if not os.path.isdir(root_folder):
        raise ValueError(f"root_folder={root_folder!r} is invalid: {' and '.join(wants)} needs an existing "
                         "output folder (no such directory)")
    try:
        probe_writable(root_folder)
    except OSError as exc:
        raise ValueError(f"root_folder={root_folder!r} is invalid: {' and '.join(wants)} needs a writable "
                         f"output folder ({exc.strerror or exc})") from exc


#: the step schedule of one measurement (see OscillatorySimulation.measurement_schedule)
MeasurementSchedule = namedtuple("MeasurementSchedule", "dt f cool N_pre dt_max")
MeasurementSchedule.__doc__ = """``(dt, f, cool, N_pre, dt_max)``: protocol step (s), excitation frequency (Hz),
damping factor per step, pre-equilibration step unit and coarsest pre-equilibration step (s)."""


class RunSession:
    """One run of :meth:`OscillatorySimulation.runSimulation`, in its phases.

    :func:`particleShear.simulation.driver.measure_sessions` drives the phases of one session
    (``runSimulation``) or of a batch's (``run_batch``, ``doParticleShearSimulation``): the engine
    measures and each experiment adopts its record, so every run builds, reserves, writes and
    cleans up in one way (docs/output.md, docs/engine.md "Runs").

    Parameters
    ----------
    simulation : OscillatorySimulation
        The configured simulation (not yet constituted).
    cool_factor : float
        Fraction of the peculiar velocity left after one excitation period, 0 < c ≤ 1.
    periods : float
        Excitation periods, > 0.
    plotStress : bool
        Live stress/strain window.

    Raises
    ------
    ValueError
        For an unusable ``root_folder``, ``periods`` ≤ 0, ``cool_factor`` outside (0, 1] or an
        unknown output format — before any work.
    """

    def __init__(self, simulation, cool_factor, periods, plotStress):
        sim = simulation
        check_output_folder(sim.root_folder, sim.saveData, sim.saveOutputImages, sim.doDrawing)
        if not periods > 0:
            raise ValueError(f"periods={periods!r} is out of range: allowed > 0")
        if not 0 < cool_factor <= 1:
            raise ValueError(f"cool_factor={cool_factor!r} is out of range: allowed 0 < value <= 1")
        self.output_format = getattr(sim, "output_format", "text")
        check_output_format(self.output_format)
        self.sim, self.cool_factor, self.periods, self.plotStress = sim, cool_factor, periods, plotStress
        self.out = None          # the reservation of the output file (a locked .part file)
        self.image_tmp = None    # the temporary snapshot folder
        self.image_folder = False
        self.header = None       # block 1 of the file
        self.exp = None
        self.schedule = None
        self.t_start = time.perf_counter()
        self.state = None                 # the measurement's state (hand_over)
        self.scene_configuration = None   # the ensemble's drawing configuration (hand_over)
        self.removed_fraction = 0.0

    def constitution(self, relaxation_law=None, relaxation_backend="numpy", skin_factor=RELAX_SKIN):
        """The constitution as a generator of its relaxations (docs/engine.md, "Runs").

        Yields each :class:`~particleShear.linkable.builders.Relaxation` of the constitution (the
        caller runs it in the engine, alone or with a batch's, and resumes) when the
        simulation's ``initEnsemble`` is one of the documented simulation classes'
        (:meth:`OscillatorySimulation.constitution_builder`), as ``constitution_steps``
        with that class's builder, on the engine's state; any other ``initEnsemble`` (a
        subclass's own) is called as it is, with nothing yielded.  It reports ``progress("constitution", …)`` at its start and end; the ``constitution``
        timing is the wall time since the start less :attr:`waited` (time the caller spent on
        other runs while this one was suspended).

        Parameters
        ----------
        relaxation_law, relaxation_backend, skin_factor : optional
            The central law, host backend and Verlet skin of the relaxations, passed to
            ``constitution_steps`` (defaults: the builders'; the driver gives the run's law and
            backend and its skin).

        Yields
        ------
        Relaxation
            The next relaxation block of the constitution.
        """
        sim = self.sim
        sim.write_error = None
        sim.theExperiment = None
        self.t_start = time.perf_counter()  # the run's clock starts with its own constitution
        self.waited = 0.0
        if sim.progress is not None:
            sim.progress("constitution", 0, 0, 0.0)
        builder = sim.constitution_builder()
        if builder is not None:
            yield from sim.constitution_steps(relaxation_law=relaxation_law, relaxation_backend=relaxation_backend,
                                              skin_factor=skin_factor, builder=builder)
        else:
            sim.initEnsemble()
        sim.timings["constitution"] = time.perf_counter() - self.t_start - self.waited
        if sim.progress is not None:
            sim.progress("constitution", 1, 1, sim.timings["constitution"])

    def prepare(self):
        """Renderer, reservation of the file number, block 1, the experiment and the schedule."""
        sim = self.sim
        sim._attach_renderer()
        sim.dt, sim.f, _ = sim.time_steps()
        fileName = False
        if sim.saveData or sim.saveOutputImages:
            # the reservation (a locked .part file) is held for the whole run, also when only
            # the image folder needs the name
            self.out = reserve_numbered_path(sim._file_stem(), FORMAT_SUFFIXES[self.output_format])
            fileName = self.out.path
        sim.output_path = fileName if sim.saveData else None
        if sim.saveOutputImages and sim.renderer is not None and fileName:
            self.image_tmp = self.out.dependent("images")
            os.makedirs(self.image_tmp)
            self.image_folder = sim.image_folder_path(fileName)
        if sim.saveData:
            block1 = io.StringIO()
            sim.write_information_on_simulation_to_file(block1)
            self.header = block1.getvalue()
        exp = self.exp = sim.createExperiment(False, self.periods, self.plotStress, self.image_tmp or False)
        exp.keep_tensor_history = bool(sim.saveData and sim.saveStressTensorData)
        self.schedule = sim.measurement_schedule(self.cool_factor)
        if sim.verbose:
            _log.info("cool factor per dt= " + str(self.schedule.cool))
            if sim.saveData:
                _log.info("Writing output to file " + fileName)
        return exp

    def hand_over(self):
        """The constituted ensemble as the measurement's state, copied once (after :meth:`prepare`).

        The one point where a measurement reads the documented ensemble: its spheres, box, clock,
        constants, pair list with its history and generator become :attr:`state` (one replica, on
        the host; :func:`~particleShear.base.engine_adapter.state_from_ensembles`), with the two
        facts a result reports from it, :attr:`scene_configuration` and :attr:`removed_fraction`.
        It runs after :meth:`prepare`, so whatever the experiment set on the ensemble is handed over
        too; from here on the driver (:func:`~particleShear.simulation.driver.measure_sessions`)
        reads this state and never the ensemble.  A copy, also where the ensemble is a view of a
        constituted state (``sim.constituted``): the measurement does not step that state, and
        ``theEnsemble`` stays the constituted gel after the run."""
        sim = self.sim
        ens = sim.theEnsemble
        self.state = state_from_ensembles([ens], backend="numpy", laws=[sim.contact_law])
        self.scene_configuration = getattr(ens, "graphical_output_configuration", None)
        self.removed_fraction = float(getattr(ens, "removed_fraction", 0.0))
        if self.exp is not None:          # block 2 of the file and the evaluator, from the ensemble
            self.exp.describe(self.schedule.cool)

    def finish(self):
        """After the measurement: snapshot folder and output file into place, ``result_info``; G.

        A failure while writing does not lose the result: it is kept in ``write_error``.

        Returns
        -------
        list of float
            ``[G′_surface, G″_surface]`` (Pa).
        """
        sim, exp, out = self.sim, self.exp, self.out
        t0 = time.perf_counter()
        try:
            if self.image_tmp is not None:
                os.rename(self.image_tmp, self.image_folder)  # complete: the folder appears under its name
                self.image_tmp = None
            if sim.saveData:
                sim._write_output(out, self.header, exp, self.output_format)
        except Exception as exc:  # noqa: BLE001 - any write failure: keep the computed result
            sim.write_error = exc
            sim.output_path = None
            if sim.verbose:
                _log.warning("Writing the output failed: " + repr(exc))
        if out is not None and not out.committed:
            out.abort()  # images only (or a failed write): release the reservation
        exp.timings["output"] = exp.timings.get("output", 0.0) + time.perf_counter() - t0
        sim.timings.update(exp.timings)
        sim.timings["total"] = time.perf_counter() - self.t_start
        surf, internal = exp.results["surface"], exp.results["internal"]
        sim.result_info = {
            "G_surface": (surf[2], surf[3]), "G_internal": (internal[2], internal[3]),
            "stress_surface": (surf[0], surf[1]), "stress_internal": (internal[0], internal[1]),
            "dt": sim.dt, "f": sim.f, "N_steps": exp.N_steps, "N_pre_equilibration": self.schedule.N_pre,
            "damping_factor": self.schedule.cool, "output_path": sim.output_path,
            "image_folder": (self.image_folder if self.image_tmp is None else None) or None,
            "n_images": exp.n_images_saved, "timings": dict(sim.timings), "write_error": sim.write_error,
        }
        return [surf[2], surf[3]]

    def position(self):
        """``(phase, step, total)`` where the run is (where an interrupt stopped it)."""
        exp = self.sim.theExperiment
        return exp.position if exp is not None else ("constitution", 0, 0)

    def close(self):
        """Remove every temporary entry (an uncommitted reservation, the snapshot folder), close windows."""
        if self.out is not None and not self.out.committed:
            self.out.abort()
        if self.image_tmp is not None and os.path.isdir(self.image_tmp):
            shutil.rmtree(self.image_tmp, ignore_errors=True)
        self.sim._close_windows()


class _TextSink:
    """Text writes encoded as UTF-8 into a binary file (plain or gzip)."""

    def __init__(self, binary):
        self._b = binary

    def write(self, text):
        self._b.write(text.encode("utf-8"))


def _writes(simulation, theFile):
    """Whether ``write_information_on_simulation_to_file`` writes: a file is given (``False``/None mean
    none, as in the reference) and the simulation saves data (1.0.2 writes nothing with ``saveData=False``)."""
    return theFile is not False and theFile is not None and bool(simulation.saveData)


def call_string(name, **arguments):
    """``name(k1=v1,k2=v2,...)`` with ``str()`` values and no spaces: the header's function-call line.

    Parameters
    ----------
    name : str
        The function or class name.
    **arguments
        The arguments, in order.

    Returns
    -------
    str
    """
    return name + "(" + ",".join(k + "=" + str(v) for k, v in arguments.items()) + ")"


class OscillatorySimulation:
    """Base class: output paths, file header, experiment set-up and the run.

    Parameters
    ----------
    root_folder : str
        Folder of the text file and the image folder (needed when saving).
    amplitude : float
        Strain amplitude A.
    relative_y_scale_force : float
        Plot scaling of the stress window only.
    relative_frequency : float
        Excitation frequency in units of 1/τ (f = relative_frequency/τ).
    doDrawing : bool
        Particle drawing (live window when a display exists; needed for snapshots).
    saveData : bool
        Write the text file (docs/output.md).

    Attributes beyond the reference: ``rng`` (Generator/seed for the builder), ``verbose``,
    ``renderer_backend`` ("auto", "tk", "pillow", "none"), ``correct_drift_sign``,
    ``reference_header`` (see :class:`OscillatoryShearExperiment`), ``progress``
    (callback), ``timings`` and ``result_info`` (after the run), ``output_path``.
    """

    #: multiplies dt and dt_max of the measurement (1 = the reference rule)
    time_step_factor = 1.0
    #: "euler" (reference) or "verlet"
    integrator = "euler"
    #: stop a diverging measurement with a clear error
    stability_guard = True
    #: file format of ``saveData``: "text" (reference), "text.gz", "npz" or "parquet" (see .formats)
    output_format = "text"
    #: provenance written into the header and the sidecar (set by doParticleShearSimulation)
    run_id = None
    seed_entropy = None
    spawn_key = ()
    #: the run's checked arguments (a :class:`~particleShear.run.validation.RunParameters`; None outside a run)
    parameters = None
    #: the backend that measured the run (``backend="auto"`` resolved by the driver; None before)
    backend_used = None
    #: the contact law of the run, ``(name, values)`` of ``run.validation.contact_law_spec`` (None: the callbacks')
    contact_law = None
    #: the exception of a failed write after the run (None when the output was written)
    write_error = None

    def __init__(self, root_folder, amplitude=0.5, relative_y_scale_force=5e-4, relative_frequency=0.05,
                 doDrawing=True, saveData=False):
        self.amplitude = amplitude
        self.doDrawing = doDrawing
        self.relative_y_scale_force = relative_y_scale_force
        self.relative_frequency = relative_frequency
        self.theTkSimulation = False
        self.f = -1
        self.root_folder = root_folder
        self.saveData = saveData
        self.baseline_pre_periods = 0
        self.baseline_post_periods = 0
        self.imageOutputFolder = False
        self.imageBaseFileName = "image"
        self.saveOutputImages = False
        self.imageFileType = "jpg"
        self.saveStressTensorData = True
        self.function_call = "OscillatorySimulation(root_folder=" + str(root_folder) + ")"
        self.theExperiment = None
        self.theEnsemble = None
        self.model = False
        # beyond the reference
        self.rng = None
        self.verbose = False
        self.renderer_backend = "auto"
        self.renderer = None
        self.correct_drift_sign = False
        self.reference_header = False
        self.progress = None
        self.timings = {}
        self.result_info = None
        self.output_path = None

    # -- ensemble --------------------------------------------------------------------------------
    def initEnsemble(self):
        """Base class: nothing to build (subclasses create ``theEnsemble``)."""
        return None

    def constitution_builder(self):
        """The documented class whose builder constitutes this simulation on the engine's state
        (with ``constitution_steps``, batched by a run's driver), or None: ``initEnsemble`` is
        called as it is (here; the documented simulation classes say which, ``simulation.fragmentation``)."""
        return None

    def _attach_renderer(self):
        """Choose the drawing backend now that the ensemble exists (live window or files or nothing)."""
        ens = self.theEnsemble
        want_images = bool(self.saveOutputImages) and bool(self.root_folder)
        title = self._window_title()
        self.renderer = make_renderer(self.doDrawing, want_images, ens.size_x, ens.size_y, title,
                                      getattr(ens, "graphical_output_configuration", None),
                                      backend=self.renderer_backend)
        if self.renderer is not None and self.renderer.live:
            ens._renderer = self.renderer
            self.theTkSimulation = getattr(self.renderer, "root", False)
            ens.initiateGraphics()

    def _window_title(self):
        return "particleShear A=" + str(self.amplitude)

    def adjustment_factor_for_bounded_preequilibration_steps(self):
        """Multiplier of the fixed-boundary pre-equilibration length (``N = 25 · int(factor)``); 1 here."""
        return 1

    # -- paths -----------------------------------------------------------------------------------
    def _file_stem(self):
        return os.path.join(str(self.root_folder), "oscillatory_simulation_")

    def file_path(self):
        """``root/<name><k>.txt`` for the smallest k ≥ 1 not yet used (docs/output.md, "Name"); False without a root folder."""
        if not self.root_folder:
            return False
        stem = self._file_stem()
        suffix = FORMAT_SUFFIXES.get(getattr(self, "output_format", "text"), ".txt")
        for k in range(1, 1_000_001):  # bounded, as reserve_numbered_path
            if number_is_free(stem + str(k) + suffix):
                return stem + str(k) + suffix
        raise OSError("no free file number for " + stem + "<k>" + suffix)

    def image_folder_path(self, fileName):
        """The snapshot folder of the run file ``fileName`` (docs/output.md, "Snapshots").

        ``<run name>_images``: the file's path without its format suffix (``x_nr_1.txt`` →
        ``x_nr_1_images``), so the folder is named after the run whether or not a file is written;
        with ``reference_header=True`` the reference's ``<file path>_images_folder``
        (``x_nr_1.txt_images_folder``).

        Parameters
        ----------
        fileName : str or os.PathLike
            The path of the run's (reserved) output file.

        Returns
        -------
        str
        """
        if getattr(self, "reference_header", False):
            return str(fileName) + REFERENCE_IMAGE_FOLDER_SUFFIX
        return run_file_stem(fileName) + IMAGE_FOLDER_SUFFIX

    def createFolder(self, directory):
        """Create ``directory`` (and its parents); ``False``/None (no folder, as in the reference) does nothing.

        Parameters
        ----------
        directory : str, os.PathLike, False or None
            The folder.
        """
        if directory is False or directory is None:
            return
        os.makedirs(directory, exist_ok=True)

    def write_information_on_simulation_to_file(self, theFile):
        """Block 1 of the text file (docs/output.md); nothing for ``theFile`` False/None or ``saveData`` False.

        Parameters
        ----------
        theFile : file-like, False or None
            An open text file (or any object with ``write``).
        """
        if not _writes(self, theFile):
            return
        theFile.write("Oscillatory simulation\n\n\n\nFunction call : \n" + self.function_call + "\n\n")

    # -- experiment ------------------------------------------------------------------------------
    def createExperiment(self, output_file=False, periods=2, plotStress=False, imageOutputFolder=False):
        """Build the experiment exactly as :meth:`runSimulation` does (also used by the stochastic tests).

        Parameters
        ----------
        output_file : file-like or False, optional
            Where the experiment writes its description and results (default False: nothing).
        periods : float, optional
            Excitation periods (default 2).
        plotStress : bool, optional
            Live stress/strain window (default False).
        imageOutputFolder : str or False, optional
            Snapshot folder (default False: none).

        Returns
        -------
        OscillatoryShearExperiment
            Also kept as ``self.theExperiment``.
        """
        ens = self.theEnsemble
        model = self.model or getattr(ens, "model", False)
        y_scale_force = self.relative_y_scale_force / model.k / self.amplitude if model else 1
        self.dt, self.f, dt_max = self.time_steps()
        ens.set_integrator(getattr(self, "integrator", "euler"))
        if getattr(self, "stability_guard", True):
            ens.stability_guard = StabilityGuard()
        if self.verbose:
            _log.info("Setting relative frequency: " + str(self.relative_frequency) + " f= " + str(self.f) + "Hz")
        exp = OscillatoryShearExperiment(ens, self.dt, self.f, self.amplitude, output_file,
                                         force_scale=y_scale_force, TkSimulation=self.theTkSimulation,
                                         dt_max=dt_max, imageOutputFolder=imageOutputFolder,
                                         imageBaseFileName=self.imageBaseFileName,
                                         imageFileType=self.imageFileType, plotStress=plotStress,
                                         saveStressTensorData=self.saveStressTensorData)
        exp.periods = periods
        exp.baseline_pre_periods = self.baseline_pre_periods
        exp.baseline_post_periods = self.baseline_post_periods
        exp.do_preequilibration_with_fixed_boundaries = True
        exp.correct_drift_sign = self.correct_drift_sign
        exp.reference_header = self.reference_header
        exp.renderer = self.renderer
        exp.save_movie = bool(getattr(self, "saveOutputMovie", False))
        exp.verbose = self.verbose
        exp.progress = self.progress
        if self.verbose:
            _log.info("Creating oscillatory shear experiment, dt = " + str(exp.dt) + " max dt = " + str(exp.dt_max))
            _log.info("OscillatoryShearExperiment: Plot stress graph: " + str(plotStress))
        if plotStress and self.doDrawing:
            exp.stress_window = open_stress_plot(exp.width, exp.height, renderer=self.renderer,
                                                 backend=self.renderer_backend)
        self.theExperiment = exp
        return exp

    def runSimulation(self, cool_factor=1, periods=2, plotStress=True):
        """Build, equilibrate, shear, write; return ``[G′_surface, G″_surface]`` (Pa).

        Measured as ``doParticleShearSimulation`` measures: the constitution's relaxations, the
        pre-equilibration and the protocol run in the engine, a batch of one
        (:func:`particleShear.simulation.driver.measure_sessions`); the drawing, snapshots and the live
        stress window observe its loops.  Spheres with parameters of their own (c, permanent
        ratios, kept viscosities set through the sphere handles) are measured by the engine too:
        each visit of a relation sees its own sphere's values, as in 1.0.2.

        Output (see ``docs/output.md``): the folder is probed for writability before any work;
        the file number is reserved (a locked ``.part`` file) when the ensemble exists, snapshots
        go to a temporary folder renamed when the protocol is complete, and the file (format
        ``self.output_format``) and its JSON sidecar are streamed to disk after the run and
        renamed into place.  A failure while writing after the run does not lose the result:
        it is kept in ``self.write_error`` (and ``result_info["write_error"]``) and nothing
        partial is left.  An interrupt (``KeyboardInterrupt``) removes every temporary entry
        and is re-raised with ``position = (phase, step, total)`` attached.

        Parameters
        ----------
        cool_factor : float, optional
            Fraction of the peculiar velocity left after one excitation period, 0 < c ≤ 1
            (default 1: no damping); the per-step factor is ``cool_factor ** (1/N_per_period)``
            with ``N_per_period = 1/(f·dt)``.
        periods : float, optional
            Excitation periods, > 0 (default 2).
        plotStress : bool, optional
            Live stress/strain window (needs a display; default True).

        Returns
        -------
        list of float
            ``[G′_surface, G″_surface]`` in Pa (moduli from the plate forces).

        Raises
        ------
        ValueError
            For an unusable ``root_folder``, ``periods`` ≤ 0, ``cool_factor`` outside (0, 1] or an
            unknown output format — before any work.
        """
        run = RunSession(self, cool_factor, periods, plotStress)
        try:
            relax_constitution(run.constitution())
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                exc.position = run.position()
            run.close()
            raise
        return measure_sessions([run], constituted=True)[0]

    def time_steps(self):
        """``(dt, f, dt_max)`` of the measurement: the ensemble's steps times ``time_step_factor`` and
        ``f = relative_frequency / τ`` (docs/parameters.md, "Derived quantities (default run)").  Needs the ensemble."""
        ens = self.theEnsemble
        model = self.model or getattr(ens, "model", False)
        factor = getattr(self, "time_step_factor", 1.0)
        return ens.dt * factor, self.relative_frequency / model.time_constant, ens.dt_max * factor

    def measurement_schedule(self, cool_factor=1):
        """The step schedule of the measurement, for the classes and the engine alike.

        Parameters
        ----------
        cool_factor : float, optional
            Fraction of the peculiar velocity left after one excitation period (default 1).

        Returns
        -------
        MeasurementSchedule
            ``dt`` and ``f`` (:meth:`time_steps`), the per-step damping factor
            ``cool = cool_factor ** (f·dt)`` (written ``cool_factor ** (1/N_per_period)``,
            ``N_per_period = 1/(f·dt)``), the pre-equilibration unit
            ``N_pre = 25 · int(adjustment factor)`` and the coarsest pre-equilibration step ``dt_max``.
        """
        dt, f, dt_max = self.time_steps()
        N_pre = 25 * int(self.adjustment_factor_for_bounded_preequilibration_steps())
        N_per_period = 1 / f / dt
        return MeasurementSchedule(dt, f, cool_factor ** (1 / N_per_period), N_pre, dt_max)

    def parameters_record(self):
        """The run's arguments as its result and its files record them: a plain dict of
        :attr:`parameters`, with ``backend`` the backend that measured the run (:attr:`backend_used`).

        The checked arguments themselves stay as they were checked (immutable); the resolved
        backend is only known once the driver has made the run's state, so it is put into this copy.

        Returns
        -------
        dict or None
            None when the simulation has no run parameters (made by its class, not by a run).
        """
        if self.parameters is None:
            return None
        record = dict(self.parameters)
        if self.backend_used is not None:
            record["backend"] = self.backend_used
        return record

    def run_metadata(self, output_format, path):
        """JSON-safe description of the run: parameters and provenance (the sidecar's content).

        Parameters
        ----------
        output_format : str
            The format of the output file (one of ``OUTPUT_FORMATS``).
        path : str or None
            The output file (its base name is recorded).

        Returns
        -------
        dict
        """
        return {
            "file": os.path.basename(path) if path else None, "output_format": output_format,
            "package_version": package_version(), "run_id": getattr(self, "run_id", None),
            "seed_entropy": json_safe(getattr(self, "seed_entropy", None)),
            "spawn_key": json_safe(list(getattr(self, "spawn_key", ()))),
            "parameters": json_safe(self.parameters_record()),
            "time_step_factor": float(getattr(self, "time_step_factor", 1.0)),
            "integrator": getattr(self, "integrator", "euler"), "correct_drift_sign": bool(self.correct_drift_sign),
            "reference_header": bool(self.reference_header), "function_call": self.function_call,
        }

    def _write_output(self, out, header, exp, output_format):
        """Stream the run into the reserved ``out`` in ``output_format``, write the sidecar, commit both.

        Text formats are written by the experiment's own block-3 writer (summary, then the table
        in chunks); npz and parquet by :func:`~.formats.write_run`.  When the file is complete
        its size and SHA-256 are read back and recorded, with the table's row count
        (``n_rows``), in the sidecar ``<stem>.json`` (:func:`~.output.sidecar_path`), which
        :meth:`~.output.AtomicOutputFile.commit` moves into place just before the file.  A
        failure raises the exception of the failing write; the caller aborts ``out``, which
        removes the temporary file and the temporary sidecar.
        """
        metadata = self.run_metadata(output_format, out.path)
        p = exp.plotter
        tensors = p.tensor_history if self.saveStressTensorData else None
        metadata["n_rows"] = table_rows(output_format, len(p), tensors is not None)
        if output_format in ("text", "text.gz"):
            with text_stream(out.binary, output_format) as raw:
                sink = _TextSink(raw)
                sink.write(header)
                sink.write(exp.description_text)
                exp.output_file = sink
                try:
                    exp.write_output_information_to_file()
                finally:
                    exp.output_file = False
        else:
            G_int, G_surf = exp.results["internal"], exp.results["surface"]
            text = (header + exp.description_text
                    + output_summary_text(G_int, G_surf, reference_header=self.reference_header))
            write_run(out.binary, output_format, text, p._scal[: len(p)], tensors, metadata)
        metadata["size_bytes"], metadata["sha256"] = out.digest()
        out.add_companion("json", json.dumps(metadata, indent=1).encode("utf-8"), sidecar_path(out.path))
        out.commit()

    def _close_windows(self):
        exp = self.theExperiment
        if exp is not None and exp.stress_window is not None:
            # after a successful run the window stays open until closed (main process), then closes
            exp.stress_window.finish(wait=sys.exc_info()[0] is None)
            exp.stress_window = None
        if self.renderer is not None:
            self.renderer.close()
        if self.theEnsemble is not None:
            self.theEnsemble._renderer = None

