"""Points and circles: the per-sphere API of layer 1 (spec §10.4).

A sphere object is a thin handle.  Before it is appended to an ensemble it
keeps its own values; once appended, its state attributes (``x``, ``xspeed``,
``omega``, ``xforce`` …) read and write the ensemble's arrays at its index and
its ``neighbors`` are views of the ensemble's pair table.  The scalar methods
here (``d``, ``elastic_force``, ``tangential_force`` …) are the documented API
for scripts and tests; the ensembles never call them in a step.
"""
import math
import random as _random

import numpy as np

from .laws import elastic_force_law
from .register import Force_register
from .relations import neighbor_relation

__all__ = ["Point", "PointLeesEdwards", "Circle", "CircleMass", "CircleMassNeighbors",
           "CircleBasicElasticity", "CircleFrictionElasticity", "ArrayField", "dotProduct2"]


def dotProduct2(a, b):
    """Dot product of two 2-vectors."""
    return a[0] * b[0] + a[1] * b[1]


class ArrayField:
    """Attribute stored locally before the sphere joins an ensemble, in the ensemble's array after."""

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
    """Lees-Edwards parameter: a per-sphere copy in the reference, the ensemble's value here once appended."""

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


def _le_closest(dx, dy, Lx, Ly, shear):
    """Scalar Lees-Edwards minimum image (§3.1), identical to the array kernel."""
    while dy >= Ly / 2:
        dy -= Ly
        dx -= Ly * shear
    while dy < -Ly / 2:
        dy += Ly
        dx += Ly * shear
    while dx >= Lx / 2:
        dx -= Lx
    while dx < -Lx / 2:
        dx += Lx
    return dx, dy


class Point:
    """A point with position (µm) and velocity (µm/s)."""

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
        return [self.x, self.y, 0]

    def boundary_conditions(self, boundary_x, boundary_y):
        """Plain periodic wrap into ``[0, boundary)``."""
        x, y = self.x, self.y
        while x >= boundary_x:
            x -= boundary_x
        while x < 0:
            x += boundary_x
        while y >= boundary_y:
            y -= boundary_y
        while y < 0:
            y += boundary_y
        self.x, self.y = x, y

    def d_euclidian(self, theSphere):
        return math.sqrt((theSphere.x - self.x) ** 2 + (theSphere.y - self.y) ** 2)

    def relative_vector(self, theSphere):
        return [theSphere.x - self.x, theSphere.y - self.y]

    def d(self, theSphere):
        v = self.relative_vector(theSphere)
        return math.sqrt(v[0] ** 2 + v[1] ** 2)

    def n(self, theSphere):
        """Unit vector towards the other point; a random direction when the two coincide (§2.1)."""
        v = self.relative_vector(theSphere)
        d = math.sqrt(v[0] ** 2 + v[1] ** 2)
        if d > 0:
            return [v[0] / d, v[1] / d]
        ens = self.__dict__.get("_ens")
        u = ens._rng.random() if ens is not None else _random.random()
        return [math.cos(2 * math.pi * u), math.sin(2 * math.pi * u)]

    def relative_position(self, theSphere):
        n = self.n(theSphere)
        d = self.d(theSphere)
        return [n[0] * d, n[1] * d]

    def move(self, dt=1):
        self.x = self.x + self.xspeed * dt
        self.y = self.y + self.yspeed * dt

    def cool(self, f=0.8):
        self.xspeed = self.xspeed * f
        self.yspeed = self.yspeed * f

    def relative_speed(self, theSphere):
        return [theSphere.xspeed - self.xspeed, theSphere.yspeed - self.yspeed]


