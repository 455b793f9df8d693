"""Points, the root of the per-sphere API (docs/classes.md, "The documented classes"); the circles of
:mod:`.circles` and :mod:`.elastic_circles` subclass them, and :mod:`.points` gathers all of them.

A sphere keeps its own values until appended to an ensemble, then reads and writes the ensemble's
arrays at its index.  These scalar methods (and those of the circles) serve scripts and tests: each evaluates the engine's pure functions on arrays of
length 1 with 1.0.2's bookkeeping (one visit per call); the documented step does not call them.
"""
__docformat__ = "numpy"

import math
import random as _random

import numpy as np

from ..checks import finite as _check_finite, positive as _check_positive
from ..engine.box import flow_velocity, min_image, wrap
from ..engine.forces import normals
from ..engine.integrate import damp, drift
from ..engine.terms import (TermConstants, relative_velocity, slip_speed)

__all__ = ["Point", "PointLeesEdwards", "ArrayField", "dotProduct2"]


def dotProduct2(a, b):
    """Return ``a[0]·b[0] + a[1]·b[1]``, the dot product of two 2-vectors.

    Parameters
    ----------
    a, b : sequence of float
    """
    return a[0] * b[0] + a[1] * b[1]


class ArrayField:
    """Descriptor: a sphere attribute stored locally, or in the ensemble's array once appended.

    Parameters
    ----------
    default : float
        Value before it is first set.
    geometry, param : bool
        Setting it rebuilds the neighbour candidates (position, radius) / the cached step constants.
    positive : bool
        Accept only values > 0.
    flag : bool
        A yes/no setting stored as 1 or 0: True and False are accepted too.

    Raises
    ------
    TypeError, ValueError
        On assigning a non-number, a value not finite, or not > 0 when ``positive``.
    """

    def __init__(self, default=0.0, geometry=False, param=False, positive=False, flag=False):
        self.default, self.geometry, self.param, self.positive, self.flag = default, geometry, param, positive, flag

    def __set_name__(self, owner, name):
        self.name, self.key = name, "_v_" + name

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
        elif not (self.flag and isinstance(value, (bool, np.bool_))):
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


class EnsembleField(ArrayField):
    """Descriptor: a Lees-Edwards parameter, the ensemble's attribute of that name once the sphere is appended.

    Parameters
    ----------
    default : float
    """

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        ens = obj.__dict__.get("_ens")
        if ens is not None and hasattr(ens, self.name):
            return getattr(ens, self.name)
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
    """The engine's inputs for visits from ``me`` to ``spheres`` over the partners: images (``image``, default
    ``me._image``), distances, normals if ``normal`` (random at ``d = 0``: the ensemble's or Python's generator)."""

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
        return np.array([[p.xspeed for p in s], [p.yspeed for p in s], [p.omega if spin else 0.0 for p in s]],
                        dtype=float)

    def velocity(self):
        """:func:`~particleShear.engine.terms.relative_velocity` of the partners' images (µm/s), (2, P)."""
        return relative_velocity(self.rows([self.me]), self.rows(self.spheres), self.dvx)

    def radii(self):
        """Radii ``r_i`` (1,) and ``r_j`` (P,) (µm)."""
        return _one(self.me.r), _one(*(s.r for s in self.spheres))

    def slip(self):
        """:func:`~particleShear.engine.terms.slip_speed` of the pairs (µm/s), with the spins if the visitor spins."""
        Vi, Vj = self.rows([self.me]), self.rows(self.spheres)
        return slip_speed(relative_velocity(Vi, Vj, self.dvx), self.nx, self.ny, *self.radii(), Vi[2], Vj[2])


class _pair_query:
    """A method ``(self, theSphere)``, named where assigned and documented by ``summary``: ``value(p)`` of the
    :class:`_Pairs` ``p`` with ``theSphere`` (normals if ``normal``; the Lees-Edwards image if ``lees_edwards``)."""

    def __init__(self, summary, value, normal=False, lees_edwards=False):
        self.args = summary, value, normal, lees_edwards

    def __set_name__(self, owner, name):
        summary, value, normal, lees_edwards = self.args

        def query(self, theSphere):
            return value(self._pairs([theSphere], normal, self._le_image if lees_edwards else None))

        query.__name__, query.__qualname__, query.__module__ = name, f"{owner.__qualname__}.{name}", owner.__module__
        query.__doc__ = summary + "\n\n        Parameters\n        ----------\n        theSphere : Point\n        "
        setattr(owner, name, query)


