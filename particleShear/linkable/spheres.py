"""Crosslinkable spheres and their relations (lengths µm, forces mg·µm·s⁻² per m depth).

A bond stores ``d_eq = r_i + r_j`` when it is made; below ``d_eq`` it pushes with the compressive
contact law (eq. S1-5b or S1-5a), above it pulls with the tensile law (default linear, eq. S1-5a);
it never breaks and its tangential spring has no Coulomb bound.
"""
__docformat__ = "numpy"
from ..base.laws import elastic_force_law_tensile
from ..base import callbacks as _callbacks
from ..engine.box import inside_half_cell
from ..base.point_base import ArrayField, _one
from ..checks import non_negative
from ..base.relations import RelationView, neighbor_relation
from ..objects.spheres import SphereFrictionLeesEdwards

__all__ = ["neighbor_relation_linkable", "SphereLinkable", "SphereLinkableAdjustableInterfaceStrength"]


class neighbor_relation_linkable(neighbor_relation):
    """Directed relation to ``theSphere`` that can be a bond (``equilibrium_distance``: ``d_eq`` in µm, 0 if none).

    Parameters
    ----------
    friction_position, interface_type, theSphere, graphical_line_index
        As for :class:`~particleShear.base.relations.neighbor_relation`.
    linking_line_index : int, optional
        Canvas item of the drawn bond line (-1: none).
    """

    def __init__(self, friction_position, interface_type, theSphere, graphical_line_index=-1,
                 linking_line_index=-1):
        neighbor_relation.__init__(self, friction_position, interface_type, theSphere, graphical_line_index)
        self.linking_line_index = linking_line_index
        self.equilibrium_distance = 0


class LinkableRelationView(RelationView, neighbor_relation_linkable):
    """Relation ``owner → partner`` (sphere indices) of a linkable ensemble, read from its pair table.

    Parameters
    ----------
    ensemble : CanvasPointsLinkable
    owner, partner : int
    """


def _same_ensemble(a, b):
    """The ensemble holding both spheres, None if not both in one; ValueError if in two different ones."""
    ens = a.__dict__.get("_ens")
    other = b.__dict__.get("_ens")
    if ens is not None and other is not None and other is not ens:
        raise ValueError(f"cannot link sphere {a.__dict__.get('_idx')} of one ensemble to sphere "
                         f"{b.__dict__.get('_idx')} of another: a bond joins spheres of the same ensemble")
    return ens if ens is not None and other is ens else None


