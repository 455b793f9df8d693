"""Circles: discs with a mass and relations to their neighbours (docs/engine.md, "State").

:class:`Circle` (radius, drawing), :class:`CircleMass` (mass, forces, 1.0.2's register) and
:class:`CircleMassNeighbors` (relations); handles into the ensemble's arrays once appended.
"""
__docformat__ = "numpy"

from ..engine.integrate import kick
from .register import Force_register
from .relations import neighbor_relation

from .point_base import ArrayField, PointLeesEdwards, _check_positive, _one, _pair_query
from .graphics import Graphical_output_configuration, headless

__all__ = ["Circle", "CircleMass", "CircleMassNeighbors"]


class Circle(PointLeesEdwards):
    """Disc of radius ``r = diameter/2`` (µm), the cross-section of an infinite cylinder.

    Parameters
    ----------
    color : str
        Drawing colour (Tk/Pillow colour name).
    x, y, use_lees_edwards
        As for :class:`~particleShear.base.points.PointLeesEdwards`.
    diameter : float
        Diameter (µm, > 0).
    theCanvas : object or bool
        Tk canvas, stored for compatibility (False: none).
    doDrawing : bool
        Whether the ensemble's renderer draws the sphere.

    Raises
    ------
    TypeError, ValueError
        If ``x``, ``y`` or ``diameter`` is not a finite number, or ``diameter`` not > 0.
    """

    r = ArrayField(1.0, geometry=True, positive=True, param=True)

    def __init__(self, color, x, y, diameter, theCanvas=False, doDrawing=False, use_lees_edwards=False):
        PointLeesEdwards.__init__(self, x, y, use_lees_edwards=use_lees_edwards)
        _check_positive("diameter", diameter)
        self.theCanvas = theCanvas
        self.r = diameter / 2
        self.doDrawing, self.shape, self.color = doDrawing, None, color
        self.graphical_output_configuration = Graphical_output_configuration()

    def __getstate__(self):
        """The sphere's attributes for a copy or a pickle, without the window handle ``theCanvas``
        (:func:`~particleShear.base.graphics.headless`); a sphere of an ensemble goes with its ensemble."""
        return headless(self.__dict__)

    def set_graphical_output_configuration(self, graphical_output_configuration):
        """Use these drawing options for the sphere and its contacts.

        Parameters
        ----------
        graphical_output_configuration : Graphical_output_configuration
        """
        self.graphical_output_configuration = graphical_output_configuration

    def coordinates(self):
        return [self.x, self.y, self.r]

    def initiate_drawing(self):
        """Do nothing (1.0.2 API: the ensemble's renderer draws the spheres)."""

    def move(self, dt=1):
        PointLeesEdwards.move(self, dt)
        self.moveDrawing(dt)

    def moveDrawing(self, dt):
        """Do nothing (1.0.2 API: the ensemble's renderer moves the drawing).

        Parameters
        ----------
        dt : float
        """

    def deleteDrawing(self):
        """Do nothing (1.0.2 API: the ensemble's renderer deletes the drawing)."""

    tangential_vector = _pair_query("Return the unit tangent ``t = (−n_y, n_x)`` of the contact with "
                                    "``theSphere``.", lambda p: [-p.ny.item(), p.nx.item()], normal=True)
    tangential_speed = _pair_query("Return the slip speed ``Δv·t − (r_i ω_i + r_j ω_j)`` to ``theSphere`` (µm/s; ω = 0 "
                                   "without spin).", lambda p: p.slip().item(), normal=True)


