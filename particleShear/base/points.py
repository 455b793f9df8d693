"""Points and circles: the per-sphere API of layer 1 (see docs/design.md).

A sphere object is a thin handle.  Before it is appended to an ensemble it
keeps its own values; once appended, its state attributes (``x``, ``xspeed``,
``omega``, ``xforce`` …) read and write the ensemble's arrays at its index and
its ``neighbors`` are views of the ensemble's pair table.  The scalar methods
here (``d``, ``elastic_force``, ``tangential_force`` …) are the documented API
for scripts and tests; the ensembles never call them in a step.

Each of them evaluates the engine's pure functions on the pairs it is asked about, as arrays
of length 1 (or over one sphere's relations): the minimum image and wrap of
:mod:`particleShear.engine.box`, the normals of :func:`particleShear.engine.forces.normals`,
the kinematics, term constants, elastic, viscous and tangential terms and the force vectors of
:mod:`particleShear.engine.terms`, and the kick, damping, ξ increments and drift of
:mod:`particleShear.engine.integrate`.  What stays here is 1.0.2's bookkeeping: one visit per
call, half of a tangential visit's force applied by that visit, and the register entries and
relation states each call leaves.  The rounding is the engine's (e.g. the torque
``d·f·(r_i/(r_i + r_j))``, the permanent ratio on the constant rather than on the force); no
test needs 1.0.2's own order of the operations of a single pair.
"""
__docformat__ = "numpy"

import math
import random as _random

import numpy as np

from ..engine import callbacks as _engine_callbacks
from ..engine.box import flow_velocity, min_image, wrap
from ..engine.forces import normals
from ..engine.integrate import damp, drift, kick, xi_increments
from ..engine.terms import (TermConstants, elastic_term, normal_speed, pair_forces, relative_velocity, slip_speed,
                            tangential_term, term_constants, viscous_term)
from .laws import elastic_force_law
from .register import Force_register
from .relations import neighbor_relation

__all__ = ["Point", "PointLeesEdwards", "Circle", "CircleMass", "CircleMassNeighbors",
           "CircleBasicElasticity", "CircleFrictionElasticity", "ArrayField", "dotProduct2"]


def dotProduct2(a, b):
    """Dot product of two 2-vectors.

    Parameters
    ----------
    a, b : sequence of float
        The vectors (their first two components are used).

    Returns
    -------
    float
        ``a[0]·b[0] + a[1]·b[1]``.
    """
    return a[0] * b[0] + a[1] * b[1]


class ArrayField:
    """Attribute stored locally before the sphere joins an ensemble, in the ensemble's array after.

    A data descriptor: reading it on a sphere of an ensemble reads the ensemble's per-sphere
    array at the sphere's index, so scripts and the vectorised step see one state.

    Parameters
    ----------
    default : float
        Value before the attribute is first set.
    geometry : bool
        Setting it changes the geometry (position, radius): the neighbour candidates are rebuilt.
    param : bool
        Setting it changes a constant of the step (mass, radius …): cached constants are recomputed.
    positive : bool
        Only finite values > 0 are accepted (else finite values).

    Raises
    ------
    ValueError
        On assignment, if the value is not finite (or not > 0 when ``positive``).
    """

    def __init__(self, default=0.0, geometry=False, param=False, positive=False):
        self.default = default
        self.geometry = geometry
        self.param = param
        self.positive = positive

    def __set_name__(self, owner, name):
        self.name = name
        self.key = "_v_" + name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        ens = obj.__dict__.get("_ens")
        if ens is None:
            return obj.__dict__.get(self.key, self.default)
        return ens._a[self.name][obj.__dict__["_idx"]].item()

    def __set__(self, obj, value):
        if self.positive:
            _check_positive(self.name, value)
        else:
            _check_finite(self.name, value)
        ens = obj.__dict__.get("_ens")
        if ens is None:
            obj.__dict__[self.key] = value
            return
        ens._a[self.name][obj.__dict__["_idx"]] = value
        if self.geometry:
            ens._invalidate_neighbours()
        if self.param:
            ens._params_changed()


