"""Stress tensors from the force register (eqs. S1-16 to S1-25; Nicot et al. with the factor 3/2).

All tensors are 2×2 in Pa, index ``[a][b]`` = (force component, lever-arm
component), compression positive.  Internal units are converted here only:
forces ×1e-12 (N/m), lengths ×1e-6 (m), torques and inertias ×1e-18.
"""
__docformat__ = "numpy"

from operator import attrgetter

import numpy as np

from .fields import MASS_ROWS
from .namespace import dot as _dot
from .register import SphereSelection

__all__ = ["StressTensorEvaluation", "TENSOR_NAMES"]

#: tensor attribute names in the column order of the output table (docs/output.md, "Table columns")
TENSOR_NAMES = (
    "stress_tensor_LW",
    "stress_tensor_linear_acceleration_otsuki",
    "stress_tensor_with_external_forces",
    "stress_tensor_linear_acceleration",
    "stress_tensor_unbalanced_forces",
    "stress_tensor_unbalanced_torque",
    "stress_tensor_internal_torque",
    "stress_tensor_spin_kinetic_energy",
    "overall_stress_tensor",
)
(_LW, _OT, _EXT, _LIN, _UNB, _TQ, _TINT, _CEN, _ALL) = range(9)
# flat positions of the entries [k, a, b] (4k + 2a + b) written as scalars
_TQ00, _TQ01, _TQ10, _TQ11 = range(4 * _TQ, 4 * _TQ + 4)
_TI00, _TI01, _TI10, _TI11 = range(4 * _TINT, 4 * _TINT + 4)
_CE00, _CE01, _CE10, _CE11 = range(4 * _CEN, 4 * _CEN + 4)

#: rows (m, m, inertia) of the ensemble state block: weights of (u_x, u_y, ω) in the kinetic tensors
_MASS_ROWS = np.array(MASS_ROWS)

_CF = 1e-12
_ENS_OF = attrgetter("_ens")
_IDX_OF = attrgetter("_idx")
_NOT_ROWS = (False, None)
_CL = 1e-6
_CT = 1e-18


def _internal_moment(p, pos, pos_version, out):
    """``Σ F_i ⊗ (x_j − x_i)`` (unscaled, into the (2, 2) ``out``) over the internal pairs of an engine
    register block with F_j = −F_i; the caller multiplies by −scale.

    Internal pairs never act through the boundary, so ``x_j − x_i`` is the pair vector of the force
    phase while no sphere has moved since; otherwise positions are gathered anew.
    """
    S = p["S"]
    F = p["Fi"]
    if S.w_int is not None:
        F = F * S.w_int2.reshape(2, -1)   # weights on both rows: a same-shape product, no broadcasting
    if p["pos_version"] == pos_version:
        return _dot(F, p["D"].T, out)
    L = pos.take(p["i"], axis=1)
    L -= pos.take(p["j"], axis=1)
    return np.negative(_dot(F, L.T), out=out)   # −(Σ F ⊗ (x_i − x_j)); × −scale is exact


def _external_moment(p, pos, c, scale=_CF * _CL, out=None, X=None):
    """``scale · Σ F ⊗ (x_target − c)`` over the external entries of an engine register block, or None.

    ``X`` may give ``pos − c`` already computed; ``scale=None`` leaves the sum unscaled (into ``out``)."""
    S = p["S"]
    if not len(S.ext_targets):
        return None
    F = p["W"].take(S.ext_flat)   # from the flat (F_i, F_j, …) array of the flush: one gather, no signs
    if X is None:
        Xt = pos.take(S.ext_targets, axis=1)
        Xt -= c
    else:
        Xt = X.take(S.ext_targets, axis=1)
    if scale is None:
        return _dot(F, Xt.T, out)
    return np.multiply(_dot(F, Xt.T), scale, out=out)


def _tensor_property(k):
    def fget(self):
        return self._t[k].tolist()

    def fset(self, value):
        self._t[k] = np.asarray(value, dtype=float)

    return property(fget, fset, doc="2×2 tensor (Pa), nested lists; see docs/output.md (eqs. S1-16 to S1-24).")


