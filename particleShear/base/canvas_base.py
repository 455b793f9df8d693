"""The first canvases: the ensemble's state arrays, ``sphereList``, mass and force register (docs/classes.md,
"The documented classes").

The pair canvases of :mod:`.pair_canvas` and the force canvases of :mod:`.elastic_canvas` subclass
:class:`CanvasPointsMass`; :mod:`.canvas` gathers all of them.
"""
__docformat__ = "numpy"

import math
import numbers
from operator import attrgetter

import numpy as np

from .fields import FIELDS, REPLICA_FIELDS, REPLICA_ROW, ROW
from .graphics import Graphical_output_configuration, headless
from ..engine.box import flow_velocity, inside_cell, wrap
from ..engine.forces import pair_roles
from ..engine.integrate import damp, drift, kick, remove_mean_velocity
from .memo import Memo
from ..engine.memory import tune_allocator
from ..checks import finite as _check_finite, non_negative as check_non_negative, positive as _check_positive
from .register import Force_register, SphereSelection, record_method
from .stability import StabilityGuard
from .neighbours import STATE_CODES


__all__ = ["CanvasPoints", "CanvasPointsMass", "ReplicaValue", "SphereList", "check_non_negative", "check_time_step"]

#: a sphere farther than this many cell lengths outside the cell has diverged (or was misplaced)
MAX_CELLS_OUTSIDE = 1000


def check_time_step(dt, step=None):
    """Raise ValueError unless the time step ``dt`` (s) is a finite number > 0 (not a bool).

    Parameters
    ----------
    dt : float
    step : int or None
        Current step, named in the message.
    """
    if isinstance(dt, bool) or not 0.0 < dt < math.inf:
        where = "" if step is None else f" at step {step}"
        raise ValueError(f"dt={dt!r} is out of range{where}: allowed a finite time step > 0 (s)")


class NonNegative:
    """Ensemble constant that must stay a finite number ≥ 0 (k, nu, k_t, nu_t; μ is a :class:`ReplicaValue`
    with the same check); only assignment is checked."""

    def __set_name__(self, owner, name):
        self.name = name

    def __set__(self, obj, value):
        check_non_negative(self.name, value)
        obj.__dict__[self.name] = value


class ReplicaValue:
    """Ensemble value held in its cell of the ensemble's replica cells (``t``, ``shear``, ``shear_rate``,
    ``mu``: :data:`~particleShear.base.fields.REPLICA_FIELDS`).

    The cell is a float; an integer assigned reads back as that integer (``ens.t = 0`` gives
    ``0``, as an attribute of 1.0.2 would) until the cell holds another value, after which it reads
    as a float (a step's clock, strain or rate).

    The cells are the engine's memory (:func:`~particleShear.base.engine_adapter.state_of_ensembles`
    makes them element b of the batch's ``t``, ``gamma``, ``rate`` and ``mu``), so what a step
    advances the ensemble reads, and what is set here the engine's next step reads.

    Parameters
    ----------
    check : callable, optional
        ``check(name, value)`` raising ValueError for a value out of range (μ: ≥ 0), called on
        assignment before the cell is written.
    """

    def __init__(self, check=None):
        self.check = check

    def __set_name__(self, owner, name):
        self.name, self.row = name, REPLICA_ROW[name]

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        v = obj._replica.item(self.row)
        i = obj.__dict__.get("_replica_ints", {}).get(self.name)
        return i if i is not None and i == v else v

    def __set__(self, obj, value):
        if self.check is not None:
            self.check(self.name, value)
        obj._replica[self.row] = value
        ints = obj.__dict__.setdefault("_replica_ints", {})
        if isinstance(value, numbers.Integral) and not isinstance(value, bool):
            ints[self.name] = value       # (read back while the cell still holds it)
        else:
            ints.pop(self.name, None)


