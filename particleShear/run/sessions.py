"""The sessions of a batch's runs: each run's simulation object and seed, its contact law
(:func:`build_sessions`), which :func:`particleShear.run.measurement.measure` hands to the one
measurement driver.

Below :mod:`particleShear.run.api`, :mod:`particleShear.run.batch` and
:mod:`particleShear.run.measurement`; the names keep their old homes as re-exports
(``run.api._build_simulation``, ``run.validation.contact_law_spec``).
"""
__docformat__ = "numpy"
import numbers

import numpy as np

from ..checks import show_value
from ..engine import contact_laws
from ..engine.xp import get_backend
from ..linkable.builders import EnsembleRecipe
from ..parameters import PARAMETERS
from ..parameters import defaults as _defaults
from ..simulation.fragmentation import Simulation_interlocking_rheology
from ..simulation.oscillatory import RunSession

__all__ = ["BACKENDS", "build_sessions", "check_backend", "check_batch_size", "check_run_backend", "contact_law_spec"]

#: array backends a batch can run on ("auto" first, the default; "cupy" needs CuPy and a CUDA device; see particleShear.engine.xp)
BACKENDS = ("auto", "numpy", "numba", "cupy")


def _signature_defaults():
    """Defaults of every keyword of ``doParticleShearSimulation`` (the parameter table's)."""
    return _defaults()


def check_backend(backend):
    """Raise ValueError unless ``backend`` names a backend that can run here.

    Parameters
    ----------
    backend : str
        Name of the array library of a measurement: one of :data:`BACKENDS` (or a backend
        registered with :func:`particleShear.engine.xp.register_backend`).

    Raises
    ------
    ValueError
        For an unknown name (naming ``backend``, its value and the allowed values), for
        ``"auto"`` with a value of ``PARTICLESHEAR_BACKEND`` that names no backend (naming the
        variable), for ``"numba"`` without Numba (naming ``particleShear[fast]``), or for
        ``"cupy"`` without CuPy or without a CUDA device.
    """
    get_backend(backend)


def check_run_backend(kw):
    """Check the backend of one run: usable here (every run is measured by the engine).

    Parameters
    ----------
    kw : dict
        Keyword arguments of :func:`~particleShear.run.api.doParticleShearSimulation` (missing
        ones take their defaults).

    Raises
    ------
    ValueError
        Naming ``backend``, for an unusable backend.
    """
    check_backend(dict(_signature_defaults(), **kw)["backend"])


def check_batch_size(batch_size):
    """Raise ValueError unless ``batch_size`` is None or an integer >= 1.

    Parameters
    ----------
    batch_size : int or None
        Largest number of replicas per batch.
    """
    if batch_size is None:
        return
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise ValueError(f"batch_size={batch_size!r} is out of range: allowed None or an integer >= 1")


def _seed_sequence(seed):
    """(SeedSequence or None, Generator) for ``seed`` = None, int, SeedSequence, Generator or BitGenerator."""
    if isinstance(seed, np.random.Generator):
        return None, seed
    if isinstance(seed, np.random.BitGenerator):
        return None, np.random.Generator(seed)
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return ss, np.random.default_rng(ss)


#: the arguments of :class:`Simulation_interlocking_rheology` that are run parameters of the same name
#: (its ``amplitude`` and ``mu`` are ``theAmplitude`` and ``theMu``; ``cut_lines`` and ``N`` are made int)
_SIMULATION_ARGUMENTS = ("do_permanent_links", "packing_fraction", "density", "bimodal_factor",
                         "Young_modulus_spheres", "relative_y_scale_force", "relative_frequency",
                         "relative_viscosity", "relative_transversal_link_strength", "central_repulsion_coefficient",
                         "avoid_horizontal_angle_degree", "interface_reenforcement_central",
                         "interface_reenforcement_tangential", "keep_viscosity_coefficients_constant",
                         "avoid_height_spanning_particles", "cut_top_bottom", "doCutByTriangulation",
                         "remove_link_fraction", "edge_fuzziness", "doDrawing", "saveData")


