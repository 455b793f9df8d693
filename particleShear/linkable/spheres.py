"""Crosslinkable spheres and their relations.

A permanent link ("bond") between two spheres stores ``d_eq = r_i + r_j`` at the time it is made;
below ``d_eq`` it pushes with the compressive contact law (eq. S1-5b, or eq. S1-5a for a linear
law), above it pulls with the tensile law (linear by default, eq. S1-5a), it never breaks and its
tangential spring has no Coulomb bound.  In the adjustable sphere class bonds are scaled by
``permanent_ratio_central`` / ``permanent_ratio_tangential`` relative to transient contacts
(see docs/parameters.md, ``interface_reenforcement_*``).  Lengths in µm, forces in mg·µm·s⁻² per
metre of depth (docs/design.md).
"""
__docformat__ = "numpy"
from ..base.laws import elastic_force_law_tensile
from ..engine import callbacks as _engine_callbacks
from ..base.points import ArrayField, _check_finite, _one
from ..base.relations import RelationView, neighbor_relation
from ..objects.spheres import SphereFrictionLeesEdwards

__all__ = ["neighbor_relation_linkable", "SphereLinkable", "SphereLinkableAdjustableInterfaceStrength"]


class neighbor_relation_linkable(neighbor_relation):
    """Directed relation to ``theSphere`` that can be made permanent (a bond).

    ``equilibrium_distance`` is ``r_i + r_j`` at the time of linking (µm), 0 while not linked.

    Parameters
    ----------
    friction_position : float
        Stored tangential displacement ξ of the pair (µm).
    interface_type : str
        State of the relation: ``"stick"``, ``"slip"`` or ``"permanent"``.
    theSphere : Sphere
        The partner sphere.
    graphical_line_index : int, optional
        Canvas item of the drawn contact line, -1 for none.
    linking_line_index : int, optional
        Canvas item of the drawn bond line, -1 for none.
    """

    def __init__(self, friction_position, interface_type, theSphere, graphical_line_index=-1,
                 linking_line_index=-1):
        neighbor_relation.__init__(self, friction_position, interface_type, theSphere, graphical_line_index)
        self.linking_line_index = linking_line_index
        self.equilibrium_distance = 0


class LinkableRelationView(RelationView, neighbor_relation_linkable):
    """View of the relation ``owner → partner`` of a linkable ensemble, read from its pair table.

    Built on demand by ``sphere.neighbors``; it looks the pair up at every access, so it stays
    valid across steps.

    Parameters
    ----------
    ensemble : CanvasPointsLinkable
        The ensemble holding the pair table.
    owner, partner : int
        Indices of the two spheres in the ensemble.
    """

    def __init__(self, ensemble, owner, partner):
        self._bind(ensemble, owner, partner)


def _same_ensemble(a, b):
    """The ensemble holding both spheres, None if neither is in one; ValueError if they are in two different ones."""
    ens = a.__dict__.get("_ens")
    other = b.__dict__.get("_ens")
    if ens is not None and other is not None and other is not ens:
        raise ValueError(f"cannot link sphere {a.__dict__.get('_idx')} of one ensemble to sphere "
                         f"{b.__dict__.get('_idx')} of another: a bond joins spheres of the same ensemble")
    return ens if ens is not None and other is ens else None