class SphereList(list):
    """The ensemble's spheres in index order; they can only be added (else ``TypeError``).

    Parameters
    ----------
    canvas : CanvasPoints
        The ensemble that owns the list.
    """

    def __init__(self, canvas):
        list.__init__(self)
        self._canvas = canvas

    def append(self, sphere):
        """Add a sphere, moving its state into the ensemble's arrays (ValueError if already in one or invalid).

        Parameters
        ----------
        sphere : Sphere
        """
        self._canvas._attach(sphere)
        list.append(self, sphere)

    def extend(self, spheres):
        """Append every sphere of ``spheres`` in order.

        Parameters
        ----------
        spheres : iterable of Sphere
        """
        for s in spheres:
            self.append(s)

    def __iadd__(self, spheres):
        self.extend(spheres)
        return self

    def _forbidden(self, *args, **kwargs):
        """Raise TypeError: spheres cannot be removed, replaced or reordered once in an ensemble.

        Parameters
        ----------
        *args, **kwargs
            Ignored.
        """
        raise TypeError("spheres cannot be removed, replaced or reordered once in an ensemble")

    insert = remove = pop = clear = sort = reverse = __setitem__ = __delitem__ = _forbidden

    def __reduce__(self):
        """Copy and pickle as the list of the same spheres of the ensemble's copy, made without
        :meth:`append`: each sphere's state is in the copied state block already, at its index."""
        return _sphere_list, (self._canvas, list(self))


def _sphere_list(canvas, spheres):
    """The :class:`SphereList` of ``canvas`` holding ``spheres``, which are in its state block already."""
    out = SphereList(canvas)
    list.extend(out, spheres)
    return out


# ufunc reductions without the Python wrappers of ndarray.max/min (hot path)
_max_reduce = np.maximum.reduce
_min_reduce = np.minimum.reduce