class EnsembleField:
    """Lees-Edwards parameter: a per-sphere copy in the reference, the ensemble's value here once appended.

    Parameters
    ----------
    default : float
        Value before it is first set.
    canvas_name : str or None
        Name of the ensemble attribute read once the sphere is in an ensemble (None: the same name).
    """

    def __init__(self, default, canvas_name=None):
        self.default = default
        self.canvas_name = canvas_name

    def __set_name__(self, owner, name):
        self.name = name
        self.key = "_v_" + name
        if self.canvas_name is None:
            self.canvas_name = name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        ens = obj.__dict__.get("_ens")
        if ens is not None and hasattr(ens, self.canvas_name):
            return getattr(ens, self.canvas_name)
        return obj.__dict__.get(self.key, self.default)

    def __set__(self, obj, value):
        obj.__dict__[self.key] = value


def _one(*values):
    """The numbers as a float array over the pairs (a pair of one: length 1)."""
    return np.array(values, dtype=float)


def _with(K, **values):
    """Copy of the term constants ``K`` with some of them replaced."""
    return TermConstants(**{**{name: getattr(K, name) for name in TermConstants.__slots__}, **values})


def _wrapped(x, y, vx, Lx, Ly, shift, rate):
    """:func:`~particleShear.engine.box.wrap` of one position: ``(x, y, vx)`` as Python floats."""
    xyv = _one(x, y, vx)[:, None]
    wrap(xyv[0], xyv[1], xyv[2], Lx, Ly, shift, rate)
    return xyv[:, 0].tolist()


class _Pairs:
    """The engine's inputs for the visits from sphere ``me`` to ``spheres``, as arrays over the partners.

    Image vectors and image velocities (``image``, default ``me._image``), distances, normals
    (if ``normal``; a random direction at ``d = 0`` from the ensemble's generator, or Python's
    for a sphere alone), velocity rows ``(vx, vy, ω)`` and radii.
    """

    def __init__(self, me, spheres, normal=True, image=None):
        dx = _one(*(s.x for s in spheres)) - me.x
        dy = _one(*(s.y for s in spheres)) - me.y
        self.me, self.spheres = me, spheres
        self.dx, self.dy, self.dvx = (me._image if image is None else image)(dx, dy)
        self.d = np.sqrt(self.dx * self.dx + self.dy * self.dy)
        if normal:
            ens = me.__dict__.get("_ens")
            self.nx, self.ny = normals(self.dx, self.dy, self.d, None, (_random if ens is None else ens._rng,))

    def rows(self, s):
        """Velocity rows ``(vx, vy, ω)`` of spheres ``s`` (µm/s, rad/s; ω = 0 unless the visitor spins)."""
        spin = self.me._spins
        return np.array([[p.xspeed for p in s], [p.yspeed for p in s], [p.omega if spin else 0.0 for p in s]], dtype=float)

    def velocity(self):
        """:func:`~particleShear.engine.terms.relative_velocity` of the partners' images (µm/s), (2, P)."""
        return relative_velocity(self.rows([self.me]), self.rows(self.spheres), self.dvx)

    def radii(self):
        """Radii ``r_i`` (1,) and ``r_j`` (P,) (µm)."""
        return _one(self.me.r), _one(*(s.r for s in self.spheres))

    def slip(self):
        """:func:`~particleShear.engine.terms.slip_speed` of the pairs (µm/s), with the spins if the visitor spins."""
        ri, rj = self.radii()
        Vi, Vj = self.rows([self.me]), self.rows(self.spheres)
        return slip_speed(relative_velocity(Vi, Vj, self.dvx), self.nx, self.ny, ri, rj, Vi[2], Vj[2])


