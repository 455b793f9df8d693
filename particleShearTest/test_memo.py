"""The one cache mechanism of the canvas classes (particleShear.base.memo) and what the canvases keep in it.

A kept value must be what recomputing it gives: the memo's contract (same key: the kept value; new key
or a drop: recomputed), and, on a sheared crosslinked scene, every value the canvas keeps
compared with the same value computed from the ensemble's state by its definition.
"""
import math
import unittest

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable
from particleShear.base.memo import Memo
from particleShear.base.neighbours import PERMANENT


class TestMemo(unittest.TestCase):
    def test_same_key_keeps_new_key_recomputes(self):
        m = Memo()
        calls = []

        def compute(v):
            calls.append(v)
            return v * v
        self.assertEqual(m.get("sq", (3,), lambda: compute(3)), 9)
        self.assertEqual(m.get("sq", (3,), lambda: compute(-1)), 9)      # kept: compute not called
        self.assertEqual(calls, [3])
        self.assertEqual(m.get("sq", (4,), lambda: compute(4)), 16)      # key changed: recomputed
        self.assertEqual(calls, [3, 4])

    def test_names_are_independent(self):
        m = Memo()
        m.get("a", (1,), lambda: "A")
        self.assertEqual(m.get("b", (1,), lambda: "B"), "B")
        self.assertEqual(m.get("a", (1,), lambda: "other"), "A")

    def test_drop_forgets_one_value(self):
        m = Memo()
        m.get("a", (1,), lambda: 1)
        m.get("b", (1,), lambda: 2)
        self.assertEqual(m.drop("a"), 1)
        self.assertIsNone(m.peek("a"))
        self.assertIsNone(m.drop("a"))
        self.assertEqual(m.get("a", (1,), lambda: 10), 10)
        self.assertEqual(m.get("b", (1,), lambda: 20), 2)

    def test_bytes_keys_compare_by_content(self):
        m = Memo()
        a = np.array([True, False, True])
        first = m.get("mask", (a.tobytes(),), lambda: a)
        b = a.copy()
        self.assertIs(m.get("mask", (b.tobytes(),), lambda: b), first)     # equal content: the kept array
        c = np.array([True, True, True])
        self.assertIs(m.get("mask", (c.tobytes(),), lambda: c), c)


def _scene(seed=2, n=40):
    """Crosslinked frictional bimodal spheres, compressed (φ = 1.3), a few bonds cut, plates on."""
    rng = np.random.default_rng(seed)
    L = 200.0
    r_b = math.sqrt(L * L * 1.3 / (n * math.pi))
    ens = EnsembleLinkable(L, L, 0, k=1e3, nu=1.0, k_t=1e3, nu_t=1.0, mu=0.3)
    ens.set_random_generator(rng)
    for p in range(n):
        r = r_b * (1.18 if p % 2 else 0.85)
        ens.sphereList.append(SphereLinkable("grey", float(rng.random() * L), float(rng.random() * L), 2 * r,
                                             0.1, p, force_register=ens, size_x=L, size_y=L))
    for _ in range(20):
        ens.mechanical_simulation_step(cool_factor=0.7, dt=1e-3)
    ens.test_neighbor_relation()
    ens.makeAllLinksPermanent()
    ens.cutRandomLine()
    ens.applyingShear = True
    ens.setShearRate(0.5)
    return ens