class CanvasPoints:
    """Periodic cell of ``size_x × size_y`` µm holding spheres in structure-of-arrays form.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0 (else ValueError).
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    """

    use_lees_edwards = False

    #: what a copy or a pickle of the ensemble leaves out: the memo (with the step's engine), the
    #: step's records of that engine (:class:`~particleShear.base.engine_view.EngineStep`) and the
    #: views of the state block (made anew on the copy's own block)
    _NOT_COPIED = ("_memo", "_st", "_a", "_pos", "_vel", "_frc", "_g", "_force_record", "_kept_terms", "_engine_pairs",
                   "_engine_strain", "_engine_mu")

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False):
        _check_positive("size_x", size_x)
        _check_positive("size_y", size_y)
        tune_allocator()
        self.theCanvas = theCanvas
        self.size_x = size_x
        self.size_y = size_y
        self.doDrawing = doDrawing
        self._n = 0
        self._set_capacity(0)
        self._replica = np.zeros(len(REPLICA_FIELDS))   # the cells of ReplicaValue (0 where a class has none)
        self._sphereList = SphereList(self)
        self._m_given = []   # masses as given to the spheres (an int stays int) for the evaluation handler
        self._rng = np.random.default_rng()
        self._renderer = None
        self._memo = Memo()   # every value kept between calls
        self._pos_version = 0
        self._params_version = 0
        self.graphical_output_configuration = Graphical_output_configuration()

    # -- copies and pickles -------------------------------------------------------------------------
    def __getstate__(self):
        """The state a copy (``copy.deepcopy``) or a pickle carries: every attribute but the caches
        (:attr:`_NOT_COPIED`), without window handles (:func:`~particleShear.base.graphics.headless`).

        The state block, the replica cells, the pair table, the Verlet predictor and the random
        generator are carried as values, so the copy is independent of the original and continues
        as it would (the generator's next draws included); the caches are made anew when needed.
        """
        return {name: value for name, value in headless(self.__dict__).items() if name not in self._NOT_COPIED}

    def __setstate__(self, state):
        """Take ``state`` (of :meth:`__getstate__`), with an empty memo and the views of its own block.

        Parameters
        ----------
        state : dict
        """
        self.__dict__.update(state)
        self._memo = Memo()
        self._views()

    def __copy__(self):
        """A shallow copy (``copy.copy``), as of 1.0.2's ensembles: the spheres are the original's,
        the clock, strain, rate and μ are the copy's own values.

        The state block, the sphere list, the pair table, the Verlet predictor and the generator
        are shared with the original (as 1.0.2's shallow copy shared its sphere objects); the
        replica cells (``t``, ``shear``, ``shear_rate``, ``mu``, attributes of their own in
        1.0.2) are copied, and the caches (:attr:`_NOT_COPIED`) are made anew.  Use
        ``copy.deepcopy`` for an independent ensemble (:meth:`__getstate__`).
        """
        new = type(self).__new__(type(self))
        new.__setstate__(self.__getstate__())
        new._replica = self._replica.copy()
        new._replica_ints = dict(getattr(self, "_replica_ints", {}))
        return new

    # -- sphere list and state arrays ----------------------------------------------------------
    @property
    def sphereList(self):
        """The spheres in index order (a :class:`SphereList`); assignable only while the ensemble is empty."""
        return self._sphereList

    @sphereList.setter
    def sphereList(self, spheres):
        if len(self._sphereList):
            raise TypeError("sphereList can only be assigned while the ensemble is empty")
        self._sphereList.extend(spheres)

    @property
    def sphere_arrays(self):
        """The per-sphere state and parameters, one read-only array per field (``sphereList`` order).

        Returns
        -------
        dict of str to numpy.ndarray
            A new dict on each read, keyed by the fields of
            :data:`~particleShear.base.fields.FIELDS`: ``x, y`` (µm), ``phi`` (rad), ``xspeed,
            yspeed`` (µm/s), ``omega`` (1/s), ``r`` (µm), ``m`` (mg/m), ``inertia`` (mg·µm²/m),
            ``xforce, yforce, torque`` of the last force phase (per metre of depth, reference
            units of docs/parameters.md) and the per-sphere model parameters
            ``central_repulsion_coefficient``, ``permanent_ratio_central``,
            ``permanent_ratio_tangential``, ``keep_viscosity_coefficients_constant``.  Each value
            is a read-only view (shape (N,)) of the ensemble's own state: it follows later steps
            until a sphere is appended (then read the property again).  Change a value through
            the sphere's attribute (``ens.sphereList[k].x = ...``), which checks it.
        """
        out = {}
        for name, row in self._a.items():
            view = row.view()
            view.flags.writeable = False
            out[name] = view
        return out

    def set_random_generator(self, rng):
        """Use ``rng`` for every random choice of this ensemble (the run seeds it).

        Parameters
        ----------
        rng : numpy.random.Generator
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

    def _fit_block(self):
        """Drop the state block's spare columns (kept for appends): contiguous ``_pos``, ``_vel``, ``_frc`` rows."""
        if self._cap != self._n:
            self._set_capacity(self._n)

    def adopt_state_block(self, block):
        """Hold the spheres' state in ``block`` from now on (the columns of a batch's joint block).

        The values are the caller's to have copied there (e.g.
        :func:`~particleShear.base.engine_adapter.state_of_ensembles`, which steps several
        ensembles as one batch); the ensemble's field views and its neighbour list follow the new
        block.  Appending a sphere later copies the block out again.

        Parameters
        ----------
        block : numpy.ndarray (len(FIELDS), N)
            One row per field of :data:`~particleShear.base.fields.FIELDS`, one column per sphere.

        Raises
        ------
        ValueError
            If ``block`` does not have that shape.
        """
        want = (len(FIELDS), self._n)
        if tuple(np.shape(block)) != want:
            raise ValueError(f"block has shape {tuple(np.shape(block))}: it must be {want} (fields × spheres)")
        self._block, self._cap = block, self._n
        self._views()
        self._invalidate_neighbours()

    def adopt_replica_cells(self, cells):
        """Hold the replica values (clock, strain, rate, μ) in ``cells`` from now on (column b of a
        batch's joint cells, as :meth:`adopt_state_block` the sphere block).

        The values are the caller's to have copied there
        (:func:`~particleShear.base.engine_adapter.state_of_ensembles`); what was kept on the old
        cells (the step's engine) is dropped.

        Parameters
        ----------
        cells : numpy.ndarray (len(REPLICA_FIELDS),) of float
            One cell per value of :data:`~particleShear.base.fields.REPLICA_FIELDS`, in that order.

        Raises
        ------
        ValueError
            If ``cells`` is not such an array.
        """
        if np.shape(cells) != (len(REPLICA_FIELDS),) or np.asarray(cells).dtype != np.float64:
            raise ValueError(f"cells have shape {np.shape(cells)}: they must be float cells of shape "
                             f"({len(REPLICA_FIELDS)},) (one per replica value)")
        self._replica = cells
        self._block_version += 1      # (the step's engine is made on the cells too)

    def _views(self):
        """Per-field views ``_a[name]`` and the grouped rows ``_pos``, ``_vel``, ``_frc``."""
        st = self._block[:, :self._n]
        self._st = st
        self._block_version = getattr(self, "_block_version", 0) + 1     # a key of what depends on the block
        self._a = {name: st[k] for k, name in enumerate(FIELDS)}
        x, vx, fx = ROW["x"], ROW["xspeed"], ROW["xforce"]
        self._pos = st[x:x + 2]
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
        d.update(_ens=self, _idx=n)
        for name in FIELDS:
            d.pop("_v_" + name, None)
        self._params_changed()
        self._invalidate_neighbours()
        self._adopt_relations(sphere)

    def _adopt_relations(self, sphere):
        """Move relations made before appending (e.g. links) into the pair table once both spheres are in."""
        own = sphere.__dict__.get("_own_neighbors")
        if not own or not hasattr(self, "_pairs"):
            return
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
            pt.open_relations(slot)
            pt.state[slot] = STATE_CODES[rel.interface_type]
            pt.d_eq[slot] = getattr(rel, "equilibrium_distance", 0)
            (pt.xi_ij if p < q else pt.xi_ji)[slot] = rel.friction_position
            back = [b for b in partner.__dict__.get("_own_neighbors", []) if b.theSphere is sphere]
            if back:
                (pt.xi_ji if p < q else pt.xi_ij)[slot] = back[-1].friction_position
        sphere.__dict__["_own_neighbors"] = pending
        self._links_changed()

    def _invalidate_neighbours(self):
        self._pos_version += 1

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
        remove_mean_velocity(self._vel[:2], 1)

    def particle_info(self):
        """Return a short description of the ensemble for the output header."""
        return "Points in a periodic cell"

    def canMove(self, theSphere):
        """Whether ``theSphere`` is mobile: always, except plate spheres while a :class:`CanvasPointsShear` shears.

        Parameters
        ----------
        theSphere : Sphere
        """
        return True

    def _mobile_mask(self):
        """Mask of the mobile spheres, or None when every sphere is mobile."""
        return None

    def movableSphereList(self):
        """The mobile spheres in index order (a new :class:`SphereSelection`, which the stress evaluation sums fast)."""
        return SphereSelection(self, self._mobile_mask())

    _mobile_selection = movableSphereList

    def do_linear_acceleration(self, dt):
        """Kick every sphere ``v += F·dt/m`` and reset its force (all move: :class:`CanvasPointsShear` has plates).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        kick(self._vel[:2], self._frc[:2], self._a["m"], dt)

    #: the velocity rows a damping step scales: (vx, vy), and ω where spheres spin
    _damped_rows = 2

    def cool(self, f=0.8):
        """Multiply the velocity relative to the affine flow ``γ̇ (y − Ly/2)`` (and any spin) by ``f``.

        Parameters
        ----------
        f : float
            Damping factor, 0 < f ≤ 1 (1 = no damping).
        """
        rate = getattr(self, "shear_rate", 0)
        damp(self._vel[:self._damped_rows], flow_velocity(self._pos[1], self.size_y, rate) if rate else None, f)

    def move(self, dt=1):
        """Drift every position by velocity × ``dt`` (with pairs: their ξ rule first, and φ turns by ω·dt).

        Parameters
        ----------
        dt : float
            Time step (s).
        """
        drift(self._pos, None, self._vel, dt)
        self._pos_version += 1

    def _le_shift(self):
        return 0.0

    def _y_centred(self):
        """``y − Ly/2`` of every sphere (µm)."""
        return self._pos[1] - self.size_y / 2

    def boundary_conditions(self):
        """Wrap every sphere into the cell (Lees-Edwards shifted where active).

        Raises :class:`SimulationInstabilityError` for a non-finite position or one more than
        :data:`MAX_CELLS_OUTSIDE` cell lengths outside.
        """
        a = self._a
        if not inside_cell(a["x"], a["y"], self.size_x, self.size_y):
            self._check_positions()
            wrap(a["x"], a["y"], a["xspeed"], float(self.size_x), float(self.size_y), float(self._le_shift()),
                 float(getattr(self, "shear_rate", 0)) if self.use_lees_edwards else 0.0)
        self._pos_version += 1

    def _check_positions(self, pos=None):
        """Raise SimulationInstabilityError for a non-finite or far-outside position among ``pos`` (2, n)."""
        pos = self._pos if pos is None else pos
        x, y = pos[0], pos[1]
        Lx, Ly = self.size_x, self.size_y
        far = MAX_CELLS_OUTSIDE * min(Lx, Ly)
        if _min_reduce(pos, axis=None) >= -far and _max_reduce(pos, axis=None) < max(Lx, Ly) + far:
            return  # two reductions (False for NaN) clear the ordinary case
        with np.errstate(invalid="ignore"):
            bad = ~((np.abs(x - Lx / 2) <= (MAX_CELLS_OUTSIDE + 0.5) * Lx)
                    & (np.abs(y - Ly / 2) <= (MAX_CELLS_OUTSIDE + 0.5) * Ly))
        if not bad.any():
            return
        k = int(np.flatnonzero(bad)[0])
        what = ("is not finite" if not (math.isfinite(x[k]) and math.isfinite(y[k]))
                else f"is more than {MAX_CELLS_OUTSIDE} cell lengths outside the {Lx:g} x {Ly:g} µm cell")
        a = self._a
        reason = (f"position (x, y) = ({float(x[k])!r}, {float(y[k])!r}) µm of sphere {k} {what} (velocity "
                  f"({float(a['xspeed'][k])!r}, {float(a['yspeed'][k])!r}) µm/s): a diverging step or a sphere "
                  "placed outside the cell")
        guard = getattr(self, "stability_guard", None) or StabilityGuard()
        guard._fail(self, getattr(self, "step_count", None), getattr(self, "phase", ""),
                    getattr(self, "_last_dt", None), reason, pair=(k,))

    def regular_sphere_distribution(self, rand_fraction=0.5):
        """Place the spheres on a square grid with random jitter.

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


