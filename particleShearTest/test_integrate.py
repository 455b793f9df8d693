"""The integration functions of ``particleShear.engine.integrate`` as pure functions.

* ``kick``: a pair force applied as +F on i and −F on j changes no total momentum (Newton's
  third law), and each velocity changes by exactly ``F·dt/m`` (its definition, evaluated here
  with the same two roundings, so the comparison is exact);
* ``damp``: the affine shear flow is a fixed point, the peculiar velocity and the spin lose the
  factor ``f`` (to rounding of one subtraction and one addition);
* ``plates_follow``: plate spheres take ``±γ̇·Ly/2`` by side and no y velocity, others are untouched;
* ``xi_increments``: rolling without slipping gives ξ̇ = 0 on both visits; on random pairs the two
  increments equal the reference's visit formula written from scratch — the j→i visit with the
  normal from j to i *after* i moved, ``(v_i − v_j + image)·t_ji − (r_i ω_i + r_j ω_j)`` — to a
  few ulps of the velocity scale;
* ``mobile_mask``: a sphere is mobile exactly when it overlaps neither plate, ``r < y < Ly − r``
  (strict: touching a plate is overlapping it);
* ``shift_flow``: after a change of rate every velocity relative to the new flow and every spin
  relative to the new rotation rate ``−γ̇/2`` is what it was relative to the old ones (to rounding
  of one product and one addition);
* ``remove_mean_velocity``: each replica's mean velocity becomes 0 (to rounding), its own sums
  only — the definition ``v − Σ v/N`` per replica evaluated here replica by replica, exactly;
* the documented classes and the engine call these functions (one implementation).
"""
import unittest

import numpy as np

from particleShear.engine import integrate
from particleShear.engine.integrate import (damp, drift, kick, mobile_mask, plates_follow, remove_mean_velocity, shift_flow,
                                           xi_increments)


def _unit(rx, ry):
    d = np.sqrt(rx * rx + ry * ry)
    return rx / d, ry / d


class TestKick(unittest.TestCase):
    def test_pair_forces_conserve_momentum(self):
        rng = np.random.default_rng(1)
        n = 40
        m = rng.uniform(0.5, 2.0, n)
        inertia = 0.5 * m * rng.uniform(0.5, 1.5, n) ** 2
        vel = rng.normal(size=(3, n))
        frc = np.zeros((3, n))
        i, j = rng.choice(n, size=(2, 200))
        keep = i != j
        i, j = i[keep], j[keep]
        F = rng.normal(size=(2, len(i)))
        np.add.at(frc[0], i, F[0])
        np.add.at(frc[0], j, -F[0])
        np.add.at(frc[1], i, F[1])
        np.add.at(frc[1], j, -F[1])
        frc[2] = rng.normal(size=n)
        before = (m * vel[:2]).sum(axis=1)
        expected = vel + frc * 1e-3 / np.stack((m, m, inertia))
        kick(vel, frc, np.stack((m, m, inertia)), 1e-3)
        np.testing.assert_array_equal(vel, expected)      # v += (F·dt)/m, the definition
        self.assertFalse(frc.any())                        # forces are consumed
        after = (m * vel[:2]).sum(axis=1)
        scale = np.abs(m * vel[:2]).sum()
        np.testing.assert_allclose(after, before, rtol=0, atol=1e-14 * scale)


class TestDamping(unittest.TestCase):
    def test_flow_is_a_fixed_point_and_peculiar_velocity_decays(self):
        rng = np.random.default_rng(2)
        n, rate, Ly, f = 50, 3.0, 100.0, 0.9
        y = rng.uniform(0, Ly, n)
        flow = (y - Ly / 2) * rate
        vel = np.stack((flow.copy(), np.zeros(n), np.zeros(n)))
        damp(vel, flow, f)
        np.testing.assert_allclose(vel[0], flow, rtol=0, atol=1e-13 * rate * Ly)
        self.assertFalse(vel[1:].any())
        pec = rng.normal(size=(3, n))
        vel = pec.copy()
        vel[0] += flow
        damp(vel, flow, f)
        np.testing.assert_allclose(vel[0] - flow, f * pec[0], rtol=0, atol=1e-13 * rate * Ly)
        np.testing.assert_array_equal(vel[1:], f * pec[1:])

    def test_without_flow_every_row_scales(self):
        v = np.array([[1.0, -2.0], [0.5, 3.0], [-1.0, 0.25]])
        w = v.copy()
        damp(w, None, 0.5)
        np.testing.assert_array_equal(w, 0.5 * v)


