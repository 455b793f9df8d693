"""Stress tensors of the documented classes (eqs. S1-16 to S1-24; Nicot et al. with the factor 3/2).

:class:`StressTensorEvaluation` turns a :class:`~particleShear.base.register.Force_register` and a
list of spheres into :class:`~particleShear.engine.stress.StressInputs` of a batch of one replica
and evaluates :data:`particleShear.engine.stress.TENSORS`; G's shear stresses are
:func:`particleShear.engine.forces.shear_stresses` alone, or the xy entries of the full evaluation
(the same sums, :func:`~particleShear.engine.forces.shear_from_sums`).  Tensors are 2×2 in Pa,
``[a][b]`` = (force, lever-arm component), compression positive; forces ×1e-12 (N/m), lengths ×1e-6
(m), torques and inertias ×1e-18 (docs/output.md).
"""
__docformat__ = "numpy"

from operator import attrgetter

import numpy as np

from ..checks import positive
from ..engine import stress as _es
from ..engine.forces import pair_roles, shear_stresses as _engine_shear_stresses
from ..engine.stress import TENSORS, StressInputs
from ..engine.xp import get_backend
from .compiled_phases import tensor_sums
from .register import SphereSelection

__all__ = ["StressTensorEvaluation", "TENSOR_NAMES"]

#: tensor attribute names (the engine registry's), in the output table's column order (docs/output.md)
TENSOR_NAMES = tuple(t.name for t in TENSORS)
_INDEX = {t.function: k for k, t in enumerate(TENSORS)}
_EXT, _ALL = _es.EXTERNAL, _es.OVERALL

_ENS_OF = attrgetter("_ens")
_IDX_OF = attrgetter("_idx")
_NOT_ROWS = (False, None)


class OneReplicaRows:
    """Pair rows of a batch of one: the :class:`~particleShear.engine.forces.PairConstants` attributes tensors read.

    Parameters
    ----------
    ai, aj : ndarray of int (P,)
        Sphere rows of the two spheres of each pair row.
    """

    def __init__(self, ai, aj):
        self.ai = ai
        self.aj = aj
        self.P = P = len(ai)
        self.B = 1
        self.rep = np.zeros(P, dtype=np.intp)
        self.offsets = np.array((0, P))
        self.seg_rep = self.seg_rep_b = np.flatnonzero(self.offsets[1:] > self.offsets[:-1])
        self.seg_starts = self.seg_starts_b = self.offsets[:-1][self.seg_rep]
        self.backend = get_backend("numpy")   # the classes step NumPy arrays
        self.replica_sum = None                 # ordered reduceat per segment, as the engine on NumPy

    @classmethod
    def none(cls):
        """No pair rows (inputs of sphere rows only)."""
        return cls(np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp))


class ForcePhase(StressInputs):
    """The inputs of one force phase in three parts, each row function summed on its own part.

    Parameters
    ----------
    pairs, totals, spheres : StressInputs
        Inputs of the pair rows (also the cell volume ``V``), of the sphere-total rows, and of the
        kinetic rows (the caller's spheres, which need not be the register's).
    """

    def __init__(self, pairs, totals, spheres):
        super().__init__(B=1, V=pairs.V, pairs=pairs, totals=totals, spheres=spheres)

    def _part(self, rows):
        if rows.by_pair:
            return self.pairs
        return self.spheres if rows in _es.KINETIC_ROWS else self.totals

    def sums(self, rows):
        """The sums of ``rows`` on its part: shape (k, 1).

        Parameters
        ----------
        rows : callable
            A row function of :data:`~particleShear.engine.stress.ROWS`.
        """
        return self._part(rows).sums(rows)

    def reduce(self, groups):
        """Sum ``groups`` part by part (one reduction per kind of rows and part).

        Parameters
        ----------
        groups : iterable of callable
            Row functions of :data:`~particleShear.engine.stress.ROWS`.
        """
        parts = {}
        for g in groups:
            part = self._part(g)
            parts.setdefault(id(part), (part, []))[1].append(g)
        for part, gs in parts.values():
            part.reduce(gs)


