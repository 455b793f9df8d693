"""Points: the base of the per-sphere API of layer 1 (see docs/design.md).

A sphere object is a thin handle.  Before it is appended to an ensemble it
keeps its own values; once appended, its state attributes (``x``, ``xspeed``,
``omega``, ``xforce`` …) read and write the ensemble's arrays at its index and
its ``neighbors`` are views of the ensemble's pair table.  The scalar methods
here and in :mod:`.circles` and :mod:`.elastic_circles` (``d``, ``elastic_force``,
``tangential_force`` …; the classes are re-exported here) are the documented API
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

from ..engine.box import flow_velocity, min_image, wrap
from ..engine.forces import normals
from ..engine.integrate import damp, drift
from ..engine.terms import (TermConstants, relative_velocity, slip_speed)

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


# the circles subclass PointLeesEdwards: imported after it, re-exported here
from .circles import Circle, CircleMass, CircleMassNeighbors  # noqa: E402
from .elastic_circles import CircleBasicElasticity, CircleFrictionElasticity  # noqa: E402
