"""Circles: discs with a mass and relations to their neighbours (docs/design.md, "State").

:class:`Circle` (a disc of radius r, µm, and its drawing), :class:`CircleMass` (mass, forces and the
register of 1.0.2) and :class:`CircleMassNeighbors` (the relations, views of the ensemble's pair
table).  Handles into the ensemble's arrays once appended (:class:`~particleShear.base.points.ArrayField`).
"""
__docformat__ = "numpy"

from ..engine.integrate import kick
from .register import Force_register
from .relations import neighbor_relation

from .points import ArrayField, PointLeesEdwards, _check_positive, _one

__all__ = ["Circle", "CircleMass", "CircleMassNeighbors"]



class Circle(PointLeesEdwards):
    """Disc of radius ``diameter/2`` (µm); the cross-section of an infinite cylinder.

    Parameters
    ----------
    color : str
        Drawing colour (Tk/Pillow colour name).
    x, y : float
        Position of the centre (µm).
    diameter : float
        Diameter (µm, > 0); the radius ``r`` is half of it.
    theCanvas : object or bool
        Tk canvas to draw on (stored for compatibility; False when none).
    doDrawing : bool
        Whether the sphere is drawn (the ensemble's renderer draws it).
    use_lees_edwards : bool
        Use Lees-Edwards minimum images and wrapping (True) or a plain periodic cell (False).

    Raises
    ------
    ValueError
        If ``diameter`` is not a finite number > 0, or ``x``/``y`` is not finite.
    """

    r = ArrayField(1.0, geometry=True, positive=True, param=True)

    def __init__(self, color, x, y, diameter, theCanvas=False, doDrawing=False, use_lees_edwards=False):
        PointLeesEdwards.__init__(self, x, y, use_lees_edwards=use_lees_edwards)
        _check_positive("diameter", diameter)
        self.theCanvas = theCanvas
        self.r = diameter / 2
        self.doDrawing = doDrawing
        self.shape = None
        self.color = color
        from .graphics import Graphical_output_configuration
        self.graphical_output_configuration = Graphical_output_configuration()

    def set_graphical_output_configuration(self, graphical_output_configuration):
        """Use these drawing options for the sphere.

        Parameters
        ----------
        graphical_output_configuration : Graphical_output_configuration
            The options.
        """
        self.graphical_output_configuration = graphical_output_configuration

    def coordinates(self):
        """Position and radius as ``[x, y, r]`` (µm).

        Returns
        -------
        list of float
            ``[x, y, r]``.
        """
        return [self.x, self.y, self.r]

    # Drawing happens in the renderer of the ensemble (layer 4); these hooks keep the API.
    def initiate_drawing(self):
        """Kept for the 1.0.2 API: the ensemble's renderer draws the spheres (does nothing)."""
        pass

    def move(self, dt=1):
        """Drift by velocity × ``dt`` (the drawing follows in the renderer).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        PointLeesEdwards.move(self, dt)
        self.moveDrawing(dt)

    def moveDrawing(self, dt):
        """Kept for the 1.0.2 API: the ensemble's renderer moves the drawing (does nothing).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        pass

    def deleteDrawing(self):
        """Kept for the 1.0.2 API: the ensemble's renderer deletes the drawing (does nothing)."""
        pass

    def tangential_vector(self, theSphere):
        """Unit tangent ``t = (−n_y, n_x)`` of the contact with the other sphere.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[t_x, t_y]``.
        """
        n = self.n(theSphere)
        return [-n[1], n[0]]

    def tangential_speed(self, theSphere):
        """Slip velocity along ``t_ij`` (:func:`~particleShear.engine.terms.slip_speed`, µm/s).

        ``Δv·t_ij − (r_i ω_i + r_j ω_j)``: the translational part only for a sphere without spin,
        the slip of the two surfaces at the contact point for a spinning one
        (:class:`CircleFrictionElasticity`).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        float
            Speed (µm/s).
        """
        return self._pairs([theSphere]).slip().item()


