"""Ensembles of compact particles: crosslinked spheres cut into particles.

A *particle* is a connected component of the graph of permanent links (by
default only *physical* links, i.e. links that do not wrap through the
periodic boundary).  Components are found with array operations (min-label
propagation with pointer jumping over the bond arrays); ``particles`` is kept,
as in particleShear 1.0.2, as a list of lists of sphere objects.  The constitution
protocol that uses these methods (relax, crosslink, cut, remove links, join isolated
spheres, relax again) is described in docs/design.md and docs/parameters.md.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..base.canvas import check_non_negative
from ..base.kernels import min_image
from ..base.neighbours import PERMANENT
from ..objects.ensembles import RandomBimodalSpheres
from .canvas import CanvasPointsLinkable
from .spheres import SphereLinkable, SphereLinkableAdjustableInterfaceStrength

__all__ = ["EnsembleCompactParticles", "EnsembleCompactParticlesAdjustableInterfaceStrength",
           "component_labels"]


def component_labels(n, i, j):
    """Connected components of an undirected graph, by min-label propagation with pointer jumping.

    Parameters
    ----------
    n : int
        Number of nodes (0 … n−1).
    i, j : array_like of int
        End nodes of the edges (equal lengths; an edge may be listed twice or in either order).

    Returns
    -------
    numpy.ndarray of int
        Per node, the label of its component: the smallest node index of the component.
    """
    lab = np.arange(n, dtype=np.intp)
    i = np.asarray(i, dtype=np.intp)
    j = np.asarray(j, dtype=np.intp)
    if not len(i):
        return lab
    while True:
        li, lj = lab[i], lab[j]
        m = np.minimum(li, lj)
        new = lab.copy()
        # hook both the nodes and their current labels (roots) onto the smaller label
        np.minimum.at(new, li, m)
        np.minimum.at(new, lj, m)
        np.minimum.at(new, i, m)
        np.minimum.at(new, j, m)
        while True:  # pointer jumping: every node points at its root
            nn = new[new]
            if np.array_equal(nn, new):
                break
            new = nn
        if np.array_equal(new, lab):
            return lab
        lab = new


class EnsembleCompactParticles(RandomBimodalSpheres, CanvasPointsLinkable):
    """Random bimodal linkable spheres that are crosslinked and cut into compact particles.

    ``dt`` / ``dt_max`` (s) are the final and the coarsest step of the multi-level
    relaxation :meth:`free_pre_equilibration`.  ``rng`` (an addition to 1.0.2) is set before
    the spheres are drawn so that whole builds are reproducible.

    Parameters
    ----------
    size_x, size_y : float
        Width and height of the periodic cell (µm), > 0.
    N : int
        Number of spheres, >= 0 (0 for hand-built scenes).
    packing_fraction : float, optional
        Nominal (uncompressed) area fraction φ of the spheres, > 0; sets the radii (eq. S1-14).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the spheres are drawn on ``theCanvas``.
    k : float, optional
        Central spring constant (mg·s⁻² per metre of depth), >= 0 (eq. S1-8).
    nu : float, optional
        Central viscosity constant ν (mg·s⁻¹ per metre of depth), >= 0 (eq. S1-9).
    m : float, optional
        Mass of a sphere of the bimodal mean radius (mg per metre of depth); each sphere's mass
        scales with its area.
    bimodal_factor : float, optional
        Ratio bf of the large to the small radius, > 0; radii ``r_b/√bf`` or ``r_b·√bf`` with
        probability 1/2 each.
    k_t : float, optional
        Tangential spring constant (mg·s⁻² per metre of depth), >= 0.
    nu_t : float, optional
        Tangential viscosity constant (mg·s⁻¹ per metre of depth), >= 0.
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts, >= 0.
    dt : float, optional
        Final (finest) time step of :meth:`free_pre_equilibration` (s), > 0 when relaxing.
    dt_max : float, optional
        Coarsest time step of the multi-level relaxation (s).
    theTkSimulation : object or False, optional
        Tk window of the live drawing, False for none (stored only).
    avoid_horizontal_angle_degree : float, optional
        Half-width (degrees, 0 <= value < 90) of the band of near-horizontal line directions that
        :meth:`cutRandomLine` redraws; 0 accepts every direction.
    rng : numpy.random.Generator, int or None, optional
        Random generator or seed for every random choice of the ensemble (sphere placement,
        cutting, link removal), set before the spheres are drawn; None keeps the ensemble's own
        unseeded generator.

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it and its value).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1, dt=1, dt_max=10, theTkSimulation=False,
                 avoid_horizontal_angle_degree=0, rng=None):
        CanvasPointsLinkable.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m, k_t, nu_t, mu)
        _check_angle(avoid_horizontal_angle_degree)
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

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkable(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                              self.theCanvas, self.doDrawing, self, self.size_x, self.size_y)

    def particle_info(self, reference=False):
        """Description of the spheres for the header of the output file (radii in µm, masses in mg).

        Parameters
        ----------
        reference : bool, optional
            True: the text of particleShear 1.0.2 exactly (its typos and its radius ratio of
            0.8/1.2 included); False: the corrected text with the actual radii and masses.

        Returns
        -------
        str
            The description.
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

    # -- relaxation ----------------------------------------------------------------------------------
    def free_pre_equilibration(self, N=25):
        """Frictionless damped multi-level relaxation, then N frictionless and N frictional steps at ``dt``.

        Starting at ``dt_max`` with damping factor 0.5, N frictionless steps are run per level
        while the level step exceeds ``dt``; each level halves the step, moves the damping factor
        half-way to 1 and removes the mean velocity.  Then N steps at ``dt`` without friction
        and N steps with friction follow, both undamped.  Shear is off throughout; the
        ensemble's ``mu`` is restored afterwards.  Run by the engine on this ensemble alone
        (:func:`particleShear.engine.relax.relax_ensembles`, the relaxation of every
        constitution), the result written back.

        Parameters
        ----------
        N : int, optional
            Number of steps per level and per final block, >= 0.

        Raises
        ------
        ValueError
            If the ensemble's ``dt`` is not > 0, or ``N`` < 0 (before any step).
        """
        from ..engine.relax import relax_ensembles
        N = int(N)
        if not self.dt > 0:
            raise ValueError(f"dt must be > 0 for free_pre_equilibration, got {self.dt!r}")
        if N < 0:
            raise ValueError(f"N={N!r} is out of range for free_pre_equilibration: allowed >= 0")
        relax_ensembles([self], N)

    # -- particles -----------------------------------------------------------------------------------
    def _labels(self, physical_neighbors_only=True):
        i, j = self.permanent_pairs(physical_neighbors_only)
        return component_labels(self._n, i, j)

    def _particles_from_labels(self, lab):
        """Lists of spheres per component, ordered by the lowest sphere index (spheres in index order)."""
        order = np.argsort(lab, kind="stable")
        cuts = np.flatnonzero(np.diff(lab[order])) + 1
        sl = self.sphereList
        return [[sl[k] for k in grp] for grp in np.split(order, cuts)] if self._n else []

    def identify_particles(self, physical_neighbors_only=True):
        """Set and return ``particles``: the connected components of the permanent-link graph.

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Count only bonds that do not wrap through the periodic boundary.

        Returns
        -------
        list of list of SphereLinkable
            One list per particle, ordered by the lowest sphere index (spheres in index order).
        """
        self.particles = self._particles_from_labels(self._labels(physical_neighbors_only))
        return self.particles

    def _particle_heights(self, lab):
        a = self._a
        top = np.full(self._n, -np.inf)
        bottom = np.full(self._n, np.inf)
        np.maximum.at(top, lab, a["y"] + a["r"])
        np.minimum.at(bottom, lab, a["y"] - a["r"])
        roots = np.flatnonzero(lab == np.arange(self._n))
        return top[roots] - bottom[roots]

    def maximal_particle_height(self):
        """Height of the tallest particle: the largest ``max(y + r) − min(y − r)`` (raw coordinates).

        Particles are the components of the physical bonds; ``particles`` is set as by
        :meth:`identify_particles`.

        Returns
        -------
        float
            The height (µm); 0 for an empty ensemble.
        """
        lab = self._labels(True)
        self.particles = self._particles_from_labels(lab)
        if not self._n:
            return 0
        return float(self._particle_heights(lab).max())

    def _index_of(self, theSphere):
        d = theSphere.__dict__
        if d.get("_ens") is not self:
            return None
        return d["_idx"]

    def findParticle(self, theSphere):
        """The particle of ``particles`` that contains ``theSphere``.

        Parameters
        ----------
        theSphere : SphereLinkable
            The sphere looked for.

        Returns
        -------
        list of SphereLinkable or False
            The particle, or False if no particle of ``particles`` contains the sphere.
        """
        for particle in self.particles:
            for s in particle:
                if s is theSphere:
                    return particle
        return False

    def addParticleFromSphere(self, theSphere, physical_neighbors_only=True):
        """Grow the particle of ``theSphere`` breadth-first, append it to ``particles`` and return it.

        Every generation uses ``physical_neighbors_only`` (particleShear 1.0.2 ignores it
        beyond the first generation).

        Parameters
        ----------
        theSphere : SphereLinkable
            A sphere of this ensemble.
        physical_neighbors_only : bool, optional
            Follow only bonds that do not wrap through the periodic boundary.

        Returns
        -------
        list of SphereLinkable
            The particle, in breadth-first order from ``theSphere``.

        Raises
        ------
        ValueError
            If ``theSphere`` is not a sphere of this ensemble.
        """
        p = self._index_of(theSphere)
        if p is None:
            raise ValueError("theSphere is not a sphere of this ensemble")
        i, j = self.permanent_pairs(physical_neighbors_only)
        adj = _adjacency(self._n, i, j)
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
        """How two spheres are connected by bonds.

        Parameters
        ----------
        theSphere1, theSphere2 : SphereLinkable
            The two spheres.
        physical_neighbors_only : bool, optional
            Count only bonds that do not wrap through the periodic boundary.

        Returns
        -------
        str or False
            ``"direct"`` (bonded to each other), ``"indirect"`` (same particle),
            ``"no_connection"``, or False if the spheres are identical or not both of this ensemble.
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
        """Number of bonds, each pair counted once.

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Count only bonds that do not wrap through the periodic boundary.

        Returns
        -------
        float
            The number (a float, as in particleShear 1.0.2).
        """
        return float(len(self.permanent_pairs(physical_neighbors_only)[0]))

    def remove_non_essential_links(self, max_fraction_to_remove, physical_neighbors_only=True, max_trials=1000):
        """Cut random links whose spheres stay connected otherwise, up to a fraction of the links.

        A link is non-essential when its two spheres stay in the same particle without it, so
        removing it never splits a particle.  Sampling is sphere-first (a uniform random sphere,
        then a uniform random bonded partner), as in particleShear 1.0.2, so links are not
        sampled uniformly; a trial whose link is essential re-establishes it.  Stops after
        ``max_trials`` consecutive failures.  Sets and returns ``removed_fraction`` (0 without
        links).

        Parameters
        ----------
        max_fraction_to_remove : float
            Target fraction of the links to remove, >= 0.
        physical_neighbors_only : bool, optional
            Count and remove only bonds that do not wrap through the periodic boundary.
        max_trials : int, optional
            Consecutive unsuccessful trials after which the removal stops.

        Returns
        -------
        float
            The fraction of the links removed.

        Raises
        ------
        ValueError
            If ``max_fraction_to_remove`` is negative.
        """
        check_non_negative("max_fraction_to_remove", max_fraction_to_remove)
        i, j = self.permanent_pairs(physical_neighbors_only)
        n_links = len(i)
        if n_links == 0:
            self.removed_fraction = 0
            return 0
        adj = _adjacency(self._n, i, j)
        rng = self._rng
        failures = successes = 0
        target = max_fraction_to_remove * n_links
        while failures < max_trials and successes < target:
            failures += 1
            p = int(rng.integers(0, self._n))
            cand = adj[p]
            if not cand:
                continue
            q = sorted(cand)[int(rng.integers(0, len(cand)))]
            if _connected_without_edge(adj, p, q):
                adj[p].discard(q)
                adj[q].discard(p)
                self._cut_pairs([p], [q])
                successes += 1
                failures = 0
            else:  # the reference cuts and re-establishes: d_eq = r_i + r_j, ξ = 0
                self._link_pairs([p], [q])
        self.removed_fraction = successes / n_links
        return self.removed_fraction

    def join_isolated_spheres(self, physical_neighbors_only=True):
        """Bond each sphere without a bond to a random partner among its non-permanent relations.

        Spheres are visited in index order; a sphere without any relation stays free.  This avoids
        free single spheres inside the gel (the bond may cross a cut).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            A sphere counts as bonded only through bonds that do not wrap through the periodic
            boundary.
        """
        pt = self._pairs
        i, j = self.permanent_pairs(physical_neighbors_only)
        bonded = np.zeros(self._n, bool)
        bonded[i] = True
        bonded[j] = True
        rng = self._rng
        for p in np.flatnonzero(~bonded):
            if bonded[p]:
                continue
            m = pt.active & (pt.state != PERMANENT) & ((pt.i == p) | (pt.j == p))
            slots = np.flatnonzero(m)
            if not len(slots):
                continue
            slots = slots[np.argsort(pt.birth[slots], kind="stable")]  # relation-list order
            s = slots[int(rng.integers(0, len(slots)))]
            q = int(pt.j[s] if pt.i[s] == p else pt.i[s])
            self._link_pairs([p], [q])
            if not physical_neighbors_only or self._physical(np.array([p]), np.array([q]))[0]:
                bonded[p] = bonded[q] = True

    # -- cutting ---------------------------------------------------------------------------------------
    def cutByTriangulationPoints(self, triangulation_points, edge_fuzziness=0):
        """Cut every bond between spheres whose nearest seed point differs (a periodic Voronoi cut).

        The distance of a sphere to a seed is the Lees-Edwards minimum-image distance plus
        ``edge_fuzziness · U · r_max`` (U uniform, drawn per (sphere, seed) even when the fuzziness
        is 0); ties go to the lower seed index.  Sets ``doCutByTriangulation`` and ``sphere_seed``.

        Parameters
        ----------
        triangulation_points : array_like of float
            Seed points, shape (n, 2), in µm.
        edge_fuzziness : float, optional
            Roughness of the particle edges in units of the largest sphere radius, >= 0.

        Raises
        ------
        ValueError
            If ``edge_fuzziness`` is negative.
        """
        check_non_negative("edge_fuzziness", edge_fuzziness)
        pts = np.asarray(triangulation_points, dtype=float).reshape(-1, 2)
        self.doCutByTriangulation = True
        if not len(pts) or not self._n:
            return
        a = self._a
        dx, dy, _ = min_image(pts[None, :, 0] - a["x"][:, None], pts[None, :, 1] - a["y"][:, None],
                              self.size_x, self.size_y, self._le_shift())
        dist = np.sqrt(dx * dx + dy * dy)
        dist = dist + edge_fuzziness * self._rng.random(dist.shape) * self.r_max  # drawn even at 0
        seed = np.argmin(dist, axis=1)
        pt = self._pairs
        slots = np.flatnonzero(pt.state == PERMANENT)
        self._cut_slots(slots[seed[pt.i[slots]] != seed[pt.j[slots]]])
        self.sphere_seed = seed

    def cutByTriangulation(self, n_points=5, edge_fuzziness=0):
        """Periodic Voronoi cut into ``n_points`` particles around uniform random seed points.

        The seeds are drawn from the ensemble's random generator and kept in
        ``triangulation_points``; ``n_points <= 1`` cuts nothing (a bulk gel).

        Parameters
        ----------
        n_points : int, optional
            Number of seed points, i.e. of particles (``cut_lines`` of the builders).
        edge_fuzziness : float, optional
            Roughness of the particle edges in units of the largest sphere radius, >= 0.

        Raises
        ------
        ValueError
            If ``edge_fuzziness`` is negative.
        """
        n_points = int(n_points)
        pts = self._rng.random((max(n_points, 0), 2)) * np.array([self.size_x, self.size_y])
        self.triangulation_points = pts
        self.cutByTriangulationPoints(pts, edge_fuzziness)

    def angle_OK(self, angle):
        """Whether a cut line with this normal angle is accepted (not near-horizontal).

        Parameters
        ----------
        angle : float
            Angle of the line's normal to the x axis (rad), in [0, 2π).

        Returns
        -------
        bool
            False if the normal lies within ``avoid_horizontal_angle_degree`` of ±y, True otherwise
            (always True when ``avoid_horizontal_angle_degree`` is 0).
        """
        a = self.avoid_horizontal_angle_degree
        if not a > 0:
            return True
        w = a / 180 * math.pi
        return not ((math.pi / 2 - w <= angle <= math.pi / 2 + w)
                    or (3 * math.pi / 2 - w <= angle <= 3 * math.pi / 2 + w))

    def cutRandomLine(self):
        """Cut along an infinite line through a random integer point; near-horizontal lines are redrawn.

        The angle is redrawn while :meth:`angle_OK` rejects it (bounded: the avoided band is
        narrower than all directions, ``avoid_horizontal_angle_degree < 90``).
        """
        rng = self._rng
        point = (int(rng.integers(0, int(self.size_x) + 1)), int(rng.integers(0, int(self.size_y) + 1)))
        angle = 2 * math.pi * rng.random()
        while not self.angle_OK(angle):
            angle = 2 * math.pi * rng.random()
        self.cutLine(point, angle)


