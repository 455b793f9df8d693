"""Ensembles with permanent links (bonds, rows of the pair table): making, listing and cutting them."""
__docformat__ = "numpy"
from ..base.canvas import CanvasPointsFrictionElasticityLeesEdwards
from ..objects.ensembles import RandomBimodalSpheres
from . import bonds
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

    def _bonds_edited(self):
        """The bookkeeping after the table's bonds were edited: cached bond constants and grid dropped."""
        self._links_changed()
        self._g = None

    def _rows(self):
        """``(x, y, r)`` of the spheres (µm): the rows the algorithms of :mod:`.bonds` read."""
        a = self._a
        return a["x"], a["y"], a["r"]

    def _link_pairs(self, i, j):
        """Make pairs (i, j) permanent: ``d_eq = r_i + r_j``, ξ = 0; creates missing relations."""
        bonds.link_pairs(self._pairs, self._a["r"], i, j)
        self._bonds_edited()

    def _set_bonds(self, slots, state, d_eq):
        """Pairs ``slots`` to ``state`` with ``d_eq`` and ξ = 0; drops the cached bond constants and grid."""
        bonds.set_bonds(self._pairs, slots, state, d_eq)
        self._bonds_edited()

    def _cut_slots(self, slots):
        bonds.cut_slots(self._pairs, slots)
        self._bonds_edited()

    def _cut_pairs(self, i, j):
        """Cut bonds (i, j): state slip, ξ = 0, ``d_eq`` = 0; the contact stays while touching."""
        bonds.cut_pairs(self._pairs, i, j)
        self._bonds_edited()

    def permanent_pairs(self, physical_neighbors_only=False):
        """Sphere indices ``(i, j)``, i < j, of the bonds (two integer arrays, copies).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Only bonds not wrapping through the periodic boundary (raw differences below half the cell).
        """
        x, y, _ = self._rows()
        return bonds.permanent_pairs(self._pairs, x, y, self.size_x, self.size_y, physical_neighbors_only)

    def _physical(self, i, j):
        """Bonds that do not cross the periodic boundary (raw coordinate differences below L/2)."""
        x, y, _ = self._rows()
        return bonds.physical(x, y, self.size_x, self.size_y, i, j)

    def makeAllLinksPermanent(self):
        """Bond every current relation (updating the neighbours if none exists): ``d_eq = r_i + r_j``, ξ = 0."""
        pt = self._pairs
        if self._g is None and not pt.active.any():
            self.test_neighbor_relation()
        bonds.link_relations(self._pairs, self._a["r"])
        self._bonds_edited()

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
        x, y, _ = self._rows()
        bonds.cut_line(self._pairs, x, y, self.size_x, self.size_y, self._le_shift(), point, angle)
        self._bonds_edited()

    def cutRandomLine(self):
        """Cut along a line through a random integer point, uniform random normal angle (draws x, y, angle)."""
        self.cutLine(*bonds.random_line(self._rng, self.size_x, self.size_y))

    def cutTopBottomEdge(self):
        """Cut every bond crossing y = 0 or y = size_y (wall slip, ``cut_top_bottom`` of the builders)."""
        x, y, _ = self._rows()
        bonds.cut_top_bottom_edge(self._pairs, x, y, self.size_x, self.size_y, self._le_shift())
        self._bonds_edited()

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
