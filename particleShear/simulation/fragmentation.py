"""The simulation classes of crosslinked ensembles cut into particles ("fragmentation"; docs/output.md).

:class:`OscillatorySimulationFragmentation` (the legacy builder with fixed material constants),
:class:`Simulation_dermal_filler_rheology` (full material parameters, legacy builder) and
:class:`Simulation_interlocking_rheology` (the adjustable interface strength builder: the scene of
``doParticleShearSimulation``).  Each constitutes its gel on the engine's state
(:meth:`OscillatorySimulationFragmentation.constitution_steps`, the builders' schedule of its
recipe; ``theEnsemble`` is the documented ensemble as a view of that state) and writes its file
header; the run itself is :class:`~particleShear.simulation.oscillatory.OscillatorySimulation`'s.
"""
__docformat__ = "numpy"
import inspect
import math
import os

from ..engine.relax import RELAX_SKIN
from ..linkable.builders import (EnsembleCompactParticlesFromModelParameters, EnsembleRecipe,
                                 ensemble_of_state, relax_constitution, state_constitution)
from .provenance import header_number, positional_numbers_in_call, provenance_lines
from .oscillatory import OscillatorySimulation, _log, _writes, call_string

__all__ = ["OscillatorySimulationFragmentation", "Simulation_dermal_filler_rheology", "Simulation_interlocking_rheology",
           "builder_of"]

#: the legacy builder's defaults, by parameter name: the recipe of
#: :class:`OscillatorySimulationFragmentation` is that builder called with the class's parameters
_LEGACY_DEFAULTS = {name: p.default for name, p in
                    inspect.signature(EnsembleCompactParticlesFromModelParameters).parameters.items()}