def _register_filter(name, what):
    """The ``record_*`` method ``name`` of :class:`CanvasPointsMass`, documented as recording ``what`` ({}: quantity).

    It calls the register's method ``name`` for a mobile target; a pair entry (``record_individual_*``) is routed as
    the step routes it (:meth:`CanvasPointsMass._entry_of`): internal, external (``record_external_*``) or dropped.
    """
    force = name.endswith("force")
    pair = name.startswith("record_individual")
    register = attrgetter(name)
    external = attrgetter("record_external_" + ("force" if force else "torque"))

    def route(self, target, source, value):
        where = self._entry_of(target, source)
        if where == 1:
            register(self.force_register)(target, source, value)
        elif where == 2:
            external(self.force_register)(target, value)

    def filtered(self, target, source, value):
        if self.canMove(target):
            register(self.force_register)(target, value)

    quantity = "force ``(F_x, F_y)`` (mg·µm·s⁻² per m)" if force else "torque (mg·µm²·s⁻² per m)"
    rule = (".\n\nDropped on an immobile target; external from an immobile source or through the boundary." if pair
            else " unless it is immobile.")
    return record_method(name, "CanvasPointsMass", route if pair else filtered,
                         f"Record {what.format(quantity)} ``target``{rule}")


class CanvasPointsMass(CanvasPoints):
    """Adds the clock ``t`` (s), the force register and momentum bookkeeping.

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing
        As for :class:`CanvasPoints`.
    m : float
        Default sphere mass (mg per m depth); each sphere carries its own.
    """

    #: the clock (s)
    t = ReplicaValue()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPoints.__init__(self, size_x, size_y, theCanvas, doDrawing)
        self.t = 0
        self.force_register = Force_register()
        self.m = m

    def reset_force_register(self):
        """Clear the force register (start of a force phase)."""
        self.force_register.reset_force_register()

    # registration filters for scripts that apply forces sphere by sphere
    def _through_boundary(self, target, source):
        """Whether the pair acts through the periodic boundary (its minimum image removes a period)."""
        return False

    def _entry_of(self, target, source):
        """Where an entry of ``source`` on ``target`` goes: 0 nowhere (immobile target), 1 internal,
        2 external (:func:`~particleShear.engine.forces.pair_roles`, the rule of the step)."""
        internal, external, _ = pair_roles(self.canMove(target), self.canMove(source),
                                           np.bool_(self._through_boundary(target, source)))
        return 1 if internal else 2 if external else 0

    for _name, _what in (("record_individual_internal_force", "the pair {} of ``source`` on"),
                         ("record_individual_internal_torque", "the pair {} of ``source`` on"),
                         ("record_total_particle_force", "the total {} of"),
                         ("record_external_force", "an external {} on"),
                         ("record_external_torque", "an external {} on"),
                         ("record_unbalanced_moment", "the net {} of")):
        locals()[_name] = _register_filter(_name, _what)
    del _name, _what

    def _torque_total(self):
        return None

    def record_total_particle_forces(self):
        """Store the accumulated force of every mobile sphere (and torques, where spin exists)."""
        tot = self._frc.copy()
        self.force_register._set_totals(self, self._mobile_mask(), tot[0], tot[1],
                                        tot[2] if self._torque_total() is not None else None)

    def particle_info(self):
        return "Spheres with mass"

    def evaluate_stress_tensors(self, StressTensorEvaluator):
        """Evaluate every tensor (eqs. S1-16 to S1-24) of the register, mobile spheres and rate; return the evaluator.

        Parameters
        ----------
        StressTensorEvaluator : StressTensorEvaluation
        """
        sel = self._mobile_selection()
        StressTensorEvaluator.evaluate_stress_tensors(self.force_register, sel, getattr(self, "shear_rate", 0))
        return StressTensorEvaluator

    def reset_force(self):
        """Set the force of every sphere to zero."""
        self._frc[:2] = 0.0

    # momenta in raw coordinates (origin at the cell corner)
    def total_momentum(self):
        """Linear momentum ``Σ m v`` (mg·µm/s per m depth)."""
        a = self._a
        return np.array([a["m"] @ a["xspeed"], a["m"] @ a["yspeed"]])

    def total_angular_momentum(self):
        """``Σ m (x v_y − y v_x) + Σ I ω`` about the origin (mg·µm²/s per m depth)."""
        a = self._a
        return float(a["m"] @ (a["x"] * a["yspeed"] - a["y"] * a["xspeed"]) + a["inertia"] @ a["omega"])

