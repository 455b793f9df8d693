"""Canvases: the ensemble state arrays and the vectorised step (see docs/design.md).

Each class of the documented chain adds one capability:

=========================================  ==============================================
``CanvasPoints``                           state arrays, ``sphereList``, bookkeeping
``CanvasPointsMass``                       kick, damping, force register, momenta
``CanvasPointsNeighbors``                  pair table and the O(N) neighbour update
``CanvasPointsShear``                      Lees-Edwards offset, plates, shear rate
``CanvasPointsBasicElasticity``            central elastic + viscous pair term
``CanvasPointsBasicElasticityLeesEdwards`` rate changes, boundary-aware registration
``CanvasPointsFrictionElasticityLeesEdwards``  tangential term, torques, ξ history
=========================================  ==============================================

A step never loops over spheres or pairs in Python.  Forces of one force phase
are collected per active pair and applied with one ``bincount`` per component
(`_flush_pair_forces`), which also fills the force register.
"""
__docformat__ = "numpy"

import math

import numpy as np

from .fields import FIELDS, MASS_ROWS, ROW
from .graphics import Graphical_output_configuration
from .kernels import le_wrap, min_image, pair_geometry
from .namespace import (bincount as _bincount, concatenate as _concat, copyto as _copyto,
                        count_nonzero as _nz, where as _where)
from . import laws
from .laws import call_law_vectorised
from ..engine.integrate import damp, half_kick, kick, plates_follow, xi_increments
from ..engine.terms import (elastic_term, normal_speed, pair_forces, relative_velocity, slip_speed, tangential_term,
                            term_constants, viscous_term)
from ..engine.neighbours import verlet_bound
from .memo import Memo
from .memory import tune_allocator
from .neighbours import PERMANENT, SLIP, STICK, PairTable, candidate_pairs
from .points import CircleBasicElasticity, _check_finite, _check_positive
from .register import Force_register, PairBlock, SphereSelection
from .relations import _BaseRelationView
from .stability import StabilityGuard


__all__ = ["CanvasPoints", "CanvasPointsMass", "CanvasPointsNeighbors", "CanvasPointsShear",
           "CanvasPointsBasicElasticity", "CanvasPointsBasicElasticityLeesEdwards",
           "CanvasPointsFrictionElasticityLeesEdwards", "SphereList", "check_non_negative", "check_time_step"]

_PARAMS = ("central_repulsion_coefficient", "permanent_ratio_central", "permanent_ratio_tangential",
           "keep_viscosity_coefficients_constant")


#: a sphere found farther than this many cell lengths outside the cell after a step has diverged
#: (or was placed there by mistake): no physical step moves a sphere across a thousand cells
MAX_CELLS_OUTSIDE = 1000


def check_time_step(dt, step=None):
    """Raise ValueError unless the time step ``dt`` (s) is a finite real number > 0.

    A zero, negative, infinite or NaN step would freeze, reverse or destroy the state
    (NaN or infinite positions) without any error; refusing it costs one comparison.

    Parameters
    ----------
    dt : float
        Time step (s).
    step : int or None
        Current step, named in the message when given.

    Raises
    ------
    ValueError
        If ``dt`` is not a finite number > 0 (a bool is refused too).
    """
    if isinstance(dt, bool) or not 0.0 < dt < math.inf:
        where = "" if step is None else f" at step {step}"
        raise ValueError(f"dt={dt!r} is out of range{where}: allowed a finite time step > 0 (s)")


def check_non_negative(name, value):
    """Raise ValueError unless ``value`` is a finite number ≥ 0.

    Parameters
    ----------
    name : str
        Parameter name used in the message.
    value : float
        The value to check.

    Raises
    ------
    TypeError
        If ``value`` is not a real number.
    ValueError
        If ``value`` is not finite or is negative.
    """
    _check_finite(name, value)
    if value < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")


class NonNegative:
    """Ensemble constant that must stay a finite number ≥ 0 (k, nu, k_t, nu_t, mu).

    Only assignment is intercepted (and validated); the value lives in the instance
    ``__dict__`` under its own name, so reading it is a plain attribute lookup
    (a descriptor without ``__get__`` yields to the instance dictionary).
    """

    def __set_name__(self, owner, name):
        self.name = name

    def __set__(self, obj, value):
        check_non_negative(self.name, value)
        obj.__dict__[self.name] = value


class SphereList(list):
    """The ensemble's spheres in index order; ``append`` moves a sphere's state into the arrays.

    Spheres can only be added: removing, replacing or reordering raises ``TypeError``.

    Parameters
    ----------
    canvas : CanvasPoints
        The ensemble that owns the list.
    """

    def __init__(self, canvas):
        list.__init__(self)
        self._canvas = canvas

    def append(self, sphere):
        """Add a sphere: its state moves into the ensemble's arrays and its relations into the pair table.

        Parameters
        ----------
        sphere : object
            A sphere (e.g. :class:`~particleShear.base.points.CircleFrictionElasticity`) not yet in an ensemble.

        Raises
        ------
        ValueError
            If the sphere is already in an ensemble, or its position, radius or mass is invalid.
        """
        self._canvas._attach(sphere)
        list.append(self, sphere)

    def extend(self, spheres):
        """Append every sphere of ``spheres`` in order (see :meth:`append`).

        Parameters
        ----------
        spheres : iterable
            The spheres.
        """
        for s in spheres:
            self.append(s)

    def __iadd__(self, spheres):
        self.extend(spheres)
        return self

    def _forbidden(self, *args, **kwargs):
        """Refused: spheres cannot be removed, replaced or reordered once in an ensemble.

        Parameters
        ----------
        *args
            Ignored.
        **kwargs
            Ignored.

        Raises
        ------
        TypeError
            Always: spheres cannot be removed, replaced or reordered once in an ensemble.
        """
        raise TypeError("spheres cannot be removed, replaced or reordered once in an ensemble")

    insert = remove = pop = clear = sort = reverse = __setitem__ = __delitem__ = _forbidden


_SLIP8 = np.int8(SLIP)   # compared with the int8 state array without a scalar conversion


# ufunc reductions without the Python wrappers of ndarray.max/min (hot path)
_max_reduce = np.maximum.reduce
_min_reduce = np.minimum.reduce
_MASS_ROWS = np.array(MASS_ROWS)
#: built-in central laws, which are exactly 0 for d ≥ r_i + r_j (no masking of inactive candidates needed)
_ZERO_BEYOND_CONTACT = (laws.elastic_force_law, laws.elastic_force_law_plateau)


class _Structure:
    """Arrays over the pairs of the step that stay valid while the candidates, bonds and images do (and, for
    a compacted table, the set of relations); kept in the canvas's memo under ``key``."""
    __slots__ = ("key", "safe_images", "sel", "sel2", "ai", "aj", "d0", "ri", "rj", "w2", "idx6",
                 "ky", "kyf", "kx", "any_y", "perm", "trans", "deq", "perm_code", "shifted", "view")


class _Geometry:
    """Per-step arrays over the active pairs (positions at the start of the step).

    The per-structure arrays (``ai``, ``aj``, ``d0``, ``perm``, ``trans``, ``ri``, ``rj``) are copied in
    from the structure's ``view`` dictionary and the flags ``internal``, ``ext_i``, ``ext_j`` from the memo;
    what the force terms compute on first use starts as the class default None."""
    fn_i = fn_j = ft = vn = vt = fel = rv = None
    parts = None       # [(term, f_i, f_j)] of the central terms, for the register's per-visit lists
    ft_visits = None   # (2, P) scalar forces of the two tangential visits (0.0: all slipped at μ = 0)
    all_slip = False   # set when the μ = 0 tangential path made every relation slip (no ξ to integrate)

    # components of the pair vector and normal, for inspection (the kernels use the (2, P) arrays)
    dx = property(lambda self: self.D[0])
    dy = property(lambda self: self.D[1])
    nx = property(lambda self: self.n[0])
    ny = property(lambda self: self.n[1])


