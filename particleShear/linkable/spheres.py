"""Crosslinkable spheres and their relations (spec §2.5, §10.4-10.5)."""
from ..base.laws import elastic_force_law_tensile
from ..base.points import ArrayField, CircleBasicElasticity, _check_finite
from ..base.relations import RelationView, neighbor_relation
from ..objects.spheres import SphereFrictionLeesEdwards

__all__ = ["neighbor_relation_linkable", "SphereLinkable", "SphereLinkableAdjustableInterfaceStrength"]


class neighbor_relation_linkable(neighbor_relation):
    """Relation that can be made permanent; ``equilibrium_distance`` is ``r_i + r_j`` at linking (µm)."""

    def __init__(self, friction_position, interface_type, theSphere, graphical_line_index=-1,
                 linking_line_index=-1):
        neighbor_relation.__init__(self, friction_position, interface_type, theSphere, graphical_line_index)
        self.linking_line_index = linking_line_index
        self.equilibrium_distance = 0


class LinkableRelationView(RelationView, neighbor_relation_linkable):
    """View of a relation of a linkable ensemble."""

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
    """Frictional Lees-Edwards sphere that can be permanently bonded to its neighbours."""

    call_back_elastic_force_law_tensile = elastic_force_law_tensile
    permanent_ratio_central = ArrayField(1.0, param=True)
    permanent_ratio_tangential = ArrayField(1.0, param=True)
    keep_viscosity_coefficients_constant = ArrayField(1.0, param=True)

    def _new_relation(self, theSphere):
        return neighbor_relation_linkable(0, "stick", theSphere)

    # -- links ------------------------------------------------------------------------------------
    def establish_permanent_link(self, theSphere, do_backlink=True):
        """Bond to ``theSphere``: state permanent, ``d_eq = r_i + r_j``, ξ = 0 (both directions)."""
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
        """Turn a bond into a slipping contact: state slip, ξ = 0, ``d_eq`` = 0 (both directions)."""
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
        """Partners bonded to this sphere; with ``physical_neighbors_only`` only bonds that do not wrap."""
        out = []
        for rel in self.neighbors:
            if rel.interface_type == "permanent":
                s = rel.theSphere
                if not physical_neighbors_only or self._is_physical(s):
                    out.append(s)
        return out

    # -- scalar pair forces of bonds (API; the ensemble uses array kernels) ---------------------------
    def _perm_ratio_c(self):
        return self.permanent_ratio_central

    def get_elastic_force_permanent(self, theSphere, k=1):
        rel = self._relation(theSphere)
        d = self.d(theSphere)
        d_eq = rel.equilibrium_distance
        if d >= d_eq:
            f = SphereLinkable.call_back_elastic_force_law_tensile(d, d_eq, k)
        else:
            f = CircleBasicElasticity.call_back_elastic_force_law(d, d_eq, k, self.central_repulsion_coefficient)
        return f * self.permanent_ratio_central

    def elastic_force(self, theSphere, k):
        rel = self._relation(theSphere)
        if rel is None or rel.interface_type != "permanent":
            return SphereFrictionLeesEdwards.elastic_force(self, theSphere, k)
        return self._apply_along_n(theSphere, self.get_elastic_force_permanent(theSphere, k))

    def get_central_viscous_force(self, theSphere, nu):
        f = SphereFrictionLeesEdwards.get_central_viscous_force(self, theSphere, nu)
        rel = self._relation(theSphere)
        if rel is not None and rel.interface_type == "permanent" and not self.keep_viscosity_coefficients_constant:
            f = f * self.permanent_ratio_central
        return f

    def tangential_force_viscous_permanent(self, theSphere, nu):
        f = self.tangential_force_viscous(theSphere, nu)
        if not self.keep_viscosity_coefficients_constant:
            f = f * self.permanent_ratio_tangential
        return f

    def tangential_force_elastic_permanent(self, theSphere, k_t):
        return k_t * self._relation(theSphere).friction_position * self.permanent_ratio_tangential

    def tangential_force(self, theSphere, nu, mu, k, k_t):
        """One visit of the tangential routine, bonds included (§2.6)."""
        rel = self._relation(theSphere)
        if rel is None:
            return 0
        if rel.interface_type != "permanent":
            return SphereFrictionLeesEdwards.tangential_force(self, theSphere, nu, mu, k, k_t)
        f = (self.tangential_force_viscous_permanent(theSphere, nu)
             + self.tangential_force_elastic_permanent(theSphere, k_t))
        self.distribute_tangential_couple(theSphere, f / 2)
        return f

    def contactLineColor(self, interface_type):
        cfg = self.graphical_output_configuration
        if interface_type in ("stick", "permanent"):
            return cfg.color_interface_locked
        return cfg.color_interface_slip


class SphereLinkableAdjustableInterfaceStrength(SphereLinkable):
    """Linkable sphere whose bonds are weaker or stronger than transient contacts by fixed ratios."""

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
        cfg = self.graphical_output_configuration
        if interface_type == "stick":
            return cfg.color_interface_locked
        if interface_type == "permanent":
            return "darkorange"
        return cfg.color_interface_slip