class PointLeesEdwards(Point):
    """Point in a Lees-Edwards cell of ``size_x × size_y`` µm with strain ``shear`` and rate ``shear_rate``."""

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
        self.size_x = boundary_x
        self.size_y = boundary_y
        if self.use_lees_edwards:
            self.lee_edwards_boundary_conditions()
        else:
            Point.boundary_conditions(self, boundary_x, boundary_y)

    def lee_edwards_closest_to_zero(self, x, y):
        """Minimum image of a difference vector (§3.1)."""
        return list(_le_closest(x, y, self.size_x, self.size_y, self.shear))

    def lee_edwards_positive(self, x, y):
        """Map a position into the cell (§3.3), without velocity correction."""
        Lx, Ly, g = self.size_x, self.size_y, self.shear
        while y >= Ly:
            y -= Ly
            x -= Ly * g
        while y < 0:
            y += Ly
            x += Ly * g
        while x >= Lx:
            x -= Lx
        while x < 0:
            x += Lx
        return [x, y]

    def lee_edwards_relative_speed(self, theSphere):
        """Velocity of the nearest image of the other point relative to this one (§3.2)."""
        vx = theSphere.xspeed - self.xspeed
        vy = theSphere.yspeed - self.yspeed
        dy = theSphere.y - self.y
        Ly = self.size_y
        while dy >= Ly / 2:
            dy -= Ly
            vx -= Ly * self.shear_rate
        while dy < -Ly / 2:
            dy += Ly
            vx += Ly * self.shear_rate
        return [vx, vy]

    def relative_speed(self, theSphere):
        if self.use_lees_edwards:
            return self.lee_edwards_relative_speed(theSphere)
        return Point.relative_speed(self, theSphere)

    def lee_edwards_boundary_conditions(self):
        """Wrap into the cell; crossing y changes x by ∓Ly·γ and vx by ∓Ly·γ̇ (§3.3)."""
        y_old = self.y
        x, y = self.lee_edwards_positive(self.x, self.y)
        self.xspeed = self.xspeed + (y - y_old) * self.shear_rate
        self.x, self.y = x, y

    def lee_edwards_relative_vector(self, theSphere):
        return self.lee_edwards_closest_to_zero(theSphere.x - self.x, theSphere.y - self.y)

    def relative_vector(self, theSphere):
        if self.use_lees_edwards:
            return self.lee_edwards_relative_vector(theSphere)
        return Point.relative_vector(self, theSphere)

    def transmit_lees_edwards_parameters(self, theSphere):
        theSphere.size_x = self.size_x
        theSphere.size_y = self.size_y
        theSphere.shear = self.shear
        theSphere.shear_rate = self.shear_rate
        theSphere.use_lees_edwards = self.use_lees_edwards

    def cool(self, f=0.8):
        """Damp the velocity relative to the affine flow ``γ̇ (y − Ly/2)`` (§4.4)."""
        u = self.shear_rate * (self.y - self.size_y / 2)
        self.xspeed = u + (self.xspeed - u) * f
        self.yspeed = self.yspeed * f


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
    """Disc of radius ``diameter/2`` (µm); the cross-section of an infinite cylinder."""

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
        self.graphical_output_configuration = graphical_output_configuration

    def coordinates(self):
        return [self.x, self.y, self.r]

    # Drawing happens in the renderer of the ensemble (layer 4); these hooks keep the API.
    def initiate_drawing(self):
        pass

    def move(self, dt=1):
        PointLeesEdwards.move(self, dt)
        self.moveDrawing(dt)

    def moveDrawing(self, dt):
        pass

    def deleteDrawing(self):
        pass

    def tangential_vector(self, theSphere):
        n = self.n(theSphere)
        return [-n[1], n[0]]

    def tangential_speed(self, theSphere):
        """Relative translational speed along ``t_ij`` (no spin part)."""
        return dotProduct2(self.relative_speed(theSphere), self.tangential_vector(theSphere))


