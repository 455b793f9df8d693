"""High-level entry points: one simulation, and series on any executor.

``doParticleShearSimulation(...)`` keeps the reference signature (plus a trailing ``seed``)
and return value ``[G′_surface, G″_surface]``; the complete outcome is a
:class:`SimulationResult`, available as ``doParticleShearSimulation.last_result`` after
every call (per process) or returned directly with ``return_result=True``.

``doParticleShearSimulationSeries(...)`` runs the reference iteration order on a
``concurrent.futures.Executor`` (a ``ProcessPoolExecutor`` by default) with per-run seeds
``numpy.random.SeedSequence(seed).spawn(n)`` and returns the results in iteration order.
"""

import numpy as np

from ..hooks import entry
from ..messages import console_messages
from ..parameters import BY_NAME, EXTRA, PARAMETERS
from .validation import check_seed, checked_point, validate_series, validated_run
from .sessions import _build_simulation, _seed_sequence, check_batch_size  # noqa: F401 - re-exported
from .guard import PARAMETER_ALIASES, PARAMETER_HINTS, checked_keywords
from .result import SimulationResult
from ..simulation.drawing import _backend_choice, display_available
from .measurement import measure, measure_batch  # noqa: F401 - measure_batch re-exported (deprecated)

__docformat__ = "numpy"
__all__ = ["doParticleShearSimulation", "doParticleShearSimulationSeries", "SimulationResult", "series_jobs"]


#: the defaults of the contact laws' parameters outside the signature (``**law_parameters``)
_EXTRA_DEFAULTS = {name: BY_NAME[name].default for name in EXTRA}