class OscillatorySimulationFragmentation(OscillatorySimulation):
    """Crosslinked ensembles cut into particles ("fragmentation"); file naming and header of docs/output.md.

    Builds the ensemble of the legacy builder ``EnsembleCompactParticlesFromModelParameters``
    (fixed material constants apart from those given here) on the engine's state
    (:meth:`constitution_steps`; the ensemble a view of it).

    Parameters
    ----------
    root_folder : str
        Folder of the text file and the image folder (must exist and be writable when saving).
    do_permanent_links : bool, optional
        Crosslink all contacts after relaxation (False: frictional spheres only).
    cut_lines : int, optional
        Number of particles the crosslinked gel is cut into (Voronoi seeds); ≤ 1 / 0 = bulk gel.
    N : int, optional
        Number of spheres.
    packing_fraction : float, optional
        Nominal (uncompressed) area fraction φ defining the radii (eq. S1-14).
    amplitude : float, optional
        Strain amplitude A (0.5 = 50 %).
    Young_modulus_spheres : float, optional
        Young modulus E of the sphere material (Pa); spring constant k = π E/8 (eq. S1-8).
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts.
    relative_y_scale_force : float, optional
        Plot scaling of the stress window only.
    relative_frequency : float, optional
        Excitation frequency in units of the characteristic frequency 1/τ (f = relative_frequency/τ).
    doDrawing : bool, optional
        Live particle window when a display exists (snapshots do not need it).
    saveData : bool, optional
        Write the text file (docs/output.md).
    """

    def __init__(self, root_folder, do_permanent_links=True, cut_lines=5, N=150, packing_fraction=2, amplitude=0.5,
                 Young_modulus_spheres=1000, mu=0.1, relative_y_scale_force=5e-4, relative_frequency=0.05,
                 doDrawing=True, saveData=False):
        OscillatorySimulation.__init__(self, root_folder, amplitude, relative_y_scale_force, relative_frequency,
                                       doDrawing, saveData)
        self.packing_fraction = packing_fraction
        self.N = N
        self.do_permanent_links = do_permanent_links
        self.cut_lines = cut_lines
        self.Young_modulus_spheres = Young_modulus_spheres
        self.mu = mu
        self.theEnsemble = None
        self.model = False
        self.function_call = call_string("OscillatorySimulationFragmentation", root_folder=root_folder,
            do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N, packing_fraction=packing_fraction,
            amplitude=amplitude, Young_modulus_spheres=Young_modulus_spheres, mu=mu,
            relative_y_scale_force=relative_y_scale_force, relative_frequency=relative_frequency,
            doDrawing=doDrawing)

    def adjustment_factor_for_bounded_preequilibration_steps(self):
        """Multiplier of the pre-equilibration length: ``int(2 − log10 μ)`` for 0 < μ ≤ 1, else 1."""
        if 0 < self.mu <= 1:
            return int(2 - math.log10(self.mu))
        return 1

    def _window_title(self):
        return ("Interface: tangential=" + str(getattr(self, "interface_reenforcement_tangential", 1))
                + " central=" + str(getattr(self, "interface_reenforcement_central", 1))
                + " A=" + str(self.amplitude) + " mu=" + str(self.mu))

    #: the builders' constitution of the class: the legacy builder's (``linkable.builders``,
    #: ``legacy=True``); :class:`Simulation_interlocking_rheology` has the adjustable interface's
    legacy_builder = True
    #: the method giving the recipe of the class's builder: this class's own legacy call (which
    #: its 1.0.2 ``initEnsemble`` made whatever the subclass), the others' :meth:`ensemble_recipe`
    recipe_method = "_legacy_call_recipe"
    #: the constitution of the last :meth:`initEnsemble` or :meth:`constitution_steps` on the engine's
    #: state (``linkable.builders.ConstitutedState``), whose state ``theEnsemble`` is a view of; None before
    constituted = None

    def ensemble_recipe(self):
        """The :class:`~particleShear.linkable.builders.EnsembleRecipe` of this simulation's ensemble
        (here :meth:`_legacy_call_recipe`).

        Returns
        -------
        EnsembleRecipe
        """
        return self._legacy_call_recipe()

    def _legacy_call_recipe(self):
        """The recipe of the legacy builder ``EnsembleCompactParticlesFromModelParameters`` called with
        this class's parameters (its own defaults for the rest; the cell of 500 × 500 µm, the
        anticipated amplitude ``amplitude``)."""
        return EnsembleRecipe.of(_LEGACY_DEFAULTS, size_x=500, size_y=500, N=self.N,
                                 packing_fraction=self.packing_fraction, mu=self.mu,
                                 Young_modulus_spheres=self.Young_modulus_spheres, cut_lines=self.cut_lines,
                                 do_permanent_links=self.do_permanent_links, anticipated_amplitude=self.amplitude)

    def initEnsemble(self, do_debug=False):
        """Build ``theEnsemble``: the requests of :meth:`constitution_steps` of this class's builder
        run one by one.

        The builder's ensemble bit for bit (here the legacy builder called with this class's
        parameters, also on a subclass's instance, as in 1.0.2; the subclasses' ``initEnsemble``
        their builders'), as a view of the state :attr:`constituted`.

        Parameters
        ----------
        do_debug : bool, optional
            Passed to the builder: a tenth of the relaxation steps, for quick tests (default False).

        Returns
        -------
        EnsembleCompactParticles or EnsembleCompactParticlesAdjustableInterfaceStrength
            The relaxed, crosslinked and cut ensemble (also ``self.theEnsemble``).
        """
        return relax_constitution(self.constitution_steps(do_debug, builder=OscillatorySimulationFragmentation))

    def constitution_builder(self):
        """The documented class whose ``initEnsemble`` this simulation's class has (:func:`builder_of`),
        None where it has its own."""
        return builder_of(type(self))

    def constitution_steps(self, do_debug=False, relaxation_law=None, relaxation_backend="numpy",
                           skin_factor=RELAX_SKIN, builder=None):
        """:meth:`initEnsemble` as a generator of the relaxations of a constitution on the engine's state.

        Runs :func:`~particleShear.linkable.builders.state_constitution` of the recipe of
        ``builder`` (its :attr:`recipe_method`; the builders' schedule, ``legacy`` =
        ``builder.legacy_builder``, on a one-replica engine state), yielding each of its
        :class:`~particleShear.linkable.builders.Relaxation` requests, then keeps the
        :class:`~particleShear.linkable.builders.ConstitutedState` as :attr:`constituted` and sets
        ``theEnsemble`` to its documented ensemble, a view of its state
        (:func:`~particleShear.linkable.builders.ensemble_of_state`: bit for bit the builder's
        ensemble of the same recipe and seed, but for the rows of ended relations the builder's
        pair table keeps), and ``model``, ``dt`` and ``dt_max``, as
        :meth:`initEnsemble` does (which runs the requests one by one).  A run's driver runs the
        requests of its sessions together (``simulation.driver``) with the run's law and backend.

        Parameters
        ----------
        do_debug : bool, optional
            Passed to the builder: a tenth of the relaxation steps, for quick tests (default False).
        relaxation_law, relaxation_backend, skin_factor : optional
            The central law, host backend and Verlet skin of the relaxations, as
            :func:`~particleShear.linkable.builders.constituted_state` takes them (defaults: the
            builders').
        builder : type, optional
            The documented class whose builder constitutes (:func:`builder_of`; default: the one
            whose ``initEnsemble`` this simulation's class has, else the nearest in its MRO).

        Yields
        ------
        Relaxation
            The next relaxation block.

        Returns
        -------
        EnsembleCompactParticles or EnsembleCompactParticlesAdjustableInterfaceStrength
            The constituted ensemble (also ``self.theEnsemble``).
        """
        if builder is None:
            builder = builder_of(type(self)) or next(c for c in type(self).__mro__ if c in _DOCUMENTED)
        recipe, legacy = getattr(self, builder.recipe_method)(), builder.legacy_builder
        self.constituted = yield from state_constitution(
            recipe, legacy=legacy, rng=self.rng, law=self.contact_law, relaxation_law=relaxation_law,
            relaxation_backend=relaxation_backend, skin_factor=skin_factor, do_debug=do_debug, verbose=self.verbose)
        self.theEnsemble = ensemble_of_state(self.constituted, recipe, legacy=legacy)
        self.model = self.theEnsemble.model
        self.dt = self.theEnsemble.dt
        self.dt_max = self.theEnsemble.dt_max
        return self.theEnsemble

    def _file_stem(self):
        name = "dermal_filler"
        if self.do_permanent_links:
            if not self.cut_lines > 0:
                name += "_bulk"
        else:
            name += "_uncrosslinked"
        f = self.f if self.f != -1 else self._frequency()
        name += (str(self.mu) + "_f_" + str(round(f * 10000) / 10000) + "_strain_"
                 + str(round(self.amplitude * 100000) / 100000) + "_nr_")
        return os.path.join(str(self.root_folder), name)

    def _frequency(self):
        model = self.model or getattr(self.theEnsemble, "model", False)
        return self.relative_frequency / model.time_constant if model else -1

    def write_information_on_simulation_to_file(self, theFile):
        """Block 1 of the text file (docs/output.md; and, unless ``reference_header``, the provenance lines
        after μ); nothing for ``theFile`` False/None or ``saveData`` False.

        Parameters
        ----------
        theFile : file-like, False or None
            An open text file (or any object with ``write``).
        """
        if not _writes(self, theFile):
            return
        if self.do_permanent_links:
            if self.cut_lines > 0:
                head = ("Dermal filler Ensemble: \n\tCutting lines used to generate the particles"
                        + str(self.cut_lines) + "\n")
            else:
                head = "Dermal filler control ensemble: no cut lines \n"
        else:
            head = "Dermal filler control ensemble: No permanent links\n"
        if self.reference_header:  # the reference text exactly
            num, call, extra = str, self.function_call, ""
        else:  # positional numbers for the R patterns, and the provenance lines
            num, call = header_number, positional_numbers_in_call(self.function_call)
            extra = provenance_lines(self.run_id, self.seed_entropy, self.spawn_key,
                                     getattr(self, "time_step_factor", 1.0), getattr(self, "integrator", "euler"),
                                     self.correct_drift_sign, getattr(self, "contact_law", None)) + "\n"
        theFile.write(head
                      + "\tN=" + num(self.N) + " spheres, nominal packing density = " + num(self.packing_fraction)
                      + "\n\tYoung modulus of the individual spheres = " + num(self.Young_modulus_spheres) + " Pa \n"
                      + "\tFriction coefficient = " + num(self.mu) + "\n" + extra + "\n\n\n"
                      + "Function call : \n" + call + "\n\n")


