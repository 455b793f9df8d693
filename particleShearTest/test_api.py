"""Array-backed API behaviour: sphere views, relations, active terms, integrator choice."""
import math
import unittest

import numpy as np

from particleShear import (EnsembleFrictionLeesEdwards, EnsembleLinkable, SphereLinkable,
                           StressTensorEvaluation)


def linkable(mu=0.01, k_t=1.0, nu_t=1.0):
    return EnsembleLinkable(500, 500, 0, k=1, nu=1, k_t=k_t, nu_t=nu_t, mu=mu)


def add(ens, x, y, d=120, idx=1):
    s = SphereLinkable("grey", x, y, d, 1, idx, force_register=ens)
    ens.sphereList.append(s)
    return s


class TestSphereViews(unittest.TestCase):
    def test_attribute_reads_and_writes_go_to_the_arrays(self):
        ens = linkable()
        s = add(ens, 150, 200)
        s.xspeed = 3.5
        arrays = ens.sphere_arrays
        self.assertEqual(arrays["xspeed"][0], 3.5)
        s.omega = 0.25
        self.assertEqual(arrays["omega"][0], 0.25)       # the arrays are views of the ensemble's state
        with self.assertRaises(ValueError):              # read-only: writes go through the spheres
            arrays["omega"][0] = 0.5
        self.assertEqual(s.omega, 0.25)
        self.assertEqual(s.inertia, 1 * 60 * 60 / 2)

    def test_sphere_list_cannot_lose_spheres(self):
        ens = linkable()
        add(ens, 150, 200)
        for op in (lambda: ens.sphereList.pop(), lambda: ens.sphereList.remove(ens.sphereList[0]),
                   lambda: ens.sphereList.__delitem__(0)):
            self.assertRaises(TypeError, op)
        self.assertEqual(len(ens.sphereList), 1)

    def test_link_made_before_append_is_adopted(self):
        ens = linkable()
        a = SphereLinkable("grey", 150, 200, 120, 1, 1, force_register=ens)
        b = SphereLinkable("grey", 220, 260, 120, 1, 2, force_register=ens)
        a.establish_permanent_link(b)
        ens.sphereList.append(a)
        ens.sphereList.append(b)
        for s, other in ((a, b), (b, a)):
            (rel,) = s.neighbors
            self.assertIs(rel.theSphere, other)
            self.assertEqual(rel.interface_type, "permanent")
            self.assertEqual(rel.equilibrium_distance, 120)
        self.assertIn("permanent_links", ens.active_terms)

    def test_relation_views_write_through(self):
        ens = linkable()
        a = add(ens, 150, 200, idx=1)
        b = add(ens, 220, 260, idx=2)
        a.establish_permanent_link(b)
        a.neighbors[0].friction_position = 1.5
        pt = ens.pair_table
        self.assertEqual(pt.xi_ij[pt.find(0, 1)], 1.5)
        pt.xi_ij[:] = 0.0                                           # a copy: the ensemble keeps its history
        self.assertEqual(a.neighbors[0].friction_position, 1.5)
        self.assertEqual(b.neighbors[0].friction_position, 0.0)  # the other direction is its own history
        a.cut_permanent_link(b)
        self.assertEqual(a.neighbors[0].interface_type, "slip")
        self.assertEqual(a.neighbors[0].friction_position, 0.0)

    def test_neighbors_are_contacts_in_creation_order(self):
        ens = linkable()
        c = add(ens, 250, 250, idx=0)
        far = add(ens, 400, 250, idx=1)     # touches c later only if it moves; here never
        near2 = add(ens, 250, 150, idx=2)   # d = 100 < 120
        near1 = add(ens, 160, 250, idx=3)   # d = 90 < 120
        ens.test_neighbor_relation()
        self.assertEqual([r.theSphere for r in c.neighbors], [near2, near1])
        self.assertEqual(far.neighbors, [])


class TestActiveTerms(unittest.TestCase):
    def test_terms_follow_the_scene(self):
        ens = EnsembleFrictionLeesEdwards(500, 500, 30, packing_fraction=1.2, mu=0, nu=0)
        self.assertEqual(ens.active_terms, ["central_elastic"])
        ens.mu = 0.1
        ens.nu = 0.5
        self.assertEqual(ens.active_terms, ["central_elastic", "central_viscous", "tangential"])
        lk = linkable(mu=0)
        a, b = add(lk, 150, 200), add(lk, 220, 260, idx=2)
        self.assertNotIn("permanent_links", lk.active_terms)
        a.establish_permanent_link(b)
        self.assertIn("permanent_links", lk.active_terms)
        self.assertNotIn("tangential", lk.active_terms)

    def test_frictionless_contacts_slip_with_zero_history(self):
        # μ = 0: the Coulomb bound is 0, so a touching pair slips and keeps ξ = 0 (reference rule)
        ens = linkable(mu=0)
        a, b = add(ens, 150, 200), add(ens, 230, 200, idx=2)
        b.yspeed = 2.0
        for _ in range(5):
            ens.mechanical_simulation_step(1, 0.1)
        (rel,) = a.neighbors
        self.assertEqual(rel.interface_type, "slip")
        self.assertEqual(rel.friction_position, 0.0)
        self.assertEqual(a.torque, 0.0)