class Point:
    """A point with position (µm) and velocity (µm/s); the root of the sphere classes.

    Parameters
    ----------
    x, y : float
        Position of the centre (µm).

    Raises
    ------
    TypeError
        If ``x`` or ``y`` is not a real number.
    ValueError
        If ``x`` or ``y`` is not finite.
    """

    x = ArrayField(0.0, geometry=True)
    y = ArrayField(0.0, geometry=True)
    xspeed = ArrayField(0.0)
    yspeed = ArrayField(0.0)

    def __init__(self, x, y):
        self.__dict__["_ens"] = None
        self.__dict__["_idx"] = -1
        _check_finite("x", x)
        _check_finite("y", y)
        self.x = x
        self.y = y
        self.xspeed = 0
        self.yspeed = 0

    def coordinates(self):
        """Position as ``[x, y, 0]`` (µm); circles return their radius as the third entry.

        Returns
        -------
        list of float
            ``[x, y, 0]``.
        """
        return [self.x, self.y, 0]

    #: whether the sphere spins (ω enters its slip speed, φ its drift)
    _spins = False

    def boundary_conditions(self, boundary_x, boundary_y):
        """Plain periodic wrap into ``[0, boundary)`` (:func:`~particleShear.engine.box.wrap` without shift).

        Parameters
        ----------
        boundary_x, boundary_y : float
            Cell size (µm).
        """
        self.x, self.y, _ = _wrapped(self.x, self.y, 0.0, boundary_x, boundary_y, 0.0, 0.0)

    def _image(self, dx, dy):
        """Pair vectors from raw differences (µm) and the x velocities of the images (µm/s; None: no image)."""
        return dx, dy, None

    def _pairs(self, spheres, normal=True, image=None):
        """The :class:`_Pairs` of this point with ``spheres`` (arrays over the partners)."""
        return _Pairs(self, spheres, normal, image)

    def d_euclidian(self, theSphere):
        """Euclidean distance to the other point, without periodic images (µm).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        float
            Distance (µm).
        """
        return math.sqrt((theSphere.x - self.x) ** 2 + (theSphere.y - self.y) ** 2)

    def relative_vector(self, theSphere):
        """Vector from this point to the other one (µm): the Lees-Edwards minimum image where used.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[dx, dy]`` (µm).
        """
        p = self._pairs([theSphere], normal=False)
        return [p.dx.item(), p.dy.item()]

    def d(self, theSphere):
        """Distance to the other point (µm), the length of :meth:`relative_vector`.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        float
            Distance (µm).
        """
        return self._pairs([theSphere], normal=False).d.item()

    def n(self, theSphere):
        """Unit vector towards the other point; a random direction when the two coincide.

        The random direction (:func:`~particleShear.engine.forces.normals`) comes from the
        ensemble's random generator (the run's seed) when the point is in an ensemble.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[n_x, n_y]``, of length 1.
        """
        p = self._pairs([theSphere])
        return [p.nx.item(), p.ny.item()]

    def relative_position(self, theSphere):
        """Vector to the other point as ``n·d`` (µm).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[dx, dy]`` (µm).
        """
        n = self.n(theSphere)
        d = self.d(theSphere)
        return [n[0] * d, n[1] * d]

    def move(self, dt=1):
        """Drift: advance the position by velocity × ``dt`` (:func:`~particleShear.engine.integrate.drift`).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        pos = _one(self.x, self.y)[:, None]
        vel = _one(self.xspeed, self.yspeed, getattr(self, "omega", 0.0))[:, None]
        phi = _one(self.phi) if self._spins else None
        drift(pos, phi, vel, dt)
        if phi is not None:
            self.phi = phi.item()
        self.x, self.y = pos[:, 0].tolist()

    def _damp(self, f, flow):
        """:func:`~particleShear.engine.integrate.damp` of ``(xspeed, yspeed)`` relative to the flow (None: none)."""
        vel = _one(self.xspeed, self.yspeed)[:, None]
        damp(vel, flow, f)
        self.xspeed, self.yspeed = vel[:, 0].tolist()

    def cool(self, f=0.8):
        """Multiply both velocity components by ``f`` (damping).

        Parameters
        ----------
        f : float
            Factor (0 < f ≤ 1; 1 = no damping).
        """
        self._damp(f, None)

    def relative_speed(self, theSphere):
        """Velocity of the other point relative to this one (µm/s); of its nearest image where Lees-Edwards is used.

        :func:`~particleShear.engine.terms.relative_velocity`; an image one row up moves faster by
        ``Ly·γ̇`` in x.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[v_x, v_y]``. (µm/s)
        """
        return self._pairs([theSphere], normal=False).velocity()[:, 0].tolist()


class PointLeesEdwards(Point):
    """Point in a Lees-Edwards cell of ``size_x × size_y`` µm with strain ``shear`` and rate ``shear_rate``.

    Once the point is in an ensemble, the cell parameters are the ensemble's.

    Parameters
    ----------
    x, y : float
        Position of the centre (µm).
    size_x, size_y : float
        Cell size Lx, Ly (µm).
    shear : float
        Shear strain γ of the cell (dimensionless); the image rows are offset by ``Ly·γ``.
    shear_rate : float
        Shear rate γ̇ (1/s).
    use_lees_edwards : bool
        Use Lees-Edwards minimum images and wrapping (True) or a plain periodic cell (False).
    """

    size_x = EnsembleField(500)
    size_y = EnsembleField(500)
    shear = EnsembleField(0)
    shear_rate = EnsembleField(0)

    def __init__(self, x, y, size_x=500, size_y=500, shear=0, shear_rate=0, use_lees_edwards=True):
        Point.__init__(self, x, y)
        self.use_lees_edwards = use_lees_edwards
        self.size_x = size_x
        self.size_y = size_y
        self.shear = shear
        self.shear_rate = shear_rate

    def boundary_conditions(self, boundary_x, boundary_y):
        """Store the cell size, then wrap (Lees-Edwards with velocity correction, or plain).

        Parameters
        ----------
        boundary_x, boundary_y : float
            Cell size (µm).
        """
        self.size_x = boundary_x
        self.size_y = boundary_y
        if self.use_lees_edwards:
            self.lee_edwards_boundary_conditions()
        else:
            Point.boundary_conditions(self, boundary_x, boundary_y)

    def _image(self, dx, dy):
        """The Lees-Edwards minimum image (:meth:`_le_image`) if used, else the plain differences (see
        :meth:`Point._image`)."""
        return self._le_image(dx, dy) if self.use_lees_edwards else (dx, dy, None)

    def _le_image(self, dx, dy):
        """:func:`~particleShear.engine.box.min_image` with shift ``Ly·γ``, and the image velocities ``−Ly·γ̇·k_y``."""
        Ly = self.size_y
        dx, dy, ky, _ = min_image(dx, dy, self.size_x, Ly, Ly * self.shear)
        return dx, dy, -(Ly * self.shear_rate) * ky

    def lee_edwards_closest_to_zero(self, x, y):
        """Minimum image of a difference vector in the sheared cell.

        Crossing the y boundary shifts x by ``∓Ly·γ`` (:func:`~particleShear.engine.box.min_image`).

        Parameters
        ----------
        x, y : float
            Difference vector (µm).

        Returns
        -------
        list of float
            ``[dx, dy]``, with ``-Lx/2 ≤ dx < Lx/2`` and ``-Ly/2 ≤ dy < Ly/2`` (µm).
        """
        dx, dy, _ = self._le_image(_one(x), _one(y))
        return [dx.item(), dy.item()]

    def lee_edwards_positive(self, x, y):
        """Map a position into the cell, without velocity correction (:func:`~particleShear.engine.box.wrap`).

        Parameters
        ----------
        x, y : float
            Position (µm).

        Returns
        -------
        list of float
            ``[x, y]`` inside ``[0, Lx) × [0, Ly)`` (µm).
        """
        return _wrapped(x, y, 0.0, self.size_x, self.size_y, self.size_y * self.shear, 0.0)[:2]

    def lee_edwards_relative_speed(self, theSphere):
        """Velocity of the nearest Lees-Edwards image of the other point relative to this one.

        An image one row up moves faster by ``Ly·γ̇`` in x.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[v_x, v_y]``. (µm/s)
        """
        return self._pairs([theSphere], normal=False, image=self._le_image).velocity()[:, 0].tolist()

    def lee_edwards_boundary_conditions(self):
        """Wrap into the cell; crossing y changes x by ∓Ly·γ and vx by ∓Ly·γ̇ (:func:`~particleShear.engine.box.wrap`)."""
        x, y, self.xspeed = _wrapped(self.x, self.y, self.xspeed, self.size_x, self.size_y,
                                     self.size_y * self.shear, self.shear_rate)
        self.x, self.y = x, y

    def lee_edwards_relative_vector(self, theSphere):
        """Minimum-image vector from this point to the other one (µm).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.

        Returns
        -------
        list of float
            ``[dx, dy]`` (µm).
        """
        return self.lee_edwards_closest_to_zero(theSphere.x - self.x, theSphere.y - self.y)

    def transmit_lees_edwards_parameters(self, theSphere):
        """Copy the cell size, strain, rate and Lees-Edwards flag to another point.

        Parameters
        ----------
        theSphere : PointLeesEdwards
            The point that receives them.
        """
        theSphere.size_x = self.size_x
        theSphere.size_y = self.size_y
        theSphere.shear = self.shear
        theSphere.shear_rate = self.shear_rate
        theSphere.use_lees_edwards = self.use_lees_edwards

    def cool(self, f=0.8):
        """Damp the velocity relative to the affine flow ``γ̇ (y − Ly/2)`` (SLLOD-like; see docs/design.md).

        Parameters
        ----------
        f : float
            Factor applied to the peculiar velocity (0 < f ≤ 1; 1 = no damping).
        """
        self._damp(f, flow_velocity(_one(self.y), self.size_y, self.shear_rate))


def _check_finite(name, value):
    try:
        ok = math.isfinite(value)
    except TypeError:
        raise TypeError(f"{name} must be a real number, got {value!r}") from None
    if not ok:
        raise ValueError(f"{name} must be finite, got {value!r}")


def _check_positive(name, value):
    _check_finite(name, value)
    if not value > 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")


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


class CircleBasicElasticity(CircleMassNeighbors):
    """Disc with central elastic and viscous contact forces (eqs. S1-5a, S1-5b; viscosity eq. S1-9).

    The class attribute ``call_back_elastic_force_law`` (default
    :func:`~particleShear.base.laws.elastic_force_law`) is the central force law of every sphere.

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

    call_back_elastic_force_law = elastic_force_law
    central_repulsion_coefficient = ArrayField(0.0, param=True)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        CircleMassNeighbors.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                     force_register, use_lees_edwards)
        self.central_repulsion_coefficient = 0

    def _bond(self, theSphere):
        """Equilibrium distance (µm) of the bond to ``theSphere``; None: a contact (these spheres have no bonds)."""
        return None

    def _terms(self, theSphere, d_eq=None, k=1.0, nu=0.0, k_t=0.0, nu_t=0.0, mu=0.0):
        """:func:`~particleShear.engine.terms.term_constants` of the visit from this sphere to ``theSphere`` (a contact,
        or a bond at ``d_eq``), with this sphere's c and permanent ratios (1 where it has none); the constants a
        method does not take keep their defaults and do not enter its term."""
        bond = d_eq is not None
        return term_constants(_one(self.r + theSphere.r), np.array([True]) if bond else None, _one(d_eq) if bond else None,
                              k, self.central_repulsion_coefficient, nu, k_t, nu_t, mu,
                              getattr(self, "permanent_ratio_central", 1.0), getattr(self, "permanent_ratio_tangential", 1.0),
                              getattr(self, "keep_viscosity_coefficients_constant", 1.0))

    def _replaced_law(self, K, d):
        """A replaced ``call_back_elastic_force_law`` at ``(d, d_law, k, c)`` as an array of 1 (called with floats,
        as in 1.0.2); None for the built-in law."""
        law = CircleBasicElasticity.call_back_elastic_force_law
        return None if law is elastic_force_law else _one(law(d.item(), K.d_law.item(), K.k, K.c))

    def _elastic(self, K, d):
        """``(law·ratio_c, law)`` of the pair at distance ``d`` (arrays of 1): :func:`~particleShear.engine.terms.elastic_term`,
        or the replaced callbacks."""
        law = self._replaced_law(K, d)
        return elastic_term(K, d) if law is None else (law * K.ratio_c, law)

    def _apply_central(self, theSphere, p, f):
        """Apply and register the central force ``f·n`` of the pair ``p`` (:func:`~particleShear.engine.terms.pair_forces`);
        returns ``[F_x, F_y]``."""
        fx, fy = pair_forces(f, None, p.nx, p.ny, p.d, None)[:2]
        vec = [fx.item(), fy.item()]
        self.applyInternalForceAndRegister(vec, theSphere)
        return vec

    def get_elastic_force(self, theSphere, k=1):
        """Scalar central elastic force of the active contact law, ``law(d, r_i + r_j, k, c)`` (negative = repulsion).

        :func:`~particleShear.engine.terms.elastic_term` of the pair (eqs. S1-5a/b, cap S1-6),
        or the replaced ``call_back_elastic_force_law``.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        k : float
            Spring constant (mg·s⁻² per m depth, eq. S1-8).

        Returns
        -------
        float
            Force (mg·µm·s⁻² per m depth); 0 beyond contact for the built-in laws.
        """
        return self._elastic(self._terms(theSphere, k=k), self._pairs([theSphere], normal=False).d)[0].item()

    def elastic_force(self, theSphere, k):
        """Apply and register the central elastic force along ``n`` if the discs overlap (a bond: at any distance).

        A contact takes the law of :meth:`get_elastic_force`, a bond of a linkable sphere that of
        ``get_elastic_force_permanent``.

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        k : float
            Spring constant (mg·s⁻² per m depth, eq. S1-8).

        Returns
        -------
        list of float
            The force vector on this sphere (``[0, 0]`` for a contact without overlap).
        """
        d_eq = self._bond(theSphere)
        p = self._pairs([theSphere])
        if d_eq is None and not p.d[0] < self.r + theSphere.r:
            return [0, 0]
        return self._apply_central(theSphere, p, self._elastic(self._terms(theSphere, d_eq, k=k), p.d)[0])

    def elastic_force_from_neighbors(self, k):
        """Apply the central elastic force of every relation (:meth:`elastic_force`, in ``neighbors`` order).

        Parameters
        ----------
        k : float
            Spring constant (mg·s⁻² per m depth, eq. S1-8).
        """
        for rel in list(self.neighbors):
            self.elastic_force(rel.theSphere, k)

    def _viscous(self, theSphere, nu):
        """The pair's :class:`_Pairs` and its :func:`~particleShear.engine.terms.viscous_term` ``ν·v_n`` (a bond's ν × its
        ratio unless kept constant)."""
        p = self._pairs([theSphere])
        vn = normal_speed(p.velocity(), p.nx, p.ny)
        return p, viscous_term(self._terms(theSphere, self._bond(theSphere), nu=nu), vn, None)

    def get_central_viscous_force(self, theSphere, nu):
        """Scalar central viscous force ``ν v_n`` (eq. S1-9; a linkable sphere's bond: × ``permanent_ratio_central``
        unless ``keep_viscosity_coefficients_constant``).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        nu : float
            Viscosity constant (mg·s⁻¹ per m depth, eq. S1-9).

        Returns
        -------
        float
            Force (mg·µm·s⁻² per m depth).
        """
        return self._viscous(theSphere, nu)[1].item()

    def central_viscous_force(self, theSphere, nu):
        """Apply and register the central viscous force ``ν v_n n`` (of :meth:`get_central_viscous_force`).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        nu : float
            Viscosity constant (mg·s⁻¹ per m depth, eq. S1-9).

        Returns
        -------
        list of float
            The force vector on this sphere.
        """
        return self._apply_central(theSphere, *self._viscous(theSphere, nu))

    def central_viscous_force_from_neighbors(self, nu):
        """Apply the central viscous force of every relation (:meth:`central_viscous_force`, in ``neighbors`` order).

        Parameters
        ----------
        nu : float
            Viscosity constant (mg·s⁻¹ per m depth, eq. S1-9).
        """
        for rel in list(self.neighbors):
            self.central_viscous_force(rel.theSphere, nu)