class TestCanvasMemo(unittest.TestCase):
    """Each value the canvas keeps equals its definition evaluated from the current state."""

    def setUp(self):
        self.ens = _scene()
        for _ in range(15):
            self.ens.mechanical_simulation_step(cool_factor=0.95, dt=1e-3)
        self.ens.mechanical_simulation_step_calculate_forces()

    def test_mobile_mask_is_its_definition(self):
        ens = self.ens
        a = ens.sphere_arrays
        expected = (a["r"] < a["y"]) & (a["y"] < ens.size_y - a["r"])
        mob = ens._mobile_mask()
        np.testing.assert_array_equal(mob, expected)
        self.assertTrue(0 < expected.sum() < len(expected))   # the scene has plate spheres

    def test_mobile_mask_follows_a_moved_sphere(self):
        ens = self.ens
        mob = ens._mobile_mask()
        k = int(np.flatnonzero(mob)[0])
        s = ens.sphereList[k]
        s.y = 0.5 * s.r       # onto the lower plate
        self.assertFalse(ens._mobile_mask()[k])

    def test_mobile_selection_holds_the_mobile_spheres(self):
        ens = self.ens
        a = ens.sphere_arrays
        mobile = (a["r"] < a["y"]) & (a["y"] < ens.size_y - a["r"])
        expected = [s for s, m in zip(ens.sphereList, mobile) if m]
        for sel in (ens._mobile_selection(), ens.movableSphereList()):
            self.assertEqual(len(sel), len(expected))
            self.assertTrue(all(x is y for x, y in zip(sel, expected)))
            np.testing.assert_array_equal(sel.mask, mobile)
        k = int(np.flatnonzero(mobile)[0])
        ens.sphereList[k].y = 0.5 * ens.sphereList[k].r   # onto the lower plate: one sphere fewer
        self.assertEqual(len(ens._mobile_selection()), len(expected) - 1)
        self.assertNotIn(ens.sphereList[k], ens._mobile_selection())

    # -- the constants of the ensemble's engine (the step's one cache of per-candidate values) --------
    def _constants(self):
        """The per-candidate constants of the last force phase and the table rows they describe."""
        ens = self.ens
        C = ens._engine.s.contacts.C
        pt = ens.pair_table
        return C, pt.find(C.ai, C.aj)

    def test_pair_constants_are_their_definition(self):
        ens = self.ens
        C, slots = self._constants()
        pt = ens.pair_table
        r = ens.sphere_arrays["r"]
        self.assertTrue((slots >= 0).all())          # every candidate of the engine is a row of the table
        i, j = pt.i[slots], pt.j[slots]
        np.testing.assert_array_equal(C.ai, i)
        np.testing.assert_array_equal(C.aj, j)
        np.testing.assert_array_equal(C.d0, r[i] + r[j])
        np.testing.assert_array_equal(C.ri, r[i])
        np.testing.assert_array_equal(C.rj, r[j])
        perm = pt.state[slots] == PERMANENT
        self.assertTrue(perm.any() and not perm.all())
        np.testing.assert_array_equal(C.perm, perm)
        np.testing.assert_array_equal(C.trans, ~perm)
        deq = pt.d_eq[slots]
        np.testing.assert_array_equal(C.d_law, np.where(perm, deq, C.d0))
        np.testing.assert_array_equal(C.d_cap, np.where(perm, deq, C.d0) / 1000)
        np.testing.assert_array_equal(C.perm_code, np.where(perm, PERMANENT, 0).astype(np.int8))
        np.testing.assert_array_equal(C.fc_inf, np.where(perm, np.inf, 0.0))
        np.testing.assert_array_equal(C.mu, ens.mu)
        self.assertIsNone(C.Kj)                       # every sphere has the same parameters

    def test_register_flags_are_their_definition(self):
        ens = self.ens
        p = ens.force_register._blocks[0]
        mob = ens._mobile_mask()
        pos = ens._pos
        D0 = pos[:, p["j"]] - pos[:, p["i"]]
        D = p["D"]
        # through the boundary: raw and minimum-image vectors differ
        shifted = (D0 != D).any(axis=0)
        mi, mj = mob[p["i"]], mob[p["j"]]
        internal = mi & mj & ~shifted
        live = p["active"]
        self.assertTrue((shifted & live).any() and (~(mi & mj) & live).any())   # both kinds of external pair
        np.testing.assert_array_equal(p["internal"], internal)
        np.testing.assert_array_equal(p["ext_i"], mi & ~internal)
        np.testing.assert_array_equal(p["ext_j"], mj & ~internal)

    def test_register_lists_are_those_of_their_force_phase(self):
        """The six lists are made when first read, from the record of the force phase: read after
        the step's kick and movement (which change velocities, positions, ξ, states and relation
        numbers) they are, entry by entry, the lists read at once, as 1.0.2's register, filled
        during the force phase, keeps them until the next one."""
        def lists(ens):
            reg = ens.force_register
            flat = lambda e: tuple(x._idx if hasattr(x, "_idx") else tuple(x) if isinstance(x, list) else x
                                   for x in e)   # noqa: E731
            return {name: [flat(e) for e in getattr(reg, name)] for name in (
                "pair_register", "external_force_register", "internal_moment_register",
                "external_moment_register", "total_particle_force_register", "unbalanced_moment_register")}
        at_once, later = self.ens, _scene()
        for _ in range(15):
            later.mechanical_simulation_step(cool_factor=0.95, dt=1e-3)
        later.mechanical_simulation_step_calculate_forces()
        later.record_total_particle_forces()
        at_once.record_total_particle_forces()
        expected = lists(at_once)
        xi_before = later.pair_table.xi.copy()
        later.mechanical_simulation_step_calculate_acceleration(0.95, 1e-3)
        later.mechanical_simulation_step_calculate_movement(1e-3)
        self.assertFalse(np.array_equal(later.pair_table.xi, xi_before))     # the movement changed the history
        got = lists(later)
        self.assertGreater(len(expected["pair_register"]), 0)
        self.assertGreater(len(expected["external_force_register"]), 0)
        for name in expected:
            self.assertEqual(got[name], expected[name], name)

    def test_sphere_parameters_give_each_visit_its_constants(self):
        ens = self.ens
        s = ens.sphereList[3]
        s.permanent_ratio_tangential = 2.0            # one sphere: its visits see twice k_t on its bonds
        ens.mechanical_simulation_step_calculate_forces()
        C, slots = self._constants()
        perm = ens.pair_table.state[slots] == PERMANENT
        ratio = np.where(np.arange(len(ens.sphereList)) == 3, 2.0, 1.0)
        self.assertIsNotNone(C.Kj)
        np.testing.assert_array_equal(C.k_t, ens.k_t * np.where(perm, ratio[C.ai], 1.0))
        np.testing.assert_array_equal(C.Kj.k_t, ens.k_t * np.where(perm, ratio[C.aj], 1.0))
        self.assertTrue(((C.ai == 3) | (C.aj == 3))[perm].any())   # the sphere has bonds

    def test_changed_parameters_renew_the_constants(self):
        ens = self.ens
        for name, value in (("mu", 0.7), ("k", 2e3), ("nu", 3.0), ("k_t", 5e2), ("nu_t", 0.25)):
            with self.subTest(name=name):
                setattr(ens, name, value)
                ens.mechanical_simulation_step_calculate_forces()
                C, slots = self._constants()
                perm = ens.pair_table.state[slots] == PERMANENT
                got = {"mu": np.max(C.mu), "k": np.max(C.k), "nu": np.max(C.nu), "k_t": np.max(C.k_t),
                       "nu_t": np.max(C.nu_t)}[name]
                self.assertEqual(got, value)
                if name == "k":
                    np.testing.assert_array_equal(C.a_tens, -np.where(perm, value, 0.0))

    def test_cut_bond_changes_the_constants(self):
        ens = self.ens
        n_bonds = int(np.isinf(self._constants()[0].fc_inf).sum())
        i, j = ens.permanent_pairs()
        ens._cut_pairs(i[:1], j[:1])
        ens.mechanical_simulation_step_calculate_forces()
        C = self._constants()[0]
        self.assertEqual(int(np.isinf(C.fc_inf).sum()), n_bonds - 1)
        self.assertEqual(int((C.perm_code != 0).sum()), n_bonds - 1)

    def test_edited_relations_renew_the_constants(self):
        ens = self.ens
        C = ens._engine.s.contacts.C
        ens._relations_edited()
        ens.mechanical_simulation_step_calculate_forces()
        self.assertIsNot(ens._engine.s.contacts.C, C)


if __name__ == "__main__":
    unittest.main()