class CanvasPoints:
    """Cell of ``size_x × size_y`` µm holding spheres in structure-of-arrays form.

    Random choices use the generator set by :meth:`set_random_generator` (seeded by the run).

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    use_lees_edwards = False

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False):
        _check_positive("size_x", size_x)
        _check_positive("size_y", size_y)
        tune_allocator()
        self.theCanvas = theCanvas
        self.size_x = size_x
        self.size_y = size_y
        self.doDrawing = doDrawing
        self._cap = 0
        self._n = 0
        self._set_capacity(0)
        self._sphereList = SphereList(self)
        self._m_given = []   # masses as given to the spheres (an int stays int) for the evaluation handler
        self._rng = np.random.default_rng()
        self._renderer = None
        self._memo = Memo()   # every value kept between calls (docs/design.md, "The documented classes")
        self._pos_version = 0
        self._params_version = 0
        self._in_cell = False
        self._images_valid = False
        self.graphical_output_configuration = Graphical_output_configuration()

    # -- sphere list and state arrays ----------------------------------------------------------
    @property
    def sphereList(self):
        """The spheres in index order (a :class:`SphereList`); assignable only while the ensemble is empty."""
        return self._sphereList

    @sphereList.setter
    def sphereList(self, spheres):
        """The spheres in index order (a :class:`SphereList`); assignable only while the ensemble is empty."""
        if len(self._sphereList):
            raise TypeError("sphereList can only be assigned while the ensemble is empty")
        for s in spheres:
            self._sphereList.append(s)

    def set_random_generator(self, rng):
        """Use ``rng`` (a ``numpy.random.Generator``) for every random choice of this ensemble.

        Parameters
        ----------
        rng : numpy.random.Generator
            The generator (e.g. ``numpy.random.default_rng(seed)``).
        """
        self._rng = rng

    def _set_capacity(self, cap):
        """(Re)allocate the state block: one row per field of FIELDS, one column per sphere slot."""
        block = np.zeros((len(FIELDS), cap))
        old = getattr(self, "_block", None)
        if old is not None:
            block[:, :self._n] = old[:, :self._n]
        self._block = block
        self._cap = cap
        self._views()

    def _views(self):
        """Per-field views ``_a[name]`` and the grouped rows the kernels gather in one call:
        ``_pos`` (x, y), ``_coord`` (x, y, phi), ``_vel`` (xspeed, yspeed, omega), ``_frc`` (xforce,
        yforce, torque)."""
        st = self._block[:, :self._n]
        self._st = st
        self._a = {name: st[k] for k, name in enumerate(FIELDS)}
        x, vx, fx = ROW["x"], ROW["xspeed"], ROW["xforce"]
        self._pos = st[x:x + 2]
        self._coord = st[x:x + 3]   # x, y, phi: advanced by (xspeed, yspeed, omega)·dt in one pass
        self._vel = st[vx:vx + 3]
        self._frc = st[fx:fx + 3]

    def _attach(self, sphere):
        if sphere.__dict__.get("_ens") is not None:
            raise ValueError("sphere is already in an ensemble; a sphere can be appended to one ensemble only")
        for name in ("x", "y", "xspeed", "yspeed"):
            _check_finite(name, getattr(sphere, name))
        _check_positive("r", getattr(sphere, "r", 1.0))
        _check_positive("m", getattr(sphere, "m", 1.0))
        n = self._n
        if n == self._cap:
            self._set_capacity(max(16, 2 * self._cap))
        cls = type(sphere)
        self._m_given.append(getattr(sphere, "m", 1.0))
        col = self._block[:, n]
        for name, default in FIELDS.items():
            col[ROW[name]] = float(getattr(sphere, name) if hasattr(cls, name) else default)
        self._n = n + 1
        self._views()
        d = sphere.__dict__
        d["_ens"] = self
        d["_idx"] = n
        for name in FIELDS:
            d.pop("_v_" + name, None)
        self._params_changed()
        self._spheres_changed()
        self._adopt_relations(sphere)

    def _adopt_relations(self, sphere):
        """Move relations made before appending (e.g. links) into the pair table.

        A relation is adopted once both of its spheres are in this ensemble; the
        partner's own relation back supplies the second history.
        """
        own = sphere.__dict__.get("_own_neighbors")
        if not own or not hasattr(self, "_pairs"):
            return
        from .neighbours import STATE_CODES
        p = sphere.__dict__["_idx"]
        pending = []
        for rel in own:
            partner = rel.theSphere
            if partner.__dict__.get("_ens") is not self:
                pending.append(rel)  # adopted when the partner joins
                continue
            q = partner.__dict__["_idx"]
            pt = self._pairs
            slot = int(pt.ensure(p, q)[0])
            if not pt.active[slot]:
                pt.active[slot] = True
                pt.birth[slot] = pt.next_births(1)[0]
            pt.state[slot] = STATE_CODES[rel.interface_type]
            pt.d_eq[slot] = getattr(rel, "equilibrium_distance", 0)
            (pt.xi_ij if p < q else pt.xi_ji)[slot] = rel.friction_position
            back = [b for b in partner.__dict__.get("_own_neighbors", []) if b.theSphere is sphere]
            if back:
                (pt.xi_ji if p < q else pt.xi_ij)[slot] = back[-1].friction_position
        sphere.__dict__["_own_neighbors"] = pending
        self._links_changed()

    def _spheres_changed(self):
        self._invalidate_neighbours()

    def _invalidate_neighbours(self):
        self._pos_version += 1
        self._in_cell = False

    def _params_changed(self):
        self._params_version += 1

    def _param(self, name):
        """Scalar value of a per-sphere parameter if all spheres share it, else None."""
        arr = self._a[name]
        return float(arr[0]) if len(arr) and (arr == arr[0]).all() else None

    # -- bookkeeping ----------------------------------------------------------------------------
    def set_graphical_output_configuration(self, graphical_output_configuration):
        """Share one drawing configuration with every sphere.

        Parameters
        ----------
        graphical_output_configuration : Graphical_output_configuration
            The drawing options.
        """
        self.graphical_output_configuration = graphical_output_configuration
        for s in self.sphereList:
            s.set_graphical_output_configuration(graphical_output_configuration)

    def initiateGraphics(self):
        """Draw the ensemble in its live window, if a renderer is attached (else nothing)."""
        if self._renderer is not None:
            self._renderer.draw(self)

    def correct_linear_drift(self):
        """Subtract the unweighted mean velocity from all spheres."""
        a = self._a
        if self._n:
            a["xspeed"] -= a["xspeed"].sum() / self._n
            a["yspeed"] -= a["yspeed"].sum() / self._n

    def particle_info(self):
        """Short description of the ensemble for the output header.

        Returns
        -------
        str
            The description.
        """
        return "Points in a periodic cell"

    def canMove(self, theSphere):
        """Whether the sphere is mobile (always True here; plates are added by :class:`CanvasPointsShear`).

        Parameters
        ----------
        theSphere : object
            A sphere of this ensemble.

        Returns
        -------
        bool
            True.
        """
        return True

    def _mobile_mask(self):
        """Boolean mask of mobile spheres, or None when every sphere is mobile."""
        return self._mobile()[0]

    def _mobile(self):
        """(mask of the mobile spheres, its bytes): (None, None) when every sphere is mobile."""
        return None, None

    def movableSphereList(self):
        """The mobile spheres, in index order, as a list (a :class:`SphereSelection`: new on each call,
        and recognised by the stress evaluation, which then sums over the ensemble's arrays)."""
        sel = self._mobile_selection()
        return SphereSelection(self, sel.mask, sel)

    def _mobile_selection(self):
        """The selection of the mobile spheres the stress evaluation is given (kept while the same spheres are
        mobile: building the list of spheres costs ≈ 10 % of a step at N = 10,000)."""
        mob, mob_bytes = self._mobile()
        return self._memo.get("selection", (self._n, mob_bytes), lambda: SphereSelection(self, mob))

    def do_linear_acceleration(self, dt):
        """Kick mobile spheres ``v += F·dt/m`` and reset their force.

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0.
        """
        a = self._a
        mob = self._mobile_mask()
        fx, fy, m = a["xforce"], a["yforce"], a["m"]
        if mob is None:
            a["xspeed"] += fx * dt / m
            a["yspeed"] += fy * dt / m
            fx[:] = 0.0
            fy[:] = 0.0
        else:
            a["xspeed"][mob] += fx[mob] * dt / m[mob]
            a["yspeed"][mob] += fy[mob] * dt / m[mob]
            fx[mob] = 0.0
            fy[mob] = 0.0

    def _cool_spin(self, f):
        pass

    def cool(self, f=0.8):
        """Damp the velocity relative to the affine flow ``γ̇ (y − Ly/2)`` of all spheres (SLLOD-like; docs/design.md).

        Parameters
        ----------
        f : float
            Factor applied to the peculiar velocity (0 < f ≤ 1; 1 = no damping).
        """
        rate = getattr(self, "shear_rate", 0)
        damp(self._vel[:2], self._affine_vx(rate) if rate else None, f)
        self._cool_spin(f)

    def _drift(self, dt):
        a = self._a
        a["x"] += a["xspeed"] * dt
        a["y"] += a["yspeed"] * dt
        self._pos_version += 1

    def move(self, dt=1):
        """Drift: advance every position by velocity × ``dt``.

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        self._drift(dt)

    def _le_shift(self):
        return 0.0

    def _y_centred(self):
        """``y − Ly/2`` of every sphere (µm): the affine flow, the damping, the shear-rate change, the
        drift bookkeeping and the shear stress need it."""
        return self._pos[1] - self.size_y / 2

    def _affine_vx(self, rate):
        """Velocity ``γ̇ (y − Ly/2)`` of the shear flow at every sphere (µm/s)."""
        return self._y_centred() * rate

    def boundary_conditions(self):
        """Wrap every sphere into the cell (Lees-Edwards shifted where active; docs/design.md).

        Raises
        ------
        SimulationInstabilityError
            If a position is not finite or lies more than :data:`MAX_CELLS_OUTSIDE` cell lengths outside.
        """
        a = self._a
        if self._n:
            pos = self._pos
            Lx, Ly = self.size_x, self.size_y
            if _min_reduce(pos, axis=None) < 0:
                inside = False
            elif Lx == Ly:
                inside = _max_reduce(pos, axis=None) < Lx
            else:
                hi = _max_reduce(pos, axis=1)
                inside = hi[0] < Lx and hi[1] < Ly
        else:
            inside = True
        if not inside:
            self._check_positions()
        if not inside and le_wrap(a["x"], a["y"], a["xspeed"], self.size_x, self.size_y, self._le_shift(),
                                  getattr(self, "shear_rate", 0) if self.use_lees_edwards else 0.0):
            self._images_valid = False
        self._pos_version += 1
        self._in_cell = True

    def _check_positions(self):
        """Raise :class:`SimulationInstabilityError` for a non-finite position or one more than
        :data:`MAX_CELLS_OUTSIDE` cell lengths outside the cell (step, sphere and value in the message)."""
        x, y = self._pos[0], self._pos[1]
        Lx, Ly = self.size_x, self.size_y
        far = MAX_CELLS_OUTSIDE * min(Lx, Ly)
        if _min_reduce(self._pos, axis=None) >= -far and _max_reduce(self._pos, axis=None) < max(Lx, Ly) + far:
            return  # two reductions (False for NaN) clear the ordinary case
        with np.errstate(invalid="ignore"):
            bad = ~((np.abs(x - Lx / 2) <= (MAX_CELLS_OUTSIDE + 0.5) * Lx)
                    & (np.abs(y - Ly / 2) <= (MAX_CELLS_OUTSIDE + 0.5) * Ly))
        if not _nz(bad):
            return
        k = int(np.flatnonzero(bad)[0])
        step = getattr(self, "step_count", None)
        phase = getattr(self, "phase", "")
        what = ("is not finite" if not (math.isfinite(x[k]) and math.isfinite(y[k]))
                else f"is more than {MAX_CELLS_OUTSIDE} cell lengths outside the {Lx:g} x {Ly:g} µm cell")
        a = self._a
        reason = (f"position (x, y) = ({float(x[k])!r}, {float(y[k])!r}) µm of sphere {k} {what} (velocity "
                  f"({float(a['xspeed'][k])!r}, {float(a['yspeed'][k])!r}) µm/s): a diverging step or a sphere "
                  "placed outside the cell")
        guard = getattr(self, "stability_guard", None) or StabilityGuard()
        guard._fail(self, step, phase, getattr(self, "_last_dt", None), reason, pair=(k,))

    def regular_sphere_distribution(self, rand_fraction=0.5):
        """Place the spheres on a square grid with random jitter of ``rand_fraction`` of a spacing.

        Parameters
        ----------
        rand_fraction : float
            Jitter amplitude as a fraction of the grid spacing (0 = exact grid).
        """
        n = self._n
        if n == 0:
            return
        cols = int(math.ceil(math.sqrt(n * self.size_x / self.size_y)))
        rows = int(math.ceil(n / cols))
        sx, sy = self.size_x / cols, self.size_y / rows
        k = np.arange(n)
        jitter = (self._rng.random((2, n)) - 0.5) * rand_fraction
        a = self._a
        a["x"][:] = ((k % cols) + 0.5 + jitter[0] * 1.0) * sx % self.size_x
        a["y"][:] = ((k // cols) + 0.5 + jitter[1] * 1.0) * sy % self.size_y
        self._invalidate_neighbours()


class CanvasPointsMass(CanvasPoints):
    """Adds the clock ``t`` (s), the force register and momentum bookkeeping.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPoints.__init__(self, size_x, size_y, theCanvas, doDrawing)
        self.t = 0
        self.force_register = Force_register()
        self.m = m

    def reset_force_register(self):
        """Clear the force register (start of a force phase)."""
        self.force_register.reset_force_register()

    # Registration filters (boundary-crossing forces are external) for scripts that apply forces sphere by sphere.
    def _source_is_external(self, target, source):
        return False

    def record_individual_internal_force(self, target, source, force_vector):
        """Record a pair force sphere by sphere: dropped for an immobile target, external when the source is
        immobile or acts through the periodic boundary, internal otherwise.

        Parameters
        ----------
        target : object
            The sphere the force acts on.
        source : object
            The sphere exerting it.
        force_vector : sequence of float
            ``(F_x, F_y)`` (mg·µm·s⁻² per m depth).
        """
        if not self.canMove(target):
            return
        if not self.canMove(source) or self._source_is_external(target, source):
            self.force_register.record_external_force(target, force_vector)
        else:
            self.force_register.record_individual_internal_force(target, source, force_vector)

    def record_individual_internal_torque(self, target, source, moment):
        """Record a pair torque with the same filters as :meth:`record_individual_internal_force`.

        Parameters
        ----------
        target : object
            The sphere the torque acts on.
        source : object
            The sphere exerting it.
        moment : float
            Torque (mg·µm²·s⁻² per m depth).
        """
        if not self.canMove(target):
            return
        if not self.canMove(source) or self._source_is_external(target, source):
            self.force_register.record_external_torque(target, moment)
        else:
            self.force_register.record_individual_internal_torque(target, source, moment)

    def record_total_particle_force(self, target, force_vector):
        """Record the total force of a mobile sphere (dropped for an immobile one).

        Parameters
        ----------
        target : object
            The sphere the force acts on.
        force_vector : sequence of float
            ``(F_x, F_y)`` (mg·µm·s⁻² per m depth).
        """
        if self.canMove(target):
            self.force_register.record_total_particle_force(target, force_vector)

    def record_external_force(self, target, force_vector):
        """Record an external force on a mobile sphere (dropped for an immobile one).

        Parameters
        ----------
        target : object
            The sphere the force acts on.
        force_vector : sequence of float
            ``(F_x, F_y)`` (mg·µm·s⁻² per m depth).
        """
        if self.canMove(target):
            self.force_register.record_external_force(target, force_vector)

    def record_external_torque(self, target, moment):
        """Record an external torque on a mobile sphere (dropped for an immobile one).

        Parameters
        ----------
        target : object
            The sphere the torque acts on.
        moment : float
            Torque (mg·µm²·s⁻² per m depth).
        """
        if self.canMove(target):
            self.force_register.record_external_torque(target, moment)

    def record_unbalanced_moment(self, target, moment):
        """Record the net torque of a mobile sphere (dropped for an immobile one).

        Parameters
        ----------
        target : object
            The sphere the torque acts on.
        moment : float
            Torque (mg·µm²·s⁻² per m depth).
        """
        if self.canMove(target):
            self.force_register.record_unbalanced_moment(target, moment)

    def _torque_total(self):
        return None

    def record_total_particle_forces(self):
        """Store the accumulated force of every mobile sphere (and torques, where spin exists)."""
        tot = self._frc.copy()
        self.force_register._set_totals(self, self._mobile_mask(), tot[0], tot[1],
                                        tot[2] if self._torque_total() is not None else None, tot)

    def particle_info(self):
        return "Spheres with mass"

    def evaluate_stress_tensors(self, StressTensorEvaluator):
        """Evaluate every tensor (eqs. S1-16 to S1-24) for the current register, mobile spheres and shear rate.

        Parameters
        ----------
        StressTensorEvaluator : StressTensorEvaluation
            The evaluator whose tensors are updated.

        Returns
        -------
        StressTensorEvaluation
            The same evaluator.
        """
        sel = self._mobile_selection()
        StressTensorEvaluator.evaluate_stress_tensors(self.force_register, sel, getattr(self, "shear_rate", 0))
        return StressTensorEvaluator

    def reset_force(self):
        """Set the force of every sphere to zero."""
        self._frc[:2] = 0.0

    # Momenta (raw coordinates, origin at the cell corner) — conserved in isolated scenes.
    def total_momentum(self):
        """Linear momentum ``Σ m v`` (mg·µm/s per m depth)."""
        a = self._a
        return np.array([a["m"] @ a["xspeed"], a["m"] @ a["yspeed"]])

    def total_angular_momentum(self):
        """``Σ m (x v_y − y v_x) + Σ I ω`` about the origin (mg·µm²/s per m depth)."""
        a = self._a
        return float(a["m"] @ (a["x"] * a["yspeed"] - a["y"] * a["xspeed"]) + a["inertia"] @ a["omega"])


class CanvasPointsNeighbors(CanvasPointsMass):
    """Adds the pair table and the neighbour update (relations = contacts ∪ permanent links).

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    #: extra search distance of the candidate list, in units of the largest radius
    neighbour_skin = 0.5
    #: candidate tables at least this long are compacted to the active pairs each time relations change;
    #: shorter ones run every term over all candidates (per-call overhead dominates there)
    compact_pairs_from = 20000

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsMass.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self._pairs = PairTable()
        self._nl_valid = False
        self._g = None
        self._relation_view_class = _BaseRelationView
        self._in_force_phase = False
        self._disp = np.zeros((2, 0))
        self._nl_strain = 0.0
        self._nl_abs_strain = 0.0
        self._links_version = 0
        self._relations_version = 0   # changes whenever the step's neighbour update changes the relations
        self._images_token = 0

    def _invalidate_neighbours(self):
        self._nl_valid = False
        self._pos_version += 1
        self._in_cell = False
        self._images_valid = False

    def _links_changed(self):
        self._pairs.n_permanent = int((self._pairs.state == PERMANENT).sum())
        self._links_version += 1

    def _spheres_changed(self):
        self._nl_valid = False
        self._in_cell = False
        self._pos_version += 1
        self._disp = np.zeros((2, self._n))

    def _drift(self, dt, spin=False):
        """Move every sphere by ``v·dt`` (and turn it by ``ω·dt`` with ``spin``) and accumulate its
        displacement relative to the affine flow.

        The Verlet criterion works with displacements *relative to the shear flow*
        ``γ̇ (y − Ly/2)``: under Lees-Edwards the flow carries neighbours along with
        each other, so only peculiar motion (plus the small affine stretch of a
        pair, bounded through the accumulated strain) can bring a far pair into contact.
        """
        rate = float(self._shear_rate_for_images())
        if rate:
            dg = rate * dt
            self._disp[0] -= self._y_centred() * dg
            self._nl_strain += dg
            self._nl_abs_strain += abs(dg)
        if spin:
            step = self._vel * dt
            self._coord += step
            self._disp += step[:2]
        else:
            step = self._vel[:2] * dt
            self._pos += step
            self._disp += step
        self._pos_version += 1

    def _skin(self):
        return self.neighbour_skin * float(self._a["r"].max()) if self._n else 0.0

    def _needs_rebuild(self):
        if not self._nl_valid:
            return True
        # how much a pair can have approached since the rebuild: the engine's bound of the peculiar
        # displacements U and the accumulated |strain| (engine.neighbours.verlet_bound), plus any strain
        # change not carried by the flow (e.g. γ set directly), which moves boundary images by Ly·Δγ
        d2 = self._disp * self._disp
        U = math.sqrt(float(_max_reduce(d2[0] + d2[1]))) if self._n else 0.0
        bound = verlet_bound(U, self._nl_abs_strain, self._nl_rmax)
        bound += abs(self._le_shift() - self._nl_shift - float(self.size_y) * self._nl_strain)
        return bound >= self._nl_skin or (self.size_x, self.size_y) != self._nl_box

    def _rebuild_candidates(self):
        a = self._a
        x = a["x"].copy()
        y = a["y"].copy()
        shift = self._le_shift()
        le_wrap(x, y, np.zeros(self._n), self.size_x, self.size_y, shift, 0.0)
        skin = self._skin()
        i, j = candidate_pairs(x, y, a["r"], self.size_x, self.size_y, shift, skin)
        self._pairs.replace(i, j)
        self._nl_valid = True
        self._nl_skin = skin
        self._nl_shift = shift
        self._nl_box = (self.size_x, self.size_y)
        self._nl_rmax = float(a["r"].max()) if self._n else 0.0
        self._nl_strain = 0.0
        self._nl_abs_strain = 0.0
        self._disp[:] = 0.0

    def _shear_rate_for_images(self):
        return 0.0

    def _store_images(self, ky, kx, n):
        """Keep the period counts of the candidates' minimum images while they stay valid.

        Valid until a sphere wraps, the candidates change or positions are set from
        outside; only for positions inside the cell, single periods, and cells much
        larger than the candidate reach (so the nearest image cannot change).
        """
        self._images_valid = False
        if not self._in_cell or not self._nl_valid:
            return
        reach = 2 * (2 * float(self._a["r"].max()) + 2 * self._nl_skin)
        if min(self.size_x, self.size_y) <= reach:
            return
        if ky is None:
            return
        # period counts as floats too: a float times a float array avoids a per-call cast
        self._images = (ky, ky.astype(float), kx, np.array((float(self.size_x) * kx, float(self.size_y) * ky)))
        self._images_any_y = bool(_nz(ky))
        self._images_version = self._pairs.version
        self._images_valid = True

    def test_neighbor_relation(self):
        """Neighbour update (docs/design.md): activate touching pairs, drop transient ones that separated.

        Also computes the geometry of the active pairs that every force term of
        this step uses.  What depends only on *which* pairs are active (indices,
        contact distances, bond flags, image periods, internal/external flags) is
        kept from the previous step while that set, the bonds and the images stay
        the same — most steps.
        """
        pt = self._pairs
        if self._needs_rebuild():
            self._rebuild_candidates()
        pos = self._pos
        C = len(pt.i)
        Lx, Ly = self.size_x, self.size_y
        r = self._a["r"]
        T = pos.take(_concat((pt.j, pt.i)), axis=1)
        D0 = T[:, :C] - T[:, C:]   # raw differences (x_j − x_i, y_j − y_i)
        cached_images = self._images_valid and self._images_version == pt.version
        dvx_rate = 0.0
        if cached_images:
            # no sphere wrapped since the images were found: reuse their period counts (minimum image,
            # one period at a time, so bit-identical to a fresh minimum image)
            ky, kyf, kx, LK = self._images
            D = D0   # fresh array; the raw differences are not needed again on this path
            if self._images_any_y:
                D[0] -= float(self._le_shift()) * kyf
                dvx_rate = float(self._shear_rate_for_images())
            D -= LK
            dvx = None
        else:
            dx, dy, dvx, ky, kx = min_image(D0[0], D0[1], Lx, Ly, self._le_shift(), self._shear_rate_for_images(),
                                            counts=True)
            D = np.array((dx, dy))
            self._store_images(ky, kx, C)
            self._images_token += 1
        DD = D * D
        d = np.sqrt(DD[0] + DD[1])
        d0 = r[pt.i] + r[pt.j]   # contact distances r_i + r_j
        touching = d < d0
        perm = pt.state == PERMANENT if pt.n_permanent else None
        new_active = touching if perm is None else (touching | perm)
        old = pt.active
        # most steps keep every relation: a byte comparison of the masks is cheaper than != and a count
        changed = new_active.tobytes() != old.tobytes()
        if changed:
            flip = new_active != old
            # relations born or ended: stick state, no history; the born ones get the next birth numbers
            pt.state[flip] = STICK
            _copyto(pt.xi, 0.0, where=flip)
            born = new_active & flip
            n_born = _nz(born)
            if n_born:
                pt.birth[born] = pt.next_births(n_born)
            pt.active = new_active
            self._relations_version += 1
        # Small tables (overhead-bound): every force term runs over all candidate pairs, inactive ones
        # getting exactly zero force (ξ = 0, law = 0 beyond contact, viscous terms masked), so nothing
        # is gathered per step.  Large tables (throughput-bound): the terms run over the active pairs only.
        compact = C >= self.compact_pairs_from
        # the pair structure depends on the candidates, the bonds, the image periods and, for a compacted
        # table, on the relations themselves
        key = (pt.version, self._links_version, self._images_token, compact,
               self._relations_version if compact else None)
        S = self._memo.get("pair_structure", key,
                           lambda: self._pair_structure(new_active if compact else None, d0, perm, ky, kx, D0, D, d,
                                                        cached_images, key))
        mob, mob_bytes = self._mobile()
        g = _Geometry()
        g.S = S
        g.__dict__.update(S.view)
        g.internal, g.ext_i, g.ext_j = self._memo.get("internal_flags", (key, mob_bytes),
                                                      lambda: self._internal_flags(S, mob))
        sel = S.sel
        if sel is None:
            g.slots = slice(None)
            g.active = new_active
            g.touching = touching
        else:
            g.slots = sel
            g.active = None            # every pair of the step is a relation
            D = D.take(sel, axis=1)
            d = d.take(sel)
            g.touching = touching.take(sel)
            if dvx is not None:
                dvx = dvx.take(sel)
        g.P = C = len(d)
        if _nz(d) != C:
            d, nx, ny = pair_geometry(D[0], D[1], self._rng)
            g.n = np.array((nx, ny))
        else:
            g.n = D / d
        g.t = t = np.empty((2, C))   # t_ij = (−n_y, n_x)
        np.negative(g.n[1], out=t[0])
        t[1] = g.n[0]
        g.D = D
        g.d = d
        if dvx is not None:
            g.dvx = dvx
        elif dvx_rate and S.any_y:
            g.dvx = -(float(Ly) * dvx_rate) * S.kyf
        else:
            g.dvx = None
        self._g = g
        return g

    @staticmethod
    def _internal_flags(S, mob):
        """(internal, ext_i, ext_j) of the pairs of structure ``S`` for mobility mask ``mob`` (docs/design.md):
        a pair is internal when both spheres are mobile and it does not act through the boundary; every other
        pair gives an external force to each of its mobile spheres."""
        shifted = S.shifted
        if mob is None:
            return ~shifted, shifted, shifted
        mi = mob.take(S.ai)
        mj = mob.take(S.aj)
        internal = mi & mj & ~shifted
        return internal, mi & ~internal, mj & ~internal

    def _pair_structure(self, active, d0, perm, ky, kx, D0, D, d, cached_images, key):
        """Per-pair data that change only when the candidates, bonds or images change — or, for a
        table compacted to its ``active`` pairs, when the set of relations changes (``key``, its memo key,
        is kept as ``S.key`` for the values derived from the structure)."""
        pt = self._pairs
        r = self._a["r"]
        n = self._n
        S = _Structure()
        S.key = key
        if active is None:
            S.sel = S.sel2 = None
            S.ai = pt.i
            S.aj = pt.j
        else:
            S.sel = sel = np.flatnonzero(active)
            S.sel2 = _concat((sel, sel + len(pt.i)))   # flat slots of (ξ_ij, ξ_ji) in the (2, C) table
            S.ai = pt.i.take(sel)
            S.aj = pt.j.take(sel)
            d0 = d0.take(sel)
            D0 = D0.take(sel, axis=1)
            D = D.take(sel, axis=1)
            d = d.take(sel)
            if ky is not None:
                ky = ky.take(sel)
                kx = kx.take(sel)
            if perm is not None:
                perm = perm.take(sel)
        S.d0 = d0
        S.ri = r.take(S.ai)
        S.rj = r.take(S.aj)
        S.w2 = np.array((S.ri, S.rj)) / S.d0   # torque lever fractions r_i/(r_i + r_j), r_j/(r_i + r_j) (S1-3)
        # flat bincount index of (x, y, torque) rows: one call accumulates every pair force on the spheres
        S.idx6 = _concat((S.ai, S.ai + n, S.aj, S.aj + n, S.ai + 2 * n, S.aj + 2 * n))
        S.ky = ky
        S.kyf = None if ky is None else ky.astype(float)
        S.kx = kx
        S.any_y = ky is not None and bool(_nz(ky))
        if perm is None or not _nz(perm):
            S.perm = S.trans = S.deq = S.perm_code = None
        else:
            S.perm = perm
            S.trans = ~perm
            S.deq = pt.d_eq.copy() if S.sel is None else pt.d_eq.take(S.sel)   # equilibrium distances of the bonds
            S.perm_code = perm.view(np.int8) * np.int8(PERMANENT)             # state code of a bond, 0 elsewhere
        # a pair interacts through the boundary iff its raw and minimum-image distances differ;
        # with cached images the cell is much larger than a contact, so any period applied means that
        if ky is None:
            shifted = (D != D0).any(axis=0)
        else:
            shifted = (ky != 0) | (kx != 0)
        if not cached_images and _nz(shifted):
            w = np.nonzero(shifted)[0]
            rx, ry = D0[0].take(w), D0[1].take(w)
            shifted[w] = np.sqrt(rx * rx + ry * ry) != d.take(w)
        S.shifted = shifted
        # what every step's geometry takes over from the structure
        # (not S itself: a structure referring to itself would wait for the cyclic collector)
        S.view = {"ai": S.ai, "aj": S.aj, "d0": S.d0, "perm": S.perm, "trans": S.trans,
                  "ri": S.ri, "rj": S.rj}
        # the cell is much larger than the candidate reach: a pair's nearest image cannot change within a step
        S.safe_images = bool(self._images_valid)
        return S

    # -- pair-force accumulation -----------------------------------------------------------------
    def _geometry(self):
        if self._g is None:
            self.test_neighbor_relation()
        return self._g

    def _add_normal(self, f_i, f_j=None, term="elastic"):
        """Add scalar central forces along n_ij: ``f_i`` on i, ``f_j`` (default ``f_i``) on j (reversed).

        The first term is kept by reference (terms never modify their results afterwards); each term is
        also noted by name for the register's per-visit lists (built only when read)."""
        g = self._g
        if g.parts is None:
            g.parts = []
        g.parts.append((term, f_i, f_j))
        if f_j is None and g.fn_j is None:
            g.fn_i = f_i if g.fn_i is None else g.fn_i + f_i
            return
        if g.fn_i is None:
            g.fn_i = np.zeros(g.P)
        if g.fn_j is None:
            g.fn_j = g.fn_i
        g.fn_i = g.fn_i + f_i
        g.fn_j = g.fn_j + (f_i if f_j is None else f_j)

    @staticmethod
    def _flush_arrays(P, spin):
        """The flat force array of a flush and its views: F_i, F_j (2, P), torques (2P,) and (2, P)."""
        W = np.empty((6 if spin else 4) * P)
        T = W[4 * P:] if spin else None
        return (W, W[:2 * P].reshape(2, P), W[2 * P:4 * P].reshape(2, P), T,
                None if T is None else T.reshape(2, P))

    def _flush_pair_forces(self):
        """Apply the collected pair forces to the spheres and put them into the force register.

        Forces on i and j and the tangential torques go into one flat array, in contiguous (2, P)
        blocks F_i, F_j, (t_i, t_j), that a single ``bincount`` adds to the (xforce, yforce, torque)
        rows of the state block.
        """
        g = self._g
        if g is None:
            return
        n = self._n
        P = g.P
        S = g.S
        spin = g.ft is not None
        fa = self._flush_arrays(P, spin)
        W = fa[0]
        Fi = fa[1]
        Fj = fa[2]
        antisymmetric = g.fn_j is None
        # F_i = f_n·n + f_t·t and the torques d·f_t·(r_i, r_j)/(r_i + r_j) (eq. S1-3): the engine's pair_forces
        nx, ny = g.n[0], g.n[1]
        fx, fy, _, tq = pair_forces(0.0 if g.fn_i is None else g.fn_i, g.ft, nx, ny, g.d, S.w2)
        Fi[0] = fx
        Fi[1] = fy
        if antisymmetric:
            np.negative(Fi, out=Fj)
        else:
            fx, fy = pair_forces(g.fn_j, g.ft, nx, ny, g.d, None)[:2]
            np.negative(fx, out=Fj[0])
            np.negative(fy, out=Fj[1])
        ti = tj = None
        if spin:
            Wt = fa[4]
            Wt[...] = tq
            ti = Wt[0]   # indexing, not tuple unpacking (iterating an array is slow)
            tj = Wt[1]
        if P:
            k = 3 if spin else 2
            idx = S.idx6 if spin else S.idx6[:4 * P]
            self._frc[:k] += _bincount(idx, W, k * n).reshape(k, n)
        self.force_register._set_pairs(self, PairBlock({
            "i": g.ai, "j": g.aj, "Fi": Fi, "Fj": Fj,
            "ti": ti, "tj": tj, "internal": g.internal, "ext_i": g.ext_i,
            "ext_j": g.ext_j, "active": g.active, "antisymmetric": antisymmetric, "engine": True, "D": g.D,
            "pos_version": self._pos_version,
            # per-visit terms for the reference lists of the register (read only when asked for)
            "visits": (g.parts, g.ft_visits, g.n, g.t, g.d, S.w2, g.touching, g.perm, self._pairs.birth,
                       g.slots)}))
        g.fn_i = None
        g.fn_j = None
        g.ft = None
        g.parts = None
        g.ft_visits = None

    def _term_done(self):
        if not self._in_force_phase:
            self._flush_pair_forces()

    # -- views and scalar helpers for the API ------------------------------------------------------
    def _relations_of(self, p):
        pt = self._pairs
        m = pt.active & ((pt.i == p) | (pt.j == p))
        slots = np.flatnonzero(m)
        slots = slots[np.argsort(pt.birth[slots], kind="stable")]
        partners = _where(pt.i[slots] == p, pt.j[slots], pt.i[slots])
        cls = self._relation_view_class
        return [cls(self, p, int(q)) for q in partners]

    def _relations_edited(self):
        """The one place that drops every kept value (docs/design.md, "The documented classes"): relations were changed
        outside the step's neighbour update (the per-sphere API, a batched constitution), which no counter
        of the memo keys records."""
        self._memo.invalidate()

    @property
    def _struct(self):
        """The pair structure of the last neighbour update (None before the first one or after
        :meth:`_relations_edited`), for inspection."""
        return self._memo.peek("pair_structure")

    def _drop_relations_of(self, p):
        self._relations_edited()
        if self._g is not None:
            self._g.all_slip = False
        pt = self._pairs
        m = pt.active & ((pt.i == p) | (pt.j == p)) & (pt.state != PERMANENT)
        pt.active[m] = False
        pt.xi_ij[m] = 0.0
        pt.xi_ji[m] = 0.0

    def _pair_d(self, p, q):
        a = self._a
        dx, dy, _ = min_image(np.array([a["x"][q] - a["x"][p]]), np.array([a["y"][q] - a["y"][p]]),
                              self.size_x, self.size_y, self._le_shift())
        return float(np.sqrt(dx * dx + dy * dy)[0])

    def _test_pair(self, p, q):
        """Neighbour test of one pair (the scalar ``test_neighbor_relation(theSphere)`` API)."""
        self._relations_edited()
        if self._g is not None:
            self._g.all_slip = False
        a = self._a
        touching = self._pair_d(p, q) < a["r"][p] + a["r"][q]
        pt = self._pairs
        s = int(pt.find(p, q))
        if touching:
            s = int(pt.ensure(p, q)[0])
            if not pt.active[s]:
                pt.active[s] = True
                pt.state[s] = STICK
                pt.xi_ij[s] = pt.xi_ji[s] = 0.0
                pt.birth[s] = pt.next_births(1)[0]
        elif s >= 0 and pt.active[s] and pt.state[s] != PERMANENT:
            pt.active[s] = False
            pt.xi_ij[s] = pt.xi_ji[s] = 0.0

    def contact_pairs(self):
        """Sphere indices (i, j), i < j, of the current relations (contacts and links)."""
        pt = self._pairs
        return pt.i[pt.active].copy(), pt.j[pt.active].copy()


class CanvasPointsShear(CanvasPointsNeighbors):
    """Adds the shear strain ``shear`` (γ), its rate ``shear_rate`` (1/s) and the moving plates.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    use_lees_edwards = True

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsNeighbors.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self.t = 0
        self.applyingShear = False
        self.shear_rate = 0
        self.shear = 0

    def canMove(self, theSphere):
        """During shear, spheres overlapping y = 0 or y = Ly are glued to the plates (docs/design.md).

        Parameters
        ----------
        theSphere : object
            A sphere of this ensemble.

        Returns
        -------
        bool
            True if the sphere moves freely.
        """
        if not self.applyingShear:
            return True
        return theSphere.r < theSphere.y < self.size_y - theSphere.r

    def _mobile(self):
        """(mask of the mobile spheres ``r < y < Ly − r``, its bytes) while shearing, else (None, None).

        The bytes are the memo key of what is derived from the mask (the pairs' internal flags, the
        selection of the mobile spheres), kept while the plates hold the same spheres."""
        if not self.applyingShear:
            return None, None
        y = self._pos[1]
        r = self._a["r"]
        mob = r < y
        mob &= y < self.size_y - r
        return mob, mob.tobytes()

    def do_linear_acceleration(self, dt):
        """Kick mobile spheres; immobile ones take the velocity of their plate.

        Every sphere is kicked and the plate velocity then overwrites the
        immobile ones, which gives the mobile spheres exactly the reference kick.

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0.
        """
        kick(self._vel[:2], self._frc[:2], self._a["m"], dt)
        self._plates_follow()

    def _plates_follow(self):
        """Immobile (plate) spheres take the velocity ±γ̇·Ly/2 of their plate and no y velocity (docs/design.md)."""
        mob = self._mobile_mask()
        if mob is None:
            return
        a = self._a
        plates_follow(a["xspeed"], a["yspeed"], ~mob, self._y_centred(), self.shear_rate * self.size_y / 2)

    def transmit_lees_edwards_parameters(self, theSphere):
        """Copy the cell size, strain, rate and Lees-Edwards flag to a sphere.

        Parameters
        ----------
        theSphere : object
            The sphere that receives them.
        """
        theSphere.size_x = self.size_x
        theSphere.size_y = self.size_y
        theSphere.shear = self.shear
        theSphere.shear_rate = self.shear_rate
        theSphere.use_lees_edwards = self.use_lees_edwards

    def _le_shift(self):
        return self.size_y * self.shear if self.use_lees_edwards else 0.0

    def _shear_rate_for_images(self):
        return self.shear_rate if self.use_lees_edwards else 0.0

    def _source_is_external(self, target, source):
        dx = source.x - target.x
        dy = source.y - target.y
        return math.sqrt(dx ** 2 + dy ** 2) != target.d(source)


class CanvasPointsBasicElasticity(CanvasPointsShear):
    """Adds the central elastic and viscous pair forces with constants ``k`` and ``nu``.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``/``nu`` is not a finite number ≥ 0.
    """

    k = NonNegative()
    nu = NonNegative()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1):
        CanvasPointsShear.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self.k = k
        self.nu = nu
        self.central_repulsion_coefficient = 0
        self.integrator = "euler"
        self.stability_guard = None
        self.phase = ""
        self.step_count = 0
        self._half_kick = None

    INTEGRATORS = ("euler", "verlet")

    def set_integrator(self, integrator):
        """Choose the time integrator.

        ``"euler"`` (default) is the reference's semi-implicit Euler: kick with the
        forces of the step, damp, drift.  ``"verlet"`` is velocity Verlet with a
        half-kick predictor (Groot-Warren λ = 1/2): the velocity-dependent forces
        see the velocity at the force time instead of half a step earlier, which
        makes the viscous terms second-order accurate.  Positions and the
        conservative forces are updated identically by both.

        Parameters
        ----------
        integrator : str
            One of :attr:`INTEGRATORS` (``"euler"`` or ``"verlet"``).

        Raises
        ------
        ValueError
            If ``integrator`` is not one of them.
        """
        if integrator not in self.INTEGRATORS:
            raise ValueError(f"integrator must be one of {self.INTEGRATORS}, got {integrator!r}")
        self.integrator = integrator
        self._half_kick = None

    def set_central_repulsion_coefficient(self, central_repulsion_coefficient=0):
        """Set the law's repulsion coefficient c ∈ [0, 1] on the ensemble and every sphere.

        Parameters
        ----------
        central_repulsion_coefficient : float
            c of the force law: 0 = linear (eq. S1-5a), 1 = divergent (eq. S1-5b).

        Raises
        ------
        ValueError
            If the value is not finite.
        """
        _check_finite("central_repulsion_coefficient", central_repulsion_coefficient)
        self.central_repulsion_coefficient = central_repulsion_coefficient
        self._a["central_repulsion_coefficient"][:] = central_repulsion_coefficient
        self._params_changed()

    def _builtin_laws(self):
        """Whether the built-in central law is in use (a law replaced through ``call_back_elastic_force_law`` is
        evaluated by :meth:`_user_law_term`)."""
        return CircleBasicElasticity.call_back_elastic_force_law is laws.elastic_force_law

    def _term_constants(self, g):
        """``(K_i, K_j, differ)``: the constants of the force terms of the step's pairs as seen by the visit from i
        and from j (:func:`~particleShear.engine.terms.term_constants`), and the names of the terms whose two
        visits differ (``"elastic"``, ``"viscous"``, ``"tangential"``; empty when every sphere has the same
        parameters, and then ``K_j is K_i``).

        They are made from the pair structure, the ensemble's k, ν, k_t, ν_t, μ and each visit's own sphere
        parameters (c and the permanent ratios, :data:`_PARAMS`), and kept in the memo under exactly
        these (the structure's key, the version of the sphere parameters and the ensemble's values).
        """
        S = g.S
        values = (self.k, self.nu, getattr(self, "k_t", 0.0), getattr(self, "nu_t", 0.0), getattr(self, "mu", 0.0))
        return self._memo.get("term_constants", (S.key, self._params_version) + values,
                              lambda: self._visit_constants(S, *values))

    def _visit_constants(self, S, k, nu, k_t, nu_t, mu):
        """The :meth:`_term_constants` of structure ``S``: a parameter all spheres share is one number, else the
        value of the visiting sphere (i for the first visit, j for the second) per pair."""
        shared = dict(zip(_PARAMS, (self._param(name) for name in _PARAMS)))

        def visit(rows):
            c, prc, prt, keep = (shared[name] if shared[name] is not None else self._a[name].take(rows)
                                 for name in _PARAMS)
            return term_constants(S.d0, S.perm, S.deq, k, c, nu, k_t, nu_t, mu, prc, prt, keep)

        K_i = visit(S.ai)
        # the parameters each term reads (the permanent ratios and kept viscosities only on bonds)
        bonds = S.perm is not None
        reads = {"elastic": ("central_repulsion_coefficient",) + (("permanent_ratio_central",) if bonds else ()),
                 "viscous": ("permanent_ratio_central", "keep_viscosity_coefficients_constant") if bonds else (),
                 "tangential": ("permanent_ratio_tangential", "keep_viscosity_coefficients_constant") if bonds else ()}
        differ = frozenset(term for term, names in reads.items() if any(shared[n] is None for n in names))
        return K_i, (visit(S.aj) if differ else K_i), differ

    def _user_law_term(self, K, g):
        """Elastic term with a law replaced through ``call_back_elastic_force_law``, pair by pair (as
        :func:`~particleShear.engine.terms.elastic_term`): ``(law·ratio_c, law)``, 0 on inactive candidates
        unless the law is one of the built-in ones that vanish beyond contact."""
        law = self._mask_law(call_law_vectorised(CircleBasicElasticity.call_back_elastic_force_law, g.d, K.d_law,
                                                 K.k, K.c))
        return law * K.ratio_c, law

    def _mask_law(self, f):
        """Zero a user law's value on inactive candidates (the built-in laws are 0 beyond contact)."""
        if self._g.active is None or CircleBasicElasticity.call_back_elastic_force_law in _ZERO_BEYOND_CONTACT:
            return f
        return f * self._g.active

    def elastic_force_from_neighbors(self):
        """Central elastic force of every relation (eqs. S1-5a, S1-5b; links in tension: docs/design.md)."""
        self._geometry()
        self._elastic_terms()
        self._term_done()

    def _elastic_terms(self):
        """Central elastic force of every relation, each visit with its own constants: contacts ``law(d, r_i + r_j,
        k, c)`` (0 beyond contact), bonds the law at ``d_eq`` and the tensile law beyond it, × the permanent ratio
        (:func:`~particleShear.engine.terms.elastic_term`).  Keeps the law of the visit from i as ``g.fel``, the
        base of the Coulomb bound."""
        g = self._g
        if not g.P:
            return
        K_i, K_j, differ = self._term_constants(g)
        term = elastic_term if self._builtin_laws() else (lambda K, d: self._user_law_term(K, g))
        f_i, g.fel = term(K_i, g.d)
        f_j = term(K_j, g.d)[0] if "elastic" in differ else None
        self._add_normal(f_i, f_j)

    def _relative_velocity(self, g):
        """Velocity of j's nearest image relative to i (µm/s), shape (2, P), computed once per force phase.

        Also keeps the gathered (xspeed, yspeed, omega) of both spheres for the tangential term."""
        if g.rv is None:
            vel = self._vel
            g.Vi = vel.take(g.ai, axis=1)
            g.Vj = vel.take(g.aj, axis=1)
            g.rv = relative_velocity(g.Vi, g.Vj, g.dvx)
        return g.rv

    def _normal_speed(self, g):
        if g.vn is None:
            g.vn = normal_speed(self._relative_velocity(g), g.n[0], g.n[1])
        return g.vn

    def central_viscous_force_from_neighbors(self):
        """Central viscous force ``ν v_n`` of every relation (eq. S1-9)."""
        self._geometry()
        self._viscous_terms()
        self._term_done()

    def _viscous_terms(self):
        """Central viscous force of every relation, each visit with its own ν (bonds: × the permanent ratio unless
        the viscosities are kept constant; :func:`~particleShear.engine.terms.viscous_term`)."""
        g = self._g
        if not g.P:
            return
        if self.nu == 0:
            # no force, but the reference still registers ν·v_n = 0 per visit (noted for the register only)
            g.parts = (g.parts or []) + [("viscous", None, None)]
            return
        K_i, K_j, differ = self._term_constants(g)
        vn = self._normal_speed(g)
        f_i = viscous_term(K_i, vn, g.active)
        f_j = viscous_term(K_j, vn, g.active) if "viscous" in differ else None
        self._add_normal(f_i, f_j, "viscous")

    def elastic_force(self):
        """All-pairs variant (reference API): a neighbour update, then the elastic term."""
        self.test_neighbor_relation()
        self.elastic_force_from_neighbors()

    def central_viscous_force(self):
        """All-pairs variant (reference API): a neighbour update, then the central viscous term."""
        self.test_neighbor_relation()
        self.central_viscous_force_from_neighbors()

    def _force_terms(self):
        self._elastic_terms()
        self._viscous_terms()

    def mechanical_simulation_step_calculate_forces(self, dt=1):
        """Clear the register, update neighbours, add every pair force (first phase of a step).

        ``dt`` is accepted for the 1.0.2 signature.

        Parameters
        ----------
        dt : float
            Time step (s); not used by the force phase.
        """
        self.reset_force_register()
        self.test_neighbor_relation()
        predicted = self._predict_velocities() if self._half_kick is not None else None
        self._in_force_phase = True
        try:
            self._force_terms()
        finally:
            self._in_force_phase = False
            if predicted is not None:
                self._restore_velocities(predicted)
        self._flush_pair_forces()
        if self.stability_guard is not None:
            self.stability_guard.check(self, step=self.step_count, phase=self.phase, dt=self._last_dt)

    _last_dt = None

    def _predict_velocities(self):
        """Velocity Verlet: move velocities half a kick ahead for the velocity-dependent forces."""
        a = self._a
        saved = (a["xspeed"].copy(), a["yspeed"].copy(), a["omega"].copy())
        hx, hy, ht = self._half_kick
        if len(hx) == self._n:
            a["xspeed"] += hx
            a["yspeed"] += hy
            if ht is not None:
                a["omega"] += ht
        if self._g is not None:
            self._g.rv = None
            self._g.vn = None
            self._g.vt = None
        return saved

    def _restore_velocities(self, saved):
        a = self._a
        a["xspeed"][:], a["yspeed"][:], a["omega"][:] = saved

    def _store_half_kick(self, dt):
        """Remember ``F·dt/(2m)`` of mobile spheres (and ``T·dt/(2I)``) for the next force phase (Verlet only;
        :func:`~particleShear.engine.integrate.half_kick`)."""
        spin = self._torque_total() is not None
        k = 3 if spin else 2
        h = half_kick(self._frc[:k], self._st.take(_MASS_ROWS[:k], axis=0), dt, self._mobile_mask())
        self._half_kick = (h[0], h[1], h[2] if spin else None)

    def mechanical_simulation_step_calculate_acceleration(self, cool_factor=0.97, dt=1):
        """Kick the velocities with the forces of the step, then damp them (third phase of a step).

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)
        if self.integrator != "euler":
            self._store_half_kick(dt)
        self._last_dt = dt
        self.do_linear_acceleration(dt)
        self.cool(cool_factor)

    def _advance_strain(self, dt):
        if self.applyingShear:
            self.shear = self.shear + self.shear_rate * dt

    def mechanical_simulation_step_calculate_movement(self, dt=1):
        """Drift, strain update (while shearing), wrap, clock (last phase of a step).

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)
        self.move(dt)
        self._advance_strain(dt)
        self.boundary_conditions()
        self.t = self.t + dt
        self.step_count += 1
        self._g = None
        if self._renderer is not None:
            self._renderer.update(self)

    def mechanical_simulation_step(self, cool_factor=0.97, dt=1):
        """One step in reference order: forces → totals → kick + damping → movement.

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)  # before the force phase: a refused step does no work
        self.mechanical_simulation_step_calculate_forces()
        self.record_total_particle_forces()
        self.mechanical_simulation_step_calculate_acceleration(cool_factor, dt)
        self.mechanical_simulation_step_calculate_movement(dt)

    def mechanical_relaxation(self, N=1000, cool_factor=0.97, dt=1, theTk=False, StressTensorEvaluator=False):
        """N steps; optionally a window update and a stress evaluation after each.

        Parameters
        ----------
        N : int
            Number of steps.
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.
        theTk : object or bool
            Tk root window updated after each step (False: none).
        StressTensorEvaluator : StressTensorEvaluation or bool
            Evaluator updated after each step (False: none).

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        for _ in range(int(N)):
            self.mechanical_simulation_step(cool_factor, dt)
            if theTk:
                theTk.update()
            if StressTensorEvaluator:
                self.evaluate_stress_tensors(StressTensorEvaluator)

    @property
    def active_terms(self):
        """Names of the force terms a step of this ensemble evaluates now."""
        terms = ["central_elastic"]
        if self.nu != 0:
            terms.append("central_viscous")
        return terms


