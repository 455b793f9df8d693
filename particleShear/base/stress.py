"""Stress tensors from the force register (spec §7; Nicot et al. with the factor 3/2).

All tensors are 2×2 in Pa, index ``[a][b]`` = (force component, lever-arm
component), compression positive.  Internal units are converted here only:
forces ×1e-12 (N/m), lengths ×1e-6 (m), torques and inertias ×1e-18.
"""
import numpy as np

from .register import SphereSelection

__all__ = ["StressTensorEvaluation", "TENSOR_NAMES"]

#: tensor attribute names in the column order of the output table (§9.1)
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

_CF = 1e-12
_CL = 1e-6
_CT = 1e-18


def _tensor_property(k):
    def fget(self):
        return self._t[k].tolist()

    def fset(self, value):
        self._t[k] = np.asarray(value, dtype=float)

    return property(fget, fset, doc="2×2 tensor (Pa), nested lists; see spec §7.")


class StressTensorEvaluation:
    """Evaluates every stress tensor of §7 from a :class:`Force_register` with array operations."""

    def __init__(self, size_x, size_y, theCanvas=False):
        self.size_x = size_x
        self.size_y = size_y
        self.theCanvas = theCanvas
        self.graphical_output_configuration = None
        self.toDeleteList = []
        self._t = np.zeros((9, 2, 2))

    for _k, _name in enumerate(TENSOR_NAMES):
        locals()[_name] = _tensor_property(_k)
    del _k, _name

    @property
    def tensors(self):
        """All nine tensors as an array of shape (9, 2, 2) in output-column order."""
        return self._t

    def _volume(self):
        return (self.size_x * _CL) * (self.size_y * _CL)

    # -- sphere lists -----------------------------------------------------------------------
    @staticmethod
    def _sphere_values(theSphereList):
        """(I, omega, m, vx, vy, y) arrays of the spheres in a list or selection."""
        if isinstance(theSphereList, SphereSelection):
            a = theSphereList.ensemble._a
            if theSphereList.mask is None:
                return a["inertia"], a["omega"], a["m"], a["xspeed"], a["yspeed"], a["y"]
            mk = theSphereList.mask
            return (a["inertia"][mk], a["omega"][mk], a["m"][mk], a["xspeed"][mk],
                    a["yspeed"][mk], a["y"][mk])
        sl = list(theSphereList)
        vals = [[getattr(s, "inertia", 0.0), getattr(s, "omega", 0.0), s.m, s.xspeed, s.yspeed, s.y]
                for s in sl]
        arr = np.array(vals, dtype=float).reshape(-1, 6)
        return tuple(arr[:, q] for q in range(6))

    # -- force tensors ----------------------------------------------------------------------
    def evaluate_force_stress_tensors(self, force_register):
        """Love-Weber, unbalanced-force, linear-acceleration and external-force tensors (§7.3-7.5)."""
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
            if internal.any():
                ii, jj = i[internal], j[internal]
                ddx = x[ii] - x[jj]
                ddy = y[ii] - y[jj]
                for a_, fi, fj in ((0, p["fix"][internal], p["fjx"][internal]),
                                   (1, p["fiy"][internal], p["fjy"][internal])):
                    gi = fi * _CF
                    gj = fj * _CF
                    for b_, dd in ((0, ddx), (1, ddy)):
                        lw[a_, b_] += np.sum(gi * dd * _CL / 2) + np.sum(gj * -dd * _CL / 2)
            for side, idx, fx, fy in (("ext_i", i, p["fix"], p["fiy"]), ("ext_j", j, p["fjx"], p["fjy"])):
                m = p[side]
                if m.any():
                    t = idx[m]
                    lx = (x[t] - cx) * _CL
                    ly = (y[t] - cy) * _CL
                    gx = fx[m] * _CF
                    gy = fy[m] * _CF
                    ext -= [[gx @ lx, gx @ ly], [gy @ lx, gy @ ly]]
        if reg._tot is not None:
            mobile, fx, fy = reg._tot
            x = ens._a["x"]
            y = ens._a["y"]
            if mobile is None:
                lx, ly, gx, gy = x, y, fx, fy
            else:
                lx, ly, gx, gy = x[mobile], y[mobile], fx[mobile], fy[mobile]
            lx = (lx - cx) * _CL
            ly = (ly - cy) * _CL
            gx = gx * _CF
            gy = gy * _CF
            unb += [[gx @ lx, gx @ ly], [gy @ lx, gy @ ly]]
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
        """Centrifugal tensor ``-(1/V) Σ I ω²/2 · 1`` over the given spheres (§7.6)."""
        inertia, omega = self._sphere_values(theSphereList)[:2]
        K = float(np.sum((inertia * _CT) * omega ** 2 / 2))
        v = -K / self._volume()
        self._t[_CEN] = [[v, 0.0], [0.0, v]]

    @staticmethod
    def _antisym(total, V):
        s = total * _CT / V
        return [[0.0, -s / 2], [s / 2, 0.0]]

    def evaluate_unbalanced_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of all net torques, immobile spheres included (§7.7)."""
        total = 0.0
        if force_register._mom is not None:
            total += float(np.sum(force_register._mom))
        total += sum(m for _, m in force_register._m_unb.values())
        self._t[_TQ] = self._antisym(total, self._volume())

    def evaluate_internal_torque_stress_tensor(self, force_register):
        """Antisymmetric tensor of the internal pair torques (§7.7); symmetrises Love-Weber."""
        total = 0.0
        for p in force_register._blocks:
            if p.get("ti") is not None:
                internal = p["internal"]
                total += float(np.sum(p["ti"][internal]) + np.sum(p["tj"][internal]))
        total += sum(m for _, _, m in force_register._m_imom)
        self._t[_TINT] = self._antisym(total, self._volume())

    def evaluate_rotational_stress_tensors(self, force_register, theSphereList):
        self.evaluate_spin_kinetic_energy_stress_tensor(theSphereList)
        self.evaluate_unbalanced_torque_stress_tensor(force_register)
        self.evaluate_internal_torque_stress_tensor(force_register)

    def evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(self, theSphereList, shear_rate):
        """Otsuki peculiar-momentum term (§7.10), for comparison only (never enters G)."""
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
        """Every tensor of §7 and the overall tensor ``σ = σ_LW + σ_Tint + σ_cen`` (eq. S1-24)."""
        self.evaluate_force_stress_tensors(force_register)
        self.evaluate_rotational_stress_tensors(force_register, theSphereList)
        self.evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(theSphereList, shear_rate)
        self._t[_ALL] = self._t[_LW] + self._t[_TINT] + self._t[_CEN]

    def evaluate_quasistatic_shear_stress(self):
        """τ_internal = −σ_xy of the overall tensor (Pa)."""
        return -float(self._t[_ALL, 0, 1])

    def evaluate_externally_applied_shear_stress(self):
        """τ_surface = −σ_xy of the external-force tensor (Pa)."""
        return -float(self._t[_EXT, 0, 1])
