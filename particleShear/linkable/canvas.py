"""Ensembles with permanent links (crosslinks): bonds, cutting along lines, bond forces.

``CanvasPointsLinkable`` adds the bond term to the friction canvas: bonds use
the compressive law below ``d_eq`` and the tensile law above it, never break,
carry an unbounded tangential spring and are scaled by the per-sphere
``permanent_ratio_*`` of the adjustable sphere class.  The bond kernel runs only
while bonds exist.  The force laws are eq. S1-5a/b of the manual; the constants are those
of docs/parameters.md; how bonds are made and cut is described in docs/design.md.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from ..base.kernels import min_image
from ..base.namespace import count_nonzero as _nz, where as _where
from ..base.laws import call_law_vectorised, elastic_force_law, elastic_force_law_tensile
from ..engine import laws as _engine_laws
from ..base.neighbours import PERMANENT, SLIP
from ..base.points import CircleBasicElasticity
from ..objects.ensembles import RandomBimodalSpheres
from .spheres import LinkableRelationView, SphereLinkable


__all__ = ["CanvasPointsLinkable", "EnsembleLinkable"]


class _BondStructure:
    """Bond constants over the pairs of a pair structure (``S.bond``, made and kept with the structure)."""
    __slots__ = ("deq", "d0", "deq_stretch", "perm_code", "fc_inf")


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

    # -- bond forces -------------------------------------------------------------------------------
    def _bond_structure(self, g):
        """Per-pair bond constants of the step's pair structure: bonds and their ``d_eq`` change only with the
        structure's key (candidates, links), so they are made with the structure."""
        return g.S.bond

    def _bond_constants(self, S):
        """The :class:`_BondStructure` of the pairs of structure ``S`` (which has bonds: ``S.perm`` is not None)."""
        B = _BondStructure()
        perm = S.perm
        B.deq = deq = self._pairs.d_eq.copy() if S.sel is None else self._pairs.d_eq.take(S.sel)
        B.d0 = _where(perm, deq, S.d0)               # contact distance of the central law
        B.deq_stretch = _where(perm, deq, np.inf)    # d ≥ this: tensile law (never for contacts)
        B.perm_code = perm.view(np.int8) * np.int8(PERMANENT)
        B.fc_inf = _where(perm, np.inf, 0.0)         # bonds have no Coulomb bound
        return B

    def _elastic_terms(self):
        """Transient contacts as in the parent; bonds: law below ``d_eq``, tensile law above, × ratio."""
        g = self._g
        if g.perm is None:
            CanvasPointsFrictionElasticityLeesEdwards._elastic_terms(self)
            return
        B = self._bond_structure(g)
        perm = g.perm
        c_i, c_j = self._pair_param("central_repulsion_coefficient", g)
        law = CircleBasicElasticity.call_back_elastic_force_law
        k = self.k
        if (c_j is c_i and type(c_i) is float and law is elastic_force_law
                and SphereLinkable.call_back_elastic_force_law_tensile is elastic_force_law_tensile):
            # built-in laws: beyond d0 (= d_eq for bonds) a bond pulls with k·(d − d_eq) and a contact
            # has no force (k·(d − 0)·0 = +0); up to d0 both follow the compressive law
            f_i = f_j = _where(g.d > B.d0, self._tensile_inline(g.d, k, B, perm),
                               self._builtin_law_inside(g.d, B.d0, k, c_i))
            g.fel = f_i
        else:
            f_i = self._central_law(g.d, B.d0, k, c_i)
            g.fel = f_i
            f_j = f_i if c_j is c_i else self._mask_law(call_law_vectorised(law, g.d, B.d0, k, c_j))
            stretched = g.d >= B.deq_stretch
            if _nz(stretched):
                tensile = SphereLinkable.call_back_elastic_force_law_tensile
                if tensile is elastic_force_law_tensile:
                    f_t = _engine_laws.tensile_inside(g.d, B.deq, -k)    # the built-in linear tensile law
                else:
                    f_t = call_law_vectorised(tensile, g.d, B.deq, k)
                f_i = _where(stretched, f_t, f_i)
                f_j = f_i if c_j is c_i else _where(stretched, f_t, f_j)
        rc_i, rc_j = self._pair_param("permanent_ratio_central", g)
        if not (rc_i is rc_j and rc_i == 1.0):
            f_i = f_i * _where(perm, rc_i, 1.0)
            f_j = f_j * _where(perm, rc_j, 1.0)
        self._add_normal(f_i, None if f_j is f_i else f_j)

    @staticmethod
    def _tensile_inline(d, k, B, perm):
        """Built-in tensile law ``−k (d_eq − d)`` (:func:`particleShear.engine.laws.tensile_inside`) on bonds and
        ``−0·(0 − d) = +0`` on contacts (the constants ``−k`` and ``d_eq`` masked to the bonds)."""
        return _engine_laws.tensile_inside(d, _where(perm, B.deq, 0.0), -_where(perm, k, 0.0))

    def _tangential_terms(self):
        """Transient contacts and bonds in one two-visit pass; bonds have no Coulomb bound."""
        g = self._g
        if g.perm is None:
            CanvasPointsFrictionElasticityLeesEdwards._tangential_terms(self)
            return
        B = self._bond_structure(g)
        kt_i, kt_j, nut_i, nut_j = self._tangential_constants(g, self.k_t, self.nu_t)
        fc = np.abs(self.mu * self._coulomb_law(g))
        fc += B.fc_inf
        self._apply_tangential(B.perm_code, kt_i, kt_j, nut_i, nut_j, fc)

    def _tangential_constants(self, g, kt, nut):
        """(k_t, ν_t) seen by each visit: scaled by the sphere's ratios on bonds."""
        perm = g.perm
        rt_i, rt_j = self._pair_param("permanent_ratio_tangential", g)
        nv_i, nv_j = self._visc_ratio(g, "permanent_ratio_tangential")
        if rt_i is rt_j and type(rt_i) is float and kt * rt_i == kt:
            kt_i = kt_j = kt
        else:
            kt_i = _where(perm, kt * rt_i, kt)
            kt_j = kt_i if rt_j is rt_i else _where(perm, kt * rt_j, kt)
        if nv_i is nv_j and nv_i == 1.0:
            nut_i = nut_j = nut
        else:
            nut_i = _where(perm, nut * nv_i, nut)
            nut_j = _where(perm, nut * nv_j, nut)
        return kt_i, kt_j, nut_i, nut_j

    def _visc_ratio(self, g, ratio_name):
        """Per-visit viscosity factors of bonds: the ratio unless viscosities are kept constant."""
        r_i, r_j = self._pair_param(ratio_name, g)
        k_i, k_j = self._pair_param("keep_viscosity_coefficients_constant", g)
        if type(r_i) is float and type(k_i) is float:
            v = 1.0 if k_i else r_i
            return v, v
        r_i = np.broadcast_to(r_i, (g.P,))
        r_j = np.broadcast_to(r_j, (g.P,))
        return (_where(np.broadcast_to(k_i, (g.P,)) != 0, 1.0, r_i),
                _where(np.broadcast_to(k_j, (g.P,)) != 0, 1.0, r_j))

    def _viscous_scale(self, g):
        """Per-visit factors (s_i, s_j) on ν: the viscosity ratio on bonds, 1 on contacts (None: all 1)."""
        if g.perm is None:
            return None
        v_i, v_j = self._visc_ratio(g, "permanent_ratio_central")
        if type(v_i) is float and v_i == 1.0:
            return None
        s_i = _where(g.perm, v_i, 1.0)
        s_j = _where(g.perm, v_j, 1.0)
        return s_i, s_j

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