class CanvasPointsBasicElasticityLeesEdwards(CanvasPointsBasicElasticity):
    """Adds shear-rate changes that keep velocities relative to the flow (docs/design.md).

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``/``nu`` is not a finite number ≥ 0.
    """

    def setShear(self, theShear):
        """Set the shear strain γ (the Lees-Edwards offset is ``Ly·γ``).

        Parameters
        ----------
        theShear : float
            Strain (dimensionless).
        """
        self.shear = theShear
        self._g = None

    def setShearInSpheres(self):
        """Kept for the 1.0.2 API: spheres read γ from the ensemble (does nothing)."""
        pass  # spheres read γ from the ensemble

    def setShearRateInSpheres(self):
        """Kept for the 1.0.2 API: spheres read γ̇ from the ensemble (does nothing)."""
        pass  # spheres read γ̇ from the ensemble

    def adjust_sphere_speed_to_shear_rate_change(self, delta_shear_rate):
        """Add the change of the affine flow to every velocity (and −Δγ̇/2 to every spin).

        Parameters
        ----------
        delta_shear_rate : float
            Change Δγ̇ of the shear rate (1/s).
        """
        a = self._a
        a["xspeed"] += self._y_centred() * delta_shear_rate
        a["omega"] -= delta_shear_rate / 2

    def setShearRate(self, theShearRate):
        """Change γ̇; every sphere keeps its velocity relative to the local flow.

        Parameters
        ----------
        theShearRate : float
            New shear rate γ̇ (1/s).
        """
        delta = theShearRate - self.shear_rate
        if delta != 0:
            self.adjust_sphere_speed_to_shear_rate_change(delta)
        self.shear_rate = theShearRate