class EnsembleCompactParticlesAdjustableInterfaceStrength(EnsembleCompactParticles):
    """Compact-particle ensemble whose bonds are scaled by ``permanent_ratio_*`` relative to transient contacts.

    The spheres are :class:`~particleShear.linkable.spheres.SphereLinkableAdjustableInterfaceStrength`;
    the builders pass ``1/interface_reenforcement_*`` as the ratios.

    Parameters
    ----------
    size_x, size_y : float
        Width and height of the periodic cell (µm), > 0.
    N : int
        Number of spheres, >= 0 (0 for hand-built scenes).
    packing_fraction : float, optional
        Nominal (uncompressed) area fraction φ of the spheres, > 0; sets the radii (eq. S1-14).
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the spheres are drawn on ``theCanvas``.
    k : float, optional
        Central spring constant (mg·s⁻² per metre of depth), >= 0 (eq. S1-8).
    nu : float, optional
        Central viscosity constant ν (mg·s⁻¹ per metre of depth), >= 0 (eq. S1-9).
    m : float, optional
        Mass of a sphere of the bimodal mean radius (mg per metre of depth); each sphere's mass
        scales with its area.
    bimodal_factor : float, optional
        Ratio bf of the large to the small radius, > 0; radii ``r_b/√bf`` or ``r_b·√bf`` with
        probability 1/2 each.
    k_t : float, optional
        Tangential spring constant (mg·s⁻² per metre of depth), >= 0.
    nu_t : float, optional
        Tangential viscosity constant (mg·s⁻¹ per metre of depth), >= 0.
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts, >= 0.
    dt : float, optional
        Final (finest) time step of :meth:`free_pre_equilibration` (s), > 0 when relaxing.
    dt_max : float, optional
        Coarsest time step of the multi-level relaxation (s).
    theTkSimulation : object or False, optional
        Tk window of the live drawing, False for none (stored only).
    avoid_horizontal_angle_degree : float, optional
        Half-width (degrees, 0 <= value < 90) of the band of near-horizontal line directions that
        :meth:`cutRandomLine` redraws; 0 accepts every direction.
    permanent_ratio_central : float, optional
        Factor of the central elastic force of bonds (and of their viscous force unless
        ``keep_viscosity_coefficients_constant``), >= 0.
    permanent_ratio_tangential : float, optional
        Factor of the tangential spring of bonds (and of their tangential viscosity unless
        ``keep_viscosity_coefficients_constant``), >= 0.
    keep_viscosity_coefficients_constant : bool, optional
        True: the viscous forces of bonds are not scaled by the ratios.
    rng : numpy.random.Generator, int or None, optional
        Random generator or seed for every random choice of the ensemble (sphere placement,
        cutting, link removal), set before the spheres are drawn; None keeps the ensemble's own
        unseeded generator.

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it and its value).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1, dt=1, dt_max=10, theTkSimulation=False,
                 avoid_horizontal_angle_degree=0, permanent_ratio_central=1, permanent_ratio_tangential=1,
                 keep_viscosity_coefficients_constant=True, rng=None):
        for name, v in (("permanent_ratio_central", permanent_ratio_central),
                        ("permanent_ratio_tangential", permanent_ratio_tangential)):
            check_non_negative(name, v)
        self.permanent_ratio_central = permanent_ratio_central
        self.permanent_ratio_tangential = permanent_ratio_tangential
        self.keep_viscosity_coefficients_constant = keep_viscosity_coefficients_constant
        self.cut_top_bottom = False
        EnsembleCompactParticles.__init__(self, size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m,
                                          bimodal_factor, k_t, nu_t, mu, dt, dt_max, theTkSimulation,
                                          avoid_horizontal_angle_degree, rng)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkableAdjustableInterfaceStrength(
            self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index, self.theCanvas,
            self.doDrawing, self, self.size_x, self.size_y, self.permanent_ratio_central,
            self.permanent_ratio_tangential, self.keep_viscosity_coefficients_constant)

    def particle_info(self, reference=False):
        if reference:
            return ("Frictional spheres under Lees-Edwards boundary conditions, organized in fixed particles, "
                    "adjustment ofstrength between permament and temporary interfaces\n\t" + self._sphere_info(True))
        return ("Frictional spheres under Lees-Edwards boundary conditions, organized in fixed particles, "
                "adjustment of strength between permanent and temporary interfaces\n\t" + self._sphere_info())


def _check_angle(a):
    check_non_negative("avoid_horizontal_angle_degree", a)
    if not a < 90:
        raise ValueError(f"avoid_horizontal_angle_degree must be in [0, 90) degrees, got {a!r} "
                         "(90 or more rejects every line direction)")


def _adjacency(n, i, j):
    """Neighbour sets per node of the undirected graph with edges i–j."""
    adj = [set() for _ in range(n)]
    for p, q in zip(i.tolist(), j.tolist()):
        adj[p].add(q)
        adj[q].add(p)
    return adj


def _connected_without_edge(adj, p, q):
    """Is q reachable from p without the edge p–q? Bidirectional breadth-first search, early exit."""
    front_a, seen_a = [p], {p}
    front_b, seen_b = [q], {q}
    while front_a and front_b:
        if len(front_a) > len(front_b):
            front_a, seen_a, front_b, seen_b = front_b, seen_b, front_a, seen_a
        nxt = []
        for u in front_a:
            for w in adj[u]:
                if (u == p and w == q) or (u == q and w == p):
                    continue
                if w in seen_b:
                    return True
                if w not in seen_a:
                    seen_a.add(w)
                    nxt.append(w)
        front_a = nxt
    return False