def _build_simulation(params, rng, *, verbose, progress, correct_drift_sign, reference_header, renderer,
                      time_step_factor, integrator, stability_guard):
    """The :class:`Simulation_interlocking_rheology` of one run, configured but not run.

    The documented class is made with keyword arguments read straight from ``params`` (no
    intermediate names), so a parameter's value reaches the simulation object in one step; its
    ensemble's :class:`~particleShear.linkable.builders.EnsembleRecipe` (``recipe``) is made from
    ``params`` likewise, so the constitution reads the run's values, not the object's attributes.

    Parameters
    ----------
    params : Mapping
        The validated arguments of :func:`doParticleShearSimulation` (a
        :class:`~particleShear.run.validation.RunParameters`, or any mapping with the reference
        arguments).
    rng : numpy.random.Generator
        The run's generator.
    verbose, progress, correct_drift_sign, reference_header, renderer, time_step_factor, integrator, stability_guard
        The keyword-only options of the run, set as attributes.

    Returns
    -------
    Simulation_interlocking_rheology
    """
    p = params
    pre_periods, post_periods, periods = p["pre_periods"], p["post_periods"], p["periods"]
    saveOutputImages, imageFileType, cool_factor = p["saveOutputImages"], p["imageFileType"], p["cool_factor"]
    N, cut_lines = int(p["N"]), int(p["cut_lines"])
    theSimulation = Simulation_interlocking_rheology(
        p["root_folder"], cut_lines=cut_lines, N=N, amplitude=p["theAmplitude"], mu=p["theMu"],
        **{name: p[name] for name in _SIMULATION_ARGUMENTS})
    # the ensemble's parameters: one record of the run's values (μ its field ``mu``), which the constitution
    # reads as they are (not from the simulation's attributes)
    theSimulation.recipe = EnsembleRecipe.of(p, mu=p["theMu"], anticipated_amplitude=p["theAmplitude"], N=N,
                                             cut_lines=cut_lines)
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
    theSimulation.saveStressTensorData = p["saveStressTensorData"]
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


def contact_law_spec(p):
    """The central law of one run as the engine takes it: None for "linear", else ``(name, values)``.

    "linear" is the documented callback ``CircleBasicElasticity.call_back_elastic_force_law``
    (the built-in linear law unless replaced: the class-attribute way of 1.0.2); another law of
    the laws folder (:mod:`particleShear.engine.contact_laws`), of :func:`register_law` or
    ``"package.module:function"`` is that law with its parameters (given, else their declared
    defaults).  The parameters of every law of the laws folder are checked whatever the law
    (types, declared ranges, the law's own check), as the plateau parameters were in 2.0.0.

    Parameters
    ----------
    p : dict
        Arguments of the run (``contact_law`` and the laws' parameters; missing ones take
        their defaults).

    Returns
    -------
    tuple or None
        ``(name, values)``: the law's name and its parameter values in order.

    Raises
    ------
    TypeError
        For a law parameter that is not a real number.
    ValueError
        For an unknown law (naming ``contact_law``, the allowed names and the closest one) or a
        law parameter out of range (naming it, its value and the range).
    """
    def given(law):
        out = {}
        for name, default in law.parameters.items():
            v = p.get(name, default)
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
                raise TypeError(f"{name}={show_value(v)} is invalid: allowed a real number")
            out[name] = float(v)
        return out

    for name in contact_laws.MODULES:
        contact_laws.law_values(contact_laws.LAWS[name], given(contact_laws.LAWS[name]))
    law = contact_laws.get_law(p.get("contact_law", "linear"))
    if law.name == "linear":
        return None
    return law.name, contact_laws.law_values(law, given(law))


def build_sessions(runs):
    """The simulation object and :class:`~particleShear.simulation.oscillatory.RunSession` of every run.

    Parameters
    ----------
    runs : list of RunParameters
        The checked arguments of the replicas (:func:`~particleShear.run.validation.validated_run`);
        each is read as it is (no copy) and keeps its seed and run id.

    Returns
    -------
    sims : list
        The documented simulation of each run (not constituted).
    seeds : list of tuple
        ``(seed entropy, spawn key, run parameters)`` of each run.
    sessions : list of RunSession
        One session per run, in order.
    """
    sims, seeds, sessions = [], [], []
    for kw in runs:  # every replica's settings were checked (validated_run) before any work
        seed_entropy, spawn_key = kw.seed_entropy, kw.spawn_key
        sim = _build_simulation(kw, kw.generator, verbose=kw["verbose"], progress=kw["progress"],
                                correct_drift_sign=kw["correct_drift_sign"], reference_header=kw["reference_header"],
                                renderer=kw["renderer"], time_step_factor=kw["time_step_factor"],
                                integrator=kw["integrator"], stability_guard=kw["stability_guard"])
        sim.output_format = kw["output_format"]
        sim.saveOutputMovie = bool(kw["saveOutputMovie"])
        sim.run_id, sim.seed_entropy, sim.spawn_key = kw.run_id, seed_entropy, spawn_key
        sim.parameters = kw
        sim.contact_law = contact_law_spec(kw)
        sessions.append(RunSession(sim, kw["cool_factor"], kw["periods"], kw["plotStress"]))
        sims.append(sim)
        seeds.append((seed_entropy, spawn_key, kw))
    return sims, seeds, sessions


#: the arguments a SimulationResult lists in ``parameters`` (the reference's, in its order)
_REFERENCE_ARGUMENTS = tuple(p.name for p in PARAMETERS if not p.keyword_only)
