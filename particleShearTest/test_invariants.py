"""Physical invariants of the stress evaluation and of the integrator (docs/engine.md).

* The overall tensor σ = σ_LW + σ_Tint + σ_cen is symmetric (the internal-torque
  term cancels the antisymmetric Love–Weber part of the tangential forces) in a
  random, frictional, crosslinked, sheared ensemble with plates.
* σ_LW = σ_ext + σ_linacc holds component-wise (each pair's action and reaction sum to zero).
* Every tensor of the array path equals its definition (eq. S1-16 … S1-24) summed entry by entry
  over the reference register lists and the mobile spheres.
* Pair forces obey Newton's third law and the torque split conserves angular
  momentum (docs/engine.md), so Σ m v and Σ m (x v_y − y v_x) + Σ I ω of an isolated,
  undamped scene are constant up to rounding — with the symplectic Euler step
  this holds exactly in exact arithmetic (forces are evaluated at x_n and
  x_{n+1} × v_{n+1} = x_n × v_{n+1}).
* Forces depend only on relative positions and velocities: translating a scene
  leaves every tensor but the Otsuki term unchanged; so does a uniform velocity
  boost as long as the tangential spring k_t is 0 (see the note at
  ``TestGalileanInvariance``).
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable, StressTensorEvaluation

TENSORS = ("stress_tensor_LW", "stress_tensor_with_external_forces", "stress_tensor_unbalanced_forces",
           "stress_tensor_linear_acceleration", "stress_tensor_spin_kinetic_energy",
           "stress_tensor_unbalanced_torque", "stress_tensor_internal_torque", "overall_stress_tensor",
           "stress_tensor_linear_acceleration_otsuki")


def tensors(ev):
    return {name: np.array(getattr(ev, name), dtype=float) for name in TENSORS}


def random_ensemble(n, L, seed, packing_fraction=1.2, k=3.14e9, nu=2e3, mu=0.3, m=0.1):
    """n bimodal linkable spheres at random positions (radius ratio 1.4, masses ∝ r²), c = 1."""
    rng = np.random.default_rng(seed)
    bf = 1.4
    r_mean = math.sqrt(L * L * packing_fraction / (n * math.pi)) / ((math.sqrt(bf) + 1 / math.sqrt(bf)) / 2)
    ens = EnsembleLinkable(L, L, 0, k=k, nu=nu, k_t=k, nu_t=nu, mu=mu)
    for p in range(n):
        r = r_mean * (math.sqrt(bf) if rng.integers(0, 2) else 1 / math.sqrt(bf))
        s = SphereLinkable("grey", float(rng.random() * L), float(rng.random() * L), 2 * r, m * (r / r_mean) ** 2,
                           p + 1, force_register=ens, size_x=L, size_y=L)
        ens.sphereList.append(s)
    ens.set_central_repulsion_coefficient(1)
    return ens


def definition_tensors(ens, Lx, Ly):
    """Every tensor from its definition (reference manual eq. S1-16 … S1-24; docs/engine.md), summed
    entry by entry over the reference register lists and the mobile spheres, independently of the
    array path: V = Lx·Ly·1e-12 m², forces ×1e-12, lengths ×1e-6, torques and inertias ×1e-18,
    lever arms from the cell centre."""
    reg = ens.force_register
    V = (Lx * 1e-6) * (Ly * 1e-6)
    c = (Lx / 2, Ly / 2)
    z = {name: np.zeros((2, 2)) for name in TENSORS}
    rot = np.array([[0.0, -0.5], [0.5, 0.0]])
    for t, src, F in reg.pair_register:                     # eq. S1-19, each contact registered twice
        z["stress_tensor_LW"] += np.outer(np.asarray(F) * 1e-12, [(t.x - src.x) * 1e-6, (t.y - src.y) * 1e-6]) / 2
    for p, F in reg.external_force_register:                # eq. S1-16
        z["stress_tensor_with_external_forces"] -= np.outer(np.asarray(F) * 1e-12,
                                                            [(p.x - c[0]) * 1e-6, (p.y - c[1]) * 1e-6])
    for p, F in reg.total_particle_force_register:          # eq. S1-17 (m·a = F_total)
        z["stress_tensor_unbalanced_forces"] += np.outer(np.asarray(F) * 1e-12,
                                                         [(p.x - c[0]) * 1e-6, (p.y - c[1]) * 1e-6])
    z["stress_tensor_linear_acceleration"] = z["stress_tensor_unbalanced_forces"].copy()
    for p, T in reg.unbalanced_moment_register:             # eq. S1-22, all net torques
        z["stress_tensor_unbalanced_torque"] += T * 1e-18 * rot
    for t, src, M in reg.internal_moment_register:          # eq. S1-22, internal torques only
        z["stress_tensor_internal_torque"] += M * 1e-18 * rot
    for p in ens.movableSphereList():                       # eq. S1-21 and the Otsuki term
        z["stress_tensor_spin_kinetic_energy"] -= p.inertia * 1e-18 * p.omega ** 2 / 2 * np.eye(2)
        P = np.array([p.m * 1e-12 * (p.xspeed - ens.shear_rate * (p.y - Ly / 2)), p.m * 1e-12 * p.yspeed])
        z["stress_tensor_linear_acceleration_otsuki"] -= np.outer(P, P) / (p.m * 1e-6)
    for name in TENSORS:
        if name != "overall_stress_tensor":
            z[name] = z[name] / V
    z["overall_stress_tensor"] = (z["stress_tensor_LW"] + z["stress_tensor_internal_torque"]
                                  + z["stress_tensor_spin_kinetic_energy"])   # eq. S1-24
    return z


class TestShearedCrosslinkedEnsemble(unittest.TestCase):
    """120 frictional spheres, crosslinked then cut, sheared with plates, 60 evaluated steps."""

    N_STEPS = 60

    @classmethod
    def setUpClass(cls):
        L = 500.0
        ens = random_ensemble(120, L, seed=1)
        ens.mu = 0.0
        for _ in range(60):  # relax the random placement (frictionless, damped)
            ens.mechanical_simulation_step(cool_factor=0.5, dt=1e-7)
        ens.mu = 0.3
        ens.test_neighbor_relation()
        ens.makeAllLinksPermanent()
        for angle in (0.4, 1.3, 2.2):
            ens.cutLine((250.0, 250.0), angle)
        ens.applyingShear = True
        cls.n_links = len(ens.permanent_pairs()[0])
        cls.n_immobile = len(ens.sphereList) - len(ens.movableSphereList())
        ev = StressTensorEvaluation(L, L)
        cls.records = []
        cls.generic = []
        cls.defined = []
        cls.states = set()
        dt = 1e-7
        for _ in range(cls.N_STEPS):
            ens.setShearRate(2000 * math.cos(2 * math.pi * 4000 * ens.t))
            ens.mechanical_simulation_step_calculate_forces()
            ens.record_total_particle_forces()
            ens.evaluate_stress_tensors(ev)
            cls.records.append(tensors(ev))
            if len(cls.records) % 10 == 1:
                # the same tensors through the generic adapter (register entries as rows) and a plain list of mobile spheres
                ref = StressTensorEvaluation(L, L)
                mobile = list(ens.movableSphereList())
                ref.evaluate_force_stress_tensors(ens.force_register)
                ref.evaluate_rotational_stress_tensors(ens.force_register, mobile)
                ref.evaluate_peculiar_momentum_transport_for_linear_acceleration_tensor(mobile, ens.shear_rate)
                ref.overall_stress_tensor = (np.array(ref.stress_tensor_LW)
                                             + np.array(ref.stress_tensor_internal_torque)
                                             + np.array(ref.stress_tensor_spin_kinetic_energy))
                cls.generic.append((tensors(ev), tensors(ref)))
                cls.defined.append((tensors(ev), definition_tensors(ens, L, L)))
            for s in ens.sphereList[:40]:
                cls.states.update(rel.interface_type for rel in s.neighbors)
            ens.mechanical_simulation_step_calculate_acceleration(0.9997, dt)
            ens.mechanical_simulation_step_calculate_movement(dt)
            ens.reset_force()
        cls.ens = ens

    def test_scene_is_what_it_claims(self):
        self.assertGreaterEqual(len(self.ens.sphereList), 100)
        self.assertGreater(self.n_links, 50)
        self.assertGreater(self.n_immobile, 0)  # plates exist
        self.assertIn("permanent", self.states)
        self.assertIn("stick", self.states)
        self.assertNotEqual(self.ens.shear, 0.0)
        # boundary-crossing and plate contacts exist: the external tensor is not zero
        self.assertTrue(any(np.any(r["stress_tensor_with_external_forces"] != 0) for r in self.records))

    def test_array_path_equals_generic_path(self):
        # same sums in another order and grouping: rounding only, ≲ 1e-13 of each tensor's own scale
        self.assertGreaterEqual(len(self.generic), 5)
        for n, (fast, ref) in enumerate(self.generic):
            for name in TENSORS:
                with self.subTest(step=10 * n, tensor=name):
                    scale = np.max(np.abs(ref[name]))
                    self.assertLessEqual(np.max(np.abs(fast[name] - ref[name])), 1e-12 * scale + 1e-300)

    def test_overall_tensor_symmetric(self):
        asym_lw = 0.0
        for n, r in enumerate(self.records):
            with self.subTest(step=n):
                s = r["overall_stress_tensor"]
                self.assertLessEqual(abs(s[0, 1] - s[1, 0]) / (abs(s[0, 0]) + abs(s[1, 1])), 1e-13)
                lw = r["stress_tensor_LW"]
                asym_lw = max(asym_lw, abs(lw[0, 1] - lw[1, 0]) / (abs(s[0, 0]) + abs(s[1, 1])))
        # the check has teeth: without the internal-torque term the tensor would be far from symmetric
        self.assertGreater(asym_lw, 1e-4)

    def test_love_weber_equals_external_plus_linear_acceleration(self):
        # action and reaction: both sides sum the same pair forces with levers of up to L/2 instead of a
        # contact length, so rounding is ≲ N·ε·(L/2)/d ≈ 1e-13 of the pressure scale
        for n, r in enumerate(self.records):
            with self.subTest(step=n):
                lw = r["stress_tensor_LW"]
                rhs = r["stress_tensor_with_external_forces"] + r["stress_tensor_linear_acceleration"]
                self.assertLessEqual(np.max(np.abs(lw - rhs)), 1e-12 * (abs(lw[0, 0]) + abs(lw[1, 1])))

    def test_every_tensor_equals_its_definition(self):
        # the array path against the definitions summed entry by entry over the reference register lists:
        # the same terms in another order and grouping, rounding ≲ 1e-13 of the pressure scale; the
        # spin and Otsuki terms are compared on their own (much smaller) scale
        self.assertGreaterEqual(len(self.defined), 5)
        for n, (fast, ref) in enumerate(self.defined):
            p = abs(ref["stress_tensor_LW"][0, 0]) + abs(ref["stress_tensor_LW"][1, 1])
            self.assertGreater(p, 0.0)
            for name in TENSORS:
                with self.subTest(step=10 * n, tensor=name):
                    scale = p if name not in ("stress_tensor_spin_kinetic_energy",
                                              "stress_tensor_linear_acceleration_otsuki") \
                        else np.max(np.abs(ref[name])) + 1e-300
                    self.assertLessEqual(np.max(np.abs(fast[name] - ref[name])), 1e-12 * scale)
            # the definitions have teeth: the terms the overall tensor adds to Love-Weber are not zero
            self.assertGreater(np.max(np.abs(ref["stress_tensor_internal_torque"])), 1e-6 * p)
            self.assertGreater(np.max(np.abs(ref["stress_tensor_spin_kinetic_energy"])), 0.0)


# ---------------------------------------------------------------------------------------------
def isolated_cluster(seed, shift=(0.0, 0.0), boost=(0.0, 0.0), k_t=1.0, L=2000.0, n=40):
    """A jittered, overlapping 7×6 block of spheres in the middle of a large cell (no boundary contact),
    with random velocities and spins, friction, c = 1, and permanent links cut by one line."""
    rng = np.random.default_rng(seed)
    ens = EnsembleLinkable(L, L, 0, k=1.0, nu=0.05, k_t=k_t, nu_t=0.05, mu=0.3)
    side = int(math.ceil(math.sqrt(n)))
    for p in range(n):
        gx, gy = p % side, p // side
        d = float(rng.choice([50.0, 60.0]))
        x = L / 2 + (gx - side / 2) * 45 + rng.normal(0, 2) + shift[0]
        y = L / 2 + (gy - side / 2) * 45 + rng.normal(0, 2) + shift[1]
        s = SphereLinkable("grey", x, y, d, 1.0 + 0.3 * rng.random(), p + 1, force_register=ens, size_x=L, size_y=L)
        s.xspeed = float(rng.normal(0, 0.5)) + 0.3 + boost[0]
        s.yspeed = float(rng.normal(0, 0.5)) - 0.2 + boost[1]
        s.omega = float(rng.normal(0, 0.01))
        ens.sphereList.append(s)
    ens.set_central_repulsion_coefficient(1)
    ens.test_neighbor_relation()
    ens.makeAllLinksPermanent()
    ens.cutLine((L / 2 + shift[0] + 3, L / 2 + shift[1]), 0.7)
    return ens


def evaluated_step(ens, ev, dt):
    ens.mechanical_simulation_step_calculate_forces()
    ens.record_total_particle_forces()
    ens.evaluate_stress_tensors(ev)
    ens.mechanical_simulation_step_calculate_acceleration(1, dt)  # no damping
    ens.mechanical_simulation_step_calculate_movement(dt)


def momentum(ens):
    return np.array([sum(s.m * s.xspeed for s in ens.sphereList), sum(s.m * s.yspeed for s in ens.sphereList)])


def angular_momentum(ens):
    return sum(s.m * (s.x * s.yspeed - s.y * s.xspeed) + s.inertia * s.omega for s in ens.sphereList)


class TestMomentumConservation(unittest.TestCase):
    """Isolated scene: no plates, γ̇ = 0, cool = 1, contacts and links, nothing near the boundary."""

    def test_linear_and_angular_momentum(self):
        ens = isolated_cluster(5)
        self.assertGreater(len(ens.permanent_pairs()[0]), 20)
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        p0, l0 = momentum(ens), angular_momentum(ens)
        self.assertGreater(np.hypot(*p0), 1.0)
        contacts = 0
        for n in range(400):
            evaluated_step(ens, ev, 0.1)
            # isolated: no boundary-crossing pair was ever registered, no sphere is immobile
            self.assertTrue(np.all(np.array(ev.stress_tensor_with_external_forces) == 0))
            contacts += len(ens.contact_pairs()[0])
            if n % 50 == 49:
                p, l_ = momentum(ens), angular_momentum(ens)
                self.assertLessEqual(np.max(np.abs(p - p0)) / np.hypot(*p0), 1e-12, f"step {n}: {p0} → {p}")
                self.assertLessEqual(abs(l_ - l0) / abs(l0), 1e-12, f"step {n}: {l0} → {l_}")
        self.assertGreater(contacts, 400 * 30)
        xs = [s.x for s in ens.sphereList]
        ys = [s.y for s in ens.sphereList]
        self.assertTrue(200 < min(xs) and max(xs) < 1800 and 200 < min(ys) and max(ys) < 1800)


class TestGalileanInvariance(unittest.TestCase):
    """Two runs of the same undamped isolated scene, compared step by step.

    Every tensor except the Otsuki term (which contains absolute velocities) must agree to
    1e-12 of its largest magnitude over the run.  Rounding of the shifted coordinates
    (≈ 1e-13 µm) is the only difference; 60 steps keep its chaotic growth far below 1e-12.

    Note: a velocity boost is compared with ``k_t = 0``.  With a tangential spring, the
    reference's sequential ξ rule (docs/engine.md, B.2) integrates ξ_ji with sphere i already moved
    by ``v_i·dt``, i.e. with an *absolute* displacement, so ξ_ji (and the tensors) change by
    O(|u|·dt/d) under a boost — a reference quirk, not a rounding effect.
    """

    N_STEPS = 60

    def _compare(self, a, b, expect_otsuki_change):
        eva = StressTensorEvaluation(a.size_x, a.size_y)
        evb = StressTensorEvaluation(b.size_x, b.size_y)
        ta, tb = [], []
        for _ in range(self.N_STEPS):
            evaluated_step(a, eva, 0.1)
            evaluated_step(b, evb, 0.1)
            ta.append(tensors(eva))
            tb.append(tensors(evb))
        for name in TENSORS[:-1]:
            scale = max(float(np.max(np.abs(t[name]))) for t in ta)
            for n in range(self.N_STEPS):
                with self.subTest(tensor=name, step=n):
                    err = float(np.max(np.abs(ta[n][name] - tb[n][name])))
                    if scale == 0.0:
                        self.assertEqual(err, 0.0)
                    else:
                        self.assertLessEqual(err / scale, 1e-12)
        self.assertGreater(max(float(np.max(np.abs(t["stress_tensor_LW"]))) for t in ta), 0.0)
        ot = max(float(np.max(np.abs(x["stress_tensor_linear_acceleration_otsuki"]
                                     - y["stress_tensor_linear_acceleration_otsuki"]))) for x, y in zip(ta, tb))
        if expect_otsuki_change:
            self.assertGreater(ot, 1e-6 * max(float(np.max(np.abs(t["stress_tensor_linear_acceleration_otsuki"])))
                                              for t in ta))

    def test_translation(self):
        self._compare(isolated_cluster(9), isolated_cluster(9, shift=(300.37, -211.9)), False)

    def test_velocity_boost(self):
        self._compare(isolated_cluster(9, k_t=0.0), isolated_cluster(9, boost=(0.7, -0.4), k_t=0.0), True)

    def test_translation_and_boost(self):
        self._compare(isolated_cluster(9, k_t=0.0),
                      isolated_cluster(9, shift=(123.4, -77.7), boost=(-0.55, 0.35), k_t=0.0), True)


if __name__ == "__main__":
    unittest.main()