class CircleMass(Circle):
    """Disc with mass ``m`` (mg per m depth) and a force accumulator (mg·µm·s⁻² per m)."""

    m = ArrayField(1.0, positive=True, param=True)
    xforce = ArrayField(0.0)
    yforce = ArrayField(0.0)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        Circle.__init__(self, color, x, y, diameter, theCanvas, doDrawing, use_lees_edwards)
        _check_positive("m", m)
        self.m = m
        # a register of its own unless one is given (the reference shares one mutable default, §12 #36)
        self.force_register = Force_register() if force_register is None else force_register
        self.xforce = 0
        self.yforce = 0

    def record_total_particle_force(self):
        self.force_register.record_total_particle_force(self, [self.xforce, self.yforce])

    def do_linear_acceleration(self, dt):
        """Register the total force, kick the velocity, reset the force."""
        self.record_total_particle_force()
        self.xspeed = self.xspeed + self.xforce * dt / self.m
        self.yspeed = self.yspeed + self.yforce * dt / self.m
        self.xforce = 0
        self.yforce = 0

    def applyInternalForceAndRegister(self, force_vector, source, register_homolog=False):
        self.xforce = self.xforce + force_vector[0]
        self.yforce = self.yforce + force_vector[1]
        self.force_register.record_individual_internal_force(self, source, force_vector)
        if register_homolog:
            source.force_register.record_individual_internal_force(
                source, self, [-force_vector[0], -force_vector[1]])


class CircleMassNeighbors(CircleMass):
    """Disc with a neighbour list of relation objects (views of the ensemble's pair table)."""

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
        self.graphical_output_configuration = graphical_output_configuration

    def deleteNeighborDrawing(self):
        pass

    def contactLineColor(self, interface_type):
        cfg = self.graphical_output_configuration
        if interface_type == "stick":
            return cfg.color_interface_locked
        return cfg.color_interface_slip

    def initiateNeighborDrawing(self):
        pass

    def moveDrawing(self, dt):
        pass

    def deleteDrawing(self):
        pass

    def _relation(self, theSphere):
        k = self.findNeighborIndex(theSphere)
        return None if k < 0 else self.neighbors[k]

    def findNeighborIndex(self, theSphere):
        """Index of the relation pointing at ``theSphere`` in ``neighbors``, −1 if none."""
        found = -1
        for k, rel in enumerate(self.neighbors):
            if rel.theSphere is theSphere:
                found = k
        return found

    def _new_relation(self, theSphere):
        return neighbor_relation(0, "stick", theSphere)

    def test_neighbor_relation(self, theSphere):
        """Create or delete the relation to ``theSphere`` from the current overlap (§4.2)."""
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
    """Disc with central elastic and viscous contact forces (§2.3-2.4)."""

    call_back_elastic_force_law = elastic_force_law
    central_repulsion_coefficient = ArrayField(0.0, param=True)

    def __init__(self, color, x, y, diameter, m=1, theCanvas=False, doDrawing=False,
                 force_register=None, use_lees_edwards=False):
        CircleMassNeighbors.__init__(self, color, x, y, diameter, m, theCanvas, doDrawing,
                                     force_register, use_lees_edwards)
        self.central_repulsion_coefficient = 0

    def get_elastic_force(self, theSphere, k=1):
        """Scalar central elastic force of the active law (negative = repulsion)."""
        return CircleBasicElasticity.call_back_elastic_force_law(
            self.d(theSphere), self.r + theSphere.r, k, self.central_repulsion_coefficient)

    def _apply_along_n(self, theSphere, f):
        n = self.n(theSphere)
        vec = [f * n[0], f * n[1]]
        self.applyInternalForceAndRegister(vec, theSphere)
        return vec

    def elastic_force(self, theSphere, k):
        if self.d(theSphere) < self.r + theSphere.r:
            return self._apply_along_n(theSphere, self.get_elastic_force(theSphere, k))
        return [0, 0]

    def elastic_force_from_neighbors(self, k):
        for rel in list(self.neighbors):
            self.elastic_force(rel.theSphere, k)

    def get_central_viscous_force(self, theSphere, nu):
        return nu * dotProduct2(self.relative_speed(theSphere), self.n(theSphere))

    def central_viscous_force(self, theSphere, nu):
        return self._apply_along_n(theSphere, self.get_central_viscous_force(theSphere, nu))

    def central_viscous_force_from_neighbors(self, nu):
        for rel in list(self.neighbors):
            self.central_viscous_force(rel.theSphere, nu)


