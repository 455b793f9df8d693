"""Compact particles: crosslinked spheres cut into particles, the connected components of the bond graph.

``physical_neighbors_only``: count only physical bonds, which do not wrap through the periodic
boundary.  ``particles`` is, as in 1.0.2, a list of lists of spheres.
"""
__docformat__ = "numpy"

import numpy as np

from ..base.canvas_base import check_non_negative
from ..base.engine_adapter import relax_ensembles
from ..checks import in_range
from ..engine.graph import adjacency, component_labels
from ..objects.ensembles import RandomBimodalSpheres
from . import bonds
from .canvas import CanvasPointsLinkable, EnsembleLinkable
from .spheres import SphereLinkableAdjustableInterfaceStrength

__all__ = ["EnsembleCompactParticles", "EnsembleCompactParticlesAdjustableInterfaceStrength",
           "component_labels"]


class EnsembleCompactParticles(RandomBimodalSpheres, CanvasPointsLinkable):
    """Random bimodal linkable spheres that are crosslinked and cut into compact particles.

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor, k_t, nu_t, mu
        As for :class:`~particleShear.objects.ensembles.EnsembleFrictionLeesEdwards` (ValueError when out of range).
    dt, dt_max : float, optional
        Final and coarsest step of :meth:`free_pre_equilibration` (s).
    theTkSimulation : object or False, optional
    avoid_horizontal_angle_degree : float, optional
        Half-width (degrees, in [0, 90)) of the band of near-horizontal lines :meth:`cutRandomLine` redraws.
    rng : numpy.random.Generator, int or None, optional
        Generator or seed of every random choice (None: the ensemble's own).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1, dt=1, dt_max=10, theTkSimulation=False,
                 avoid_horizontal_angle_degree=0, rng=None):
        CanvasPointsLinkable.__init__(self, size_x, size_y, theCanvas=theCanvas, doDrawing=doDrawing, k=k, nu=nu, m=m,
                                      k_t=k_t, nu_t=nu_t, mu=mu)
        in_range("avoid_horizontal_angle_degree", avoid_horizontal_angle_degree, 0, 90, hi_open=True)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        if rng is not None:
            self.set_random_generator(np.random.default_rng(rng))
        self.avoid_horizontal_angle_degree = avoid_horizontal_angle_degree
        self.avoid_height_spanning_particles = False
        self.doCutByTriangulation = False
        self.removed_fraction = 0
        self.edge_fuzziness = 0
        self.dt = dt
        self.dt_max = dt_max
        self.theTkSimulation = theTkSimulation
        self.model = False
        self.particles = []
        #: number of relaxation steps run by :meth:`free_pre_equilibration` so far (bookkeeping)
        self.n_constitution_steps = 0
        self._create_spheres(N, m)

    _new_sphere = EnsembleLinkable._new_sphere

    def particle_info(self, reference=False):
        """Description of the spheres for the output file's header (exactly the text of 1.0.2 if ``reference``).

        Parameters
        ----------
        reference : bool, optional
        """
        return ("Frictional spheres under Lees-Edwards boundary conditions, organized in fixed particles\n\t"
                + self._sphere_info(reference))

    def _sphere_info(self, reference=False):
        if reference:
            mass = str(float(self._a["m"][0])) if self._n else "0"
            return ("Spheres with, bimodal distribution, equal probability, \n\tr1=" + str(self.r_max * 0.8 / 1.2)
                    + "r2=" + str(self.r_max) + "\n\tidentical mass=" + mass + "mg")
        m = self._a["m"]
        m1 = str(float(m.min())) if self._n else "0"
        m2 = str(float(m.max())) if self._n else "0"
        r1 = self.r_max * self.bimodal_lower / self.bimodal_upper
        return ("Spheres with bimodal distribution, equal probability, \n\tr1=" + str(r1) + " r2="
                + str(self.r_max) + "\n\tmasses m1=" + m1 + "mg m2=" + m2 + "mg")

    def free_pre_equilibration(self, N=25):
        """Damped frictionless multi-level relaxation, then N frictionless and N frictional steps at ``dt``.

        From ``dt_max`` with damping 0.5, N steps per level while the step exceeds ``dt``, each level halving
        the step, moving the damping half-way to 1 and removing the mean velocity (docs/engine.md, "Runs").

        Parameters
        ----------
        N : int, optional
            Steps per level and per final block.

        Raises
        ------
        ValueError
            If ``dt`` is not > 0 or ``N`` < 0 (before any step).
        """
        relax_ensembles([self], N)

    def _labels(self, physical_neighbors_only=True):
        x, y, _ = self._rows()
        return bonds.particle_labels(self._pairs, x, y, self.size_x, self.size_y, physical_neighbors_only)

    def _particles_from_labels(self, lab):
        order = np.argsort(lab, kind="stable")
        cuts = np.flatnonzero(np.diff(lab[order])) + 1
        sl = self.sphereList
        return [[sl[k] for k in grp] for grp in np.split(order, cuts)] if self._n else []

    def identify_particles(self, physical_neighbors_only=True):
        """Set and return ``particles``, ordered by lowest sphere index (spheres in index order).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
        """
        self.particles = self._particles_from_labels(self._labels(physical_neighbors_only))
        return self.particles

    def maximal_particle_height(self):
        """Height ``max(y + r) − min(y − r)`` of the tallest particle (µm; 0 if empty); sets ``particles``."""
        lab = self._labels(True)
        self.particles = self._particles_from_labels(lab)
        _, y, r = self._rows()
        return bonds.maximal_particle_height(lab, y, r)

    def _index_of(self, theSphere):
        d = theSphere.__dict__
        if d.get("_ens") is not self:
            return None
        return d["_idx"]

    def findParticle(self, theSphere):
        """The particle of ``particles`` that contains ``theSphere``, or False.

        Parameters
        ----------
        theSphere : SphereLinkable
        """
        for particle in self.particles:
            for s in particle:
                if s is theSphere:
                    return particle
        return False

    def addParticleFromSphere(self, theSphere, physical_neighbors_only=True):
        """Grow the particle of ``theSphere`` breadth-first, append it to ``particles`` and return it.

        Parameters
        ----------
        theSphere : SphereLinkable
        physical_neighbors_only : bool, optional
            Physical bonds only (in every generation, unlike 1.0.2).

        Raises
        ------
        ValueError
            If ``theSphere`` is not a sphere of this ensemble.
        """
        p = self._index_of(theSphere)
        if p is None:
            raise ValueError("theSphere is not a sphere of this ensemble")
        i, j = self.permanent_pairs(physical_neighbors_only)
        adj = adjacency(self._n, i, j)
        seen = {p}
        order = [p]
        for q in order:  # breadth-first: the list grows while being traversed
            for s in adj[q]:
                if s not in seen:
                    seen.add(s)
                    order.append(s)
        particle = [self.sphereList[k] for k in order]
        self.particles.append(particle)
        return particle

    def permanentConnectionBetweenSpheres(self, theSphere1, theSphere2, physical_neighbors_only=True):
        """``"direct"`` (bonded), ``"indirect"`` (same particle), ``"no_connection"``; False if identical or foreign.

        Parameters
        ----------
        theSphere1, theSphere2 : SphereLinkable
        physical_neighbors_only : bool, optional
        """
        p, q = self._index_of(theSphere1), self._index_of(theSphere2)
        if p is None or q is None or p == q:
            return False
        i, j = self.permanent_pairs(physical_neighbors_only)
        lo, hi = min(p, q), max(p, q)
        if ((i == lo) & (j == hi)).any():
            return "direct"
        lab = component_labels(self._n, i, j)
        return "indirect" if lab[p] == lab[q] else "no_connection"

    def n_permanent_connections(self, physical_neighbors_only=True):
        """Number of bonds, each pair once (a float, as in 1.0.2).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
        """
        return float(len(self.permanent_pairs(physical_neighbors_only)[0]))

    def remove_non_essential_links(self, max_fraction_to_remove, physical_neighbors_only=True, max_trials=1000):
        """Cut random links that do not split a particle (sphere-first, as 1.0.2); set and return ``removed_fraction``.

        Parameters
        ----------
        max_fraction_to_remove : float
            Target fraction of the links, >= 0 (ValueError if negative).
        physical_neighbors_only : bool, optional
        max_trials : int, optional
            Consecutive failed trials after which the removal stops.
        """
        check_non_negative("max_fraction_to_remove", max_fraction_to_remove)
        x, y, r = self._rows()
        try:
            self.removed_fraction = bonds.remove_non_essential_links(
                self._pairs, x, y, r, self.size_x, self.size_y, max_fraction_to_remove, self._rng,
                physical_neighbors_only, max_trials)
        finally:
            self._bonds_edited()
        return self.removed_fraction

    def join_isolated_spheres(self, physical_neighbors_only=True):
        """Bond each unbonded sphere (index order) to a random partner among its relations (may cross a cut).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
        """
        x, y, r = self._rows()
        try:
            bonds.join_isolated_spheres(self._pairs, x, y, r, self.size_x, self.size_y, self._rng,
                                        physical_neighbors_only)
        finally:
            self._bonds_edited()

    def cutByTriangulationPoints(self, triangulation_points, edge_fuzziness=0):
        """Periodic Voronoi cut: cut every bond between spheres with different nearest seeds.

        Distance: Lees-Edwards minimum image plus ``edge_fuzziness·U·r_max`` (U uniform, drawn per sphere
        and seed even at 0); ties go to the lower seed.  Sets ``doCutByTriangulation``, ``sphere_seed``.

        Parameters
        ----------
        triangulation_points : array_like of float
            Seed points, shape (n, 2) (µm).
        edge_fuzziness : float, optional
            Edge roughness in units of the largest radius (ValueError if negative).
        """
        check_non_negative("edge_fuzziness", edge_fuzziness)
        pts = np.asarray(triangulation_points, dtype=float).reshape(-1, 2)
        self.doCutByTriangulation = True
        x, y, _ = self._rows()
        seed = bonds.voronoi_cut(self._pairs, x, y, self.size_x, self.size_y, self._le_shift(), pts, edge_fuzziness,
                                 self.r_max, self._rng)
        if seed is not None:
            self._bonds_edited()
            self.sphere_seed = seed

    def cutByTriangulation(self, n_points=5, edge_fuzziness=0):
        """Periodic Voronoi cut around ``n_points`` random seeds (kept in ``triangulation_points``; <= 1: none).

        Parameters
        ----------
        n_points : int, optional
        edge_fuzziness : float, optional
            As for :meth:`cutByTriangulationPoints`.
        """
        pts = bonds.seed_points(self._rng, n_points, self.size_x, self.size_y)
        self.triangulation_points = pts
        self.cutByTriangulationPoints(pts, edge_fuzziness)

    def angle_OK(self, angle):
        """False if the normal ``angle`` lies within ``avoid_horizontal_angle_degree`` of ±y.

        Parameters
        ----------
        angle : float
            Angle of the cut line's normal to the x axis (rad), in [0, 2π).
        """
        return bonds.angle_ok(angle, self.avoid_horizontal_angle_degree)

    def cutRandomLine(self):
        """Cut along a line through a random integer point, redrawing angles :meth:`angle_OK` rejects."""
        self.cutLine(*bonds.random_line(self._rng, self.size_x, self.size_y, self.avoid_horizontal_angle_degree))


class EnsembleCompactParticlesAdjustableInterfaceStrength(EnsembleCompactParticles):
    """Compact-particle ensemble of :class:`~particleShear.linkable.spheres.SphereLinkableAdjustableInterfaceStrength`.

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor, k_t, nu_t, mu
        As for :class:`EnsembleCompactParticles`.
    dt, dt_max, theTkSimulation, avoid_horizontal_angle_degree, rng
        Likewise.
    permanent_ratio_central, permanent_ratio_tangential, keep_viscosity_coefficients_constant
        As for the sphere class.
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1, dt=1, dt_max=10, theTkSimulation=False,
                 avoid_horizontal_angle_degree=0, permanent_ratio_central=1, permanent_ratio_tangential=1,
                 keep_viscosity_coefficients_constant=True, rng=None):
        check_non_negative("permanent_ratio_central", permanent_ratio_central)
        check_non_negative("permanent_ratio_tangential", permanent_ratio_tangential)
        self.permanent_ratio_central = permanent_ratio_central
        self.permanent_ratio_tangential = permanent_ratio_tangential
        self.keep_viscosity_coefficients_constant = keep_viscosity_coefficients_constant
        self.cut_top_bottom = False
        EnsembleCompactParticles.__init__(
            self, size_x, size_y, N, packing_fraction=packing_fraction, theCanvas=theCanvas, doDrawing=doDrawing,
            k=k, nu=nu, m=m, bimodal_factor=bimodal_factor, k_t=k_t, nu_t=nu_t, mu=mu, dt=dt, dt_max=dt_max,
            theTkSimulation=theTkSimulation, avoid_horizontal_angle_degree=avoid_horizontal_angle_degree, rng=rng)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkableAdjustableInterfaceStrength(
            self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index, self.theCanvas,
            self.doDrawing, self, self.size_x, self.size_y, self.permanent_ratio_central,
            self.permanent_ratio_tangential, self.keep_viscosity_coefficients_constant)

    def particle_info(self, reference=False):
        adjustment = "ofstrength between permament" if reference else "of strength between permanent"   # 1.0.2's typos
        return ("Frictional spheres under Lees-Edwards boundary conditions, organized in fixed particles, adjustment "
                + adjustment + " and temporary interfaces\n\t" + self._sphere_info(reference))