class CircleMass(Circle):
    """Disc with mass ``m`` (mg per m depth) and a force accumulator (mg·µm·s⁻² per m).

    Parameters
    ----------
    color : str
        Drawing colour (Tk/Pillow colour name).
    x, y : float
        Position of the centre (µm).
    diameter : float
        Diameter (µm, > 0); the radius ``r`` is half of it.
    m : float
        Mass (mg per m depth, > 0).
    theCanvas : object or bool
        Tk canvas to draw on (stored for compatibility; False when none).
    doDrawing : bool
        Whether the sphere is drawn (the ensemble's renderer draws it).
    force_register : Force_register or None
        Register that records the forces; None gives the sphere a register of its own (in an
        ensemble the ensemble's register is used).
    use_lees_edwards : bool
        Use Lees-Edwards minimum images and wrapping (True) or a plain periodic cell (False).

    Raises
    ------
    ValueError
        If ``diameter`` or ``m`` is not a finite number > 0, or ``x``/``y`` is not finite.
    """

    m = ArrayField(1.0, positive=True, param=True)
    xforce = ArrayField(0.0)
    yforce = ArrayField(0.0)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        Circle.__init__(self, color, x, y, diameter, theCanvas, doDrawing, use_lees_edwards)
        _check_positive("m", m)
        self.m = m
        # a register of its own unless one is given (1.0.2 shared one mutable default register among all spheres)
        self.force_register = Force_register() if force_register is None else force_register
        self.xforce = 0
        self.yforce = 0

    def record_total_particle_force(self):
        """Record the accumulated force ``(xforce, yforce)`` as this sphere's total in the register."""
        self.force_register.record_total_particle_force(self, [self.xforce, self.yforce])

    def do_linear_acceleration(self, dt):
        """Register the total force, kick the velocity by ``F dt / m``, reset the force.

        :func:`~particleShear.engine.integrate.kick` on this sphere.

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        self.record_total_particle_force()
        vel, frc = _one(self.xspeed, self.yspeed)[:, None], _one(self.xforce, self.yforce)[:, None]
        kick(vel, frc, self.m, dt)
        self.xspeed, self.yspeed = vel[:, 0].tolist()
        self.xforce, self.yforce = frc[:, 0].tolist()

    def applyInternalForceAndRegister(self, force_vector, source, register_homolog=False):
        """Add a pair force to the accumulator and record it as internal.

        Parameters
        ----------
        force_vector : sequence of float
            ``(F_x, F_y)`` on this sphere (mg·µm·s⁻² per m depth).
        source : CircleMass
            The sphere exerting it.
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
    """Disc with a neighbour list of relation objects (views of the ensemble's pair table).

    Parameters
    ----------
    color : str
        Drawing colour (Tk/Pillow colour name).
    x, y : float
        Position of the centre (µm).
    diameter : float
        Diameter (µm, > 0); the radius ``r`` is half of it.
    m : float
        Mass (mg per m depth, > 0).
    theCanvas : object or bool
        Tk canvas to draw on (stored for compatibility; False when none).
    doDrawing : bool
        Whether the sphere is drawn (the ensemble's renderer draws it).
    force_register : Force_register or None
        Register that records the forces; None gives the sphere a register of its own (in an
        ensemble the ensemble's register is used).
    use_lees_edwards : bool
        Use Lees-Edwards minimum images and wrapping (True) or a plain periodic cell (False).

    Raises
    ------
    ValueError
        If ``diameter`` or ``m`` is not a finite number > 0, or ``x``/``y`` is not finite.
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

    def set_graphical_output_configuration(self, graphical_output_configuration):
        """Use these drawing options for the sphere and its contacts.

        Parameters
        ----------
        graphical_output_configuration : Graphical_output_configuration
            The options.
        """
        self.graphical_output_configuration = graphical_output_configuration

    def deleteNeighborDrawing(self):
        """Kept for the 1.0.2 API: the renderer draws the contacts (does nothing)."""
        pass

    def contactLineColor(self, interface_type):
        """Colour of a contact line: the locked colour when sticking, else the slip colour.

        Parameters
        ----------
        interface_type : {"stick", "slip", "permanent"}
            State of the relation.

        Returns
        -------
        str
            A colour of :attr:`graphical_output_configuration`.
        """
        cfg = self.graphical_output_configuration
        if interface_type == "stick":
            return cfg.color_interface_locked
        return cfg.color_interface_slip

    def initiateNeighborDrawing(self):
        """Kept for the 1.0.2 API: the renderer draws the contacts (does nothing)."""
        pass

    def moveDrawing(self, dt):
        """Kept for the 1.0.2 API: the renderer moves the drawing (does nothing).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        pass

    def deleteDrawing(self):
        """Kept for the 1.0.2 API: the renderer deletes the drawing (does nothing)."""
        pass

    def _relation(self, theSphere):
        k = self.findNeighborIndex(theSphere)
        return None if k < 0 else self.neighbors[k]

    def findNeighborIndex(self, theSphere):
        """Index of the relation pointing at ``theSphere`` in ``neighbors``, −1 if none (the last match wins).

        Parameters
        ----------
        theSphere : CircleMassNeighbors
            The partner (matched by identity).

        Returns
        -------
        int
            The index, or −1.
        """
        found = -1
        for k, rel in enumerate(self.neighbors):
            if rel.theSphere is theSphere:
                found = k
        return found

    def _new_relation(self, theSphere):
        return neighbor_relation(0, "stick", theSphere)

    def test_neighbor_relation(self, theSphere):
        """Create or delete the relation to ``theSphere`` from the current overlap.

        A relation is created when the discs overlap and dropped when they separate, unless it is
        permanent (see docs/design.md).

        Parameters
        ----------
        theSphere : CircleMassNeighbors
            The possible partner.
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
