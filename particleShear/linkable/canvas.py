"""Ensembles with permanent links (spec §2.5, §2.9, §6.5, §6.7, §10.6).

``CanvasPointsLinkable`` adds the bond term to the friction canvas: bonds use
the compressive law below ``d_eq`` and the tensile law above it, never break,
carry an unbounded tangential spring and are scaled by the per-sphere
``permanent_ratio_*`` of the adjustable sphere class.  The bond kernel runs only
while bonds exist.
"""
import math

import numpy as np

from ..base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from ..base.kernels import min_image, tangential_two_pass
from ..base.laws import call_law_vectorised
from ..base.neighbours import PERMANENT, SLIP, STICK
from ..objects.ensembles import RandomBimodalSpheres
from .spheres import LinkableRelationView, SphereLinkable

__all__ = ["CanvasPointsLinkable", "EnsembleLinkable"]


class CanvasPointsLinkable(CanvasPointsFrictionElasticityLeesEdwards):
    """Friction canvas whose relations can be made permanent (crosslinks)."""

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
        if (i == j).any():
            k = int(np.flatnonzero(i == j)[0])
            raise ValueError(f"cannot link sphere {int(i[k])} to itself")
        if not len(i):
            return
        pt = self._pairs
        slots = pt.ensure(i, j)
        r = self._a["r"]
        newly = ~pt.active[slots]
        if newly.any():
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
        """Sphere indices (i, j), i < j, of the bonds; optionally only those that do not wrap."""
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
        """Bond every current relation (the contacts of the last neighbour update) (§6.5)."""
        pt = self._pairs
        if self._g is None and not pt.active.any():
            self.test_neighbor_relation()
        m = np.flatnonzero(pt.active)
        self._link_pairs(pt.i[m], pt.j[m])

    def cutLine(self, point, angle):
        """Cut every bond crossed by the infinite line through ``point`` with normal angle ``angle`` (rad)."""
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
        """Cut along a line through a random point with a random direction."""
        rng = self._rng
        point = (int(rng.integers(0, int(self.size_x) + 1)), int(rng.integers(0, int(self.size_y) + 1)))
        self.cutLine(point, 2 * math.pi * rng.random())

    def cutTopBottomEdge(self):
        """Cut every bond crossing y = 0 or y = Ly through the periodic image (wall slip)."""
        self.cutLine((0, 0), math.pi / 2)
        self.cutLine((0, self.size_y), math.pi / 2)

    # -- bond forces -------------------------------------------------------------------------------
    def _perm_subset(self, g):
        perm = g.perm
        return perm, g.slots[perm]

    def _elastic_terms(self):
        CanvasPointsFrictionElasticityLeesEdwards._elastic_terms(self)
        g = self._g
        if g.perm is None:
            return
        from ..base.points import CircleBasicElasticity
        perm, slots = self._perm_subset(g)
        d = g.d[perm]
        deq = self._pairs.d_eq[slots]
        c_i, c_j = self._pair_param("central_repulsion_coefficient", g)
        rc_i, rc_j = self._pair_param("permanent_ratio_central", g)
        law = CircleBasicElasticity.call_back_elastic_force_law
        tensile = SphereLinkable.call_back_elastic_force_law_tensile
        stretched = d >= deq
        f_t = call_law_vectorised(tensile, d, deq, self.k)
        f_i = np.where(stretched, f_t, call_law_vectorised(
            law, d, deq, self.k, c_i if np.ndim(c_i) == 0 else c_i[perm]))
        if np.ndim(c_i) == 0:
            f_j = f_i
        else:
            f_j = np.where(stretched, f_t, call_law_vectorised(law, d, deq, self.k, c_j[perm]))
        f_i = f_i * (rc_i if np.ndim(rc_i) == 0 else rc_i[perm])
        f_j = f_j * (rc_j if np.ndim(rc_j) == 0 else rc_j[perm])
        if np.ndim(c_i) == 0 and np.ndim(rc_i) == 0:
            self._add_normal(self._scatter(f_i, perm, g.P))
        else:
            self._add_normal(self._scatter(f_i, perm, g.P), self._scatter(f_j, perm, g.P))

    def _visc_ratio(self, g, ratio_name):
        """Per-visit viscosity factors of bonds: the ratio unless viscosities are kept constant."""
        r_i, r_j = self._pair_param(ratio_name, g)
        k_i, k_j = self._pair_param("keep_viscosity_coefficients_constant", g)
        if np.ndim(r_i) == 0 and np.ndim(k_i) == 0:
            v = 1.0 if k_i else r_i
            return v, v
        r_i = np.broadcast_to(r_i, (g.P,))
        r_j = np.broadcast_to(r_j, (g.P,))
        return (np.where(np.broadcast_to(k_i, (g.P,)) != 0, 1.0, r_i),
                np.where(np.broadcast_to(k_j, (g.P,)) != 0, 1.0, r_j))

    def _viscous_scale(self, g):
        if g.perm is None:
            return None
        v_i, v_j = self._visc_ratio(g, "permanent_ratio_central")
        if np.ndim(v_i) == 0 and v_i == 1.0:
            return None
        s_i = np.where(g.perm, v_i, 1.0)
        s_j = np.where(g.perm, v_j, 1.0)
        return s_i, s_j

    def _tangential_terms(self):
        CanvasPointsFrictionElasticityLeesEdwards._tangential_terms(self)
        g = self._g
        if g.perm is None:
            return
        pt = self._pairs
        perm, slots = self._perm_subset(g)
        vt = self._tangential_speed(g)[perm]
        touching = g.d[perm] < g.d0[perm]
        rt_i, rt_j = self._pair_param("permanent_ratio_tangential", g)
        nv_i, nv_j = self._visc_ratio(g, "permanent_ratio_tangential")

        def sub(v):
            return v if np.ndim(v) == 0 else v[perm]

        xi_ij = pt.xi_ij[slots]
        xi_ji = pt.xi_ji[slots]
        f1, f2, _ = tangential_two_pass(vt, touching, np.ones(len(slots), bool), xi_ij, xi_ji,
                                        self.k_t * sub(rt_i), self.k_t * sub(rt_j),
                                        self.nu_t * sub(nv_i), self.nu_t * sub(nv_j), 0.0)
        self._add_tangential(self._scatter(f1 / 2 + f2 / 2, perm, g.P))

    @property
    def active_terms(self):
        terms = CanvasPointsFrictionElasticityLeesEdwards.active_terms.fget(self)
        if self._pairs.n_permanent:
            terms.append("permanent_links")
        return terms


class EnsembleLinkable(RandomBimodalSpheres, CanvasPointsLinkable):
    """N random linkable spheres (``N = 0`` for hand-built scenes, as in the unit tests)."""

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1, nu=0.01,
                 m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1):
        CanvasPointsLinkable.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m, k_t, nu_t, mu)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLinkable(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                              self.theCanvas, self.doDrawing, self, self.size_x, self.size_y)
