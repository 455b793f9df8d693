"""Ensembles with permanent links (crosslinks): bonds, cutting along lines, bond forces.

``CanvasPointsLinkable`` adds bonds to the friction canvas: bonds use
the compressive law below ``d_eq`` and the tensile law above it, never break,
carry an unbounded tangential spring and are scaled by the per-sphere
``permanent_ratio_*`` of the adjustable sphere class.  They are rows of the pair table whose
constants the engine's force phase takes from :func:`particleShear.engine.terms.term_constants`
(the tensile law, also one replaced through ``call_back_elastic_force_law_tensile``, beyond
``d_eq``); this class adds the bookkeeping of bonds: making, listing and cutting them.  The force
laws are eq. S1-5a/b of the manual; the constants are those of docs/parameters.md; how bonds are
made and cut is described in docs/design.md.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from ..base.kernels import min_image
from ..base.namespace import count_nonzero as _nz
from ..base.neighbours import PERMANENT, SLIP
from ..objects.ensembles import RandomBimodalSpheres
from .spheres import LinkableRelationView, SphereLinkable


__all__ = ["CanvasPointsLinkable", "EnsembleLinkable"]


class CanvasPointsLinkable(CanvasPointsFrictionElasticityLeesEdwards):
    """Friction canvas whose relations can be made permanent (crosslinks).

    Bonds are made by :meth:`makeAllLinksPermanent` and cut by :meth:`cutLine` and its variants;
    the bond forces are added to the contact forces of the friction canvas in every step.

    Parameters
    ----------
    size_x, size_y : float
        Width and height of the periodic Lees-Edwards cell (µm), > 0.
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the spheres are drawn on ``theCanvas``.
    k : float, optional
        Central spring constant (mg·s⁻² per metre of depth), >= 0 (eq. S1-8).
    nu : float, optional
        Central viscosity constant ν (mg·s⁻¹ per metre of depth), >= 0 (eq. S1-9).
    m : float, optional
        Nominal sphere mass stored on the ensemble (mg per metre of depth).
    k_t : float, optional
        Tangential spring constant (mg·s⁻² per metre of depth), >= 0.
    nu_t : float, optional
        Tangential viscosity constant (mg·s⁻¹ per metre of depth), >= 0.
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts, >= 0.

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it and its value).
    """

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1, k_t=1, nu_t=0.01,
                 mu=0.1):
        CanvasPointsFrictionElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m,
                                                           k_t, nu_t, mu)
        self._relation_view_class = LinkableRelationView

    # -- bond bookkeeping (arrays) -------------------------------------------------------------------
    def _link_pairs(self, i, j):
        """Make pairs (i, j) permanent: ``d_eq = r_i + r_j``, ξ = 0; creates missing relations."""
        i = np.atleast_1d(np.asarray(i, dtype=np.intp))
        j = np.atleast_1d(np.asarray(j, dtype=np.intp))
        if _nz(i == j):
            k = int(np.flatnonzero(i == j)[0])
            raise ValueError(f"cannot link sphere {int(i[k])} to itself")
        if not len(i):
            return
        pt = self._pairs
        slots = pt.ensure(i, j)
        r = self._a["r"]
        newly = ~pt.active[slots]
        if _nz(newly):
            pt.birth[slots[newly]] = pt.next_births(int(newly.sum()))
        pt.active[slots] = True
        pt.state[slots] = PERMANENT
        pt.d_eq[slots] = r[pt.i[slots]] + r[pt.j[slots]]
        pt.xi_ij[slots] = 0.0
        pt.xi_ji[slots] = 0.0
        self._links_changed()
        self._g = None

    def _cut_slots(self, slots):
        pt = self._pairs
        slots = slots[pt.state[slots] == PERMANENT]
        pt.state[slots] = SLIP
        pt.xi_ij[slots] = 0.0
        pt.xi_ji[slots] = 0.0
        pt.d_eq[slots] = 0.0
        self._links_changed()
        self._g = None

    def _cut_pairs(self, i, j):
        """Cut bonds (i, j): state slip, ξ = 0, ``d_eq`` = 0; the contact stays while touching."""
        slots = self._pairs.find(np.atleast_1d(i), np.atleast_1d(j))
        self._cut_slots(slots[slots >= 0])

    def permanent_pairs(self, physical_neighbors_only=False):
        """Sphere indices (i, j), i < j, of the bonds.

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Only bonds that do not wrap through the periodic boundary (raw coordinate differences
            below half the cell size in x and in y).

        Returns
        -------
        tuple of numpy.ndarray
            ``(i, j)``, two integer arrays of equal length (copies).
        """
        pt = self._pairs
        m = pt.state == PERMANENT
        i, j = pt.i[m], pt.j[m]
        if physical_neighbors_only:
            keep = self._physical(i, j)
            i, j = i[keep], j[keep]
        return i.copy(), j.copy()

    def _physical(self, i, j):
        """Bonds that do not cross the periodic boundary (raw coordinate differences below L/2)."""
        a = self._a
        return ((np.abs(a["x"][i] - a["x"][j]) < self.size_x / 2)
                & (np.abs(a["y"][i] - a["y"][j]) < self.size_y / 2))

    def makeAllLinksPermanent(self):
        """Bond every current relation (the contacts of the last neighbour update).

        Each bond gets ``d_eq = r_i + r_j`` (not the current, compressed distance) and ξ = 0; bonds
        through the periodic boundary are made like any other (docs/design.md).  Runs a
        neighbour update first if no relation exists yet.
        """
        pt = self._pairs
        if self._g is None and not _nz(pt.active):
            self.test_neighbor_relation()
        m = np.flatnonzero(pt.active)
        self._link_pairs(pt.i[m], pt.j[m])

    def cutLine(self, point, angle):
        """Cut every bond crossed by an infinite, non-periodic line.

        With the normal ``n = (cos angle, sin angle)`` and ``b = n·point``, the bond i–j is cut
        when ``(n·x_i − b)·(n·(x_i + Δ_ij) − b) <= 0`` (from either end), ``Δ_ij`` being the
        Lees-Edwards minimum-image separation.  Cut bonds become slipping contacts (ξ = 0,
        ``d_eq`` = 0).

        Parameters
        ----------
        point : sequence of float
            A point ``(x, y)`` of the line (µm).
        angle : float
            Angle of the line's normal to the x axis (rad).
        """
        pt = self._pairs
        slots = np.flatnonzero(pt.state == PERMANENT)
        if not len(slots):
            return
        a = self._a
        i, j = pt.i[slots], pt.j[slots]
        nu = (math.cos(angle), math.sin(angle))
        b = nu[0] * point[0] + nu[1] * point[1]
        xi, yi, xj, yj = a["x"][i], a["y"][i], a["x"][j], a["y"][j]
        shift = self._le_shift()
        dx, dy, _ = min_image(xj - xi, yj - yi, self.size_x, self.size_y, shift)
        ex, ey, _ = min_image(xi - xj, yi - yj, self.size_x, self.size_y, shift)
        si = nu[0] * xi + nu[1] * yi - b
        sj = nu[0] * xj + nu[1] * yj - b
        cut = (si * (nu[0] * (xi + dx) + nu[1] * (yi + dy) - b) <= 0) | \
              (sj * (nu[0] * (xj + ex) + nu[1] * (yj + ey) - b) <= 0)
        self._cut_slots(slots[cut])

    def cutRandomLine(self):
        """Cut along a line through a random integer point of the cell with a uniform random normal angle.

        Draws from the ensemble's random generator (x, y, then the angle).
        """
        rng = self._rng
        point = (int(rng.integers(0, int(self.size_x) + 1)), int(rng.integers(0, int(self.size_y) + 1)))
        self.cutLine(point, 2 * math.pi * rng.random())

    def cutTopBottomEdge(self):
        """Cut every bond crossing y = 0 or y = size_y through the periodic image.

        This emulates wall slip at the plates (``cut_top_bottom`` of the builders).
        """
        self.cutLine((0, 0), math.pi / 2)
        self.cutLine((0, self.size_y), math.pi / 2)

    @property
    def active_terms(self):
        """Names of the force terms of a step, ``"permanent_links"`` included while bonds exist (list of str)."""
        terms = CanvasPointsFrictionElasticityLeesEdwards.active_terms.fget(self)
        if self._pairs.n_permanent:
            terms.append("permanent_links")
        return terms


class EnsembleLinkable(RandomBimodalSpheres, CanvasPointsLinkable):
    """N random bimodal linkable spheres (``N = 0`` for hand-built scenes, as in the unit tests).

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

    Raises
    ------
    ValueError
        If a parameter is out of its range (the message names it and its value).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1):
        CanvasPointsLinkable.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m, k_t, nu_t, mu)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkable(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                              self.theCanvas, self.doDrawing, self, self.size_x, self.size_y)