class Point:
    """A point with position ``x, y`` (µm) and velocity (µm/s); the root of the sphere classes.

    Parameters
    ----------
    x, y : float

    Raises
    ------
    TypeError, ValueError
        If ``x`` or ``y`` is not a finite number.
    """

    x = ArrayField(0.0, geometry=True)
    y = ArrayField(0.0, geometry=True)
    xspeed = ArrayField(0.0)
    yspeed = ArrayField(0.0)

    def __init__(self, x, y):
        self.__dict__.update(_ens=None, _idx=-1)
        self.x, self.y, self.xspeed, self.yspeed = x, y, 0, 0

    def coordinates(self):
        """Return ``[x, y, 0]`` (µm); circles return their radius as the third entry."""
        return [self.x, self.y, 0]

    #: whether the sphere spins (ω enters its slip speed, φ its drift)
    _spins = False

    def boundary_conditions(self, boundary_x, boundary_y):
        """Wrap periodically into the cell ``boundary_x × boundary_y`` (µm).

        Parameters
        ----------
        boundary_x, boundary_y : float
        """
        self.x, self.y, _ = _wrapped(self.x, self.y, 0.0, boundary_x, boundary_y, 0.0, 0.0)

    def _image(self, dx, dy):
        """Pair vectors (µm) from raw differences, and the images' x velocities (µm/s; None here)."""
        return dx, dy, None

    def _pairs(self, spheres, normal=True, image=None):
        """The :class:`_Pairs` of this point with ``spheres`` (arrays over the partners)."""
        return _Pairs(self, spheres, normal, image)

    def d_euclidian(self, theSphere):
        """Return the distance (µm) to the point or sphere ``theSphere``, without periodic images.

        Parameters
        ----------
        theSphere : Point
        """
        return math.sqrt((theSphere.x - self.x) ** 2 + (theSphere.y - self.y) ** 2)

    relative_vector = _pair_query("Return ``[dx, dy]`` to ``theSphere`` (µm): the Lees-Edwards minimum image where "
                                  "used.", lambda p: [p.dx.item(), p.dy.item()])
    d = _pair_query("Return the distance to ``theSphere`` (µm), the length of :meth:`relative_vector`.",
                    lambda p: p.d.item())
    n = _pair_query("Return the unit vector towards ``theSphere``; where they coincide, a random one (the ensemble's "
                    "seed).", lambda p: [p.nx.item(), p.ny.item()], normal=True)
    relative_position = _pair_query("Return the vector ``n·d`` to ``theSphere`` (µm).",
                                    lambda p: [p.nx.item() * p.d.item(), p.ny.item() * p.d.item()], normal=True)
    relative_speed = _pair_query("Return the velocity of ``theSphere`` (its nearest image with Lees-Edwards) relative "
                                 "to this point (µm/s).", lambda p: p.velocity()[:, 0].tolist())

    def move(self, dt=1):
        """Drift: advance the position by velocity × ``dt`` (s), and φ by ω·``dt`` for a spinning sphere.

        Parameters
        ----------
        dt : float
        """
        pos = _one(self.x, self.y)[:, None]
        vel = _one(self.xspeed, self.yspeed, getattr(self, "omega", 0.0))[:, None]
        phi = _one(self.phi) if self._spins else None
        drift(pos, phi, vel, dt)
        if phi is not None:
            self.phi = phi.item()
        self.x, self.y = pos[:, 0].tolist()

    def _damp(self, f, flow):
        """:func:`~particleShear.engine.integrate.damp` of ``(xspeed, yspeed)`` relative to ``flow`` (None: none)."""
        vel = _one(self.xspeed, self.yspeed)[:, None]
        damp(vel, flow, f)
        self.xspeed, self.yspeed = vel[:, 0].tolist()

    def cool(self, f=0.8):
        """Damp: multiply the velocity by ``f`` (0 < f ≤ 1; 1 = no damping).

        Parameters
        ----------
        f : float
        """
        self._damp(f, None)