@checked_keywords(aliases=PARAMETER_ALIASES, hints=PARAMETER_HINTS, extra=EXTRA)
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
                              time_step_factor=1.0, integrator="euler", stability_guard=True,
                              saveOutputMovie=False, output_format="text", strict_io=False, backend="auto",
                              contact_law="linear", plateau_begin=0.3, plateau_end=0.8, plateau_slope=0.1,
                              protocol="oscillatory", relative_rate=0.01, total_strain=2.0, ramp_time=1.0,
                              hold_time=200.0, creep_stress=None, creep_modulus=None, creep_response_time=5.0,
                              sweep_amplitudes=None, sweep_frequencies=None, stroboscopic=False,
                              **law_parameters):
    """Build a crosslinked, cut soft-particle ensemble, shear it sinusoidally and return its moduli.

    The run follows the reference (particleShear 1.0.2): N bimodal spheres are relaxed in a
    500 × 500 µm Lees-Edwards cell, crosslinked, cut into particles, pre-equilibrated and sheared
    with the strain γ(t) = A sin(2π f t); G′ and G″ are demodulated from the shear stress of the
    plate forces ("surface") and of the overall stress tensor ("internal", eq. S1-24); see
    docs/output.md.  Internal units: lengths in µm, time in s, masses in mg and forces in
    mg·µm·s⁻² per metre of cylinder depth; stresses and moduli in Pa.  Every parameter is checked
    before any work (limits of resolution, steps and memory: docs/parameters.md).

    Parameters
    ----------
    root_folder : str, default ""
        Output folder (path) of the text file and of the image folder.  Allowed: any string;
        it must be an existing, writable folder when ``saveData`` or ``saveOutputImages`` is
        True (probed with an empty temporary file before any work).
    theAmplitude : float, default 0.2
        Strain amplitude A, dimensionless (0.2 = 20 %); allowed 0 < value <= 100.  Also the
        builder's anticipated amplitude (time step, relaxation length).  Python alias:
        ``amplitude=`` (the same run and run id; not together with ``theAmplitude``).
    theMu : float, default 0.01
        Coulomb friction coefficient μ of transient contacts, dimensionless; allowed 0 <= value <= 1e+06 (permanent links are not limited by friction).  Python alias: ``mu=``
        (the same run and run id; not together with ``theMu``).
    do_permanent_links : bool, default True
        Crosslink all contacts after relaxation; False: frictional spheres only.
    cut_lines : int, default 5
        Triangulation: number of particles (Voronoi seeds); line mode: number of straight cuts;
        <= 1 (triangulation) or 0 (lines) is an uncut bulk gel.  Allowed: an integer 0 ... 1e6 that
        leaves >= 3 spheres per particle on average (triangulation: cut_lines <= N/3).
    Young_modulus_spheres : float, default 8000
        Young modulus E of the sphere material in Pa; allowed 1e-06 <= value <= 1e+12.  Contact stiffness
        k = π E/8 (eq. S1-8).
    N : int, default 150
        Number of spheres; allowed an integer from N_min (11 at the default packing fraction and
        bimodal factor: the largest sphere must be smaller than a quarter of the cell) to 1e6.
    packing_fraction : float, default 1.5
        Nominal (uncompressed) area fraction φ that defines the radii (eq. S1-14), dimensionless;
        allowed 0 < value <= 10.
    density : float, default 50
        Material density in kg/m³; allowed 1e-06 <= value <= 1e+06 (the manual's table says 1000, the
        reference code default is 50).
    bimodal_factor : float, default 1.4
        Ratio of large to small radius (50/50 random), dimensionless; allowed 0.01 <= value <= 100.
    relative_viscosity : float, default 0.1
        rv in the contact damping ν = rv·√(m k) (eq. S1-9), dimensionless; allowed 0 <= value <= 3.
    relative_transversal_link_strength : float, default 1
        k_t/k and ν_t/ν, dimensionless; allowed 0 <= value <= 30.
    relative_frequency : float, default 0.025
        f·τ: excitation frequency in units of the characteristic frequency 1/τ, dimensionless;
        allowed 0 < value, with >= 100 steps per excitation period (<= 0.56 at the defaults).
    avoid_horizontal_angle_degree : float, default 15
        Line-cut mode only: half-width in degrees of the forbidden band around horizontal cut
        lines; allowed 0 <= value < 90.
    interface_reenforcement_central : float, default 1
        Factor on k of transient contacts relative to permanent links, dimensionless; allowed 1e-06 <= value <= 50.
    interface_reenforcement_tangential : float, default 1
        The same factor for k_t, dimensionless; allowed 1e-06 <= value <= 1e+06.
    keep_viscosity_coefficients_constant : bool, default False
        False: the contact viscosities follow the reinforcement factors; True: they stay.
    avoid_height_spanning_particles : bool, default True
        Cut again while a particle is taller than 0.9 of the cell height.
    cut_top_bottom : bool, default False
        Cut every link through the y-periodic boundary (emulates wall slip).
    saveOutputImages : bool, default False
        Save about 200 captioned snapshots of the protocol into an image folder beside the
        output file (needs ``root_folder``; works with or without ``doDrawing``).
    imageFileType : {"jpg", "png", "ps", "svg"}, default "jpg"
        Snapshot format; "ps" is vector Encapsulated PostScript (extension .ps), "svg" vector SVG.
    remove_link_fraction : float, default 0
        Target fraction of non-essential permanent links removed at random; allowed 0 <= value <= 1.
    edge_fuzziness : float, default 0
        Random roughening of the Voronoi borders in units of the largest radius; allowed 0 <= value <= 1000.
    central_repulsion_coefficient : float, default 1
        c of the central force law, dimensionless (1 = divergent repulsion eq. S1-5b, 0 =
        linear eq. S1-5a); allowed 0 <= value <= 1.
    doCutByTriangulation : bool, default True
        Cut into particles by periodic Voronoi cells; False: by random straight lines.
    doDrawing : bool, default True
        Draw: the live particle window when a display exists (snapshots do not need it).
    saveData : bool, default False
        Write the output file of the run (format ``output_format``; docs/output.md).
    saveStressTensorData : bool, default True
        With ``saveData``: also write the 42-column per-step table of the stress tensors.
    plotStress : bool, default True
        Live stress/strain window (needs a display and ``doDrawing``); without a display, and
        with ``saveData``, it is saved as ``<output file>_stress.png`` (needs particleShear[plot]).
    relative_y_scale_force : float, default 1e8
        Vertical scale of the live stress window only, dimensionless; allowed -1e+300 <= value <= 1e+300.
    pre_periods : float, default 2
        Baseline before the excitation, in excitation periods (drift reference); allowed 0 <= value, within the step and memory limits.
    periods : float, default 3
        Excitation periods (the first is skipped in the demodulation when >= 2); allowed 0 < value, within the step and memory limits.
    post_periods : float, default 1
        Recovery after the excitation, in excitation periods; allowed 0 <= value, within the step and
        memory limits.
    cool_factor : float, default 0.5
        Fraction of the peculiar velocity left after one excitation period (damping),
        dimensionless; allowed 0 < value <= 1.
    seed : None, int, numpy.random.SeedSequence or numpy.random.Generator, default None
        Drives every random choice; one seed gives a bit-identical run.  Allowed None (fresh
        entropy, recorded in the result), an integer >= 0, a SeedSequence or a Generator.
    return_result : bool, default False
        Keyword-only.  Return the :class:`SimulationResult` instead of ``[G′_surface, G″_surface]``.
    verbose : bool, default True
        Keyword-only.  Show the reference's console messages: INFO messages of the logger
        "particleShear" on stdout during the call (see :mod:`particleShear.messages`).
    progress : callable or None, default None
        Keyword-only.  ``progress(phase, step, total, elapsed_s)``, called at most ~10 times
        per second, for the phases "constitution", "pre-equilibration" and "protocol".
    correct_drift_sign : bool, default False
        Keyword-only.  Demodulate with the mathematically correct drift correction (default:
        the reference's sign; docs/output.md).
    reference_header : bool, default False
        Keyword-only.  Reproduce the two defects of the reference's output header
        (docs/output.md).
    renderer : {"auto", "tk", "pillow", "none"}, default "auto"
        Keyword-only.  Drawing backend: "auto" (Tk when a display exists, else Pillow for the
        snapshots), "tk", "pillow" or "none"; also set by the environment variable
        PARTICLESHEAR_RENDERER.
    time_step_factor : float, default 1.0
        Keyword-only.  Multiplies the time step (and the coarsest relaxation step) of the
        measurement: plate pre-equilibration and protocol (1 = the reference rule).  The
        constitution is unchanged, so one seed gives the same packing for every factor
        (docs/accuracy.md).  Allowed > 0, leaving >= 2 steps per excitation period.
    integrator : {"euler", "verlet"}, default "euler"
        Keyword-only.  Time integrator of the measurement: the reference's semi-implicit Euler,
        or velocity Verlet with a half-kick predictor for the velocity-dependent forces.
    stability_guard : bool, default True
        Keyword-only.  Stop a diverging measurement with ``SimulationInstabilityError`` (step,
        phase, worst pair, suggested time step) instead of returning NaN moduli.
    saveOutputMovie : bool, default False
        Keyword-only.  Also write the snapshots as the animated GIF ``movie.gif`` in the image
        folder (needs ``saveOutputImages``): 80 ms a frame, each snapshot scaled down to 320 px
        wide (kept as it is when narrower); every snapshot is a frame (201 by default) until 400
        are kept, then every second kept frame is dropped and only every second later snapshot is
        kept, so a movie has fewer than 400 frames.
    output_format : {"text", "text.gz", "npz", "parquet"}, default "text"
        Keyword-only.  File format of ``saveData``: the reference text, the same gzip-compressed,
        NumPy .npz, or Parquet (needs particleShear[parquet]); read any with
        :func:`particleShear.read_run` (docs/output.md).
    strict_io : bool, default False
        Keyword-only.  Raise the ``OSError`` of a failed write after the run; False: return the
        result with ``write_error`` set (``last_result`` holds it either way).
    backend : {"auto", "numpy", "numba", "cupy"}, default "auto"
        Keyword-only.  Array library of the measurement: "auto" (the environment variable
        ``PARTICLESHEAR_BACKEND`` when set, else "numba" where Numba can be imported, else "numpy";
        :func:`particleShear.engine.xp.resolve_backend`); "numpy"; "numba" (NumPy arrays, each step
        compiled from the NumPy engine's own functions, bit-identical; needs
        ``pip install particleShear[fast]``); or "cupy" to measure on a CUDA GPU (needs
        ``pip install cupy-cuda12x`` and a device; equal to the NumPy run to rounding, not bit for
        bit).  The result (``result.parameters["backend"]``), results.csv and the sidecar record
        the backend used; "numpy", "numba" and "auto" give one run identity.  Every run measures through the engine (:mod:`particleShear.engine`) as a
        batch of one — drawn or not, with files and snapshots or not, either integrator, any law —
        so that a run in a batched series (``doParticleShearSimulationSeries(..., batch_size=B)``)
        is bit-identical to it and a drawn run to the same run headless (the drawing observes the
        engine's loops).
    contact_law : {"linear", "plateau", "hertz"}, default "linear"
        Keyword-only.  Central contact law, a law of the folder particleShear/engine/contact_laws
        (its parameters follow it in the parameter table), a law added with ``register_law``, or
        ``"package.module:function"`` (imported where it is used): "linear" the blend of eqs.
        S1-5a/b with the cap S1-6 (or the law assigned to
        ``CircleBasicElasticity.call_back_elastic_force_law``, the class-attribute way of 1.0.2),
        "plateau" the same law of a plateau-transformed distance (spongy particles, the manual's
        ``elastic_force_law_plateau``), "hertz" the Hertz force of two spheres of unequal radii
        (eq. H-1, parameter ``hertz_scale``; docs/parameters.md, docs/engine.md).
    plateau_begin : float, default 0.3
        Keyword-only.  Begin of the plateau of ``contact_law="plateau"``, a fraction of the
        contact distance; allowed 0 < plateau_begin < plateau_end.
    plateau_end : float, default 0.8
        Keyword-only.  End of the plateau, a fraction of the contact distance; allowed
        plateau_begin < plateau_end <= 1.
    plateau_slope : float, default 0.1
        Keyword-only.  Slope of the force on the plateau relative to the law's (0 flat, 1 no
        plateau); allowed 0 ... 1.
    protocol : {"oscillatory", "steady", "relaxation", "creep", "amplitude_sweep", "frequency_sweep"}, default "oscillatory"
        Keyword-only.  What the rheometer does after the pre-equilibration (docs/protocols.md):
        the reference's oscillation; a constant shear rate; a step strain to ``theAmplitude``
        and hold; a constant applied stress; or, on one packing, the oscillation at each of
        ``sweep_amplitudes`` or ``sweep_frequencies`` in turn.  The other protocols are headless
        (no drawing, no snapshots); their result is a :class:`SimulationResult` naming the protocol
        (``summary``, ``curves``, ``steps``; docs/protocols.md).
    relative_rate : float, default 0.01
        Keyword-only.  ``protocol="steady"``: shear rate γ̇·τ, dimensionless like
        ``relative_frequency`` (γ̇ = relative_rate/τ in 1/s, τ the model time constant);
        allowed > 0 with at most 0.005 strain per time step.
    total_strain : float, default 2.0
        Keyword-only.  ``protocol="steady"``: strain sheared in all; allowed 0 < value <= 1e6.
    ramp_time : float, default 1.0
        Keyword-only.  ``protocol="relaxation"``: duration of the strain ramp to γ₀, in units of τ;
        allowed > 0 with at most 0.005 strain per time step.
    hold_time : float, default 200.0
        Keyword-only.  ``protocol="relaxation"`` and ``"creep"``: duration of the hold, in units of τ;
        allowed 0 < value <= 1e9 within the step limit.
    creep_stress : float or None, default None
        Keyword-only.  ``protocol="creep"`` (required there): applied shear stress σ₀ in Pa, > 0.
    creep_modulus : float or None, default None
        Keyword-only.  ``protocol="creep"``: modulus scale G_c (Pa) of the stress controller;
        None: Young_modulus_spheres/8 (docs/protocols.md).
    creep_response_time : float, default 5.0
        Keyword-only.  ``protocol="creep"``: response time T_c of the stress controller in units of
        τ; allowed >= 10 time steps.
    sweep_amplitudes : list of float or None, default None
        Keyword-only.  ``protocol="amplitude_sweep"`` (required there): the strain amplitudes, in
        the order run, strictly increasing or strictly decreasing, each 0 < A <= 100;
        ``theAmplitude`` is set to the first.
    sweep_frequencies : list of float or None, default None
        Keyword-only.  ``protocol="frequency_sweep"`` (required there): the relative frequencies
        f·τ, in the order run, strictly monotonic; ``relative_frequency`` is set to the first.
    stroboscopic : bool, default False
        Keyword-only.  Watch the oscillatory protocol with the stroboscopic observer
        (:class:`particleShear.engine.microstructure.Stroboscope`): a snapshot at the start of every
        shear period; per cycle the non-affine displacement, D²_min, contacts made and broken, Z
        without rattlers and P(f/⟨f⟩) in ``result.microstructure`` and the per-run columns
        ``irreversibility``, ``moved_fraction``, ``Z_rattler_free``, ``rattler_fraction``,
        ``contact_change_rate`` in ``result.measures`` (docs/microstructure.md).  It only reads the
        state: G′ and G″ are those of the run without it, bit for bit; off, nothing is computed.
        Not part of the run identity.  CLI ``--stroboscopic``.
    **law_parameters
        Keyword-only.  The parameters of the contact laws that are not in this signature: those
        of ``hertz`` (``hertz_scale``, float, default 0.05, allowed 0 < value <= 1000) and of a law
        file saved into particleShear/engine/contact_laws, as each law's file declares them
        (:data:`particleShear.parameters.EXTRA`; each checked against its declared range, in
        the run identity only when its law is selected; CLI ``--hertz-scale`` etc.).

    Returns
    -------
    list of float or SimulationResult
        ``[G′_surface, G″_surface]`` in Pa (the moduli from the surface forces, as the reference
        returns), or the :class:`SimulationResult` with ``return_result=True``; the full result
        of the last call is ``doParticleShearSimulation.last_result`` either way.  Other
        protocols: ``SimulationResult.values`` (steady ``[σ, η]``, relaxation ``[G_plateau]``,
        creep ``[creep rate, σ₀/γ̇]``, sweeps ``[[G′, G″], …]``), or the
        :class:`SimulationResult` with ``return_result=True``.

    Raises
    ------
    ValueError, TypeError
        For any invalid parameter, naming it, its value and the allowed range, before any work.
    particleShear.run.guard.UnknownParameterError
        For a keyword that is not a parameter (``theAmplitud=``), naming the closest parameters
        ("did you mean theAmplitude?"), or for a parameter given under both spellings
        (``amplitude`` and ``theAmplitude``); a subclass of TypeError and ValueError.
    SimulationInstabilityError
        When the measurement diverges (``stability_guard``).

    See Also
    --------
    doParticleShearSimulationSeries : many runs on an executor.
    particleShear.Sweep : resumable parameter sweeps (docs/sweeps.md).

    Examples
    --------
    >>> G_storage, G_loss = doParticleShearSimulation(N=20, cut_lines=0, relative_frequency=0.2,
    ...     pre_periods=0.2, periods=1, post_periods=0, seed=1, doDrawing=False, verbose=False)
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
    options = dict(return_result=return_result, verbose=verbose, progress=progress,
                   correct_drift_sign=correct_drift_sign, reference_header=reference_header, renderer=renderer,
                   time_step_factor=time_step_factor, integrator=integrator, stability_guard=stability_guard,
                   output_format=output_format, strict_io=strict_io, saveOutputMovie=saveOutputMovie, backend=backend,
                   contact_law=contact_law, plateau_begin=plateau_begin, plateau_end=plateau_end,
                   plateau_slope=plateau_slope, protocol=protocol, relative_rate=relative_rate,
                   total_strain=total_strain, ramp_time=ramp_time, hold_time=hold_time, creep_stress=creep_stress,
                   creep_modulus=creep_modulus, creep_response_time=creep_response_time,
                   sweep_amplitudes=sweep_amplitudes, sweep_frequencies=sweep_frequencies,
                   stroboscopic=stroboscopic, **dict(_EXTRA_DEFAULTS, **law_parameters))
    params.update(options)   # every input, the keyword-only options included
    # every parameter and option, the resolution, the ensemble size and the cost (steps, memory) of the
    # run are checked before any work (limits in docs/parameters.md); the checked arguments, seed and
    # run id travel down as they are (RunParameters), measured by the engine as a batch of one
    result = measure_run(validated_run(params))
    return result if return_result else result.values


doParticleShearSimulation.last_result = None


def measure_run(run):
    """Measure one checked run as :func:`doParticleShearSimulation` does after its validation.

    The run is measured by the engine as a batch of one (:func:`~particleShear.run.measurement.measure`,
    console messages as ``run["verbose"]`` says); without a display the stress window of a saved
    oscillatory run is saved as a picture; the result becomes ``doParticleShearSimulation.last_result``.
    A sweep's worker measures the runs it made from a checked point (:meth:`CheckedPoint.run
    <particleShear.run.validation.CheckedPoint.run>`) here, so that they are not validated again.

    Parameters
    ----------
    run : RunParameters
        The checked arguments (:func:`~particleShear.run.validation.validated_run`).

    Returns
    -------
    SimulationResult

    Raises
    ------
    OSError
        The write error of the run's file with ``strict_io`` (``last_result`` holds the result).
    SimulationInstabilityError
        When the measurement diverges (``stability_guard``).
    """
    with console_messages(run["verbose"]):
        result = measure([run])[0]
    if run["plotStress"] and run["doDrawing"] and result.output_path and run["protocol"] == "oscillatory":
        _save_headless_stress_plot(result, run["renderer"])
    doParticleShearSimulation.last_result = result
    if run["strict_io"] and result.write_error is not None:
        raise result.write_error
    return result


def _save_headless_stress_plot(result, renderer):
    """Without a display the live stress window cannot open: save its content instead, as
    ``<output file>_stress.png`` (trace and Lissajous loop, needs matplotlib; skipped without it)."""
    import importlib.util
    if _backend_choice(renderer) in ("auto", "tk") and display_available()[0]:
        return  # the live window was shown
    if importlib.util.find_spec("matplotlib") is None:
        return
    result.plot(str(result.output_path) + "_stress.png")


def series_jobs(amplitudes, mu, cut_lines, do_bulk_control, do_uncrosslinked_control, do_non_frictional_control,
                N_repetitions):
    """The reference iteration order of a series (docs/parameters.md) as a list of (A, μ, do_permanent_links, cut_lines).

    Parameters
    ----------
    amplitudes, mu : sequence of float
        Strain amplitudes A (1) and friction coefficients μ (1), iterated A outer, μ inner.
    cut_lines : int
        Particles (cut lines) of the material runs.
    do_bulk_control, do_uncrosslinked_control, do_non_frictional_control : bool
        Add, per (A, μ), a bulk control (links, no cut) before the material run, an uncrosslinked
        control (no links) and a non-frictional control (μ = 0) after it.
    N_repetitions : int
        Repetitions of the whole grid (outermost loop).

    Returns
    -------
    list of tuple
        ``(A, μ, do_permanent_links, cut_lines)`` per run, in the reference order.
    """
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


def _run_options():
    """The keyword-only options of doParticleShearSimulation (what ``**options`` of a series may name)."""
    return [p.name for p in PARAMETERS if p.keyword_only]


#: names a series user may mean by a name of doParticleShearSimulation (the series takes lists)
_SERIES_HINTS = {"theAmplitude": "amplitudes", "amplitude": "amplitudes", "theMu": "mu", "mus": "mu",
                 "repetitions": "N_repetitions"}


@checked_keywords(documented="help(particleShear.doParticleShearSimulationSeries) and docs/parameters.md",
                  hints=_SERIES_HINTS, extra=_run_options)
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
                                    max_workers=None, verbose=False, batch_size=None, backend="auto",
                                    **options):
    """Run the reference series (repetitions × amplitudes × μ × controls) on an executor.

    Every run is a :func:`doParticleShearSimulation`; the parameters shared with it have its
    meaning, units, defaults and allowed ranges (see there), except where said below.

    Parameters
    ----------
    root_folder : str, default ""
        Output folder.  Empty: nothing is written.  Otherwise the series is a resumable sweep
        into this folder (see Notes); it must exist and be writable.
    amplitudes : list of float, default [0.2]
        Strain amplitudes A (dimensionless), each as ``theAmplitude``; 1 ... 1e5 values.  (The
        series has no ``theAmplitude``/``amplitude`` keyword: those name one value of one run.)
    mu : list of float, default [0.01]
        Friction coefficients μ (dimensionless), each as ``theMu``; 1 ... 1e5 values.
    cut_lines : int, default 5
        ``cut_lines`` of the material runs (the controls use 0).
    Young_modulus_spheres : float, default 8000
        Young modulus E in Pa, as in :func:`doParticleShearSimulation`.
    do_bulk_control : bool, default False
        Also run, per point, the uncut crosslinked gel (``cut_lines=0``).
    do_uncrosslinked_control : bool, default False
        Also run, per point, frictional spheres without links (``do_permanent_links=False``).
    do_non_frictional_control : bool, default False
        Also run, per point, the material without friction (``theMu=0``).
    N_repetitions : int, default 6
        Repetitions of the whole grid (different seeds); allowed 0 ... 1e5, at most 1e5 runs
        in all.
    N, packing_fraction, density, bimodal_factor, relative_viscosity : as in :func:`doParticleShearSimulation`
        Number of spheres; area fraction φ; density in kg/m³; radius ratio; rv (eq. S1-9).
    relative_transversal_link_strength, relative_frequency : float
        k_t/k; f·τ (as in :func:`doParticleShearSimulation`).
    avoid_horizontal_angle_degree : float, default 15
        Degrees, line-cut mode only (as in :func:`doParticleShearSimulation`).
    interface_reenforcement_central, interface_reenforcement_tangential : float, default 1
        Factors on k and k_t of transient contacts (as in :func:`doParticleShearSimulation`).
    keep_viscosity_coefficients_constant, avoid_height_spanning_particles, cut_top_bottom : bool
        As in :func:`doParticleShearSimulation` (defaults False, True, False).
    doCutByTriangulation, saveOutputImages, doDrawing, saveData, saveStressTensorData, plotStress : bool
        As in :func:`doParticleShearSimulation` (defaults True, False, True, False, True, True).
    imageFileType : {"jpg", "png", "ps", "svg"}, default "jpg"
        Snapshot format (as in :func:`doParticleShearSimulation`).
    remove_link_fraction, edge_fuzziness, central_repulsion_coefficient : float
        As in :func:`doParticleShearSimulation` (defaults 0, 0, 1).
    pre_periods, periods, post_periods : float, default 2, 3, 1
        Baseline, excitation and recovery in excitation periods.
    cool_factor : float, default 0.5
        Velocity fraction left after one period (as in :func:`doParticleShearSimulation`).
    executor : concurrent.futures.Executor, optional
        Where the runs execute (e.g. a ``ProcessPoolExecutor``, Dask's ``Client.get_executor()``,
        ``mpi4py.futures.MPIPoolExecutor``).  Default: a ``ProcessPoolExecutor(max_workers)``
        created and shut down here.  A given executor is not shut down.
    seed : None, int or numpy.random.SeedSequence, default None
        Root seed; run k gets ``SeedSequence(seed).spawn(n)[k]``, so the series is reproducible
        whatever the executor or the completion order.
    max_workers : int or None, default None
        Keyword-only.  Size of the default process pool (>= 1; None: all cores).
    verbose : bool, default False
        Keyword-only.  Forwarded to each run (default False: quiet workers).
    batch_size : int or None, default None
        Keyword-only.  When given, runs that share a step schedule (same N, time-step rule and
        protocol; see :func:`particleShear.run.batch.schedule_key`) are grouped into batches of up
        to ``batch_size`` runs, and each batch is one task of the executor
        (:func:`particleShear.run.batch.run_batch`).  The results are exactly those of the
        unbatched series, in the same order (and resumes like it with a ``root_folder``).
        Default None: one task per run.
    backend : {"auto", "numpy", "numba", "cupy"}, default "auto"
        Keyword-only.  Array backend of every run ("auto": ``PARTICLESHEAR_BACKEND`` when set, else
        "numba" where Numba can be imported, else "numpy"; "numba": each step compiled; "cupy": on a CUDA GPU, for runs without
        drawing and plotting; see :func:`doParticleShearSimulation`).  With ``batch_size`` a
        batch of replicas is measured in one set of device arrays.
    **options
        Further keyword-only options of :func:`doParticleShearSimulation`, passed to every run and
        checked as there (``progress``, ``correct_drift_sign``, ``reference_header``, ``renderer``,
        ``time_step_factor``, ``integrator``, ``stability_guard``, ``saveOutputMovie``,
        ``output_format``, ``strict_io``, ``contact_law``, ``plateau_begin``, ``plateau_end``,
        ``plateau_slope``, and the rheometer's ``protocol``, ``relative_rate``, ``total_strain``,
        ``ramp_time``, ``hold_time``, ``creep_stress``, ``creep_modulus``, ``creep_response_time``,
        ``sweep_amplitudes``, ``sweep_frequencies``: docs/protocols.md); not ``return_result``
        (every run returns its result).

    Returns
    -------
    list of SimulationResult
        One result per run (whatever its protocol; resumed runs rebuilt from the table's rows), in the
        reference iteration order (repetition, amplitude, μ, then bulk control, material,
        uncrosslinked control, non-frictional control).

    Raises
    ------
    ValueError, TypeError
        For an invalid grid or parameter of any run, before any run starts.
    particleShear.run.guard.UnknownParameterError
        For a keyword that is neither a parameter of the series nor a keyword-only option of
        :func:`doParticleShearSimulation`, naming the closest names (``theAmplitude`` →
        ``amplitudes``: the series takes lists; a subclass of TypeError and ValueError).
    RuntimeError
        When a run failed (raised once the other runs have finished).

    Notes
    -----
    Runs on the sweep machinery (docs/sweeps.md).  With a ``root_folder`` the series is a
    resumable sweep into that folder: files are named ``<reference stem><run id>.txt``, one row
    per run goes to ``root_folder/results.csv``, and calling again with the same arguments and
    ``seed`` runs only the runs that have not finished; those are returned as results rebuilt
    from their rows (moduli, parameters, seed, output path; no per-step series).
    """
    check_batch_size(batch_size)
    keyword_only = [p.name for p in PARAMETERS if p.keyword_only and p.name not in ("return_result", "verbose", "backend")]
    for name in options:
        if name not in keyword_only:
            raise TypeError(f"{name}={options[name]!r} is invalid for doParticleShearSimulationSeries: allowed the "
                            f"keyword-only options of doParticleShearSimulation {keyword_only} (every run returns "
                            "its SimulationResult)")
    # the grid (repetitions × amplitudes × μ × controls) is checked before any job is built
    amplitudes, mu = validate_series(N_repetitions, amplitudes, mu, do_bulk_control, do_uncrosslinked_control,
                                     do_non_frictional_control)
    if max_workers is not None and (isinstance(max_workers, bool) or not isinstance(max_workers, int)
                                    or max_workers < 1):
        raise ValueError(f"max_workers={max_workers!r} is out of range: allowed None or an integer >= 1")
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
    check_seed("seed", seed)
    jobs = series_jobs(amplitudes, mu, cut_lines, do_bulk_control, do_uncrosslinked_control,
                       do_non_frictional_control, N_repetitions)
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    children = root.spawn(len(jobs))
    all_kwargs = [dict(common, theAmplitude=A, theMu=m, do_permanent_links=links, cut_lines=cl, seed=child,
                       verbose=verbose, backend=backend, **options)
                  for (A, m, links, cl), child in zip(jobs, children)]
    # every run is checked before any work starts, once: its worker measures it from its checked arguments
    # (without runs: the material run of the first point, so that the options and shared parameters are
    # checked all the same)
    checked = [checked_point(kw) for kw in all_kwargs or [
        dict(common, theAmplitude=amplitudes[0], theMu=mu[0], do_permanent_links=True, cut_lines=cut_lines,
             seed=root, verbose=verbose, backend=backend, **options)]]
    if not all_kwargs:
        return []
    run_series = entry("run_series")
    per_repetition = len(jobs) // int(N_repetitions)
    return run_series(all_kwargs, root_folder, executor=executor, max_workers=max_workers, batch_size=batch_size,
                      repetitions=[k // per_repetition for k in range(len(jobs))], checked=checked)