class CircleFrictionElasticity(CircleBasicElasticity):
    """Disc with spin and tangential (frictional) contact forces (torque split eq. S1-3).

    The moment of inertia is ``m r²/2`` (mg·µm² per m depth).

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

    _spins = True
    phi = ArrayField(-math.pi / 2)
    omega = ArrayField(0.0)
    torque = ArrayField(0.0)
    inertia = ArrayField(0.5, positive=True, param=True)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        CircleBasicElasticity.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                       force_register, use_lees_edwards)
        self.phi = -math.pi / 2
        self.rotation_line = None
        self.omega = 0
        self.torque = 0
        self.inertia = self.m * self.r * self.r / 2

    def cool(self, f=0.8, shear_rate_to_rotation_rate_coefficient=0):
        """Damp the velocity relative to the affine flow and the spin relative to the local rotation rate.

        :func:`~particleShear.engine.integrate.damp` of ``(v_x, v_y)`` relative to
        ``u = γ̇ (y − Ly/2)`` (plain damping without Lees-Edwards) and of ω relative to ``κ·u``.

        Parameters
        ----------
        f : float
            Factor applied to the peculiar velocity (0 < f ≤ 1; 1 = no damping).
        shear_rate_to_rotation_rate_coefficient : float
            κ: spin of the flow the rotation is damped towards, as a multiple of ``γ̇ (y − Ly/2)``
            (0 = damp towards no rotation).
        """
        PointLeesEdwards.cool(self, f) if self.use_lees_edwards else Point.cool(self, f)
        spin = _one(self.omega)[:, None]
        damp(spin, flow_velocity(_one(self.y), self.size_y, self.shear_rate) * shear_rate_to_rotation_rate_coefficient, f)
        self.omega = spin.item()

    def _visit(self, theSphere, p, K, xi_ij, xi_ji=0.0, bounded=True):
        """One visit from this sphere of the tangential rule, :func:`~particleShear.engine.terms.tangential_term`.

        The visit is the second visit of the engine's two-visit rule on the pair after a first one
        that applies nothing (``k_t = ν_t = 0``), so the force, the slip decision and the reset of
        both histories are this visit's: ``clamp(ν_t v_t·[d < r_i + r_j] + k_t ξ_ij)`` with the
        bound ``|μ·law|`` (bonds, and ``bounded=False``: none).

        ``xi_ij``, ``xi_ji`` are the histories of this sphere's relation and of the partner's (µm).
        Returns the visit's force along ``t_ij`` (array of 1), whether it slipped, and the (2, 1)
        histories ``ξ_ji, ξ_ij`` after it (both 0 after a slip).
        """
        ri, rj = p.radii()
        law = self._elastic(K, p.d)[1] if bounded else _one(0.0)
        first = _with(K, k_t=0.0, nu_t=0.0, fc_inf=K.fc_inf if bounded else math.inf)
        xi = _one(xi_ji, xi_ij)[:, None]
        F, slip = tangential_term(first, p.slip(), p.d < ri + rj, xi, law, K)
        return F[1], bool(slip[0]), xi

    def _tangential_part(self, theSphere, bond, xi=None, **constants):
        """A part of a visit's force without bound (:meth:`_visit`): the viscous part (``xi`` None; 0 without
        overlap) or the elastic part ``k_t ξ``; ``bond``: with a bond's constants (``d_eq`` does not enter them)."""
        p = self._pairs([theSphere])
        if xi is None and not p.d[0] < self.r + theSphere.r:
            return 0
        K = self._terms(theSphere, self.r + theSphere.r if bond else None, **constants)
        return self._visit(theSphere, p, K, 0.0 if xi is None else xi, bounded=False)[0].item()

    def tangential_force_viscous(self, theSphere, nu):
        """Tangential viscous force ``ν_t v_t`` if the discs overlap, else 0 (the viscous part of a visit).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        nu : float
            Tangential viscosity constant (mg·s⁻¹ per m depth).

        Returns
        -------
        float
            Force (mg·µm·s⁻² per m depth).
        """
        return self._tangential_part(theSphere, False, nu_t=nu)

    def tangential_force_elastic(self, theSphere, k_t):
        """Tangential elastic force ``k_t ξ`` if the discs overlap and are related, else 0 (the elastic part of a visit).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        k_t : float
            Tangential spring constant (mg·s⁻² per m depth).

        Returns
        -------
        float
            Force (mg·µm·s⁻² per m depth).
        """
        rel = self._relation(theSphere)
        if rel is None or not self.d(theSphere) < self.r + theSphere.r:
            return 0
        return self._tangential_part(theSphere, False, rel.friction_position, k_t=k_t)

    def distribute_tangential_couple(self, theSphere, force):
        """Apply ``force`` along ``t_ij`` on self and the opposite on the partner, torques split by radii (eq. S1-3).

        :func:`~particleShear.engine.terms.pair_forces` of the pair: ``±f·t`` and the torques
        ``d·f·r_i/(r_i + r_j)`` on self and ``d·f·r_j/(r_i + r_j)`` on the partner (same sign),
        each registered (two forces, two torques).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        force : float
            Tangential force (mg·µm·s⁻² per m depth).
        """
        p = self._pairs([theSphere])
        w = _one(self.r, theSphere.r)[:, None] / (self.r + theSphere.r)
        fx, fy, _, tq = pair_forces(0.0, _one(force), p.nx, p.ny, p.d, w)
        vec = [fx.item(), fy.item()]
        self.applyInternalForceAndRegister(vec, theSphere)
        theSphere.applyInternalForceAndRegister([-vec[0], -vec[1]], self)
        ti, tj = tq[:, 0].tolist()
        self.torque = self.torque + ti
        theSphere.torque = theSphere.torque + tj
        reg = self.force_register
        if hasattr(reg, "record_individual_internal_torque"):
            reg.record_individual_internal_torque(self, theSphere, ti)
        reg = theSphere.force_register
        if hasattr(reg, "record_individual_internal_torque"):
            reg.record_individual_internal_torque(theSphere, self, tj)

    def tangential_force(self, theSphere, nu, mu, k, k_t):
        """One visit of the tangential routine (a contact; for a linkable sphere also a bond).

        The force ``ν_t v_t·[d < r_i + r_j] + k_t ξ`` of :meth:`_visit`: a contact is limited by
        ``μ |law(d, r_i + r_j, k, c)|`` — this visit sets the state of both directions (stick or
        slip) and a slip resets both histories — a bond has no bound and keeps its state; half
        of the force is applied (:meth:`distribute_tangential_couple`; docs/design.md).

        Parameters
        ----------
        theSphere : Point
            The other point or sphere.
        nu : float
            Tangential viscosity constant (mg·s⁻¹ per m depth).
        mu : float
            Friction coefficient μ of the Coulomb limit (dimensionless).
        k : float
            Spring constant (mg·s⁻² per m depth, eq. S1-8).
        k_t : float
            Tangential spring constant (mg·s⁻² per m depth).

        Returns
        -------
        float
            The limited tangential force (mg·µm·s⁻² per m depth), 0 without a relation and for a
            contact without overlap.
        """
        rel = self._relation(theSphere)
        d_eq = self._bond(theSphere)
        p = self._pairs([theSphere])
        if rel is None or (d_eq is None and not p.d[0] < self.r + theSphere.r):
            return 0
        back = theSphere._relation(self) if hasattr(theSphere, "_relation") else None
        F, slip, xi = self._visit(theSphere, p, self._terms(theSphere, d_eq, k=k, k_t=k_t, nu_t=nu, mu=mu),
                                  rel.friction_position, 0.0 if back is None else back.friction_position)
        if d_eq is None:
            state = "slip" if slip else "stick"
            for r, x in ((rel, xi[1]), (back, xi[0])):
                if r is not None:
                    r.friction_position = x.item()
                    r.interface_type = state
        f = F.item()
        self.distribute_tangential_couple(theSphere, f / 2)
        return f

    def tangential_force_from_neighbors(self, nu, mu, k, k_t):
        """Apply the tangential routine to every relation (:meth:`tangential_force`, in ``neighbors`` order).

        Parameters
        ----------
        nu : float
            Tangential viscosity constant (mg·s⁻¹ per m depth).
        mu : float
            Friction coefficient μ of the Coulomb limit (dimensionless).
        k : float
            Spring constant (mg·s⁻² per m depth, eq. S1-8).
        k_t : float
            Tangential spring constant (mg·s⁻² per m depth).
        """
        for rel in list(self.neighbors):
            self.tangential_force(rel.theSphere, nu, mu, k, k_t)

    def do_rotational_acceleration(self, dt):
        """Register the net torque, kick the spin by ``T dt / I``, reset the torque (:func:`~particleShear.engine.integrate.kick`).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        reg = self.force_register
        if hasattr(reg, "record_unbalanced_moment"):
            reg.record_unbalanced_moment(self, self.torque)
        spin, torque = _one(self.omega)[:, None], _one(self.torque)[:, None]
        kick(spin, torque, self.inertia, dt)
        self.omega, self.torque = spin.item(), torque.item()

    def move(self, dt=1):
        """Advance φ, integrate ξ of the stick and permanent relations, then drift (sequential rule, Appendix B.2).

        ``ξ_ij += v_t·dt`` with the current velocities and positions (partners moved before this
        sphere count at their new positions): the increment ``ξ̇_ij`` of
        :func:`~particleShear.engine.integrate.xi_increments` over this sphere's relations; the
        partner's history is integrated by the partner's own move.

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        rels = [rel for rel in self.neighbors if rel.interface_type in ("stick", "permanent")]
        if rels:
            p = self._pairs([rel.theSphere for rel in rels])
            ri, rj = p.radii()
            inc = xi_increments(p.rows([self]), p.rows(p.spheres), p.dvx, p.nx, p.ny, ri, rj, -p.dx, -p.dy,
                                lambda Rx, Ry: (-p.nx, -p.ny))[0]
            for rel, step in zip(rels, (inc * dt).tolist()):
                rel.friction_position = rel.friction_position + step
        Circle.move(self, dt)


# the engine reads the documented callback from this class at every force phase (it never imports this layer)
_engine_callbacks.hold_callbacks("central", CircleBasicElasticity)
