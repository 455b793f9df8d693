"""Reference numbers of Appendix A.4 (the five two-sphere scenarios) and A.5 (micro-scenario M).

Every quantity is compared on its own: relative error against |ref| ≤ 1e-12;
where the reference value is exactly 0 (an identically vanishing quantity) the
value must be 0 up to 1e-12 of the scale of its group (the largest reference
value of the same kind in that scenario).  The spec (B.6) expects agreement to
~1e-12 or better when the sequential ξ rule (B.2) and the two-pass tangential
force (B.3) are followed.
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable, StressTensorEvaluation

RTOL = 1e-12
L = 500.0


class _RefCase(unittest.TestCase):
    def assertRef(self, name, got, ref, scale=None):
        """Per-quantity relative comparison; ``scale`` is the floor used only where ``ref`` is exactly 0."""
        got = np.asarray(got, dtype=float)
        ref = np.asarray(ref, dtype=float)
        self.assertEqual(got.shape, ref.shape, name)
        if scale is None:
            scale = float(np.max(np.abs(ref))) if ref.size else 0.0
        for idx in np.ndindex(ref.shape):
            g, r = float(got[idx]), float(ref[idx])
            if r == 0.0:
                ok = abs(g) <= RTOL * scale
                err = abs(g)
            else:
                err = abs(g - r) / abs(r)
                ok = err <= RTOL
            self.assertTrue(ok, f"{name}{list(idx)}: got {g!r}, reference {r!r} (error {err:.3g})")


# ---------------------------------------------------------------------------------------------
# Appendix A.4
def _ens(k=1, nu=1, k_t=1, nu_t=1, mu=0.01):
    return EnsembleLinkable(L, L, 0, k=k, nu=nu, k_t=k_t, nu_t=nu_t, mu=mu)


def _sph(ens, x, y, idx):
    s = SphereLinkable("grey", x, y, 120, 1, idx, force_register=ens, size_x=L, size_y=L)
    ens.sphereList.append(s)
    return s


TENSORS = ("stress_tensor_LW", "overall_stress_tensor", "stress_tensor_unbalanced_forces",
           "stress_tensor_linear_acceleration", "stress_tensor_with_external_forces",
           "stress_tensor_spin_kinetic_energy", "stress_tensor_unbalanced_torque", "stress_tensor_internal_torque",
           "stress_tensor_linear_acceleration_otsuki")


def _snapshot(ens, ev):
    s1, s2 = ens.sphereList[0], ens.sphereList[1]
    rel1 = s1.neighbors
    rel2 = s2.neighbors
    snap = {
        "x1": (s1.x, s1.y), "v1": (s1.xspeed, s1.yspeed), "w1": s1.omega,
        "x2": (s2.x, s2.y), "v2": (s2.xspeed, s2.yspeed), "w2": s2.omega,
        "rel": ([(r.myindex, r.interface_type) for r in rel1], [(r.myindex, r.interface_type) for r in rel2]),
        "xi": (rel1[0].friction_position if rel1 else None, rel2[0].friction_position if rel2 else None),
    }
    for name in TENSORS:
        snap[name] = np.array(getattr(ev, name), dtype=float)
    return snap


def _run(ens, n_steps, dt, tested, plain_before=0, evaluate_plain=()):
    """Run a scenario and return the snapshot taken right after the evaluation of step ``tested``.

    Steps ``< plain_before`` are plain steps (evaluated afterwards if listed in ``evaluate_plain``);
    the others are evaluated steps (forces → totals → tensors → kick → move, cool = 1).
    """
    ev = StressTensorEvaluation(L, L)
    snap = None
    for n in range(n_steps):
        if n < plain_before:
            ens.mechanical_simulation_step(cool_factor=1, dt=dt)
            if n in evaluate_plain:
                ev.evaluate_stress_tensors(ens.force_register, ens.sphereList, 0)
            continue
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ev.evaluate_stress_tensors(ens.force_register, ens.sphereList, 0)
        if n == tested:
            snap = _snapshot(ens, ev)
        ens.mechanical_simulation_step_calculate_acceleration(1, dt)
        ens.mechanical_simulation_step_calculate_movement(dt)
    return snap


def _diag(v):
    return [[v, 0.0], [0.0, v]]


def _anti(s01):
    return [[0.0, s01], [-s01, 0.0]]


class TestAppendixA4(_RefCase):

    def _check_state(self, snap, ref):
        scale = max(abs(v) for key in ("x1", "x2") for v in ref[key])
        vscale = max([abs(v) for key in ("v1", "v2") for v in ref[key]] + [abs(ref["w1"]), abs(ref["w2"])])
        self.assertRef("x1", snap["x1"], ref["x1"], scale)
        self.assertRef("x2", snap["x2"], ref["x2"], scale)
        self.assertRef("v1", snap["v1"], ref["v1"], vscale)
        self.assertRef("v2", snap["v2"], ref["v2"], vscale)
        self.assertRef("omega1", snap["w1"], ref["w1"], vscale)
        self.assertRef("omega2", snap["w2"], ref["w2"], vscale)
        self.assertEqual(snap["rel"], ref["rel"])
        self.assertRef("xi", snap["xi"], ref["xi"])

    def _check_tensors(self, snap, ref):
        scale = max(float(np.max(np.abs(np.asarray(v, dtype=float)))) for v in ref.values())
        for name, value in ref.items():
            self.assertRef(name, snap[name], value, scale)

    # manual Part 4 scenario 3 (frictionless central collision), tested evaluation = step 62 (index 61): 56 plain, 5 × (plain, evaluate), 1 evaluated
    def test_central_collision(self):
        ens = _ens()
        ens.nu = 0
        ens.k_t = 0
        ens.nu_t = 0
        s1 = _sph(ens, 150, 200, 1)
        s2 = _sph(ens, 350, 300, 2)
        s1.xspeed = 15
        s2.xspeed = -15
        snap = _run(ens, 62, 0.1, tested=61, plain_before=61, evaluate_plain=range(56, 61))
        v1 = (11.144383456602055, -9.626281817281834)
        self._check_state(snap, {
            "x1": (238.2534121851733, 192.84797918311855), "v1": v1, "w1": 0.0,
            "x2": (261.7465878148267, 307.15202081688153), "v2": (-v1[0], -v1[1]), "w2": 0.0,
            "rel": ([(2, "stick")], [(1, "stick")]), "xi": (42.31334048993898, 42.34319364561435)})
        lw = [[6.255794808839015e-11, 3.043703591009006e-10], [3.043703591009006e-10, 1.480888013914959e-09]]
        self._check_tensors(snap, {
            "stress_tensor_LW": lw, "overall_stress_tensor": lw, "stress_tensor_unbalanced_forces": lw,
            "stress_tensor_linear_acceleration": lw,
            "stress_tensor_with_external_forces": _diag(0.0), "stress_tensor_spin_kinetic_energy": _diag(0.0),
            "stress_tensor_unbalanced_torque": _diag(0.0), "stress_tensor_internal_torque": _diag(0.0),
            "stress_tensor_linear_acceleration_otsuki": [[-9.935782610222843e-10, 8.582318066648385e-10],
                                                         [8.582318066648385e-10, -7.413224130058466e-10]]})

    # manual Part 4 scenario 4 (purely tangential interaction), tested evaluation = step 50 (index 49), dt = 0.01
    def test_tangential(self):
        ens = _ens()
        s1 = _sph(ens, 150, 200, 1)
        s2 = _sph(ens, 220, 260, 2)
        s2.omega = 0.25
        s1.establish_permanent_link(s2)
        ens.k = 0
        ens.nu = 0
        snap = _run(ens, 50, 0.01, tested=49)
        v1 = (2.015301842163335, -2.329186424109821)
        self._check_state(snap, {
            "x1": (150.67198736839015, 199.220253498224), "v1": v1, "w1": -0.07888156711920317,
            "x2": (219.32801263160985, 260.77974650177595), "v2": (-v1[0], -v1[1]), "w2": 0.17111843288079684,
            "rel": ([(2, "permanent")], [(1, "permanent")]),
            "xi": (-2.1279460579227005, -2.1279512415803405)})
        torque = _anti(2.772057019799222e-10)
        self._check_tensors(snap, {
            "stress_tensor_LW": [[-2.755639367408573e-10, -2.4708066292497323e-10],
                                 [3.0733074103487093e-10, 2.755639367408572e-10]],
            "overall_stress_tensor": [[-4.033776876707974e-10, 3.01250390549489e-11],
                                      [3.0125039054948796e-11, 1.4775018581091713e-10]],
            "stress_tensor_spin_kinetic_energy": _diag(-1.2781375092994007e-10),
            "stress_tensor_internal_torque": torque, "stress_tensor_unbalanced_torque": torque,
            "stress_tensor_linear_acceleration_otsuki": [[-3.2491532120215446e-11, 3.755210953000282e-11],
                                                         [3.755210953000282e-11, -4.340087518605995e-11]],
            "stress_tensor_with_external_forces": _diag(0.0)})

    # manual Part 4 scenario 5 (general collision with a permanent link), tested evaluation = step 50 (index 49), dt = 0.01
    def test_general(self):
        ens = _ens()
        s1 = _sph(ens, 150, 200, 1)
        s2 = _sph(ens, 220, 260, 2)
        s1.xspeed = 10
        s2.xspeed = -10
        s2.omega = 0.25
        s1.establish_permanent_link(s2)
        snap = _run(ens, 50, 0.01, tested=49)
        v1 = (0.24377030017982176, -9.401409148962355)
        self._check_state(snap, {
            "x1": (152.02563113972198, 197.26539687912367), "v1": v1, "w1": -0.009991809507400383,
            "x2": (217.97436886027802, 262.73460312087633), "v2": (-v1[0], -v1[1]), "w2": 0.24000819049259967,
            "rel": ([(2, "permanent")], [(1, "permanent")]),
            "xi": (-0.2752295367649557, -0.27580530139167037)})
        # the sign of the torque off-diagonals is not stated: compare |σ01| and antisymmetry
        for name in ("stress_tensor_internal_torque", "stress_tensor_unbalanced_torque"):
            t = snap[name]
            self.assertEqual(t[1, 0], -t[0, 1])
            snap[name] = np.abs(t) * np.array([[1, 1], [-1, 1]])
        torque = _anti(7.229571030267409e-11)
        self._check_tensors(snap, {
            "stress_tensor_LW": [[2.580829031380047e-09, 2.5620631109889632e-09],
                                 [2.706654531594311e-09, 2.686973699253819e-09]],
            "overall_stress_tensor": [[2.373095467441296e-09, 2.6343588212916373e-09],
                                      [2.634358821291637e-09, 2.4792401353150682e-09]],
            "stress_tensor_spin_kinetic_energy": _diag(-2.0773356393875108e-10),
            "stress_tensor_internal_torque": torque, "stress_tensor_unbalanced_torque": torque,
            "stress_tensor_with_external_forces": _diag(0.0)})

    # manual Part 4 scenario 7 (interaction through the periodic boundary), tested evaluation = step 50 (index 49), dt = 0.01
    def test_across_periodic_boundary(self):
        ens = _ens(mu=0.5)
        s1 = _sph(ens, 20, 200, 1)
        s2 = _sph(ens, 480, 230, 2)
        s1.xspeed = 10
        s2.xspeed = -10
        s2.omega = 0.25
        snap = _run(ens, 50, 0.01, tested=49)
        v1 = (22.25992859040587, -6.905338588246746)
        self._check_state(snap, {
            "x1": (28.711525193699067, 197.7097647745568), "v1": v1, "w1": -0.02034255476789899,
            "x2": (471.28847480630094, 232.2902352254432), "v2": (-v1[0], -v1[1]), "w2": 0.22965744523210094,
            "rel": ([(2, "stick")], [(1, "stick")]), "xi": (-0.9720638841400733, -0.9892941887907992)})
        t = snap["stress_tensor_unbalanced_torque"]
        self.assertEqual(t[1, 0], -t[0, 1])
        snap["stress_tensor_unbalanced_torque"] = np.abs(t) * np.array([[1, 1], [-1, 1]])
        ext = [[1.3880878428978401e-08, 1.0845736696540473e-09], [-3.3922191391283018e-09, -2.6504890009802053e-10]]
        cen = _diag(-1.9136290206607346e-10)
        self._check_tensors(snap, {
            "stress_tensor_LW": _diag(0.0), "overall_stress_tensor": cen, "stress_tensor_spin_kinetic_energy": cen,
            "stress_tensor_with_external_forces": ext,
            "stress_tensor_unbalanced_forces": -np.array(ext), "stress_tensor_linear_acceleration": -np.array(ext),
            "stress_tensor_internal_torque": _diag(0.0),
            "stress_tensor_unbalanced_torque": _anti(3.222216340503384e-10)})

    # manual Part 4 scenario 6 (sphere hitting a sphere glued to the boundary), tested evaluation = step 70 (index 69), dt = 0.1
    def test_boundary_sphere(self):
        ens = _ens(mu=0.5)
        s1 = _sph(ens, 150, 80, 1)
        s2 = _sph(ens, 300, 10, 2)
        s1.xspeed = 10
        s2.xspeed = -10
        ens.applyingShear = True
        snap = _run(ens, 70, 0.1, tested=69)
        w = -0.04057649351180975
        self._check_state(snap, {
            "x1": (210.74132534735045, 84.60098426638659), "v1": (1.8268337301834023, 4.678996530253445), "w1": w,
            "x2": (300.0, 10.0), "v2": (0.0, 0.0), "w2": w,
            "rel": ([(2, "stick")], [(1, "stick")]), "xi": (-0.08732159277095317, -0.08628948805292033)})
        ext = [[-2.4760153904102645e-10, -1.043159281709214e-09], [2.1117040130645023e-10, 8.896728388614055e-10]]
        cen = _diag(-1.1854453145140362e-11)
        self._check_tensors(snap, {
            "stress_tensor_LW": _diag(0.0), "overall_stress_tensor": cen, "stress_tensor_spin_kinetic_energy": cen,
            "stress_tensor_with_external_forces": ext,
            "stress_tensor_unbalanced_forces": -np.array(ext),
            "stress_tensor_internal_torque": _diag(0.0),
            "stress_tensor_unbalanced_torque": _anti(-4.807493267270605e-12)})


# ---------------------------------------------------------------------------------------------
# Appendix A.5 — micro-scenario M
M_SPHERES = [(100, 100, 60, 1.0, 1), (150, 110, 50, 0.8, 2), (100, 185, 40, 0.6, 3), (108, 12, 44, 0.7, 4),
             (185, 100, 50, 0.9, 5), (12, 120, 46, 0.75, 6), (100, 150, 50, 0.85, 7)]

M_TABLE = {  # step: t, γ, γ̇, τ_internal, τ_surface, mobile indices
    0: (0, 0, 0.3141592653589793, 8.74075737820581e-09, 1.1520222080683903e-08, [1, 2, 5, 6, 7]),
    1: (0.05, 0.015707963267948967, 0.3102914434849978, 8.166296204789166e-09, 1.179204761701923e-08,
        [1, 2, 5, 6, 7]),
    100: (4.99999999999999, 0.01570796326795216, -0.3141592653589793, -7.031786939818385e-09, -0.0,
          [1, 2, 5, 6, 7]),
    200: (10.000000000000007, 2.3991225672759242e-15, 0.3141592653589793, 3.1123685731502554e-09,
          5.5516872096869e-09, [1, 2, 5, 6, 7]),
    399: (19.95000000000015, -0.015514572174204102, 0.31029144348502075, 2.354663120294748e-09, -0.0, [1, 2, 7]),
}

M_FINAL = [  # x, y, vx, vy, ω, relations (partner index, state, ξ)
    (56.906844929279856, 46.54241454759884, -16.710886484613386, 0.1235053349823316, -0.1253735510620941,
     [(2, "permanent", 1.1389000828598976)]),
    (109.01996247549675, 66.96764282483137, -10.804897709510033, 2.228040152291499, -0.14093502164563912,
     [(1, "permanent", 1.3503756551150081)]),
    (100.00000000000469, 185.0, 31.0244899768498, 0.0, -0.13835062405729223, [(4, "stick", 1.8531539344029313)]),
    (107.99999999999528, 12.0, -31.025420851180257, 0.0, -0.14096969298146217, [(3, "stick", 1.8518692205119114)]),
    (194.75673436564654, 24.95624034680228, -31.021400640660907, 0.0, -0.1964414506916054, []),
    (44.58870456379528, 177.03545697397794, 31.022018647297557, 0.0, -0.14875833861713642, []),
    (111.98752103842938, 138.60868483256803, 12.918178798017577, 0.27318892226956193, -0.3629148361012122, []),
]


class TestAppendixA5(_RefCase):

    @classmethod
    def setUpClass(cls):
        ens = EnsembleLinkable(200, 200, 0, k=1, nu=0.5, k_t=1, nu_t=0.5, mu=0.3)
        sp = []
        for (x, y, d, m, i) in M_SPHERES:
            s = SphereLinkable("grey", x, y, d, m, i, force_register=ens, size_x=200, size_y=200)
            ens.sphereList.append(s)
            sp.append(s)
        ens.set_central_repulsion_coefficient(1)
        sp[0].xspeed = 1
        sp[1].xspeed = -0.5
        sp[1].yspeed = 0.2
        sp[4].yspeed = -0.3
        sp[2].omega = 0.1
        sp[0].establish_permanent_link(sp[1])
        cls.d_eq = sp[0].neighbors[0].equilibrium_distance
        ens.applyingShear = True
        ev = StressTensorEvaluation(200, 200)
        rows = {}
        for n in range(400):
            ens.setShearRate(0.1 * math.cos(2 * math.pi * 0.5 * ens.t) * 2 * math.pi * 0.5)
            ens.mechanical_simulation_step_calculate_forces()
            ens.record_total_particle_forces()
            t, g, gd = ens.t, ens.shear, ens.shear_rate
            ens.evaluate_stress_tensors(ev)
            if n in M_TABLE:
                rows[n] = (t, g, gd, ev.evaluate_quasistatic_shear_stress(), ev.evaluate_externally_applied_shear_stress(),
                           [s.myindex for s in ens.movableSphereList()])
            ens.mechanical_simulation_step_calculate_acceleration(0.999, 0.05)
            ens.mechanical_simulation_step_calculate_movement(0.05)
            ens.reset_force()
        cls.rows = rows
        cls.ens = ens
        cls.sp = sp

    def test_link_equilibrium_distance(self):
        # a link's equilibrium distance is the contact distance r_i + r_j when it is made (30 + 25 µm),
        # not the centre distance then (√2600 ≈ 51.0 µm)
        self.assertEqual(self.d_eq, self.sp[0].r + self.sp[1].r)
        self.assertEqual(self.d_eq, 55.0)

    def test_table_rows(self):
        for n, ref in M_TABLE.items():
            with self.subTest(step=n):
                got = self.rows[n]
                names = ("t", "shear", "shear_rate", "tau_internal", "tau_surface")
                for k, name in enumerate(names):
                    self.assertRef(f"step {n} {name}", got[k], ref[k])
                self.assertEqual(got[5], ref[5])

    def test_final_clock_and_strain(self):
        self.assertRef("t", self.ens.t, 20.00000000000015)
        self.assertRef("shear", self.ens.shear, 4.693641308950447e-14)

    def test_final_state(self):
        pos_scale = 200.0
        vel_scale = max(max(abs(v) for v in row[2:5]) for row in M_FINAL)
        for s, ref in zip(self.sp, M_FINAL):
            with self.subTest(sphere=s.myindex):
                self.assertRef("x, y", (s.x, s.y), ref[0:2], pos_scale)
                self.assertRef("vx, vy, omega", (s.xspeed, s.yspeed, s.omega), ref[2:5], vel_scale)
                rels = s.neighbors
                self.assertEqual([(r.myindex, r.interface_type) for r in rels], [(p, st) for p, st, _ in ref[5]])
                self.assertRef("xi", [r.friction_position for r in rels], [xi for _, _, xi in ref[5]])


if __name__ == "__main__":
    unittest.main()
