"""Ensembles with permanent links (bonds, rows of the pair table): making, listing and cutting them."""
__docformat__ = "numpy"
import math

import numpy as np

from ..base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from ..engine.box import inside_half_cell, min_image
from ..base.neighbours import PERMANENT, SLIP
from ..objects.ensembles import RandomBimodalSpheres
from .spheres import LinkableRelationView, SphereLinkable


__all__ = ["CanvasPointsLinkable", "EnsembleLinkable"]


class CanvasPointsLinkable(CanvasPointsFrictionElasticityLeesEdwards):
    """Friction canvas whose relations can be made permanent (crosslinks), with bond forces in every step.

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing, k, nu, k_t, nu_t, mu
        As for :class:`~particleShear.objects.ensembles.EnsembleFrictionLeesEdwards` (ValueError when out of range).
    m : float, optional
        Nominal sphere mass stored on the ensemble (mg per m depth).
    """

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1, k_t=1, nu_t=0.01,
                 mu=0.1):
        CanvasPointsFrictionElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m,
                                                           k_t, nu_t, mu)
        self._relation_view_class = LinkableRelationView

    def _link_pairs(self, i, j):
        """Make pairs (i, j) permanent: ``d_eq = r_i + r_j``, ξ = 0; creates missing relations."""
        i = np.atleast_1d(np.asarray(i, dtype=np.intp))
        j = np.atleast_1d(np.asarray(j, dtype=np.intp))
        if (i == j).any():
            k = int(np.flatnonzero(i == j)[0])
            raise ValueError(f"cannot link sphere {int(i[k])} to itself")
        if not len(i):
            return
        pt = self._pairs
        slots = pt.ensure(i, j)
        r = self._a["r"]
        pt.open_relations(slots)
        self._set_bonds(slots, PERMANENT, r[pt.i[slots]] + r[pt.j[slots]])

    def _set_bonds(self, slots, state, d_eq):
        """Pairs ``slots`` to ``state`` with ``d_eq`` and ξ = 0; drops the cached bond constants and grid."""
        pt = self._pairs
        pt.state[slots] = state
        pt.d_eq[slots] = d_eq
        pt.xi_ij[slots] = 0.0
        pt.xi_ji[slots] = 0.0
        self._links_changed()
        self._g = None

    def _cut_slots(self, slots):
        self._set_bonds(slots[self._pairs.state[slots] == PERMANENT], SLIP, 0.0)

    def _cut_pairs(self, i, j):
        """Cut bonds (i, j): state slip, ξ = 0, ``d_eq`` = 0; the contact stays while touching."""
        slots = self._pairs.find(np.atleast_1d(i), np.atleast_1d(j))
        self._cut_slots(slots[slots >= 0])

    def permanent_pairs(self, physical_neighbors_only=False):
        """Sphere indices ``(i, j)``, i < j, of the bonds (two integer arrays, copies).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Only bonds not wrapping through the periodic boundary (raw differences below half the cell).
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
        return inside_half_cell(a["x"][i] - a["x"][j], a["y"][i] - a["y"][j], self.size_x, self.size_y)

    def makeAllLinksPermanent(self):
        """Bond every current relation (updating the neighbours if none exists): ``d_eq = r_i + r_j``, ξ = 0."""
        pt = self._pairs
        if self._g is None and not pt.active.any():
            self.test_neighbor_relation()
        m = np.flatnonzero(pt.active)
        self._link_pairs(pt.i[m], pt.j[m])

    def cutLine(self, point, angle):
        """Cut (to slipping contacts) every bond crossed by the infinite, non-periodic line.

        With ``n = (cos angle, sin angle)``, ``b = n·point``: bond i–j is cut when
        ``(n·x_i − b)·(n·(x_i + Δ_ij) − b) <= 0`` from either end (``Δ_ij``: Lees-Edwards minimum image).

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
        dx, dy = min_image(xj - xi, yj - yi, self.size_x, self.size_y, shift)[:2]
        ex, ey = min_image(xi - xj, yi - yj, self.size_x, self.size_y, shift)[:2]
        si = nu[0] * xi + nu[1] * yi - b
        sj = nu[0] * xj + nu[1] * yj - b
        cut = (si * (nu[0] * (xi + dx) + nu[1] * (yi + dy) - b) <= 0) | \
              (sj * (nu[0] * (xj + ex) + nu[1] * (yj + ey) - b) <= 0)
        self._cut_slots(slots[cut])

    def cutRandomLine(self):
        """Cut along a line through a random integer point, uniform random normal angle (draws x, y, angle)."""
        rng = self._rng
        point = (int(rng.integers(0, int(self.size_x) + 1)), int(rng.integers(0, int(self.size_y) + 1)))
        self.cutLine(point, 2 * math.pi * rng.random())

    def cutTopBottomEdge(self):
        """Cut every bond crossing y = 0 or y = size_y (wall slip, ``cut_top_bottom`` of the builders)."""
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
    """N random bimodal linkable spheres (``N = 0`` for hand-built scenes).

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor, k_t, nu_t, mu
        As for :class:`~particleShear.objects.ensembles.EnsembleFrictionLeesEdwards` (ValueError when out of range).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1):
        CanvasPointsLinkable.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m, k_t, nu_t, mu)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkable(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                              self.theCanvas, self.doDrawing, self, self.size_x, self.size_y)