class TestPlates(unittest.TestCase):
    def test_plate_spheres_move_with_their_plate(self):
        Ly, rate = 20.0, 2.0
        y = np.array([0.5, 10.0, 19.5, 12.0])
        imm = np.array([True, False, True, False])
        vx = np.array([5.0, 6.0, 7.0, 8.0])
        vy = np.array([1.0, 2.0, 3.0, 4.0])
        plates_follow(vx, vy, imm, y - Ly / 2, rate * Ly / 2)
        np.testing.assert_array_equal(vx, [-rate * Ly / 2, 6.0, rate * Ly / 2, 8.0])
        np.testing.assert_array_equal(vy, [0.0, 2.0, 0.0, 4.0])


class TestXiIncrements(unittest.TestCase):
    def test_rolling_without_slipping(self):
        # i at the origin at rest, j at (d, 0) moving up with V; spins so that the contact points move together
        d, ri, rj, V = 2.0, 1.2, 0.8, 3.0
        Vi = np.array([[0.0], [0.0], [0.5 * V / ri]])
        Vj = np.array([[0.0], [V], [0.5 * V / rj]])
        inc_ij, inc_ji = xi_increments(Vi, Vj, None, np.array([1.0]), np.array([0.0]), np.array([ri]),
                                       np.array([rj]), np.array([-d]), np.array([0.0]), _unit)
        self.assertEqual(inc_ij[0], 0.0)
        self.assertEqual(inc_ji[0], 0.0)

    def test_both_visits_against_the_reference_formula(self):
        rng = np.random.default_rng(3)
        P, dt = 300, 1e-3
        Vi, Vj = rng.normal(size=(3, P)), rng.normal(size=(3, P))
        ri, rj = rng.uniform(0.5, 1.5, (2, P))
        theta = rng.uniform(0, 2 * np.pi, P)
        D = np.stack((np.cos(theta), np.sin(theta))) * (ri + rj) * 0.95      # x_j − x_i (minimum image)
        dvx = rng.choice([0.0, 4.0, -4.0], P)                                    # image velocity of j
        n = D / np.hypot(*D)
        R = Vi[:2] * dt - D
        inc_ij, inc_ji = xi_increments(Vi, Vj, dvx, n[0], n[1], ri, rj, R[0], R[1], _unit)
        spin = ri * Vi[2] + rj * Vj[2]
        # visit i → j: relative velocity of j's image seen from i along t_ij = (−n_y, n_x)
        rel = np.stack((Vj[0] + dvx - Vi[0], Vj[1] - Vi[1]))
        ref_ij = rel[0] * -n[1] + rel[1] * n[0] - spin
        # visit j → i after i moved: normal from j to i's new position, relative velocity of i seen from j
        e = R / np.hypot(*R)              # R = (x_i + v_i dt) − x_j: from j to the moved i, normalised
        rel_ji = -rel
        ref_ji = rel_ji[0] * -e[1] + rel_ji[1] * e[0] - spin
        scale = np.abs(Vi).max() + np.abs(Vj).max() + 4.0
        np.testing.assert_allclose(inc_ij, ref_ij, rtol=0, atol=1e-14 * scale)
        np.testing.assert_allclose(inc_ji, ref_ji, rtol=0, atol=1e-14 * scale)
        # the second visit sees i moved: with dt = 0 it would be the first visit mirrored
        _, mirrored = xi_increments(Vi, Vj, dvx, n[0], n[1], ri, rj, -D[0], -D[1], _unit)
        np.testing.assert_allclose(mirrored, inc_ij, rtol=0, atol=1e-14 * scale)
        self.assertGreater(np.abs(inc_ji - inc_ij).max(), 0.0)