def _cell(ev, shear_rate=None):
    """Cell inputs ``Lx, Ly, V`` of ``ev`` (kept per cell size), and ``rate`` if ``shear_rate`` is given."""
    key = (ev.size_x, ev.size_y)
    c = ev._cell_inputs
    if c is None or c[0] != key:
        c = ev._cell_inputs = (key, dict(B=1, Lx=np.array((float(ev.size_x),)), Ly=np.array((float(ev.size_y),)),
                                         V=np.array((ev._volume(),))))
    if shear_rate is None:
        return c[1]
    return dict(c[1], rate=np.array((float(shear_rate),)))


def _with_mobile(q, mob):
    """A copy of the inputs ``q`` whose sphere sums run over the spheres of mask ``mob``."""
    d = {k: v for k, v in q.__dict__.items() if not k.startswith("_")}   # not what was evaluated
    d["mob"] = mob
    return type(q)(**d)


def _tensor_property(k):
    def fget(self):
        return self._t[k].tolist()

    def fset(self, value):
        self._t[k] = np.asarray(value, dtype=float)

    return property(fget, fset, doc="2×2 tensor (Pa), nested lists; see docs/output.md (eqs. S1-16 to S1-24).")


def _engine_phase(reg):
    """The register's sole engine force phase if a host batch of one with F_j = −F_i, else None (read by entry)."""
    ph = reg.engine_phase()
    if ph is None or ph.terms.fx_j is not None or not ph.one_host_replica:
        return None
    return ph


def _phase_arrays(ph, ens):
    """(C, active, dx, dy, fx_i, fy_i, dF = d·F_T, eq. S1-3) of an engine force phase; pair vectors are
    retaken from the positions if a sphere moved since (only internal pairs, never through the boundary, use them)."""
    t = ph.terms
    C = t.C
    dx, dy = t.dx, t.dy
    if ph.pos_version != ens._pos_version:
        pos = ens._pos
        dx, dy = pos.take(C.aj, axis=1) - pos.take(C.ai, axis=1)
    return C, t.active, dx, dy, t.fx_i, t.fy_i, t.dF


def _shear_inputs(q):
    """The engine shear-stress function's arguments after ``C, B``, from pair inputs ``q``."""
    C = q.C
    return (q.y - q.Ly[0] / 2, pair_roles(q.mob[C.ai], q.mob[C.aj], q.shifted), q.active, q.dy, q.fx_i, q.dF, q.V)


def _stack(columns, kinds):
    """Concatenate each column of the row blocks ``columns`` (a list of tuples of arrays), or zeros of
    ``kinds`` (one dtype per column) when there are no blocks."""
    if not columns:
        return [np.zeros(0, dtype=k) for k in kinds]
    return [np.concatenate(c) for c in zip(*columns)]