class CanvasPointsFrictionElasticityLeesEdwards(CanvasPointsBasicElasticityLeesEdwards):
    """Adds the tangential force (``k_t``, ``nu_t``, Coulomb ``mu``), spin and the ξ history.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    k : float
        Spring constant of the central force (mg·s⁻² per m depth, eq. S1-8), ≥ 0.
    nu : float
        Central viscosity constant (mg·s⁻¹ per m depth, eq. S1-9), ≥ 0.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).
    k_t : float
        Tangential spring constant (mg·s⁻² per m depth), ≥ 0.
    nu_t : float
        Tangential viscosity constant (mg·s⁻¹ per m depth), ≥ 0.
    mu : float
        Coulomb friction coefficient μ (dimensionless), ≥ 0.

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0, or ``k``, ``nu``, ``k_t``, ``nu_t`` or ``mu`` is not a finite number ≥ 0.
    """

    k_t = NonNegative()
    nu_t = NonNegative()
    mu = NonNegative()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, k=1, nu=0.01, m=1, k_t=1,
                 nu_t=0.01, mu=0.1):
        CanvasPointsBasicElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m)
        self.k_t = k_t
        self.nu_t = nu_t
        self.mu = mu

    def _tangential_speed(self, g):
        if g.vt is None:
            g.vt = slip_speed(self._relative_velocity(g), g.n[0], g.n[1], g.ri, g.rj, g.Vi[2], g.Vj[2])
        return g.vt

    def _add_tangential(self, f_pair):
        g = self._g
        g.ft = f_pair if g.ft is None else g.ft + f_pair

    def _tangential_needed(self):
        return self.mu != 0

    def tangential_force_from_neighbors(self):
        """Two-visit tangential force of every relation (torque split eq. S1-3; visit order: docs/design.md)."""
        self._geometry()
        self._tangential_terms()
        self._term_done()

    def _tangential_terms(self):
        """Tangential force of every relation: the two-visit rule with the Coulomb bound ``|μ·law|`` (bonds: an
        unbounded spring, k_t and ν_t × the permanent ratio; :func:`~particleShear.engine.terms.tangential_term`),
        then the states (slip, stick, permanent) and histories ξ of the relations."""
        g = self._g
        if not g.P:
            return
        pt = self._pairs
        if g.perm is None and not self._tangential_needed():
            # μ = 0 and no bonds: the Coulomb bound is zero, every moving contact slips and ξ is reset.
            if g.active is None:
                pt.state[g.slots] = SLIP
                pt.xi[:, g.slots] = 0.0
            else:
                pt.state[g.active] = SLIP
                pt.xi[...] = 0.0   # inactive candidates hold ξ = 0 already
            g.all_slip = True
            g.ft_visits = 0.0   # every visit applies a zero force (Coulomb bound 0)
            return
        K_i, K_j, differ = self._term_constants(g)
        if g.fel is None:   # the elastic term did not run in this force phase: the law of the bound
            g.fel = (elastic_term(K_i, g.d) if self._builtin_laws() else self._user_law_term(K_i, g))[1]
        sel = g.S.sel
        xi = pt.xi if sel is None else pt.xi.take(sel, axis=1)
        F, slip = tangential_term(K_i, self._tangential_speed(g), g.touching, xi, g.fel,
                                  K_j if "tangential" in differ else None)
        # states: slip 1, stick 0, and permanent on bonds
        state = slip.view(np.int8)
        perm_code = g.S.perm_code
        if sel is None:
            if perm_code is not None:
                np.add(state, perm_code, out=pt.state)
            else:
                pt.state[...] = state
        else:
            pt.state[sel] = state if perm_code is None else state + perm_code
            pt.xi.reshape(-1)[g.S.sel2] = xi.reshape(-1)   # flat 1-D scatter: much cheaper than [:, sel]
        g.ft_visits = F
        f = F[0] + F[1]
        f *= 0.5     # = F1/2 + F2/2 exactly (halving is exact in binary floating point)
        self._add_tangential(f)

    def tangential_force(self):
        """All-pairs variant (reference API)."""
        self.test_neighbor_relation()
        self.tangential_force_from_neighbors()

    def _force_terms(self):
        CanvasPointsBasicElasticityLeesEdwards._force_terms(self)
        self._tangential_terms()

    def _torque_total(self):
        return self._a["torque"]

    def do_rotational_acceleration(self, dt):
        """Kick every spin ``ω += T dt / I`` and reset the torques.

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        a = self._a
        a["omega"] += a["torque"] * dt / a["inertia"]
        a["torque"][:] = 0.0

    def _cool_spin(self, f):
        self._a["omega"] *= f

    def mechanical_simulation_step_calculate_acceleration(self, cool_factor=0.97, dt=1):
        """Linear kick (plates), rotational kick of all spheres, damping (third phase of a step).

        Parameters
        ----------
        cool_factor : float
            Damping factor of the peculiar velocity per step (0 < f ≤ 1; 1 = no damping).
        dt : float
            Time step (s), finite and > 0.

        Raises
        ------
        ValueError
            If ``dt`` is not a finite number > 0 (before any work).
        """
        check_time_step(dt, self.step_count)
        if self.integrator != "euler":
            self._store_half_kick(dt)
        self._last_dt = dt
        cls = type(self)
        friction = CanvasPointsFrictionElasticityLeesEdwards
        if (cls.do_linear_acceleration is CanvasPointsShear.do_linear_acceleration
                and cls.do_rotational_acceleration is friction.do_rotational_acceleration):
            # both kicks at once on the (xspeed, yspeed, omega) rows: v += F·dt/m, ω += τ·dt/I
            kick(self._vel, self._frc, self._st.take(_MASS_ROWS, axis=0), dt)   # weights (m, m, I)
            self._plates_follow()
        else:
            self.do_linear_acceleration(dt)
            self.do_rotational_acceleration(dt)
        self.cool(cool_factor)

    def cool(self, f=0.8):
        """Damp velocity relative to the affine flow and spin by ``f`` (docs/design.md), all three rows at once.

        Parameters
        ----------
        f : float
            Factor applied to the peculiar velocity (0 < f ≤ 1; 1 = no damping).
        """
        if type(self)._cool_spin is not CanvasPointsFrictionElasticityLeesEdwards._cool_spin:
            return CanvasPointsBasicElasticityLeesEdwards.cool(self, f)
        rate = getattr(self, "shear_rate", 0)
        damp(self._vel, self._affine_vx(rate) if rate else None, f)

    def _integrate_xi(self, dt):
        """Sequential ξ rule of the reference, without a Python loop (docs/design.md).

        Relation i→j (i < j) sees both spheres at their old positions; relation
        j→i sees i already moved by ``v_i·dt``.  Both use the velocities after
        the kick and damping; slip relations are not integrated (their increment
        is multiplied by 0, which leaves their ξ = 0 exactly).  The increments are
        :func:`particleShear.engine.integrate.xi_increments`, the engine's own.
        """
        g = self._g
        if g is None or not g.P or g.all_slip:
            return
        pt = self._pairs
        sel = g.S.sel
        P = g.P
        # the factor dt on relations that did not slip, 0 on slipped ones and on inactive candidates
        if sel is None:
            kd = _where(pt.state == _SLIP8, np.zeros(P), dt * g.active)
        else:
            kd = _where(pt.state.take(sel) == _SLIP8, 0.0, dt)
        vel = self._vel
        Vi = vel.take(g.ai, axis=1)
        Vj = vel.take(g.aj, axis=1)
        # relation j→i: i has moved by v_i·dt; the pair vector is −(x_j − x_i) of the force phase
        # plus that move (same image, the cell being much larger than any candidate pair)
        R = Vi[:2] * dt
        R -= g.D
        dvx_ji = None
        if not g.S.safe_images:
            Lx, Ly = float(self.size_x), float(self.size_y)
            if np.abs(R[0]).max() >= Lx / 2 or np.abs(R[1]).max() >= Ly / 2:
                # a cell barely larger than a contact: R may lie in another image than the force phase's D
                rx = (self._pos[0].take(g.ai) + Vi[0] * dt) - self._pos[0].take(g.aj)
                ry = (self._pos[1].take(g.ai) + Vi[1] * dt) - self._pos[1].take(g.aj)
                dx, dy, dvx_ji = min_image(rx, ry, Lx, Ly, self._le_shift(), self._shear_rate_for_images())
                R = np.array((dx, dy))
                if dvx_ji is None:
                    dvx_ji = 0.0
        unit = lambda rx, ry: pair_geometry(rx, ry, self._rng)[1:]   # noqa: E731 (random direction at |R| = 0)
        inc = np.array(xi_increments(Vi, Vj, g.dvx, g.n[0], g.n[1], g.ri, g.rj, R[0], R[1], unit, dvx_ji))
        inc *= kd   # ×dt on kept relations, ×0 (±0) on the others
        if sel is None:
            pt.xi += inc
        else:
            flat = pt.xi.reshape(-1)
            inc += flat.take(g.S.sel2).reshape(2, P)
            flat[g.S.sel2] = inc.reshape(-1)

    def move(self, dt=1):
        """ξ rule, then drift and turn: x, y, φ += (u_x, u_y, ω)·dt (φ is not read by the ξ rule).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        self._integrate_xi(dt)
        self._drift(dt, spin=True)

    def _advance_strain(self, dt):
        self.shear = self.shear + self.shear_rate * dt

    @property
    def active_terms(self):
        terms = CanvasPointsBasicElasticityLeesEdwards.active_terms.fget(self)
        if self._tangential_needed():
            terms.append("tangential")
        return terms