class Simulation_dermal_filler_rheology(OscillatorySimulationFragmentation):
    """Fragmentation simulation with full material parameters; legacy builder.

    Parameters
    ----------
    root_folder : str
        Folder of the text file and the image folder (must exist and be writable when saving).
    do_permanent_links : bool, optional
        Crosslink all contacts after relaxation (False: frictional spheres only).
    cut_lines : int, optional
        Triangulation: number of particles (Voronoi seeds); line mode: number of straight cuts;
        ≤ 1 / 0 = bulk gel.
    N : int, optional
        Number of spheres.
    packing_fraction : float, optional
        Nominal (uncompressed) area fraction φ defining the radii (eq. S1-14).
    bimodal_factor : float, optional
        Large/small radius ratio (50/50 random).
    amplitude : float, optional
        Strain amplitude A (0.5 = 50 %).
    Young_modulus_spheres : float, optional
        Young modulus E of the sphere material (Pa); spring constant k = π E/8 (eq. S1-8).
    density : float, optional
        Material density (kg/m³).
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts (permanent links are not limited).
    relative_viscosity : float, optional
        rv in the contact viscosity ν = rv·√(m k) (eq. S1-9).
    relative_y_scale_force : float, optional
        Plot scaling of the stress window only.
    relative_frequency : float, optional
        f·τ: excitation frequency in units of the characteristic frequency 1/τ.
    relative_transversal_link_strength : float, optional
        k_t/k and ν_t/ν: tangential relative to central stiffness and viscosity.
    central_repulsion_coefficient : float, optional
        c of the central force law, 0 … 1 (1 = divergent law eq. S1-5b, 0 = linear eq. S1-5a).
    avoid_horizontal_angle_degree : float, optional
        Line-cut mode only: forbidden band (degrees) around horizontal cut lines.
    avoid_height_spanning_particles : bool, optional
        Re-cut while a particle is taller than 0.9·L_y.
    doCutByTriangulation : bool, optional
        Particles by periodic Voronoi cells (False: random straight lines).
    doDrawing : bool, optional
        Live particle window when a display exists (snapshots do not need it).
    saveData : bool, optional
        Write the text file (docs/output.md).
    """

    def __init__(self, root_folder, do_permanent_links=True, cut_lines=5, N=150, packing_fraction=2,
                 bimodal_factor=1.4, amplitude=0.5, Young_modulus_spheres=1000, density=50, mu=0.1,
                 relative_viscosity=0.01, relative_y_scale_force=5e-4, relative_frequency=0.05,
                 relative_transversal_link_strength=1, central_repulsion_coefficient=1,
                 avoid_horizontal_angle_degree=0, avoid_height_spanning_particles=False, doCutByTriangulation=True,
                 doDrawing=True, saveData=False):
        OscillatorySimulationFragmentation.__init__(
            self, root_folder, do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N,
            packing_fraction=packing_fraction, amplitude=amplitude, Young_modulus_spheres=Young_modulus_spheres,
            mu=mu, relative_y_scale_force=relative_y_scale_force, relative_frequency=relative_frequency,
            doDrawing=doDrawing, saveData=saveData)
        self.avoid_horizontal_angle_degree = avoid_horizontal_angle_degree
        self.avoid_height_spanning_particles = avoid_height_spanning_particles
        self.doCutByTriangulation = doCutByTriangulation
        self.bimodal_factor = bimodal_factor
        self.central_repulsion_coefficient = central_repulsion_coefficient
        self.density = density
        self.relative_viscosity = relative_viscosity
        self.relative_transversal_link_strength = relative_transversal_link_strength
        self.dt = None
        self.dt_max = None
        # the leading arguments of the header's function-call line, shared with the subclass
        self._call_arguments = dict(root_folder=root_folder,
            do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N, packing_fraction=packing_fraction,
            bimodal_factor=bimodal_factor, amplitude=amplitude, Young_modulus_spheres=Young_modulus_spheres,
            density=density, mu=mu, relative_viscosity=relative_viscosity,
            relative_y_scale_force=relative_y_scale_force, relative_frequency=relative_frequency,
            relative_transversal_link_strength=relative_transversal_link_strength,
            central_repulsion_coefficient=central_repulsion_coefficient,
            avoid_horizontal_angle_degree=avoid_horizontal_angle_degree,
            avoid_height_spanning_particles=avoid_height_spanning_particles)
        self.function_call = call_string("Simulation_dermal_filler_rheology", **self._call_arguments,
                                         doCutByTriangulation=doCutByTriangulation, doDrawing=doDrawing)

    def adjustment_factor_for_bounded_preequilibration_steps(self):
        """Longer fixed-boundary relaxation for low friction, amplitude or viscosity.

        ``F = 1``, times 1.5 if μ ≤ 0.1, 2 if μ ≤ 0.01, 2 if μ ≤ 0.001, ``1 − (log10 A + 2)``
        if A ≤ 0.01, 2 if A ≤ 0.005 and 2 if rv ≤ 0.1 (default run: 6, so N = 150 steps).

        Returns
        -------
        float
        """
        F = 1
        mu, A = self.mu, self.amplitude
        if mu <= 0.1:
            F *= 1.5
        if mu <= 0.01:
            F *= 2
        if mu <= 0.001:
            F *= 2
        if A <= 0.01:
            F *= 1 - (math.log10(A) + 2)
        if A <= 0.005:
            F *= 2
        if self.relative_viscosity <= 0.1:
            F *= 2
        if self.verbose:
            _log.info("Adjustment factor of pre-equilibration time for low amplitude and friction: " + str(F))
        return F

    #: the recipe of the ensemble when the run gives it (``doParticleShearSimulation``: made from the checked
    #: run, :func:`particleShear.run.sessions.build_sessions`); None: made from this object's attributes
    recipe = None

    def ensemble_recipe(self):
        """The :class:`~particleShear.linkable.builders.EnsembleRecipe` of this simulation's ensemble.

        :attr:`recipe` when given, else the recipe of this object's attributes (the cell of
        500 × 500 µm, the anticipated amplitude ``amplitude``).

        Returns
        -------
        EnsembleRecipe
        """
        return self.recipe if self.recipe is not None else EnsembleRecipe(**self._recipe_fields())

    def _recipe_fields(self):
        """The fields of :meth:`ensemble_recipe` this class sets (the subclass adds its interface)."""
        return dict(
            N=self.N, packing_fraction=self.packing_fraction, mu=self.mu,
            Young_modulus_spheres=self.Young_modulus_spheres, density=self.density,
            bimodal_factor=self.bimodal_factor, cut_lines=self.cut_lines, do_permanent_links=self.do_permanent_links,
            relative_viscosity=self.relative_viscosity,
            central_repulsion_coefficient=self.central_repulsion_coefficient, anticipated_amplitude=self.amplitude,
            relative_transversal_link_strength=self.relative_transversal_link_strength,
            avoid_horizontal_angle_degree=self.avoid_horizontal_angle_degree,
            avoid_height_spanning_particles=self.avoid_height_spanning_particles,
            doCutByTriangulation=self.doCutByTriangulation)

    #: the recipe of this class's builder: :meth:`ensemble_recipe` (which a subclass may override)
    recipe_method = "ensemble_recipe"

    def initEnsemble(self, do_debug=False):
        """Build ``theEnsemble`` with the legacy builder and every material parameter
        (:meth:`ensemble_recipe`): the requests of :meth:`constitution_steps` run one by one, the
        builder's ensemble bit for bit as a view of the state :attr:`constituted`.

        Parameters
        ----------
        do_debug : bool, optional
            Passed to the builder: a tenth of the relaxation steps, for quick tests (default False).

        Returns
        -------
        EnsembleCompactParticles
            The relaxed, crosslinked and cut ensemble (also ``self.theEnsemble``).
        """
        return relax_constitution(self.constitution_steps(do_debug, builder=Simulation_dermal_filler_rheology))