class SphereLinkable(SphereFrictionLeesEdwards):
    """Frictional Lees-Edwards sphere that can be permanently bonded to its neighbours.

    The inherited ``elastic_force``, ``get_central_viscous_force``, ``central_viscous_force`` and
    ``tangential_force`` treat a permanent relation as a bond: the terms of the engine with the
    bond's constants (tensile law beyond ``d_eq``, permanent ratios, no Coulomb bound; eqs. S1-5a/b).
    """

    call_back_elastic_force_law_tensile = elastic_force_law_tensile
    permanent_ratio_central = ArrayField(1.0, param=True)
    permanent_ratio_tangential = ArrayField(1.0, param=True)
    keep_viscosity_coefficients_constant = ArrayField(1.0, param=True)

    def _new_relation(self, theSphere):
        return neighbor_relation_linkable(0, "stick", theSphere)

    # -- links ------------------------------------------------------------------------------------
    def establish_permanent_link(self, theSphere, do_backlink=True):
        """Bond to ``theSphere``: state permanent, ``d_eq = r_i + r_j``, ξ = 0.

        Creates the relation if missing.  Inside an ensemble the pair table is updated for both
        directions at once.

        Parameters
        ----------
        theSphere : SphereLinkable
            The partner, not this sphere and not a sphere of another ensemble.
        do_backlink : bool, optional
            Also make the reverse relation permanent (spheres outside an ensemble).

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
        """Turn a bond into a slipping contact: state slip, ξ = 0, ``d_eq`` = 0.

        The relation stays and acts as a frictional contact while the spheres touch.  Nothing
        happens if the pair is not bonded.

        Parameters
        ----------
        theSphere : SphereLinkable
            The partner.
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

    def _is_physical(self, theSphere):
        return (abs(self.x - theSphere.x) < self.size_x / 2) and (abs(self.y - theSphere.y) < self.size_y / 2)

    def permanentlyConnectedSpheres(self, physical_neighbors_only=True):
        """Partners bonded to this sphere.

        Parameters
        ----------
        physical_neighbors_only : bool, optional
            Only bonds that do not wrap through the periodic boundary (raw coordinate differences
            below half the cell size).

        Returns
        -------
        list of SphereLinkable
            The partners, in relation-list order.
        """
        out = []
        for rel in self.neighbors:
            if rel.interface_type == "permanent":
                s = rel.theSphere
                if not physical_neighbors_only or self._is_physical(s):
                    out.append(s)
        return out

    # -- pair forces of bonds (the per-sphere API; the terms are the engine's, see base/points.py) -------
    def _bond(self, theSphere):
        """``d_eq`` of the bond to ``theSphere`` (µm), None when the relation is missing or not permanent."""
        rel = self._relation(theSphere)
        return rel.equilibrium_distance if rel is not None and rel.interface_type == "permanent" else None

    def _replaced_law(self, K, d):
        """A stretched bond (``d ≥ d_eq``) takes the tensile callback when it is replaced (else None: the built-in
        law of :func:`~particleShear.engine.terms.elastic_term`); contacts and compressed bonds the parent's rule."""
        if K.a_tens is None or d.item() < K.d_eq.item():
            return SphereFrictionLeesEdwards._replaced_law(self, K, d)
        tensile = SphereLinkable.call_back_elastic_force_law_tensile
        return None if tensile is elastic_force_law_tensile else _one(tensile(d.item(), K.d_eq.item(), K.k))

    def get_elastic_force_permanent(self, theSphere, k=1):
        """Scalar central elastic force of the bond to ``theSphere`` (negative = repulsion).

        Tensile law ``call_back_elastic_force_law_tensile(d, d_eq, k)`` for ``d >= d_eq``, the
        compressive contact law (eq. S1-5b with the sphere's ``central_repulsion_coefficient``)
        below it, times ``permanent_ratio_central``: the engine's
        :func:`~particleShear.engine.terms.elastic_term` of a bond (or the replaced callbacks).

        Parameters
        ----------
        theSphere : SphereLinkable
            A bonded partner.
        k : float, optional
            Central spring constant (mg·s⁻² per metre of depth).

        Returns
        -------
        float
            The force along the unit vector towards the partner (mg·µm·s⁻² per metre of depth).
        """
        K = self._terms(theSphere, self._relation(theSphere).equilibrium_distance, k=k)
        return self._elastic(K, self._pairs([theSphere], normal=False).d)[0].item()

    def tangential_force_viscous_permanent(self, theSphere, nu):
        """Tangential viscous force ``ν_t·v_t`` of a bond (non-zero only while the spheres overlap).

        Multiplied by ``permanent_ratio_tangential`` unless ``keep_viscosity_coefficients_constant``.

        Parameters
        ----------
        theSphere : SphereLinkable
            A bonded partner.
        nu : float
            Tangential viscosity constant ν_t (mg·s⁻¹ per metre of depth).

        Returns
        -------
        float
            The scalar tangential force (mg·µm·s⁻² per metre of depth).
        """
        return self._tangential_part(theSphere, True, nu_t=nu)

    def tangential_force_elastic_permanent(self, theSphere, k_t):
        """Tangential elastic force ``k_t·ξ·permanent_ratio_tangential`` of a bond (no Coulomb bound).

        Parameters
        ----------
        theSphere : SphereLinkable
            A bonded partner.
        k_t : float
            Tangential spring constant (mg·s⁻² per metre of depth).

        Returns
        -------
        float
            The scalar tangential force (mg·µm·s⁻² per metre of depth).
        """
        return self._tangential_part(theSphere, True, self._relation(theSphere).friction_position, k_t=k_t)

    def contactLineColor(self, interface_type):
        """Colour of the line drawn for a relation: locked for stick contacts and bonds, else slip.

        Parameters
        ----------
        interface_type : str
            State of the relation: ``"stick"``, ``"slip"`` or ``"permanent"``.

        Returns
        -------
        str
            A colour name of the graphical output configuration.
        """
        cfg = self.graphical_output_configuration
        if interface_type in ("stick", "permanent"):
            return cfg.color_interface_locked
        return cfg.color_interface_slip


