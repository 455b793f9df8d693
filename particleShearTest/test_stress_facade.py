"""The documented classes' stress tensors are the engine's (docs/engine.md, "Written once").

* On the same state, the classes' tensors (their own force phase, read through the register)
  equal the tensors of the engine's step (``BatchEngine.step(sample="tensors")``, its own force
  phase) for a sheared scene with plates and for a crosslinked periodic scene without plates.
  The two force phases use the same laws with the operations in another order, so the forces
  agree to ≈ 1e-15 relative; the tensors to 1e-12 of the pressure scale (the spin and Otsuki
  terms, three orders smaller, on their own scale), as in ``test_engine.py``.
* A register filled only by the manual ``record_*`` calls (no ensemble) gives every tensor of
  its definition (eq. S1-16 … S1-24), summed here entry by entry.
"""
import math
import unittest

import numpy as np

from particleShear import StressTensorEvaluation
from particleShear.base.register import Force_register
from particleShear.engine import stress as es
from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine.step import BatchEngine
from particleShearTest.test_engine import constituted

KINETIC = ("stress_tensor_spin_kinetic_energy", "stress_tensor_linear_acceleration_otsuki")


def sheared(seed, plates):
    """A constituted crosslinked, frictional ensemble after a few sheared class steps."""
    _, ens, sc = constituted(seed, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.3)
    ens.applyingShear = plates
    for k in range(15):
        ens.setShearRate(400.0 * math.cos(0.2 * k))
        ens.mechanical_simulation_step(0.999, sc["dt"])
    ens.setShearRate(300.0)
    return ens, sc


class TestClassesEqualEngine(unittest.TestCase):

    def check_scene(self, plates):
        ens, sc = sheared(3, plates)
        s = state_from_ensembles([ens])
        s.applying_shear = plates
        engine = BatchEngine(s, guard=False)
        tau_int_e, tau_surf_e, tens_e = engine.step(1.0, sc["dt"], sample="tensors")
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ens.evaluate_stress_tensors(ev)
        tens_c = ev.tensors
        p = abs(tens_e[0, 8, 0, 0]) + abs(tens_e[0, 8, 1, 1])
        self.assertGreater(p, 0.0)
        for k, t in enumerate(es.TENSORS):
            with self.subTest(tensor=t.name):
                scale = np.max(np.abs(tens_e[0, k])) if t.name in KINETIC else p
                self.assertGreater(np.max(np.abs(tens_e[0, k])), 0.0)
                self.assertLessEqual(np.max(np.abs(tens_c[k] - tens_e[0, k])), 1e-12 * scale)
        tau = ev.evaluate_shear_stresses(ens.force_register, ens.movableSphereList())
        self.assertLessEqual(abs(tau[0] - tau_int_e[0]), 1e-12 * p)
        self.assertLessEqual(abs(tau[1] - tau_surf_e[0]), 1e-12 * p)
        return ens, ev

    def test_sheared_scene_with_plates(self):
        ens, ev = self.check_scene(True)
        self.assertLess(len(ens.movableSphereList()), len(ens.sphereList))   # plates exist
        self.assertNotEqual(ev.stress_tensor_with_external_forces[0][1], 0.0)

    def test_crosslinked_periodic_scene(self):
        ens, ev = self.check_scene(False)
        self.assertEqual(len(ens.movableSphereList()), len(ens.sphereList))
        self.assertGreater(len(ens.permanent_pairs()[0]), 10)
        # pairs through the periodic boundary give external entries
        self.assertNotEqual(ev.stress_tensor_with_external_forces[0][1], 0.0)


class TestLinearMaps(unittest.TestCase):
    def test_tensors_together_equal_each_on_its_own(self):
        """``evaluate_all`` evaluates the linear tensors together (one gather, product and division):
        each is bit for bit the tensor its own function gives on fresh inputs of the same force phase
        (the overall tensor, the sum of three of them, too),
        for both replicas of a batch of two; the torque and spin tensors have their fixed pattern
        (antisymmetric, isotropic), their zero entries the sign of ``value · 0``."""
        ens = [sheared(seed, True)[0] for seed in (5, 6)]
        engine = BatchEngine(state_from_ensembles(ens, backend="numpy"), guard=False)   # (NumPy's evaluate_all)
        captured = []
        real = es.evaluate_all
        from particleShear.engine import step as step_module
        step_module.evaluate_all = lambda q: captured.append(q) or real(q)
        try:
            T = engine.force_phase(sample="tensors")[1][2]   # (the state stays that of the inputs)
        finally:
            step_module.evaluate_all = real
        q = captured[0]
        fresh = es.StressInputs(**{k: v for k, v in q.__dict__.items() if not k.startswith("_")})
        for k, t in enumerate(es.TENSORS):
            alone = t.function(fresh)
            with self.subTest(tensor=t.name):
                self.assertEqual(alone.shape, (2, 2, 2))
                np.testing.assert_array_equal(T[:, k], alone)
                self.assertTrue(np.all(np.isfinite(alone)))
        # the fixed patterns, with the zero entries as the definitions give them (value · 0: the sign of
        # the value), which the text output writes ("-0.0")
        for name in ("stress_tensor_unbalanced_torque", "stress_tensor_internal_torque"):
            A = T[:, [t.name for t in es.TENSORS].index(name)]
            np.testing.assert_array_equal(A[:, 0, 1], -A[:, 1, 0])
            np.testing.assert_array_equal(A[:, 0, 0], 0.0)
            np.testing.assert_array_equal(np.signbit(A[:, 0, 0]), np.signbit(A[:, 1, 0]))
            np.testing.assert_array_equal(np.signbit(A[:, 1, 1]), np.signbit(A[:, 1, 0]))
        S = T[:, [t.name for t in es.TENSORS].index("stress_tensor_spin_kinetic_energy")]
        np.testing.assert_array_equal(S[:, 0, 0], S[:, 1, 1])
        self.assertTrue(np.all(S[:, 0, 0] < 0.0))
        self.assertTrue(np.all(np.signbit(S[:, 0, 1])) and np.all(np.signbit(S[:, 1, 0])))