class CircleFrictionElasticity(CircleBasicElasticity):
    """Disc with spin and tangential (frictional) contact forces (§2.6-2.8)."""

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
        PointLeesEdwards.cool(self, f) if self.use_lees_edwards else Point.cool(self, f)
        w_loc = self.shear_rate * (self.y - self.size_y / 2) * shear_rate_to_rotation_rate_coefficient
        self.omega = w_loc + f * (self.omega - w_loc)

    def tangential_speed(self, theSphere):
        """Slip velocity of the other surface along ``t_ij`` at the contact point (§2.2)."""
        return (dotProduct2(self.relative_speed(theSphere), self.tangential_vector(theSphere))
                - (self.r * self.omega + theSphere.r * theSphere.omega))

    def tangential_force_viscous(self, theSphere, nu):
        if self.d(theSphere) < self.r + theSphere.r:
            return nu * self.tangential_speed(theSphere)
        return 0

    def tangential_force_elastic(self, theSphere, k_t):
        rel = self._relation(theSphere)
        if rel is not None and self.d(theSphere) < self.r + theSphere.r:
            return k_t * rel.friction_position
        return 0

    def distribute_tangential_couple(self, theSphere, force):
        """Apply ``force`` along ``t_ij`` on self and the opposite on the partner, torques split by radii (eq. S1-3)."""
        t = self.tangential_vector(theSphere)
        d = self.d(theSphere)
        vec = [force * t[0], force * t[1]]
        self.applyInternalForceAndRegister(vec, theSphere)
        theSphere.applyInternalForceAndRegister([-vec[0], -vec[1]], self)
        ti = d * force * self.r / (self.r + theSphere.r)
        tj = d * force * theSphere.r / (self.r + theSphere.r)
        self.torque = self.torque + ti
        theSphere.torque = theSphere.torque + tj
        reg = self.force_register
        if hasattr(reg, "record_individual_internal_torque"):
            reg.record_individual_internal_torque(self, theSphere, ti)
        reg = theSphere.force_register
        if hasattr(reg, "record_individual_internal_torque"):
            reg.record_individual_internal_torque(theSphere, self, tj)

    def _coulomb_limited(self, theSphere, rel, f_t, mu, k):
        f_c = abs(mu * CircleBasicElasticity.call_back_elastic_force_law(
            self.d(theSphere), self.r + theSphere.r, k, self.central_repulsion_coefficient))
        back = theSphere._relation(self) if hasattr(theSphere, "_relation") else None
        if abs(f_t) <= f_c:
            state = "stick"
        else:
            state = "slip"
            rel.friction_position = 0
            if back is not None:
                back.friction_position = 0
        rel.interface_type = state
        if back is not None:
            back.interface_type = state
        return math.copysign(min(abs(f_t), f_c), f_t) if f_t != 0 else 0.0

    def tangential_force(self, theSphere, nu, mu, k, k_t):
        """One visit of the tangential routine for a transient contact (§2.6)."""
        rel = self._relation(theSphere)
        if rel is None or self.d(theSphere) >= self.r + theSphere.r:
            return 0
        f_t = self.tangential_force_viscous(theSphere, nu) + self.tangential_force_elastic(theSphere, k_t)
        f = self._coulomb_limited(theSphere, rel, f_t, mu, k)
        self.distribute_tangential_couple(theSphere, f / 2)
        return f

    def tangential_force_from_neighbors(self, nu, mu, k, k_t):
        for rel in list(self.neighbors):
            self.tangential_force(rel.theSphere, nu, mu, k, k_t)

    def do_rotational_acceleration(self, dt):
        reg = self.force_register
        if hasattr(reg, "record_unbalanced_moment"):
            reg.record_unbalanced_moment(self, self.torque)
        self.omega = self.omega + self.torque * dt / self.inertia
        self.torque = 0

    def move(self, dt=1):
        """Advance φ, integrate ξ of stick/permanent relations, then drift (§2.10)."""
        self.phi = self.phi + self.omega * dt
        for rel in self.neighbors:
            if rel.interface_type in ("stick", "permanent"):
                rel.friction_position = rel.friction_position + self.tangential_speed(rel.theSphere) * dt
        Circle.move(self, dt)