def _entries(reg):
    """The register's pair entries (eqs. S1-16, S1-19, S1-22) as pair inputs of a batch of one.

    Each entry (target, source) is a pair row with rows of its own (0 … n−1, n … 2n−1), mobile where
    the register gives it an entry, ``shifted = ~internal``: so the engine's rules reproduce the
    register's flags.  Internal entries carry half their force (the reference registers each side).
    """
    cols = []     # (tx, ty, sx, sy, fx, fy, dF, internal, external, active) of each block of entries
    for p in reg._blocks:
        i, j = p["i"], p["j"]
        if not len(i):
            continue
        x, y = reg._ens._a["x"], reg._ens._a["y"]
        act = p.get("active")
        act = np.ones(len(i), dtype=bool) if act is None else act
        for t, s, F, ext, torque in ((i, j, p["Fi"], p["ext_i"], p.get("ti")), (j, i, p["Fj"], p["ext_j"], p.get("tj"))):
            cols.append((x[t], y[t], x[s], y[s], F[0], F[1], np.zeros(len(i)) if torque is None else torque,
                         p["internal"], ext, act))
    manual = ([(t, s, f, 0.0, True) for t, s, f in reg._m_pair]
              + [(t, t, f, 0.0, False) for t, f in reg._m_ext]
              + [(t, s, (0.0, 0.0), m, True) for t, s, m in reg._m_imom])
    if manual:
        rows = np.array([(t.x, t.y, s.x, s.y, f[0], f[1], m) for t, s, f, m, _ in manual], dtype=float)
        flag = np.array([e[4] for e in manual], dtype=bool)
        cols.append((*rows.T, flag, ~flag, np.ones(len(manual), dtype=bool)))
    tx, ty, sx, sy, fx, fy, dF, internal, external, active = _stack(cols, (float,) * 7 + (bool,) * 3)
    n = len(tx)
    half = np.where(internal, 0.5, 1.0)   # × ½ is exact
    return dict(C=OneReplicaRows(np.arange(n), np.arange(n, 2 * n)), rep=np.zeros(2 * n, dtype=np.intp),
                x=np.concatenate((tx, sx)), y=np.concatenate((ty, sy)),
                mob=np.concatenate((internal | external, internal)), active=active, shifted=~internal,
                dx=sx - tx, dy=sy - ty, fx_i=fx * half, fy_i=fy * half, dF=dF)


def _totals(reg):
    """The register's sphere totals as sphere inputs of a batch of one (eqs. S1-17, S1-22).

    Rows: the ensemble's spheres (torque of immobile ones included: the reference's quirk), then the
    manual totals (mobile), then the manual net torques (torque only).
    """
    cols = []     # (x, y, fx, fy, torque, mob) of each block of rows
    if reg._tot is not None or reg._mom is not None:
        a = reg._ens._a
        n = len(a["x"])
        zero = np.zeros(n)
        mask, tfx, tfy = reg._tot if reg._tot is not None else (np.zeros(n, dtype=bool), zero, zero)
        cols.append((a["x"], a["y"], tfx, tfy, zero if reg._mom is None else reg._mom,
                     np.ones(n, dtype=bool) if mask is None else mask))
    manual = ([(t, f, 0.0, True) for t, f in reg._m_tot.values()]
              + [(t, (0.0, 0.0), m, False) for t, m in reg._m_unb.values()])
    if manual:
        rows = np.array([(t.x, t.y, f[0], f[1], m) for t, f, m, _ in manual], dtype=float)
        cols.append((*rows.T, np.array([e[3] for e in manual], dtype=bool)))
    x, y, fx, fy, torque, mob = _stack(cols, (float,) * 5 + (bool,))
    return dict(rep=np.zeros(len(x), dtype=np.intp), x=x, y=y, mob=mob, fx=fx, fy=fy, torque=torque)