class StressTensorEvaluation:
    """Evaluates every stress tensor (eqs. S1-16 to S1-24) from a :class:`Force_register` with array operations.

    The tensors are attributes (``overall_stress_tensor``, ``stress_tensor_LW`` …; see
    :data:`TENSOR_NAMES`), 2×2 nested lists in Pa, recomputed by each ``evaluate_*`` call.
    The cell volume is ``V = (size_x·1e-6)·(size_y·1e-6)`` m² per m depth.

    Parameters
    ----------
    size_x : float
        Width Lx of the periodic cell (µm), finite and > 0.
    size_y : float
        Height Ly of the cell (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas for drawing (stored for compatibility; False when none).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    def __init__(self, size_x, size_y, theCanvas=False):
        for name, v in (("size_x", size_x), ("size_y", size_y)):
            if not (isinstance(v, (int, float, np.number)) and np.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        self.size_x = size_x
        self.size_y = size_y
        self.theCanvas = theCanvas
        self.graphical_output_configuration = None
        self.toDeleteList = []
        self._t = np.zeros((9, 2, 2))
        self._tflat = self._t.reshape(-1)
        self._raw = np.zeros((5, 2, 2))
        self._w_cache = None

    for _k, _name in enumerate(TENSOR_NAMES):
        locals()[_name] = _tensor_property(_k)
    del _k, _name

    @property
    def tensors(self):
        """All nine tensors as an array of shape (9, 2, 2) in output-column order."""
        return self._t

    def _volume(self):
        return (self.size_x * _CL) * (self.size_y * _CL)

    def _cell(self):
        """(key, V, centre as a (2, 1) column, sv = 1e-18/V, scales of the first five tensors) of the
        cell, kept per cell size."""
        key = (self.size_x, self.size_y)
        c = getattr(self, "_cell_cache", None)
        if c is None or c[0] != key:
            V = self._volume()
            sv = _CF * _CL / V
            scale5 = np.array((-sv, -1e-18 / V, -sv, sv, sv)).reshape(5, 1, 1)
            c = self._cell_cache = (key, V, np.array(((self.size_x / 2,), (self.size_y / 2,))), sv, scale5)
        return c

    # -- sphere lists -----------------------------------------------------------------------
    @staticmethod
    def _rows_of(ens, spheres):
        """``(True, mask)`` when ``spheres`` are rows of ``ens``'s arrays in index order, each once
        (``mask`` None: all of them), else ``(False, None)``: the list is then read sphere by sphere.

        ``sphereList`` and the selections of ``movableSphereList()`` are recognised at once; another
        list or tuple by one pass over its spheres' ensemble and index.
        """
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

    # -- force tensors ----------------------------------------------------------------------
    def evaluate_force_stress_tensors(self, force_register):
        """Love-Weber, unbalanced-force, linear-acceleration and external-force tensors (eqs. S1-19, S1-17, S1-16).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        """
        V = self._volume()
        cx, cy = self.size_x / 2, self.size_y / 2
        lw = np.zeros((2, 2))
        ext = np.zeros((2, 2))
        unb = np.zeros((2, 2))
        reg = force_register
        ens = reg._ens
        for p in reg._blocks:
            if not len(p["i"]):
                continue
            x = ens._a["x"]
            y = ens._a["y"]
            i, j = p["i"], p["j"]
            internal = p["internal"]
            fix, fiy, fjx, fjy = p["fix"], p["fiy"], p["fjx"], p["fjy"]
            if not internal.all():
                w = np.flatnonzero(internal)
                i_, j_ = i[w], j[w]
                fix, fiy, fjx, fjy = fix[w], fiy[w], fjx[w], fjy[w]
            else:
                i_, j_ = i, j
            if len(i_):
                ddx = x[i_] - x[j_]
                ddy = y[i_] - y[j_]
                if p.get("antisymmetric", True):
                    # F_j = −F_i: the two entries of a pair are equal and their halves add up exactly
                    lw += (np.array((fix, fiy)) * _CF) @ np.array((ddx, ddy)).T * _CL
                else:
                    gx = fix * _CF
                    gy = fiy * _CF
                    hx = fjx * _CF
                    hy = fjy * _CF
                    for a_, gi, gj in ((0, gx, hx), (1, gy, hy)):
                        for b_, dd in ((0, ddx), (1, ddy)):
                            lw[a_, b_] += np.sum(gi * dd * _CL / 2) + np.sum(gj * -dd * _CL / 2)
            for side, idx, fx, fy in (("ext_i", i, p["fix"], p["fiy"]), ("ext_j", j, p["fjx"], p["fjy"])):
                m = p[side]
                if m.any():
                    w = np.flatnonzero(m)
                    t = idx[w]
                    lx = (x[t] - cx) * _CL
                    ly = (y[t] - cy) * _CL
                    gx = fx[w] * _CF
                    gy = fy[w] * _CF
                    ext -= [[gx @ lx, gx @ ly], [gy @ lx, gy @ ly]]
        if reg._tot is not None:
            mobile, fx, fy = reg._tot
            x = ens._a["x"]
            y = ens._a["y"]
            F = np.array((fx, fy))
            X = np.array((x - cx, y - cy))
            if mobile is not None:
                F = F[:, mobile]
                X = X[:, mobile]
            unb += (F * _CF) @ (X * _CL).T
        for t, s, f in reg._m_pair:
            d = ((t.x - s.x) * _CL, (t.y - s.y) * _CL)
            for a in range(2):
                for b in range(2):
                    lw[a, b] += f[a] * _CF * d[b] / 2
        for t, f in reg._m_ext:
            d = ((t.x - cx) * _CL, (t.y - cy) * _CL)
            for a in range(2):
                for b in range(2):
                    ext[a, b] -= f[a] * _CF * d[b]
        for t, f in reg._m_tot.values():
            d = ((t.x - cx) * _CL, (t.y - cy) * _CL)
            for a in range(2):
                for b in range(2):
                    unb[a, b] += f[a] * _CF * d[b]
        self._t[_LW] = lw / V
        self._t[_EXT] = ext / V
        self._t[_UNB] = unb / V
        self._t[_LIN] = self._t[_UNB]

    # -- rotational tensors -------------------------------------------------------------------
    def evaluate_spin_kinetic_energy_stress_tensor(self, theSphereList):
        """Centrifugal tensor ``-(1/V) Σ I ω²/2 · 1`` over the given spheres (eq. S1-21).

        Parameters
        ----------
        theSphereList : list
            The spheres to sum over (in the experiment, the mobile ones: ``movableSphereList()``).
        """
        inertia, omega = self._sphere_values(theSphereList)[:2]
        K = float(np.sum((inertia * _CT) * omega ** 2 / 2))
        v = -K / self._volume()
        self._t[_CEN] = [[v, 0.0], [0.0, v]]

    @staticmethod
    def _antisym(total, V):
        s = total * _CT / V
        return [[0.0, -s / 2], [s / 2, 0.0]]

    def evaluate_unbalanced_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of all net torques, immobile spheres included (eq. S1-22).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        """
        total = 0.0
        if force_register._mom is not None:
            total += float(np.sum(force_register._mom))
        total += sum(m for _, m in force_register._m_unb.values())
        self._t[_TQ] = self._antisym(total, self._volume())

    def evaluate_internal_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of the internal pair torques (eq. S1-22); symmetrises Love-Weber (eq. S1-24).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        """
        total = 0.0
        for p in force_register._blocks:
            if p.get("ti") is not None:
                internal = p["internal"]
                total += float(np.sum(p["ti"][internal]) + np.sum(p["tj"][internal]))
        total += sum(m for _, _, m in force_register._m_imom)
        self._t[_TINT] = self._antisym(total, self._volume())

    def evaluate_rotational_stress_tensors(self, force_register, theSphereList):
        """Centrifugal, unbalanced-torque and internal-torque tensors (eqs. S1-21, S1-22).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        theSphereList : list
            The spheres to sum over (in the experiment, the mobile ones: ``movableSphereList()``).
        """
        self.evaluate_spin_kinetic_energy_stress_tensor(theSphereList)
        self.evaluate_unbalanced_torque_stress_tensor(force_register)
        self.evaluate_internal_torque_stress_tensor(force_register)

    def evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(self, theSphereList, shear_rate):
        """Otsuki peculiar-momentum term ``-(1/V) Σ P ⊗ P / m``, for comparison only (never enters G).

        Parameters
        ----------
        theSphereList : list
            The spheres to sum over (in the experiment, the mobile ones: ``movableSphereList()``).
        shear_rate : float
            Shear rate γ̇ of the affine flow (1/s) that the peculiar velocities are taken against.
        """
        _, _, m, vx, vy, y = self._sphere_values(theSphereList)
        px = m * 1e-12 * (vx - shear_rate * (y - self.size_y / 2))
        py = m * 1e-12 * vy
        mm = m * 1e-6
        xx = -float(np.sum(px * px / mm))
        xy = -float(np.sum(px * py / mm))
        yy = -float(np.sum(py * py / mm))
        V = self._volume()
        self._t[_OT] = [[xx / V, xy / V], [xy / V, yy / V]]

    def evaluate_stress_tensors(self, force_register, theSphereList, shear_rate):
        """Every tensor and the overall tensor ``σ = σ_LW + σ_Tint + σ_cen`` (eq. S1-24).

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        theSphereList : list
            The spheres to sum over (in the experiment, the mobile ones: ``movableSphereList()``).
        shear_rate : float
            Shear rate γ̇ of the affine flow (1/s) that the peculiar velocities are taken against.
        """
        reg = force_register
        if len(reg._blocks) == 1 and reg._tot is not None and not reg._manual and "S" in reg._blocks[0]:
            ok, mask = self._rows_of(reg._ens, theSphereList)
            if ok:
                self._evaluate_arrays(reg, mask, shear_rate)
                return
        self.evaluate_force_stress_tensors(force_register)
        self.evaluate_rotational_stress_tensors(force_register, theSphereList)
        self.evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(theSphereList, shear_rate)
        self._t[_ALL] = self._t[_LW] + self._t[_TINT] + self._t[_CEN]

    def _evaluate_arrays(self, reg, mobile, shear_rate):
        """All tensors of one engine force phase in a few array operations (same formulas as above).

        ``mobile`` is the mask of the spheres passed by the caller (None: all), the spheres of the
        spin and Otsuki sums; the unbalanced-force tensor sums over the register's mobile spheres.
        Sums over spheres are dot products with the masks as weights; the Otsuki and spin terms
        come from one 3×3 product over (u_x, u_y, ω)."""
        t = self._t
        ens = reg._ens
        pos = ens._pos
        _, V, c, sv, scale5 = self._cell()   # sv: forces × lever arms in SI, per volume
        p = reg._blocks[0]
        S = p["S"]
        n_int = S.n_int
        X = pos - c
        # unscaled sums of the first five tensors (LW, Otsuki, external, linear acceleration, unbalanced),
        # scaled by one multiply: −sv, −1e-18/V, −sv, sv, sv
        raw = self._raw
        lw_pairs = n_int and p["antisymmetric"]
        if lw_pairs:
            _internal_moment(p, pos, ens._pos_version, raw[_LW])
        ext = n_int != S.P and _external_moment(p, pos, c, None, out=raw[_EXT], X=X) is not None
        Wm, mobf = self._mobile_weights(ens, mobile)
        reg_mobile = reg._tot[0]   # the spheres of total_particle_force_register
        if reg_mobile is mobile:
            Xm = X if mobile is None else X * mobf
        else:
            Xm = X if reg_mobile is None else X * reg_mobile
        _dot(reg._tot_block[:2], Xm.T, raw[_UNB])
        raw[_LIN] = raw[_UNB]
        # (u_x, u_y, ω) with u the velocity relative to the affine flow; weights (m, m, I) of mobile spheres
        U = ens._vel.copy()
        if shear_rate:
            U[0] -= ens._affine_vx(shear_rate)   # = shear_rate · X[1], shared with the damping
        Wt = Wm * U
        M = _dot(Wt, U.T)
        raw[_OT] = M[:2, :2]   # −Σ m u⊗u / V in SI: mass 1e-6 kg/m, velocity 1e-6 m/s
        np.multiply(raw, scale5, out=t[:5])
        if not lw_pairs:
            if n_int:
                self.evaluate_force_stress_tensors(reg)
            else:
                t[_LW] = 0.0
        if not ext:
            t[_EXT] = 0.0
        K = float(M[2, 2]) * (_CT / 2) / V
        total = float(np.add.reduce(reg._mom)) if reg._mom is not None else 0.0
        s_ = total * _CT / V
        tint = self._internal_torque(p) if n_int else 0.0
        s2 = tint * _CT / V
        # the scalar entries of the torque, internal-torque and spin tensors, through the flat view
        tf = self._tflat
        tf[_TQ00] = tf[_TQ11] = 0.0
        tf[_TQ01] = -s_ / 2
        tf[_TQ10] = s_ / 2
        tf[_TI00] = tf[_TI11] = 0.0
        tf[_TI01] = -s2 / 2
        tf[_TI10] = s2 / 2
        tf[_CE00] = tf[_CE11] = -K
        tf[_CE01] = tf[_CE10] = 0.0
        np.add(t[_LW], t[_TINT], out=t[_ALL])
        t[_ALL] += t[_CEN]

    def _mobile_weights(self, ens, mobile):
        """(m, m, I) of the mobile spheres (0 for the others), shape (3, N), and the mobility mask
        as floats on two rows; kept while the ensemble's masses and the mask (same object while
        unchanged) stay."""
        key = (ens, ens._params_version, mobile)
        w = getattr(self, "_w_cache", None)
        if w is None or w[0][0] is not ens or w[0][1] != key[1] or w[0][2] is not mobile:
            Wt = ens._st.take(_MASS_ROWS, axis=0)
            mobf = None
            if mobile is not None:
                mobf = mobile.astype(float)
                Wt *= mobf
                mobf = np.array((mobf, mobf))   # for the (2, N) lever arms: same shape, no broadcasting
            w = self._w_cache = (key, Wt, mobf)
        return w[1], w[2]

    def _centre(self):
        """Cell centre as a (2, 1) column (µm)."""
        return self._cell()[2]

    @staticmethod
    def _internal_torque(p):
        """Σ (t_i + t_j) over the internal pairs of an engine register block (internal units)."""
        T = p.get("T")
        if T is None:
            return 0.0
        S = p["S"]
        if S.w_int is None:
            return float(np.add.reduce(T))
        return float(_dot(S.w_int2, T))   # T = (t_i of every pair, t_j of every pair)

    def evaluate_shear_stresses(self, force_register, theSphereList):
        """Only what G needs: σ_xy of the overall and of the external-force tensor (Pa).

        Returns ``(τ_internal, τ_surface)`` computed with exactly the operations of
        the full evaluation, so G does not depend on whether tensors are kept.
        The other tensor entries are not updated.

        Parameters
        ----------
        force_register : Force_register
            The forces and torques of the current force phase.
        theSphereList : list
            The spheres to sum over (in the experiment, the mobile ones: ``movableSphereList()``).

        Returns
        -------
        tuple of float
            ``(τ_internal, τ_surface)`` (Pa), eq. S1-25.
        """
        reg = force_register
        if not (len(reg._blocks) == 1 and "S" in reg._blocks[0] and not reg._m_pair and not reg._m_ext
                and not reg._m_imom and self._rows_of(reg._ens, theSphereList)[0]):
            self.evaluate_stress_tensors(force_register, theSphereList, 0)
            return self.evaluate_quasistatic_shear_stress(), self.evaluate_externally_applied_shear_stress()
        t = self._t
        ens = reg._ens
        pos = ens._pos
        V = self._volume()
        p = reg._blocks[0]
        S = p["S"]
        n_int = S.n_int
        lw01 = 0.0
        if n_int:
            if not p["antisymmetric"]:
                self.evaluate_force_stress_tensors(reg)
                lw01 = t[_LW, 0, 1]
            else:
                lw01 = _internal_moment(p, pos, ens._pos_version, np.empty((2, 2)))[0, 1] * -(_CF * _CL / V)
        ext01 = 0.0
        if n_int != S.P:
            m_ = _external_moment(p, pos, self._centre(), -(_CF * _CL / V))
            if m_ is not None:
                ext01 = m_[0, 1]
        tint = self._internal_torque(p) if n_int else 0.0
        s_ = tint * _CT / V
        t[_LW, 0, 1] = lw01
        t[_EXT, 0, 1] = ext01
        t[_TINT, 0, 1] = -s_ / 2
        t[_CEN, 0, 1] = 0.0
        t[_ALL, 0, 1] = t[_LW, 0, 1] + t[_TINT, 0, 1] + t[_CEN, 0, 1]
        return -float(t[_ALL, 0, 1]), -float(t[_EXT, 0, 1])

    def evaluate_quasistatic_shear_stress(self):
        """τ_internal = −σ_xy of the overall tensor (eq. S1-25).

        Returns
        -------
        float
            Shear stress (Pa) of the last evaluation.
        """
        return -float(self._t[_ALL, 0, 1])

    def evaluate_externally_applied_shear_stress(self):
        """τ_surface = −σ_xy of the external-force tensor (eq. S1-25).

        Returns
        -------
        float
            Shear stress (Pa) measured from the forces on the boundary, of the last evaluation.
        """
        return -float(self._t[_EXT, 0, 1])