class PointLeesEdwards(Point):
    """Point in a Lees-Edwards cell; once in an ensemble, the cell parameters are the ensemble's.

    Parameters
    ----------
    x, y : float
        Position of the centre (µm).
    size_x, size_y : float
        Cell size Lx, Ly (µm).
    shear, shear_rate : float
        Strain γ (the image rows are offset by ``Ly·γ``) and rate γ̇ (1/s).
    use_lees_edwards : bool
        Lees-Edwards minimum images and wrapping (True) or a plain periodic cell (False).
    """

    size_x = EnsembleField(500)
    size_y = EnsembleField(500)
    shear = EnsembleField(0)
    shear_rate = EnsembleField(0)

    def __init__(self, x, y, size_x=500, size_y=500, shear=0, shear_rate=0, use_lees_edwards=True):
        Point.__init__(self, x, y)
        self.use_lees_edwards = use_lees_edwards
        self.size_x, self.size_y, self.shear, self.shear_rate = size_x, size_y, shear, shear_rate

    def boundary_conditions(self, boundary_x, boundary_y):
        """Store the cell size (µm), then wrap (Lees-Edwards with velocity correction, or plain).

        Parameters
        ----------
        boundary_x, boundary_y : float
        """
        self.size_x, self.size_y = boundary_x, boundary_y
        if self.use_lees_edwards:
            self.lee_edwards_boundary_conditions()
        else:
            Point.boundary_conditions(self, boundary_x, boundary_y)

    def _image(self, dx, dy):
        """:meth:`_le_image` if Lees-Edwards is used, else :meth:`Point._image`."""
        return self._le_image(dx, dy) if self.use_lees_edwards else (dx, dy, None)

    def _le_image(self, dx, dy):
        """:func:`~particleShear.engine.box.min_image` with shift ``Ly·γ``; image velocities ``−Ly·γ̇·k_y``."""
        Ly = self.size_y
        dx, dy, ky, _ = min_image(dx, dy, self.size_x, Ly, Ly * self.shear)
        return dx, dy, -(Ly * self.shear_rate) * ky

    def lee_edwards_closest_to_zero(self, x, y):
        """Return the minimum image ``[dx, dy]`` of the difference ``x, y`` in the sheared cell (µm).

        Crossing the y boundary shifts x by ``∓Ly·γ``; ``-Lx/2 ≤ dx < Lx/2``, ``-Ly/2 ≤ dy < Ly/2``.

        Parameters
        ----------
        x, y : float
        """
        dx, dy, _ = self._le_image(_one(x), _one(y))
        return [dx.item(), dy.item()]

    def lee_edwards_positive(self, x, y):
        """Return the position ``x, y`` mapped into ``[0, Lx) × [0, Ly)`` (µm), without velocity correction.

        Parameters
        ----------
        x, y : float
        """
        return _wrapped(x, y, 0.0, self.size_x, self.size_y, self.size_y * self.shear, 0.0)[:2]

    lee_edwards_relative_speed = _pair_query("Return the velocity of the nearest Lees-Edwards image of ``theSphere`` "
                                             "relative to this point (µm/s).",
                                             lambda p: p.velocity()[:, 0].tolist(), lees_edwards=True)

    def lee_edwards_boundary_conditions(self):
        """Wrap into the cell; crossing y changes x by ∓Ly·γ and vx by ∓Ly·γ̇ (``engine.box.wrap``)."""
        x, y, self.xspeed = _wrapped(self.x, self.y, self.xspeed, self.size_x, self.size_y,
                                     self.size_y * self.shear, self.shear_rate)
        self.x, self.y = x, y

    lee_edwards_relative_vector = _pair_query("Return the minimum-image vector ``[dx, dy]`` to ``theSphere`` (µm).",
                                              lambda p: [p.dx.item(), p.dy.item()], lees_edwards=True)

    def transmit_lees_edwards_parameters(self, theSphere):
        """Copy the cell size, strain, rate and Lees-Edwards flag to ``theSphere``.

        Parameters
        ----------
        theSphere : PointLeesEdwards
        """
        for name in ("size_x", "size_y", "shear", "shear_rate", "use_lees_edwards"):
            setattr(theSphere, name, getattr(self, name))

    def cool(self, f=0.8):
        """Damp the velocity relative to the affine flow ``γ̇ (y − Ly/2)`` by the factor ``f`` (SLLOD-like).

        Parameters
        ----------
        f : float
        """
        self._damp(f, flow_velocity(_one(self.y), self.size_y, self.shear_rate))