class Simulation_interlocking_rheology(Simulation_dermal_filler_rheology):
    """The simulation created by ``doParticleShearSimulation``: adjustable interface strength.

    Builds the ensemble of ``EnsembleCompactParticlesAdjustableInterfaceStrengthFromModelParameters``
    on the engine's state (:meth:`constitution_steps`; the ensemble a view of it).  The class
    defaults are the reference's and differ from those of ``doParticleShearSimulation``
    (docs/parameters.md), which passes every argument.

    Parameters
    ----------
    root_folder : str
        Folder of the text file and the image folder (must exist and be writable when saving).
    do_permanent_links : bool, optional
        Crosslink all contacts after relaxation (False: frictional spheres only).
    cut_lines : int, optional
        Triangulation: number of particles (Voronoi seeds); line mode: number of straight cuts;
        ≤ 1 / 0 = bulk gel.
    N : int, optional
        Number of spheres.
    packing_fraction : float, optional
        Nominal (uncompressed) area fraction φ defining the radii (eq. S1-14).
    bimodal_factor : float, optional
        Large/small radius ratio (50/50 random).
    amplitude : float, optional
        Strain amplitude A (0.5 = 50 %); also the builder's anticipated amplitude (time step,
        relaxation length).
    Young_modulus_spheres : float, optional
        Young modulus E of the sphere material (Pa); spring constant k = π E/8 (eq. S1-8).
    density : float, optional
        Material density (kg/m³).
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts (permanent links are not limited).
    relative_viscosity : float, optional
        rv in the contact viscosity ν = rv·√(m k) (eq. S1-9).
    relative_y_scale_force : float, optional
        Plot scaling of the stress window only.
    relative_frequency : float, optional
        f·τ: excitation frequency in units of the characteristic frequency 1/τ.
    relative_transversal_link_strength : float, optional
        k_t/k and ν_t/ν: tangential relative to central stiffness and viscosity.
    avoid_horizontal_angle_degree : float, optional
        Line-cut mode only: forbidden band (degrees) around horizontal cut lines.
    avoid_height_spanning_particles : bool, optional
        Re-cut while a particle is taller than 0.9·L_y.
    interface_reenforcement_central : float, optional
        Factor on k of transient contacts relative to permanent links.
    interface_reenforcement_tangential : float, optional
        The same for the tangential stiffness k_t.
    central_repulsion_coefficient : float, optional
        c of the central force law, 0 … 1 (1 = divergent law eq. S1-5b, 0 = linear eq. S1-5a).
    keep_viscosity_coefficients_constant : bool, optional
        False: the viscosities follow the reinforcement factors.
    cut_top_bottom : bool, optional
        Cut every link through the y-periodic boundary (wall-slip emulation).
    doCutByTriangulation : bool, optional
        Particles by periodic Voronoi cells (False: random straight lines).
    remove_link_fraction : float, optional
        Target fraction (0 … 1) of non-essential links to remove.
    edge_fuzziness : float, optional
        Random roughening of the Voronoi borders, in units of the largest radius r_max.
    doDrawing : bool, optional
        Live particle window when a display exists (snapshots do not need it).
    saveData : bool, optional
        Write the text file (docs/output.md).
    """

    def __init__(self, root_folder, do_permanent_links=True, cut_lines=5, N=150, packing_fraction=2,
                 bimodal_factor=1.4, amplitude=0.5, Young_modulus_spheres=1000, density=50, mu=0.1,
                 relative_viscosity=0.01, relative_y_scale_force=5e-4, relative_frequency=0.05,
                 relative_transversal_link_strength=1, avoid_horizontal_angle_degree=15,
                 avoid_height_spanning_particles=False, interface_reenforcement_central=1,
                 interface_reenforcement_tangential=1, central_repulsion_coefficient=1,
                 keep_viscosity_coefficients_constant=True, cut_top_bottom=True, doCutByTriangulation=True,
                 remove_link_fraction=0, edge_fuzziness=0, doDrawing=True, saveData=False):
        Simulation_dermal_filler_rheology.__init__(
            self, root_folder, do_permanent_links=do_permanent_links, cut_lines=cut_lines, N=N,
            packing_fraction=packing_fraction, bimodal_factor=bimodal_factor, amplitude=amplitude,
            Young_modulus_spheres=Young_modulus_spheres, density=density, mu=mu,
            relative_viscosity=relative_viscosity, relative_y_scale_force=relative_y_scale_force,
            relative_frequency=relative_frequency,
            relative_transversal_link_strength=relative_transversal_link_strength,
            central_repulsion_coefficient=central_repulsion_coefficient,
            avoid_horizontal_angle_degree=avoid_horizontal_angle_degree,
            avoid_height_spanning_particles=avoid_height_spanning_particles,
            doCutByTriangulation=doCutByTriangulation, doDrawing=doDrawing, saveData=saveData)
        self.interface_reenforcement_central = interface_reenforcement_central
        self.interface_reenforcement_tangential = interface_reenforcement_tangential
        self.keep_viscosity_coefficients_constant = keep_viscosity_coefficients_constant
        self.cut_top_bottom = cut_top_bottom
        self.remove_link_fraction = remove_link_fraction
        self.edge_fuzziness = edge_fuzziness
        self.function_call = call_string("Simulation_interlocking_rheology", **self._call_arguments,
            interface_reenforcement_central=interface_reenforcement_central,
            interface_reenforcement_tangential=interface_reenforcement_tangential,
            keep_viscosity_coefficients_constant=keep_viscosity_coefficients_constant,
            cut_top_bottom=cut_top_bottom, doCutByTriangulation=doCutByTriangulation,
            remove_link_fraction=remove_link_fraction, edge_fuzziness=edge_fuzziness, doDrawing=doDrawing)

    def _recipe_fields(self):
        return dict(Simulation_dermal_filler_rheology._recipe_fields(self),
                    interface_reenforcement_central=self.interface_reenforcement_central,
                    interface_reenforcement_tangential=self.interface_reenforcement_tangential,
                    keep_viscosity_coefficients_constant=self.keep_viscosity_coefficients_constant,
                    cut_top_bottom=self.cut_top_bottom, remove_link_fraction=self.remove_link_fraction,
                    edge_fuzziness=self.edge_fuzziness)

    #: the adjustable interface's constitution (``linkable.builders``, ``legacy=False``)
    legacy_builder = False

    def initEnsemble(self, do_debug=False):
        """Build ``theEnsemble`` with the adjustable interface's builder (``anticipated_amplitude =
        amplitude``): the requests of :meth:`constitution_steps` run one by one, the builder's
        ensemble bit for bit as a view of the state :attr:`constituted`.

        Parameters
        ----------
        do_debug : bool, optional
            Passed to the builder: a tenth of the relaxation steps, for quick tests (default False).

        Returns
        -------
        EnsembleCompactParticlesAdjustableInterfaceStrength
            The relaxed, crosslinked and cut ensemble (also ``self.theEnsemble``).
        """
        return relax_constitution(self.constitution_steps(do_debug, builder=Simulation_interlocking_rheology))


#: the documented simulation classes, each with the ``initEnsemble`` of its own builder
_DOCUMENTED = (OscillatorySimulationFragmentation, Simulation_dermal_filler_rheology, Simulation_interlocking_rheology)


def builder_of(cls):
    """The documented class whose ``initEnsemble`` the simulation class ``cls`` has, or None for its own.

    A run constitutes on the engine's state, batched, exactly when this is not None
    (``RunSession.constitution`` through ``constitution_builder``: ``constitution_steps`` with that
    builder).

    Parameters
    ----------
    cls : type

    Returns
    -------
    type or None
    """
    init = getattr(cls, "initEnsemble", None)
    return next((c for c in _DOCUMENTED if vars(c).get("initEnsemble") is init), None)