class StressTensorEvaluation:
    """Evaluates every stress tensor (eqs. S1-16 to S1-24) of a :class:`Force_register`.

    The tensors are attributes named in :data:`TENSOR_NAMES`, 2×2 nested lists in Pa; cell volume
    ``V = (size_x·1e-6)·(size_y·1e-6)`` m² per m depth.

    Parameters
    ----------
    size_x, size_y : float
        Width Lx and height Ly of the periodic cell (µm).
    theCanvas : object or bool
        Tk canvas (stored for compatibility; False when none).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0 (TypeError: not a real number).
    """

    def __init__(self, size_x, size_y, theCanvas=False):
        positive("size_x", size_x)
        positive("size_y", size_y)
        self.size_x = size_x
        self.size_y = size_y
        self.theCanvas = theCanvas
        self.graphical_output_configuration = None
        self.toDeleteList = []
        self._t = np.zeros((len(TENSORS), 2, 2))
        self._spheres = None   # (N, rep, all-mobile mask, zero torques) of the last ensemble size
        self._cell_inputs = None   # (key, Lx, Ly, rate, V arrays) of the last evaluation

    for _k, _name in enumerate(TENSOR_NAMES):
        locals()[_name] = _tensor_property(_k)
    del _k, _name

    @property
    def tensors(self):
        """All nine tensors as an array of shape (9, 2, 2) in output-column order."""
        return self._t

    def _volume(self):
        return (self.size_x * 1e-6) * (self.size_y * 1e-6)

    # -- sphere lists -----------------------------------------------------------------------
    @staticmethod
    def _rows_of(ens, spheres):
        """``(True, mask)`` if ``spheres`` are rows of ``ens`` in index order, each once (``mask`` None: all),
        else ``(False, None)``: then read sphere by sphere."""
        if ens is None:
            return _NOT_ROWS
        if isinstance(spheres, SphereSelection) and spheres.ensemble is ens and spheres.is_current():
            return True, spheres.mask
        sl = ens.sphereList
        if spheres is sl:
            return True, None
        if not isinstance(spheres, (list, tuple)):
            return _NOT_ROWS
        m = len(spheres)
        n = len(sl)
        if not m or m > n:
            return _NOT_ROWS
        try:
            owners = set(map(_ENS_OF, spheres))
            idx = np.array(list(map(_IDX_OF, spheres)))
        except AttributeError:
            return _NOT_ROWS
        if len(owners) != 1 or ens not in owners:
            return _NOT_ROWS
        if m > 1 and not (idx[1:] > idx[:-1]).all():
            return _NOT_ROWS   # repeated or reordered spheres: summed one by one, as given
        if m == n:
            return True, None
        mask = np.zeros(n, dtype=bool)
        mask[idx] = True
        return True, mask

    def _sphere_values(self, theSphereList, ens=None):
        """(I, omega, m, vx, vy, y) arrays of the spheres in a list or selection."""
        if ens is None:
            ens = getattr(theSphereList, "ensemble", None)
            if ens is None and isinstance(theSphereList, (list, tuple)) and len(theSphereList):
                ens = getattr(theSphereList[0], "_ens", None)
        ok, mk = self._rows_of(ens, theSphereList)
        if ok:
            a = ens._a
            if mk is None:
                return a["inertia"], a["omega"], a["m"], a["xspeed"], a["yspeed"], a["y"]
            return (a["inertia"][mk], a["omega"][mk], a["m"][mk], a["xspeed"][mk],
                    a["yspeed"][mk], a["y"][mk])
        sl = list(theSphereList)
        vals = [[getattr(s, "inertia", 0.0), getattr(s, "omega", 0.0), s.m, s.xspeed, s.yspeed, s.y]
                for s in sl]
        arr = np.array(vals, dtype=float).reshape(-1, 6)
        return tuple(arr[:, q] for q in range(6))

    # -- the engine's inputs ------------------------------------------------------------------
    def _per_sphere(self, n):
        """(replica index, all-mobile mask, zero torques) of ``n`` spheres, kept per size."""
        s = self._spheres
        if s is None or s[0] != n:
            s = self._spheres = (n, np.zeros(n, dtype=np.intp), np.ones(n, dtype=bool), np.zeros(n))
        return s[1:]

    def _shear_from_register(self, reg):
        """(τ_internal, τ_surface) of the register (eq. S1-25): the σ_xy-only evaluation."""
        cell = _cell(self)
        ph = _engine_phase(reg)
        if ph is not None:
            ens = reg._ens
            C, active, _, dy, fx_i, _, dF = _phase_arrays(ph, ens)
            mob = ph.terms.mob
            # y − Ly/2 of the spheres: the ensemble's own (kept per position update) when the cells agree
            yc = ens._y_centred() if ens.size_y == self.size_y else ens._a["y"] - self.size_y / 2
            roles = pair_roles(mob[C.ai], mob[C.aj], ph.terms.shifted)
            tau = _engine_shear_stresses(C, 1, yc, roles, active, dy, fx_i, dF, cell["V"])
        else:
            q = StressInputs(**_entries(reg), **cell)
            tau = _engine_shear_stresses(q.C, 1, *_shear_inputs(q))
        return float(tau[0][0]), float(tau[1][0])

    def _array_inputs(self, reg, spheres, shear_rate):
        """Inputs from the register's engine force phase, its totals and the ensemble's arrays, or None
        unless :func:`_engine_phase` holds; the kinetic part is the phase's own rows when ``spheres``
        are its mobile spheres, else their rows of the ensemble, else their values read one by one."""
        ph = _engine_phase(reg)
        if ph is None or reg._tot is None:
            return None
        ens = reg._ens
        mob, fx, fy = reg._tot
        a = ens._a
        rep, everyone, no_torque = self._per_sphere(len(a["x"]))
        C, active, dx, dy, fx_i, fy_i, dF = _phase_arrays(ph, ens)
        q = StressInputs(C=C, rep=rep, x=a["x"], y=a["y"], vx=a["xspeed"], vy=a["yspeed"],
                         omega=a["omega"], m=a["m"], inertia=a["inertia"], mob=everyone if mob is None else mob,
                         active=active, shifted=ph.terms.shifted, dx=dx, dy=dy, fx_i=fx_i, fy_i=fy_i, dF=dF,
                         fx=fx, fy=fy, torque=no_torque if reg._mom is None else reg._mom,
                         **_cell(self, shear_rate))
        ok, mask = self._rows_of(ens, spheres)
        if not ok:
            return ForcePhase(q, q, self._sphere_inputs(spheres, shear_rate))
        if mask is mob or (mask is not None and mob is not None and np.array_equal(mask, mob)):
            return q
        return ForcePhase(q, q, _with_mobile(q, everyone if mask is None else mask))

    def _sphere_inputs(self, theSphereList, shear_rate=0.0):
        """The spheres of a list as the engine's sphere inputs of a batch of one (all counted)."""
        inertia, omega, m, vx, vy, y = self._sphere_values(theSphereList)
        n = len(m)
        return StressInputs(C=OneReplicaRows.none(), rep=np.zeros(n, dtype=np.intp), inertia=inertia, omega=omega, m=m,
                            vx=vx, vy=vy, y=y, mob=np.ones(n, dtype=bool), **_cell(self, shear_rate))

    def _pair_inputs(self, reg):
        return StressInputs(**_entries(reg), **_cell(self))

    def _total_inputs(self, reg):
        return StressInputs(C=OneReplicaRows.none(), **_totals(reg), **_cell(self))

    def _store(self, q, functions):
        """Evaluate ``functions`` of the registry on ``q`` into the tensor attributes."""
        for f in functions:
            self._t[_INDEX[f]] = q.tensor(f)[0]

    # -- force tensors ----------------------------------------------------------------------
    def evaluate_force_stress_tensors(self, force_register):
        """Love-Weber, unbalanced-force, linear-acceleration and external-force tensors (eqs. S1-19, S1-17, S1-16).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        """
        self._store(self._pair_inputs(force_register), (_es.love_weber, _es.external_forces))
        self._store(self._total_inputs(force_register), (_es.unbalanced_forces, _es.linear_acceleration))

    # -- rotational tensors -------------------------------------------------------------------
    def evaluate_spin_kinetic_energy_stress_tensor(self, theSphereList):
        """Centrifugal tensor ``-(1/V) Σ I ω²/2 · 1`` over the given spheres (eq. S1-21).

        Parameters
        ----------
        theSphereList : list
            The spheres to sum over (in the experiment, ``movableSphereList()``).
        """
        self._store(self._sphere_inputs(theSphereList), (_es.spin_kinetic_energy,))

    def evaluate_unbalanced_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of all net torques, immobile spheres included (eq. S1-22).

        Parameters
        ----------
        force_register : Force_register
        """
        self._store(self._total_inputs(force_register), (_es.unbalanced_torque,))

    def evaluate_internal_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of the internal pair torques (eq. S1-22); symmetrises Love-Weber (eq. S1-24).

        Parameters
        ----------
        force_register : Force_register
        """
        self._store(self._pair_inputs(force_register), (_es.internal_torque,))

    def evaluate_rotational_stress_tensors(self, force_register, theSphereList):
        """Centrifugal, unbalanced-torque and internal-torque tensors (eqs. S1-21, S1-22).

        Parameters
        ----------
        force_register : Force_register
        theSphereList : list
            The spheres to sum over (in the experiment, ``movableSphereList()``).
        """
        self.evaluate_spin_kinetic_energy_stress_tensor(theSphereList)
        self.evaluate_unbalanced_torque_stress_tensor(force_register)
        self.evaluate_internal_torque_stress_tensor(force_register)

    def evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(self, theSphereList, shear_rate):
        """Otsuki peculiar-momentum term ``-(1/V) Σ P ⊗ P / m``, for comparison only (never enters G).

        Parameters
        ----------
        theSphereList : list
            The spheres to sum over (in the experiment, ``movableSphereList()``).
        shear_rate : float
            Shear rate γ̇ (1/s) of the affine flow the peculiar velocities are taken against.
        """
        self._store(self._sphere_inputs(theSphereList, shear_rate), (_es.peculiar_acceleration_otsuki,))

    def evaluate_stress_tensors(self, force_register, theSphereList, shear_rate):
        """Every tensor and the overall tensor ``σ = σ_LW + σ_Tint + σ_cen`` (eq. S1-24).

        The xy entries of the overall and external-force tensors are the shear stresses of
        :meth:`evaluate_shear_stresses` bit for bit (the same sums in the same formula), so G does
        not depend on whether tensors are kept.

        Parameters
        ----------
        force_register : Force_register
        theSphereList : list
            The spheres of the spin and Otsuki sums (in the experiment, ``movableSphereList()``).
        shear_rate : float
            Shear rate γ̇ (1/s) of the affine flow.
        """
        reg = force_register
        q = self._array_inputs(reg, theSphereList, shear_rate)
        if q is None:
            q = ForcePhase(self._pair_inputs(reg), self._total_inputs(reg),
                           self._sphere_inputs(theSphereList, shear_rate))
        elif type(q) is StressInputs and q.C.backend.compiled:    # the rows summed in compiled code (same bits)
            self._t[...] = _es.tensors_from_sums(tensor_sums(q), q.V)[0]
            return
        self._t[...] = _es.evaluate_all(q)[0]

    def evaluate_shear_stresses(self, force_register, theSphereList):
        """Only what G needs: update the xy entries of the overall and external-force tensors.

        Returns ``(τ_internal, τ_surface)`` (Pa, eq. S1-25), the numbers the full evaluation stores.

        Parameters
        ----------
        force_register : Force_register
        theSphereList : list
            Unused: the shear stresses do not depend on it (the centrifugal tensor has no xy entry).
        """
        tau_internal, tau_surface = self._shear_from_register(force_register)
        self._t[_ALL, 0, 1] = -tau_internal
        self._t[_EXT, 0, 1] = -tau_surface
        return tau_internal, tau_surface

    def evaluate_quasistatic_shear_stress(self):
        """Return τ_internal = −σ_xy of the overall tensor of the last evaluation (Pa, eq. S1-25)."""
        return -float(self._t[_ALL, 0, 1])

    def evaluate_externally_applied_shear_stress(self):
        """Return τ_surface = −σ_xy of the external-force tensor of the last evaluation (Pa, eq. S1-25)."""
        return -float(self._t[_EXT, 0, 1])