class SphereLinkableAdjustableInterfaceStrength(SphereLinkable):
    """Linkable sphere whose bonds are weaker or stronger than transient contacts by fixed ratios.

    The builders set the ratios to ``1/interface_reenforcement_*``, so that bonds keep the base
    constants while transient contacts are reinforced.

    Parameters
    ----------
    color : str
        Fill colour of the disc in drawings.
    x, y : float
        Initial position of the centre (µm).
    diameter : float
        Diameter of the disc (µm), > 0.
    m : float, optional
        Mass (mg per metre of depth).
    my_index : int, optional
        Index of the sphere in its ensemble.
    theCanvas : tkinter.Canvas or False, optional
        Canvas of the live drawing, False for none.
    doDrawing : bool, optional
        Whether the sphere draws itself on ``theCanvas``.
    force_register : object or None, optional
        Receiver of the recorded forces (the ensemble); None creates a private one.
    size_x, size_y : float, optional
        Width and height of the Lees-Edwards cell (µm).
    permanent_ratio_central : float, optional
        Factor of the central elastic force of bonds (and of their viscous force unless
        ``keep_viscosity_coefficients_constant``), >= 0.
    permanent_ratio_tangential : float, optional
        Factor of the tangential spring of bonds (and of their tangential viscosity unless
        ``keep_viscosity_coefficients_constant``), >= 0.
    keep_viscosity_coefficients_constant : bool, optional
        True: the viscous forces of bonds are not scaled by the ratios.

    Raises
    ------
    ValueError
        If a ratio is negative or not finite.
    """

    def __init__(self, color, x, y, diameter, m=1, my_index=1, theCanvas=False, doDrawing=False,
                 force_register=None, size_x=500, size_y=500, permanent_ratio_central=1,
                 permanent_ratio_tangential=1, keep_viscosity_coefficients_constant=True):
        SphereLinkable.__init__(self, color, x, y, diameter, m, my_index, theCanvas, doDrawing, force_register,
                                size_x, size_y)
        _check_finite("permanent_ratio_central", permanent_ratio_central)
        _check_finite("permanent_ratio_tangential", permanent_ratio_tangential)
        if permanent_ratio_central < 0 or permanent_ratio_tangential < 0:
            raise ValueError("permanent ratios must be >= 0, got "
                             f"{permanent_ratio_central!r}, {permanent_ratio_tangential!r}")
        self.permanent_ratio_central = permanent_ratio_central
        self.permanent_ratio_tangential = permanent_ratio_tangential
        self.keep_viscosity_coefficients_constant = keep_viscosity_coefficients_constant

    def contactLineColor(self, interface_type):
        """Colour of the line drawn for a relation: locked (stick), dark orange (bond) or slip.

        Parameters
        ----------
        interface_type : str
            State of the relation: ``"stick"``, ``"slip"`` or ``"permanent"``.

        Returns
        -------
        str
            A colour name.
        """
        cfg = self.graphical_output_configuration
        if interface_type == "stick":
            return cfg.color_interface_locked
        if interface_type == "permanent":
            return "darkorange"
        return cfg.color_interface_slip


# the engine reads the documented callback from this class at every force phase (it never imports this layer)
_engine_callbacks.hold_callbacks("tensile", SphereLinkable)