class TestAnyListOfSpheres(unittest.TestCase):
    def test_reordered_list_keeps_the_shear_stresses(self):
        """A list of the ensemble's mobile spheres in another order (summed sphere by sphere): the xy
        entries are still G's shear stresses bit for bit, the force tensors those of the ordered
        selection bit for bit, the kinetic tensors the same sums in another order (1e-12 of their
        scale)."""
        for plates in (True, False):
            ens, _ = sheared(4, plates)
            ens.mechanical_simulation_step_calculate_forces()
            ens.record_total_particle_forces()
            sel = ens.movableSphereList()
            ordered = StressTensorEvaluation(ens.size_x, ens.size_y)
            shuffled = StressTensorEvaluation(ens.size_x, ens.size_y)
            ordered.evaluate_stress_tensors(ens.force_register, sel, ens.shear_rate)
            others = list(sel)[::-1]
            shuffled.evaluate_stress_tensors(ens.force_register, others, ens.shear_rate)
            tau = shuffled.evaluate_shear_stresses(ens.force_register, others)
            with self.subTest(plates=plates):
                self.assertEqual(shuffled.evaluate_quasistatic_shear_stress(), tau[0])
                self.assertEqual(shuffled.evaluate_externally_applied_shear_stress(), tau[1])
                self.assertNotEqual(tau[1], 0.0)
                for k, t in enumerate(es.TENSORS):
                    a, b = ordered.tensors[k], shuffled.tensors[k]
                    if t.name in KINETIC:
                        self.assertGreater(np.abs(a).max(), 0.0)
                        self.assertLessEqual(np.abs(a - b).max(), 1e-12 * np.abs(a).max(), t.name)
                    elif t.name != "overall_stress_tensor":     # (its spin part is kinetic)
                        self.assertEqual(a.tobytes(), b.tobytes(), t.name)


class Point:
    """A sphere of a script without an ensemble: what the manual register entries read."""

    def __init__(self, x, y):
        self.x, self.y = x, y


class TestManualRegister(unittest.TestCase):
    def test_manual_entries_equal_their_definitions(self):
        L = 100.0
        V = (L * 1e-6) ** 2
        rng = np.random.default_rng(2)
        pts = [Point(*rng.uniform(0, L, 2)) for _ in range(6)]
        reg = Force_register()
        F = rng.normal(size=(4, 2)) * 1e3
        reg.record_individual_internal_force(pts[0], pts[1], F[0])
        reg.record_individual_internal_force(pts[1], pts[0], -F[0])
        reg.record_individual_internal_force(pts[2], pts[3], F[1])
        reg.record_external_force(pts[4], F[2])
        reg.record_total_particle_force(pts[5], F[3])
        reg.record_individual_internal_torque(pts[0], pts[1], 7.0)
        reg.record_unbalanced_moment(pts[2], -3.0)
        ev = StressTensorEvaluation(L, L)
        ev.evaluate_force_stress_tensors(reg)
        ev.evaluate_rotational_stress_tensors(reg, [])
        c = np.array((L / 2, L / 2))
        pos = [np.array((p.x, p.y)) for p in pts]
        lw = (np.outer(F[0], pos[0] - pos[1]) + np.outer(-F[0], pos[1] - pos[0]) + np.outer(F[1], pos[2] - pos[3])) / 2
        rot = np.array([[0.0, -0.5], [0.5, 0.0]])
        expected = {
            "stress_tensor_LW": lw * 1e-18 / V,                                   # eq. S1-19
            "stress_tensor_with_external_forces": -np.outer(F[2], pos[4] - c) * 1e-18 / V,   # eq. S1-16
            "stress_tensor_unbalanced_forces": np.outer(F[3], pos[5] - c) * 1e-18 / V,       # eq. S1-17
            "stress_tensor_linear_acceleration": np.outer(F[3], pos[5] - c) * 1e-18 / V,
            "stress_tensor_internal_torque": 7.0 * 1e-18 / V * rot,                # eq. S1-22
            "stress_tensor_unbalanced_torque": -3.0 * 1e-18 / V * rot,
            "stress_tensor_spin_kinetic_energy": np.zeros((2, 2)),                 # no spheres passed
        }
        for name, want in expected.items():
            with self.subTest(tensor=name):
                got = np.array(getattr(ev, name))
                # a few products and sums of exact inputs: rounding ≲ 1e-15 of the tensor's scale
                self.assertLessEqual(np.max(np.abs(got - want)), 1e-13 * (np.max(np.abs(want)) + 1e-300))
        self.assertGreater(np.max(np.abs(expected["stress_tensor_LW"])), 0.0)


if __name__ == "__main__":
    unittest.main()
