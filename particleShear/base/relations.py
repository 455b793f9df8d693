"""Neighbour relations: plain objects, and views of an ensemble's pair table (see docs/classes.md)."""
__docformat__ = "numpy"

from .neighbours import STATE_CODES, STATE_NAMES

__all__ = ["neighbor_relation", "RelationView"]


class neighbor_relation:
    """Directed relation of a sphere to ``theSphere``.

    Parameters
    ----------
    friction_position : float
        Tangential displacement history ξ (µm), the extension of the tangential spring.
    interface_type : {"stick", "slip", "permanent"}
        A sticking or slipping contact, or a permanent link.
    theSphere : object
        The partner; its ``myindex`` (0 if none) is copied to ``myindex``.
    graphical_line_index : int
        Canvas item of the drawn interface line (-1: none).
    """

    def __init__(self, friction_position, interface_type, theSphere, graphical_line_index=-1):
        self.myindex = getattr(theSphere, "myindex", 0)
        self.friction_position = friction_position
        self.interface_type = interface_type
        self.theSphere = theSphere
        self.graphical_line_index = graphical_line_index


class RelationView:
    """Mixin: the relation ``owner → partner`` in the ensemble's pair table, looked up at every access.

    Parameters
    ----------
    ensemble : object
        The ensemble (a canvas with a pair table).
    owner, partner : int
        Indices of the sphere holding the relation and of its partner.
    """

    def __init__(self, ensemble, owner, partner):
        self.__dict__.update(_ens=ensemble, _owner=owner, _partner=partner, graphical_line_index=-1,
                             linking_line_index=-1)

    def _slot(self):
        ens = self.__dict__["_ens"]
        s = int(ens._pairs.find(self.__dict__["_owner"], self.__dict__["_partner"]))
        if s < 0:
            raise LookupError("this relation no longer exists")
        return s

    def _side(self):
        return "xi_ij" if self.__dict__["_owner"] < self.__dict__["_partner"] else "xi_ji"

    @property
    def theSphere(self):
        """The partner sphere (an element of the ensemble's ``sphereList``)."""
        return self.__dict__["_ens"].sphereList[self.__dict__["_partner"]]

    @property
    def myindex(self):
        """Index ``myindex`` of the partner sphere (0 if it has none)."""
        return getattr(self.theSphere, "myindex", 0)

    @property
    def friction_position(self):
        """Tangential displacement history ξ of this direction of the pair (µm); settable."""
        return float(getattr(self.__dict__["_ens"]._pairs, self._side())[self._slot()])

    @friction_position.setter
    def friction_position(self, value):
        getattr(self.__dict__["_ens"]._pairs, self._side())[self._slot()] = value

    @property
    def interface_type(self):
        """State ``"stick"``, ``"slip"`` or ``"permanent"``; settable (a link made or ended updates its constants)."""
        return STATE_NAMES[int(self.__dict__["_ens"]._pairs.state[self._slot()])]

    @interface_type.setter
    def interface_type(self, value):
        pt = self.__dict__["_ens"]._pairs
        s = self._slot()
        was_perm = pt.state[s] == 2
        pt.state[s] = STATE_CODES[value]
        if was_perm != (value == "permanent"):
            self.__dict__["_ens"]._links_changed()

    @property
    def equilibrium_distance(self):
        """Equilibrium distance of a permanent link (µm), ``r_i + r_j`` when made; settable."""
        return float(self.__dict__["_ens"]._pairs.d_eq[self._slot()])

    @equilibrium_distance.setter
    def equilibrium_distance(self, value):
        ens = self.__dict__["_ens"]
        ens._pairs.d_eq[self._slot()] = value
        ens._links_changed()   # cached bond constants depend on d_eq

    def __repr__(self):
        return (f"<relation {self.__dict__['_owner']}->{self.__dict__['_partner']} "
                f"{self.interface_type} xi={self.friction_position}>")


class _BaseRelationView(RelationView, neighbor_relation):
    """View of a relation for non-linkable ensembles (:class:`RelationView`'s parameters)."""