class TestIntegrators(unittest.TestCase):
    def run_pair(self, integrator, dt, steps):
        ens = linkable(mu=0.5)
        a, b = add(ens, 150, 200), add(ens, 260, 220, idx=2)
        a.xspeed, b.xspeed, b.omega = 5.0, -5.0, 0.2
        ens.set_integrator(integrator)
        for _ in range(steps):
            ens.mechanical_simulation_step(1, dt)
        return np.array([a.x, a.y, b.x, b.y])

    def test_unknown_integrator_rejected(self):
        self.assertRaises(ValueError, linkable().set_integrator, "rk4")

    def test_verlet_converges_to_the_same_trajectory(self):
        # both schemes approximate the same ODE to first order at least (the velocity forces make the
        # explicit kick first order): their difference shrinks ∝ dt, 4× from dt = 0.04 to 0.01 (measured
        # 0.30 → 0.075); a factor 2.5 leaves room for higher-order terms and fails if it does not converge
        T = 8.0
        diffs = []
        for dt in (0.04, 0.02, 0.01):
            n = int(round(T / dt))
            diffs.append(np.abs(self.run_pair("verlet", dt, n) - self.run_pair("euler", dt, n)).max())
        self.assertGreater(diffs[0], 0)
        self.assertLess(diffs[2], diffs[0] / 2.5)

    def test_verlet_without_velocity_forces_equals_euler(self):
        # with ν = ν_t = 0 and no friction the predictor changes nothing: identical positions
        def run(integrator):
            ens = EnsembleLinkable(500, 500, 0, k=1, nu=0, k_t=0, nu_t=0, mu=0)
            a, b = add(ens, 150, 200), add(ens, 260, 220, idx=2)
            a.xspeed, b.xspeed = 5.0, -5.0
            ens.set_integrator(integrator)
            for _ in range(200):
                ens.mechanical_simulation_step(1, 0.05)
            return (a.x, a.y, b.x, b.y)
        self.assertEqual(run("verlet"), run("euler"))


class TestEvaluationModes(unittest.TestCase):
    def test_shear_only_evaluation_matches_full(self):
        rng = np.random.default_rng(4)
        ens = linkable(mu=0.3)
        for k in range(40):
            add(ens, float(rng.uniform(0, 500)), float(rng.uniform(0, 500)), d=float(rng.uniform(60, 90)), idx=k)
        ens.set_central_repulsion_coefficient(1)
        for _ in range(30):
            ens.mechanical_simulation_step(0.9, 0.05)
        ens.makeAllLinksPermanent()
        ens.cutLine((250, 250), 1.0)
        ens.applyingShear = True
        ens.setShearRate(0.3)
        for _ in range(20):
            ens.mechanical_simulation_step(0.9, 0.05)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        full = StressTensorEvaluation(500, 500)
        ens.evaluate_stress_tensors(full)
        part = StressTensorEvaluation(500, 500)
        from particleShear.base.register import SphereSelection
        tau_int, tau_surf = part.evaluate_shear_stresses(ens.force_register, SphereSelection(ens, ens._mobile_mask()))
        self.assertEqual(tau_int, full.evaluate_quasistatic_shear_stress())
        self.assertEqual(tau_surf, full.evaluate_externally_applied_shear_stress())
        self.assertTrue(math.isfinite(tau_int) and tau_int != 0)



class TestLegacyEnsembles(unittest.TestCase):
    def test_periodic_friction_ensemble_conserves_momentum(self):
        # plain periodic cell, no plates, no damping: pair forces cancel, Σ m v stays put
        from particleShear import EnsembleFriction
        ens = EnsembleFriction(500, 500, 60, packing_fraction=1.2, k=1, nu=0.5, k_t=1, nu_t=0.5, mu=0.3)
        ens.set_random_generator(np.random.default_rng(3))
        for sphere, v in zip(ens.sphereList, np.random.default_rng(1).normal(0, 1, 60)):
            sphere.xspeed = v
        p0 = ens.total_momentum()
        for _ in range(100):
            ens.mechanical_simulation_step(1, 0.05)
        a = ens.sphere_arrays
        scale = float(a["m"] @ np.abs(a["xspeed"]))
        self.assertLess(np.abs(ens.total_momentum() - p0).max(), 1e-12 * scale)
        self.assertIn("tangential", ens.active_terms)
        self.assertTrue(np.any(ens.sphere_arrays["omega"] != 0))  # friction spins the spheres


class TestAllocatorTuning(unittest.TestCase):
    def test_opt_out_leaves_the_allocator_alone(self):
        import os
        import subprocess
        import sys
        code = ("import particleShear.engine.memory as m; from particleShear import EnsembleLinkable; "
                "EnsembleLinkable(500, 500, 0); print(m._done)")
        env = dict(os.environ, PARTICLESHEAR_NO_MALLOPT="1")
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        self.assertEqual(out.stdout.strip(), "False")
        env.pop("PARTICLESHEAR_NO_MALLOPT")
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        import platform
        glibc = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"
        self.assertEqual(out.stdout.strip(), "True" if glibc else "False")


if __name__ == "__main__":
    unittest.main()
