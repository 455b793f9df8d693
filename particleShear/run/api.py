"""High-level entry points (spec §10.1, §10.2): one simulation, and series on any executor.

``doParticleShearSimulation(...)`` keeps the reference signature (plus a trailing ``seed``)
and return value ``[G′_surface, G″_surface]``; the complete outcome is a
:class:`SimulationResult`, available as ``doParticleShearSimulation.last_result`` after
every call (per process) or returned directly with ``return_result=True``.

``doParticleShearSimulationSeries(...)`` runs the reference iteration order on a
``concurrent.futures.Executor`` (a ``ProcessPoolExecutor`` by default) with per-run seeds
``numpy.random.SeedSequence(seed).spawn(n)`` and returns the results in iteration order.
"""
import math
import concurrent.futures
import dataclasses

import numpy as np

from ..simulation.simulations import Simulation_interlocking_rheology
from .validation import validate_simulation_parameters
from .batch import batches, check_backend, check_batch_size, engine_supports, measure_batch, run_batch

__all__ = ["doParticleShearSimulation", "doParticleShearSimulationSeries", "SimulationResult", "series_jobs"]


@dataclasses.dataclass
class SimulationResult:
    """Everything a run of :func:`doParticleShearSimulation` produced.

    Attributes
    ----------
    G_surface : tuple of float
        (G′, G″) in Pa from the external (surface) forces — the reference's return value.
    G_internal : tuple of float
        (G′, G″) in Pa from the overall stress tensor — the values the header lists first.
    stress_surface, stress_internal : tuple of float
        (in-phase, out-of-phase) stress amplitudes in Pa of the two estimators.
    parameters : dict
        Every argument of the call (reference names).
    seed : int or None
        Entropy of the ``numpy.random.SeedSequence`` that drove the run (None if a Generator was given).
    spawn_key : tuple
        Spawn key of that SeedSequence (non-empty for runs of a series).
    timings : dict
        Wall time in s: "constitution", "pre_equilibration", "protocol", "demodulation", "output", "total".
    output_path : str or None
        The text file (when ``saveData``).
    image_folder : str or None
    n_images : int
    dt, f : float
        Protocol time step (s) and excitation frequency (Hz).
    N_steps : int
        Protocol steps.
    damping_factor : float
        Per-step damping factor.
    removed_fraction : float
        Actual fraction of removed non-essential bonds.
    series : dict of numpy.ndarray
        t (s), strain, strain_rate (1/s), stress_surface, stress_internal (Pa), and "tensors"
        (n, 9, 2, 2) when the tensor history was kept (``saveData`` with ``saveStressTensorData``).
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
    damping_factor: float = 1.0
    removed_fraction: float = 0.0
    series: dict = dataclasses.field(default_factory=dict, repr=False)

    @property
    def G(self):
        """``[G′_surface, G″_surface]`` — what :func:`doParticleShearSimulation` returns."""
        return [self.G_surface[0], self.G_surface[1]]


def _seed_sequence(seed):
    """(SeedSequence or None, Generator) for ``seed`` = None, int, SeedSequence, Generator or BitGenerator."""
    if isinstance(seed, np.random.Generator):
        return None, seed
    if isinstance(seed, np.random.BitGenerator):
        return None, np.random.Generator(seed)
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return ss, np.random.default_rng(ss)


def _build_simulation(params, rng, *, verbose, progress, correct_drift_sign, reference_header, renderer,
                      time_step_factor, integrator, stability_guard):
    """The :class:`Simulation_interlocking_rheology` of one run, configured but not run (``params``: the
    validated reference arguments of :func:`doParticleShearSimulation`; ``rng`` its Generator)."""
    p = params
    root_folder, do_permanent_links, cut_lines, N = p["root_folder"], p["do_permanent_links"], p["cut_lines"], p["N"]
    (packing_fraction, density, bimodal_factor, theAmplitude) = (p["packing_fraction"], p["density"],
                                                                 p["bimodal_factor"], p["theAmplitude"])
    Young_modulus_spheres, theMu, relative_y_scale_force = p["Young_modulus_spheres"], p["theMu"], p[
        "relative_y_scale_force"]
    relative_frequency, relative_viscosity = p["relative_frequency"], p["relative_viscosity"]
    relative_transversal_link_strength = p["relative_transversal_link_strength"]
    central_repulsion_coefficient = p["central_repulsion_coefficient"]
    avoid_horizontal_angle_degree = p["avoid_horizontal_angle_degree"]
    interface_reenforcement_central = p["interface_reenforcement_central"]
    interface_reenforcement_tangential = p["interface_reenforcement_tangential"]
    keep_viscosity_coefficients_constant = p["keep_viscosity_coefficients_constant"]
    avoid_height_spanning_particles, cut_top_bottom = p["avoid_height_spanning_particles"], p["cut_top_bottom"]
    doCutByTriangulation, remove_link_fraction = p["doCutByTriangulation"], p["remove_link_fraction"]
    edge_fuzziness, doDrawing, saveData = p["edge_fuzziness"], p["doDrawing"], p["saveData"]
    pre_periods, post_periods, periods = p["pre_periods"], p["post_periods"], p["periods"]
    saveOutputImages, imageFileType, cool_factor = p["saveOutputImages"], p["imageFileType"], p["cool_factor"]
    saveStressTensorData = p["saveStressTensorData"]
    theSimulation = Simulation_interlocking_rheology(
        root_folder, do_permanent_links=do_permanent_links, cut_lines=int(cut_lines), N=int(N),
        packing_fraction=packing_fraction, density=density, bimodal_factor=bimodal_factor, amplitude=theAmplitude,
        Young_modulus_spheres=Young_modulus_spheres, mu=theMu, relative_y_scale_force=relative_y_scale_force,
        relative_frequency=relative_frequency, relative_viscosity=relative_viscosity,
        relative_transversal_link_strength=relative_transversal_link_strength,
        central_repulsion_coefficient=central_repulsion_coefficient,
        avoid_horizontal_angle_degree=avoid_horizontal_angle_degree,
        interface_reenforcement_central=interface_reenforcement_central,
        interface_reenforcement_tangential=interface_reenforcement_tangential,
        keep_viscosity_coefficients_constant=keep_viscosity_coefficients_constant,
        avoid_height_spanning_particles=avoid_height_spanning_particles, cut_top_bottom=cut_top_bottom,
        doCutByTriangulation=doCutByTriangulation, remove_link_fraction=remove_link_fraction,
        edge_fuzziness=edge_fuzziness, doDrawing=doDrawing, saveData=saveData)
    theSimulation.function_call += (
        "\n\ttheSimulation.baseline_pre_periods = " + str(pre_periods)
        + "\n\ttheSimulation.baseline_post_periods = " + str(post_periods)
        + "\n\ttheSimulation.saveOutputImages = " + str(saveOutputImages)
        + "\n\ttheSimulation.imageFileType = " + str(imageFileType)
        + "\n\ttheSimulation.runSimulation(periods=" + str(periods) + ", cool_factor=" + str(cool_factor) + ")")
    theSimulation.baseline_pre_periods = pre_periods
    theSimulation.baseline_post_periods = post_periods
    theSimulation.saveOutputImages = saveOutputImages
    theSimulation.imageFileType = imageFileType
    theSimulation.saveStressTensorData = saveStressTensorData
    theSimulation.rng = rng
    theSimulation.verbose = verbose
    theSimulation.progress = progress
    theSimulation.correct_drift_sign = correct_drift_sign
    theSimulation.reference_header = reference_header
    theSimulation.renderer_backend = renderer
    theSimulation.time_step_factor = float(time_step_factor)
    theSimulation.integrator = integrator
    theSimulation.stability_guard = bool(stability_guard)

    return theSimulation


def doParticleShearSimulation(root_folder="", theAmplitude=0.2, theMu=0.01, do_permanent_links=True, cut_lines=5,
                              Young_modulus_spheres=8000, N=150, packing_fraction=1.5, density=50,
                              bimodal_factor=1.4, relative_viscosity=0.1, relative_transversal_link_strength=1,
                              relative_frequency=0.025, avoid_horizontal_angle_degree=15,
                              interface_reenforcement_central=1, interface_reenforcement_tangential=1,
                              keep_viscosity_coefficients_constant=False, avoid_height_spanning_particles=True,
                              cut_top_bottom=False, saveOutputImages=False, imageFileType="jpg",
                              remove_link_fraction=0, edge_fuzziness=0, central_repulsion_coefficient=1,
                              doCutByTriangulation=True, doDrawing=True, saveData=False, saveStressTensorData=True,
                              plotStress=True, relative_y_scale_force=1e8, pre_periods=2, periods=3,
                              post_periods=1, cool_factor=0.5, seed=None, *, return_result=False, verbose=True,
                              progress=None, correct_drift_sign=False, reference_header=False, renderer="auto",
                              time_step_factor=1.0, integrator="euler", stability_guard=True, backend="numpy"):
    """Build a crosslinked, cut soft-particle ensemble, shear it sinusoidally and return its moduli.

    Parameters
    ----------
    root_folder : str
        Output folder (must exist when ``saveData`` or ``saveOutputImages``).
    theAmplitude : float
        Strain amplitude A (> 0; 0.2 = 20 %).
    theMu : float
        Friction coefficient of transient contacts (>= 0).
    do_permanent_links, cut_lines, ... cool_factor :
        As in the reference; see ``docs/parameters.md`` for units, defaults and meaning.
    seed : None, int, numpy.random.SeedSequence or numpy.random.Generator
        Drives every random choice; one seed gives a bit-identical run.  None draws fresh
        entropy (recorded in the result).
    return_result : bool, keyword-only
        Return the :class:`SimulationResult` instead of ``[G′_surface, G″_surface]``.
    verbose : bool, keyword-only
        Print the reference console messages (§8.6).
    progress : callable, keyword-only
        ``progress(phase, step, total, elapsed_s)`` for phases "constitution", "pre-equilibration", "protocol".
    correct_drift_sign : bool, keyword-only
        Use the mathematically correct drift correction in the demodulation (default: reference quirk).
    reference_header : bool, keyword-only
        Reproduce the reference header defects §12 #21–22 in the output file.
    renderer : {"auto", "tk", "pillow", "none"}, keyword-only
        Drawing backend (see :mod:`particleShear.simulation.drawing`).
    time_step_factor : float, keyword-only
        Multiplies the time step (and the coarsest step) of the measurement: pre-equilibration
        with plates and protocol.  1 = the reference rule of §4.7; constitution is unchanged, so
        one seed gives the same initial packing for every factor (used by the accuracy study).
    integrator : {"euler", "verlet"}, keyword-only
        Time integrator of the measurement: the reference semi-implicit Euler (default) or
        velocity Verlet with a half-kick predictor for the velocity-dependent forces.
    stability_guard : bool, keyword-only
        Stop a diverging measurement with :class:`SimulationInstabilityError` (step, phase, worst
        pair, suggested time step) instead of producing NaN moduli.
    backend : {"numpy"}, keyword-only
        Array backend (see :mod:`particleShear.run.batch`; only NumPy in this version).

    Returns
    -------
    list of float
        ``[G′_surface, G″_surface]`` in Pa (moduli from the surface forces, as the reference returns);
        the full :class:`SimulationResult` is stored in ``doParticleShearSimulation.last_result``.

    Raises
    ------
    ValueError, TypeError
        For any invalid parameter, before any simulation work.
    """
    params = dict(root_folder=root_folder, theAmplitude=theAmplitude, theMu=theMu,
                  do_permanent_links=do_permanent_links, cut_lines=cut_lines,
                  Young_modulus_spheres=Young_modulus_spheres, N=N, packing_fraction=packing_fraction,
                  density=density, bimodal_factor=bimodal_factor, relative_viscosity=relative_viscosity,
                  relative_transversal_link_strength=relative_transversal_link_strength,
                  relative_frequency=relative_frequency, avoid_horizontal_angle_degree=avoid_horizontal_angle_degree,
                  interface_reenforcement_central=interface_reenforcement_central,
                  interface_reenforcement_tangential=interface_reenforcement_tangential,
                  keep_viscosity_coefficients_constant=keep_viscosity_coefficients_constant,
                  avoid_height_spanning_particles=avoid_height_spanning_particles, cut_top_bottom=cut_top_bottom,
                  saveOutputImages=saveOutputImages, imageFileType=imageFileType,
                  remove_link_fraction=remove_link_fraction, edge_fuzziness=edge_fuzziness,
                  central_repulsion_coefficient=central_repulsion_coefficient,
                  doCutByTriangulation=doCutByTriangulation, doDrawing=doDrawing, saveData=saveData,
                  saveStressTensorData=saveStressTensorData, plotStress=plotStress,
                  relative_y_scale_force=relative_y_scale_force, pre_periods=pre_periods, periods=periods,
                  post_periods=post_periods, cool_factor=cool_factor, seed=seed)
    validate_simulation_parameters(params)
    check_backend(backend)
    if not (isinstance(time_step_factor, (int, float)) and math.isfinite(time_step_factor) and time_step_factor > 0):
        raise ValueError(f"time_step_factor={time_step_factor!r} is out of range: allowed finite > 0")
    if integrator not in ("euler", "verlet"):
        raise ValueError(f"integrator={integrator!r} is out of range: allowed 'euler' or 'verlet'")
    full = dict(params, verbose=verbose, progress=progress, correct_drift_sign=correct_drift_sign,
                reference_header=reference_header, renderer=renderer, time_step_factor=time_step_factor,
                integrator=integrator, stability_guard=stability_guard)
    if engine_supports(full):   # measured by the engine: a batch of one (particleShear.run.batch)
        result = measure_batch([full])[0]
        doParticleShearSimulation.last_result = result
        return result if return_result else result.G
    ss, rng = _seed_sequence(seed)
    theSimulation = _build_simulation(params, rng, verbose=verbose, progress=progress,
                                      correct_drift_sign=correct_drift_sign, reference_header=reference_header,
                                      renderer=renderer, time_step_factor=time_step_factor, integrator=integrator,
                                      stability_guard=stability_guard)
    G = theSimulation.runSimulation(periods=periods, cool_factor=cool_factor, plotStress=plotStress)

    info = theSimulation.result_info
    series = theSimulation.theExperiment.plotter.arrays()
    result = SimulationResult(
        G_surface=info["G_surface"], G_internal=info["G_internal"], stress_surface=info["stress_surface"],
        stress_internal=info["stress_internal"], parameters=params,
        seed=None if ss is None else ss.entropy, spawn_key=() if ss is None else tuple(ss.spawn_key),
        timings=info["timings"], output_path=info["output_path"], image_folder=info["image_folder"],
        n_images=info["n_images"], dt=info["dt"], f=info["f"], N_steps=info["N_steps"],
        damping_factor=info["damping_factor"],
        removed_fraction=getattr(theSimulation.theEnsemble, "removed_fraction", 0.0), series=series)
    doParticleShearSimulation.last_result = result
    if return_result:
        return result
    return G


doParticleShearSimulation.last_result = None


def series_jobs(amplitudes, mu, cut_lines, do_bulk_control, do_uncrosslinked_control, do_non_frictional_control,
                N_repetitions):
    """The reference iteration order of §10.2 as a list of (A, μ, do_permanent_links, cut_lines)."""
    jobs = []
    for _ in range(int(N_repetitions)):
        for A in amplitudes:
            for m in mu:
                if do_bulk_control:
                    jobs.append((A, m, True, 0))
                jobs.append((A, m, True, cut_lines))
                if do_uncrosslinked_control:
                    jobs.append((A, m, False, 0))
                if do_non_frictional_control:
                    jobs.append((A, 0, True, cut_lines))
    return jobs


def _series_worker(kwargs):
    return doParticleShearSimulation(**kwargs, return_result=True)


def doParticleShearSimulationSeries(root_folder="", amplitudes=[0.2], mu=[0.01], cut_lines=5,  # noqa: B006
                                    Young_modulus_spheres=8000, do_bulk_control=False,
                                    do_uncrosslinked_control=False, do_non_frictional_control=False,
                                    N_repetitions=6, N=150, packing_fraction=1.5, density=50, bimodal_factor=1.4,
                                    relative_viscosity=0.1, relative_transversal_link_strength=1,
                                    relative_frequency=0.025, avoid_horizontal_angle_degree=15,
                                    interface_reenforcement_central=1, interface_reenforcement_tangential=1,
                                    keep_viscosity_coefficients_constant=False, avoid_height_spanning_particles=True,
                                    cut_top_bottom=False, doCutByTriangulation=True, saveOutputImages=False,
                                    imageFileType="jpg", remove_link_fraction=0, edge_fuzziness=0,
                                    central_repulsion_coefficient=1, doDrawing=True, saveData=False,
                                    saveStressTensorData=True, plotStress=True, pre_periods=2, periods=3,
                                    post_periods=1, cool_factor=0.5, executor=None, seed=None, *,
                                    max_workers=None, verbose=False, batch_size=None, backend="numpy",
                                    **options):
    """Run the reference series (repetitions × amplitudes × μ × controls) on an executor.

    Parameters
    ----------
    root_folder ... cool_factor :
        As in §10.2 (the lists ``amplitudes`` and ``mu`` are iterated; every other value is
        forwarded unchanged to :func:`doParticleShearSimulation`).
    executor : concurrent.futures.Executor, optional
        Where the runs execute (e.g. a ``ProcessPoolExecutor``, Dask's ``Client.get_executor()``,
        ``mpi4py.futures.MPIPoolExecutor``).  Default: a ``ProcessPoolExecutor(max_workers)``
        created and shut down here.  A given executor is not shut down.
    seed : None, int or numpy.random.SeedSequence
        Root seed; run k gets ``SeedSequence(seed).spawn(n)[k]``, so the series is reproducible
        whatever the executor or the completion order.
    max_workers : int, keyword-only
        Size of the default process pool.
    verbose : bool, keyword-only
        Forwarded to each run (default False: quiet workers).
    batch_size : int, keyword-only
        When given, runs that share a step schedule (same N, time-step rule and protocol; see
        :func:`particleShear.run.batch.schedule_key`) are grouped into batches of up to
        ``batch_size`` runs, and each batch is one task of the executor
        (:func:`particleShear.run.batch.run_batch`).  The results are exactly those of the
        unbatched series, in the same order.  Default None: one task per run.
    backend : {"numpy"}, keyword-only
        Array backend of every run.
    **options :
        Further keyword-only options of :func:`doParticleShearSimulation` (``correct_drift_sign``,
        ``reference_header``, ``renderer``, ...).

    Returns
    -------
    list of SimulationResult
        In the reference iteration order (repetition, amplitude, μ, then bulk control, material,
        uncrosslinked control, non-frictional control).
    """
    check_batch_size(batch_size)
    check_backend(backend)
    if isinstance(N_repetitions, bool) or int(N_repetitions) != N_repetitions or N_repetitions < 0:
        raise ValueError(f"N_repetitions={N_repetitions!r} is out of range: allowed integers >= 0")
    amplitudes = list(amplitudes)
    mu = list(mu)
    if not amplitudes or not mu:
        raise ValueError(f"amplitudes={amplitudes!r} and mu={mu!r} must be non-empty lists")
    common = dict(root_folder=root_folder, Young_modulus_spheres=Young_modulus_spheres, N=N,
                  packing_fraction=packing_fraction, density=density, bimodal_factor=bimodal_factor,
                  relative_viscosity=relative_viscosity,
                  relative_transversal_link_strength=relative_transversal_link_strength,
                  relative_frequency=relative_frequency, avoid_horizontal_angle_degree=avoid_horizontal_angle_degree,
                  interface_reenforcement_central=interface_reenforcement_central,
                  interface_reenforcement_tangential=interface_reenforcement_tangential,
                  keep_viscosity_coefficients_constant=keep_viscosity_coefficients_constant,
                  avoid_height_spanning_particles=avoid_height_spanning_particles, cut_top_bottom=cut_top_bottom,
                  doCutByTriangulation=doCutByTriangulation, saveOutputImages=saveOutputImages,
                  imageFileType=imageFileType, remove_link_fraction=remove_link_fraction,
                  edge_fuzziness=edge_fuzziness, central_repulsion_coefficient=central_repulsion_coefficient,
                  doDrawing=doDrawing, saveData=saveData, saveStressTensorData=saveStressTensorData,
                  plotStress=plotStress, pre_periods=pre_periods, periods=periods, post_periods=post_periods,
                  cool_factor=cool_factor)
    jobs = series_jobs(amplitudes, mu, cut_lines, do_bulk_control, do_uncrosslinked_control,
                       do_non_frictional_control, N_repetitions)
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    children = root.spawn(len(jobs))
    all_kwargs = []
    for (A, m, links, cl), child in zip(jobs, children):
        kw = dict(common, theAmplitude=A, theMu=m, do_permanent_links=links, cut_lines=cl, seed=child,
                  verbose=verbose, **options)
        validate_simulation_parameters({**kw})  # every run is checked before any work starts
        all_kwargs.append(kw)
    if not all_kwargs:
        return []
    own = executor is None
    if own:
        executor = concurrent.futures.ProcessPoolExecutor(max_workers=max_workers)
    try:
        if batch_size is None:
            futures = [executor.submit(_series_worker, kw) for kw in all_kwargs]
            return [fut.result() for fut in futures]
        groups = batches(all_kwargs, batch_size)
        futures = [executor.submit(run_batch, [all_kwargs[p] for p in g], backend) for g in groups]
        results = [None] * len(all_kwargs)
        for g, fut in zip(groups, futures):
            for p, res in zip(g, fut.result()):
                results[p] = res
        return results
    finally:
        if own:
            executor.shutdown(wait=True, cancel_futures=True)