class SphereLinkable(SphereFrictionLeesEdwards):
    """Frictional Lees-Edwards sphere that can be bonded to its neighbours.

    The inherited pair-force methods use a bond's constants for a bond.  Parameters as for
    :class:`~particleShear.objects.spheres.SphereFrictionLeesEdwards`.
    """

    call_back_elastic_force_law_tensile = elastic_force_law_tensile
    permanent_ratio_central = ArrayField(1.0, param=True)
    permanent_ratio_tangential = ArrayField(1.0, param=True)
    keep_viscosity_coefficients_constant = ArrayField(1.0, param=True, flag=True)
    _bond_colour = None   # colour of a bond's line (None: the locked colour)

    def _new_relation(self, theSphere):
        return neighbor_relation_linkable(0, "stick", theSphere)

    def establish_permanent_link(self, theSphere, do_backlink=True):
        """Bond to ``theSphere`` (relation created if missing): state permanent, ``d_eq = r_i + r_j``, ξ = 0.

        Parameters
        ----------
        theSphere : SphereLinkable
        do_backlink : bool, optional
            Also bond the reverse relation (spheres outside an ensemble; inside, both at once).

        Raises
        ------
        ValueError
            If ``theSphere`` is this sphere or belongs to another ensemble.
        """
        if theSphere is self:
            raise ValueError("cannot link a sphere to itself")
        ens = _same_ensemble(self, theSphere)
        if ens is not None:
            ens._link_pairs([self.__dict__["_idx"]], [theSphere.__dict__["_idx"]])
            return
        rel = self._relation(theSphere)
        if rel is None:
            rel = self._new_relation(theSphere)
            self.__dict__["_own_neighbors"].append(rel)
        rel.interface_type = "permanent"
        rel.equilibrium_distance = self.r + theSphere.r
        rel.friction_position = 0
        if do_backlink:
            theSphere.establish_permanent_link(self, do_backlink=False)

    def cut_permanent_link(self, theSphere, do_backlink=True):
        """Turn a bond into a slipping contact (ξ = 0, ``d_eq`` = 0); nothing happens if not bonded.

        Parameters
        ----------
        theSphere : SphereLinkable
        do_backlink : bool, optional
            Also cut the reverse relation (spheres outside an ensemble).

        Raises
        ------
        ValueError
            If ``theSphere`` belongs to another ensemble.
        """
        ens = _same_ensemble(self, theSphere)
        if ens is not None:
            ens._cut_pairs([self.__dict__["_idx"]], [theSphere.__dict__["_idx"]])
            return
        rel = self._relation(theSphere)
        if rel is not None and rel.interface_type == "permanent":
            rel.interface_type = "slip"
            rel.friction_position = 0
            rel.equilibrium_distance = 0
        if do_backlink:
            theSphere.cut_permanent_link(self, do_backlink=False)

    def permanentlyConnectedSpheres(self, physical_neighbors_only=True):
        """Partners bonded to this sphere (list, in relation-list order).

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Only bonds not wrapping through the periodic boundary.
        """
        out = []
        for rel in self.neighbors:
            if rel.interface_type == "permanent":
                s = rel.theSphere
                if not physical_neighbors_only or inside_half_cell(self.x - s.x, self.y - s.y, self.size_x,
                                                                   self.size_y):
                    out.append(s)
        return out

    def _bond(self, theSphere):
        """``d_eq`` of the bond to ``theSphere`` (µm), None when the relation is missing or not permanent."""
        rel = self._relation(theSphere)
        return rel.equilibrium_distance if rel is not None and rel.interface_type == "permanent" else None

    def _replaced_law(self, K, d):
        """Stretched bond: the tensile callback if replaced (else None, the built-in law); others as the parent."""
        if K.a_tens is None or d.item() < K.d_eq.item():
            return SphereFrictionLeesEdwards._replaced_law(self, K, d)
        tensile = SphereLinkable.call_back_elastic_force_law_tensile
        return None if tensile is elastic_force_law_tensile else _one(tensile(d.item(), K.d_eq.item(), K.k))

    def get_elastic_force_permanent(self, theSphere, k=1):
        """Central elastic force of the bond towards ``theSphere`` (< 0: repulsion), times ``permanent_ratio_central``.

        Parameters
        ----------
        theSphere : SphereLinkable
        k : float, optional
            Central spring constant (mg·s⁻² per m depth).
        """
        K = self._terms(theSphere, self._relation(theSphere).equilibrium_distance, k=k)
        return self._elastic(K, self._pairs([theSphere], normal=False).d)[0].item()

    def tangential_force_viscous_permanent(self, theSphere, nu):
        """Tangential viscous force ``ν_t·v_t`` of a bond while the spheres overlap.

        Times ``permanent_ratio_tangential`` unless ``keep_viscosity_coefficients_constant``.

        Parameters
        ----------
        theSphere : SphereLinkable
        nu : float
            Tangential viscosity constant ν_t (mg·s⁻¹ per m depth).
        """
        return self._tangential_part(theSphere, True, nu_t=nu)

    def tangential_force_elastic_permanent(self, theSphere, k_t):
        """Tangential elastic force ``k_t·ξ·permanent_ratio_tangential`` of a bond.

        Parameters
        ----------
        theSphere : SphereLinkable
        k_t : float
            Tangential spring constant (mg·s⁻² per m depth).
        """
        return self._tangential_part(theSphere, True, self._relation(theSphere).friction_position, k_t=k_t)

    def contactLineColor(self, interface_type):
        """Colour of the line drawn for a relation: locked for stick contacts, slip for slipping ones; for bonds
        locked, or dark orange in :class:`SphereLinkableAdjustableInterfaceStrength`.

        Parameters
        ----------
        interface_type : str
        """
        cfg = self.graphical_output_configuration
        if interface_type == "permanent" and self._bond_colour:
            return self._bond_colour
        if interface_type in ("stick", "permanent"):
            return cfg.color_interface_locked
        return cfg.color_interface_slip


class SphereLinkableAdjustableInterfaceStrength(SphereLinkable):
    """Linkable sphere whose bonds are scaled by fixed ratios (the builders pass ``1/interface_reenforcement_*``).

    Parameters
    ----------
    color, x, y, diameter, m, my_index, theCanvas, doDrawing, force_register, size_x, size_y
        As for :class:`~particleShear.objects.spheres.SphereFrictionLeesEdwards`.
    permanent_ratio_central, permanent_ratio_tangential : float, optional
        Factors (>= 0, ValueError otherwise) of the central and tangential springs of bonds (and
        of their viscosities unless ``keep_viscosity_coefficients_constant``).
    keep_viscosity_coefficients_constant : bool, optional
    """

    _bond_colour = "darkorange"

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500, permanent_ratio_central=1,
                 permanent_ratio_tangential=1, keep_viscosity_coefficients_constant=True):
        SphereLinkable.__init__(self, color, x, y, diameter, m, my_index, theCanvas, doDrawing, force_register,
                                size_x, size_y)
        non_negative("permanent_ratio_central", permanent_ratio_central)
        non_negative("permanent_ratio_tangential", permanent_ratio_tangential)
        self.permanent_ratio_central = permanent_ratio_central
        self.permanent_ratio_tangential = permanent_ratio_tangential
        self.keep_viscosity_coefficients_constant = keep_viscosity_coefficients_constant


# the engine reads the documented callback from this class at every force phase (it never imports this layer)
_callbacks.hold_callbacks("tensile", SphereLinkable)