class CircleMass(Circle):
    """Disc with mass ``m`` (mg per m depth) and a force accumulator (mg·µm·s⁻² per m depth).

    Parameters
    ----------
    color, x, y, diameter, theCanvas, doDrawing, use_lees_edwards
        As for :class:`Circle`.
    m : float
        Mass (mg per m depth, > 0).
    force_register : Force_register or None
        Register of the forces; None: one of its own (in an ensemble, the ensemble's is used).

    Raises
    ------
    TypeError, ValueError
        As for :class:`Circle`, and if ``m`` is not a finite number > 0.
    """

    m = ArrayField(1.0, positive=True, param=True)
    xforce = ArrayField(0)
    yforce = ArrayField(0)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        Circle.__init__(self, color, x, y, diameter, theCanvas, doDrawing, use_lees_edwards)
        self.m = m
        self.force_register = Force_register() if force_register is None else force_register

    def record_total_particle_force(self):
        """Record the accumulated force ``(xforce, yforce)`` as this sphere's total in the register."""
        self.force_register.record_total_particle_force(self, [self.xforce, self.yforce])

    def do_linear_acceleration(self, dt):
        """Register the total force, kick the velocity by ``F dt / m`` (``dt`` in s), reset the force.

        Parameters
        ----------
        dt : float
        """
        self.record_total_particle_force()
        vel, frc = _one(self.xspeed, self.yspeed)[:, None], _one(self.xforce, self.yforce)[:, None]
        kick(vel, frc, self.m, dt)
        self.xspeed, self.yspeed = vel[:, 0].tolist()
        self.xforce, self.yforce = frc[:, 0].tolist()

    def applyInternalForceAndRegister(self, force_vector, source, register_homolog=False):
        """Add the force ``force_vector`` (mg·µm·s⁻² per m depth) from ``source`` and record it as internal.

        Parameters
        ----------
        force_vector : sequence of float
        source : CircleMass
        register_homolog : bool
            Also record the opposite force on ``source`` in its register.
        """
        self.xforce = self.xforce + force_vector[0]
        self.yforce = self.yforce + force_vector[1]
        self.force_register.record_individual_internal_force(self, source, force_vector)
        if register_homolog:
            source.force_register.record_individual_internal_force(
                source, self, [-force_vector[0], -force_vector[1]])


class CircleMassNeighbors(CircleMass):
    """Disc with a neighbour list of relations (views of the ensemble's pair table once appended).

    Parameters
    ----------
    color, x, y, diameter, m, theCanvas, doDrawing, force_register, use_lees_edwards
        As for :class:`CircleMass` (and raising as it does).
    """

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        CircleMass.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing, force_register,
                            use_lees_edwards)
        self.__dict__["_own_neighbors"] = []

    @property
    def neighbors(self):
        """Relations of this sphere in creation order (views when in an ensemble)."""
        ens = self.__dict__.get("_ens")
        if ens is None:
            return self.__dict__["_own_neighbors"]
        return ens._relations_of(self.__dict__["_idx"])

    @neighbors.setter
    def neighbors(self, value):
        ens = self.__dict__.get("_ens")
        if ens is None:
            self.__dict__["_own_neighbors"] = value
        elif len(value) == 0:
            ens._drop_relations_of(self.__dict__["_idx"])
        else:
            raise AttributeError("the neighbour list of a sphere in an ensemble is managed by the ensemble")

    def deleteNeighborDrawing(self):
        """Do nothing (1.0.2 API: the renderer draws the contacts)."""

    def contactLineColor(self, interface_type):
        """Return the colour of a contact line: the locked colour when ``"stick"``, else the slip colour.

        Parameters
        ----------
        interface_type : {"stick", "slip", "permanent"}
        """
        cfg = self.graphical_output_configuration
        return cfg.color_interface_locked if interface_type == "stick" else cfg.color_interface_slip

    def initiateNeighborDrawing(self):
        """Do nothing (1.0.2 API: the renderer draws the contacts)."""

    def _relation(self, theSphere):
        k = self.findNeighborIndex(theSphere)
        return None if k < 0 else self.neighbors[k]

    def findNeighborIndex(self, theSphere):
        """Return the index in ``neighbors`` of the (last) relation to the sphere ``theSphere``, −1 if none.

        Parameters
        ----------
        theSphere : CircleMassNeighbors
        """
        return max((k for k, rel in enumerate(self.neighbors) if rel.theSphere is theSphere), default=-1)

    def _new_relation(self, theSphere):
        return neighbor_relation(0, "stick", theSphere)

    def test_neighbor_relation(self, theSphere):
        """Create the relation to ``theSphere`` when the discs overlap, drop it when they separate (unless permanent).

        Parameters
        ----------
        theSphere : CircleMassNeighbors
        """
        ens = self.__dict__.get("_ens")
        if ens is not None and theSphere.__dict__.get("_ens") is ens:
            ens._test_pair(self.__dict__["_idx"], theSphere.__dict__["_idx"])
            return
        touching = self.d(theSphere) < self.r + theSphere.r
        k = self.findNeighborIndex(theSphere)
        if not touching and k >= 0 and self.neighbors[k].interface_type != "permanent":
            del self.__dict__["_own_neighbors"][k]
        if touching and k < 0:
            self.__dict__["_own_neighbors"].append(self._new_relation(theSphere))