class TestDrift(unittest.TestCase):
    def test_positions_and_angles_advance(self):
        pos = np.array([[1.0, 2.0], [3.0, 4.0]])
        phi = np.array([0.0, 1.0])
        vel = np.array([[1.0, -1.0], [0.5, 0.0], [2.0, 4.0]])
        drift(pos, phi, vel, 0.5)
        np.testing.assert_array_equal(pos, [[1.5, 1.5], [3.25, 4.0]])
        np.testing.assert_array_equal(phi, [1.0, 3.0])


class TestFlowAndPlates(unittest.TestCase):
    def test_mobile_exactly_between_the_plates(self):
        Ly = 100.0
        r = np.array([5.0, 5.0, 5.0, 5.0, 5.0, 20.0])
        y = np.array([5.0, 5.000001, 94.999999, 95.0, 50.0, 15.0])
        np.testing.assert_array_equal(mobile_mask(r, y, Ly), [False, True, True, False, True, False])
        self.assertIs(bool(mobile_mask(5.0, 50.0, Ly)), True)

    def test_rate_change_keeps_the_peculiar_velocities(self):
        rng = np.random.default_rng(4)
        n, Ly = 50, 200.0
        y = rng.uniform(0, Ly, n)
        yc = y - Ly / 2
        vx, omega = rng.normal(size=n) * 10, rng.normal(size=n)
        old, new = 3.0, -7.5
        u0, w0 = vx - old * yc, omega + old / 2
        shift_flow(vx, omega, yc, new - old)
        scale = 1e-14 * (np.abs(vx).max() + abs(new) * Ly)
        np.testing.assert_allclose(vx - new * yc, u0, rtol=0, atol=scale)
        np.testing.assert_allclose(omega + new / 2, w0, rtol=0, atol=1e-14 * (np.abs(omega).max() + abs(new)))

    def test_mean_velocity_removed_per_replica(self):
        rng = np.random.default_rng(5)
        B, N = 4, 37
        vel = rng.normal(size=(2, B * N)) + np.repeat(rng.normal(size=(2, B)) * 5, N, axis=1)
        want = vel.copy()
        for b in range(B):
            rows = slice(b * N, (b + 1) * N)
            for k in range(2):
                want[k, rows] -= want[k, rows].sum() / N
        remove_mean_velocity(vel, B)
        np.testing.assert_array_equal(vel, want)
        self.assertLess(np.abs(vel.reshape(2, B, N).mean(axis=2)).max(), 1e-14 * 5)


class TestOneImplementation(unittest.TestCase):
    def test_engine_and_classes_call_these_functions(self):
        import inspect
        from particleShear.base import canvas_base, elastic_canvas, pair_canvas
        from particleShear.engine import step
        for name in ("kick", "damp", "plates_follow", "xi_increments", "mobile_mask", "shift_flow"):
            self.assertIs(getattr(step, name), getattr(integrate, name), name)
            # the documented canvases (three modules, gathered by base.canvas) use the engine's function wherever they use one
            # (the ξ rule only through the engine's movement: engine_view)
            users = [m for m in (canvas_base, pair_canvas, elastic_canvas) if hasattr(m, name)]
            self.assertEqual(bool(users), name != "xi_increments", name)
            for module in users:
                self.assertIs(getattr(module, name), getattr(integrate, name), (module.__name__, name))
        src = "".join(inspect.getsource(getattr(step.BatchEngine, phase)) for phase in ("accelerate", "move_spheres"))
        for name in ("kick(", "half_kick(", "damp(", "plates_follow(", "xi_increments(", "drift("):
            self.assertIn(name, src)


if __name__ == "__main__":
    unittest.main()
