"""The documented per-sphere API evaluates the engine's terms.

Every documented per-sphere method of ``base/points.py`` and ``linkable/spheres.py`` is checked
against the engine's pure functions (``engine.box``, ``engine.terms``, ``engine.integrate``)
evaluated here on arrays of many random pairs at once, independently of the sphere objects, and
then read at each pair; and, where a two-sphere value is known in closed form, against it:

* geometry and kinematics: the Lees-Edwards minimum image (the y image first, moving x by
  ``Ly·γ``; the image one row up moves faster by ``Ly·γ̇``), ``d``, ``n``, ``t``, the relative
  velocity, the slip speed — bit for bit (the same operations on the same numbers);
* central terms: the contact law (linear law ``f = −k δ`` for c = 0, divergent law
  ``−k δ/(1 − δ/d0)`` for c = 1, 0 without overlap), a bond's tensile law ``k (d − d_eq)`` × the
  permanent ratio, the viscous force ``ν v_n`` (× the ratio on bonds unless kept) — bit for bit
  against the vectorised terms, to rounding of one or two products against the closed forms;
* the tangential rule: a visit from i and then one from j give the two rows of the vectorised
  two-visit rule bit for bit (forces, the final state, both histories after a slip); a contact's
  force never exceeds ``μ |law|`` and equals it when it slips, a bond's exceeds it; the couple
  puts ``±f t`` on the two spheres and the torques ``d·f·r_i/(r_i + r_j)`` and
  ``d·f·r_j/(r_i + r_j)`` (their sum ``d·f``) — the sum of the two half visits agrees with the
  vectorised ``(F1 + F2)/2`` to rounding of one addition;
* the ``*_from_neighbors`` methods add the pair forces of a sphere's relations in ``neighbors``
  order (bit for bit against the sequential sum of the vectorised forces);
* the movement: ``move`` integrates ξ of stick and permanent relations by ``ξ̇_ij·dt`` of
  ``xi_increments`` (and not of slipping ones) and drifts; ``cool``, the kicks and the wraps are
  ``damp``, ``kick`` and ``wrap`` (analytic: the peculiar velocity relative to the flow scaled by
  f; ``v + F dt/m``; a sphere leaving through the top re-enters at the bottom, x shifted by
  ``−Ly·γ`` and vx by ``−Ly·γ̇``);
* laws replaced through ``call_back_elastic_force_law`` (plateau) and
  ``call_back_elastic_force_law_tensile`` (exponential) are the laws of the contacts, of the two
  branches of a bond (× the ratio) and of the Coulomb bound (a large history slips at ``μ|law|``);
* a 1.0.2 script with integer coordinates and speeds runs and gets Python floats back;
* in an ensemble, the per-sphere force phase (every sphere's ``*_from_neighbors`` in list order,
  as the scripts of 1.0.2 do) gives the ensemble's own force phase: the totals, torques, states and
  histories, and the six register lists entry by entry (to 1e-12 of a list's largest entry: the
  ensemble adds the two half visits of a pair before scaling), with the built-in and with the
  replaced laws.
"""
import math
import unittest

import numpy as np

from particleShear import (CircleBasicElasticity, EnsembleLinkable, Force_register, SphereLinkable, SphereLinkableAdjustableInterfaceStrength,
                           elastic_force_law_plateau, elastic_force_law_tensile_exponential)
from particleShear.engine.box import flow_velocity, min_image, wrap
from particleShear.engine.integrate import damp, kick, xi_increments
from particleShear.engine.terms import (elastic_term, normal_speed, pair_forces, relative_velocity, slip_speed,
                                        tangential_term, term_constants, viscous_term)
from particleShear.linkable.spheres import neighbor_relation_linkable
from particleShear.objects.spheres import SphereLeesEdwards
from particleShearTest.test_legacy_fidelity import SCENES, two_sphere_scene

L = 500.0
SHEAR, RATE = 0.13, 3.0
K, NU, K_T, NU_T, MU = 2.0, 0.7, 1.5, 0.4, 0.3
PRC, PRT = 0.6, 2.5


def _sphere(x, y, r, c, keep, register):
    s = SphereLinkableAdjustableInterfaceStrength("grey", x, y, 2 * r, m=1.5, force_register=register, size_x=L,
                                                  size_y=L, permanent_ratio_central=PRC, permanent_ratio_tangential=PRT,
                                                  keep_viscosity_coefficients_constant=keep)
    s.shear, s.shear_rate = SHEAR, RATE
    s.central_repulsion_coefficient = c
    return s


def random_pairs(P=64, seed=11, c=0.4, keep=False):
    """P independent pairs of standalone spheres in a 500 µm Lees-Edwards cell (γ = 0.13, γ̇ = 3/s) and the
    same state as arrays.

    j sits at ``i + D`` brought into the cell by the Lees-Edwards wrap, with ``|D|`` from 0.6 to 1.15 contact
    distances (about one pair in five is separated); i is near an edge in a third of the pairs, so those pairs
    act through the (sheared) boundary.  About 40 % of the pairs are bonds with ``d_eq`` within ±10 % of
    ``r_i + r_j``; ξ_ij, ξ_ji are up to ±3 µm, so some contacts slip in one visit or both.
    """
    rng = np.random.default_rng(seed)
    ri, rj = rng.uniform(5.0, 15.0, P), rng.uniform(5.0, 15.0, P)
    xi_pos = rng.uniform(0.0, L, P)
    yi = np.where(rng.random(P) < 1 / 3, rng.choice([2.0, L - 2.0], P), rng.uniform(0.0, L, P))
    theta = rng.uniform(0, 2 * np.pi, P)
    D = (ri + rj) * rng.uniform(0.6, 1.15, P)
    xj, yj = xi_pos + D * np.cos(theta), yi + D * np.sin(theta)
    wrap(xj, yj, np.zeros(P), L, L, L * SHEAR, 0.0)
    xi_pos, yi = xi_pos % L, yi % L
    Vi, Vj = rng.normal(0, 2, (3, P)), rng.normal(0, 2, (3, P))
    perm = rng.random(P) < 0.4
    d_eq = (ri + rj) * rng.uniform(0.9, 1.1, P)
    xi = rng.uniform(-3.0, 3.0, (2, P))
    reg = Force_register()
    pairs = []
    for p in range(P):
        a = _sphere(xi_pos[p], yi[p], ri[p], c, keep, reg)
        b = _sphere(xj[p], yj[p], rj[p], c, keep, reg)
        for s, V in ((a, Vi[:, p]), (b, Vj[:, p])):
            s.xspeed, s.yspeed, s.omega = V.tolist()
        if perm[p]:
            a.establish_permanent_link(b)
            a.neighbors[0].equilibrium_distance = b.neighbors[0].equilibrium_distance = d_eq[p]
        else:
            a.neighbors.append(neighbor_relation_linkable(0, "stick", b))
            b.neighbors.append(neighbor_relation_linkable(0, "stick", a))
        a.neighbors[0].friction_position, b.neighbors[0].friction_position = xi[:, p].tolist()
        pairs.append((a, b))
    state = dict(x=(xi_pos, xj), y=(yi, yj), V=(Vi, Vj), r=(ri, rj), perm=perm, d_eq=d_eq, xi=xi, c=c, keep=keep)
    return pairs, state, reg


def vectorised(st):
    """The engine's terms of all pairs at once, from the arrays alone."""
    (xa, xb), (ya, yb), (Vi, Vj), (ri, rj) = st["x"], st["y"], st["V"], st["r"]
    dx, dy, ky, _ = min_image(xb - xa, yb - ya, L, L, L * SHEAR)
    d = np.sqrt(dx * dx + dy * dy)
    nx, ny = dx / d, dy / d
    dvx = -(L * RATE) * ky
    rv = relative_velocity(Vi, Vj, dvx)
    vn, vt = normal_speed(rv, nx, ny), slip_speed(rv, nx, ny, ri, rj, Vi[2], Vj[2])
    Kc = term_constants(ri + rj, None, None, K, st["c"], NU, K_T, NU_T, MU)
    Km = term_constants(ri + rj, st["perm"], st["d_eq"], K, st["c"], NU, K_T, NU_T, MU, PRC, PRT, float(st["keep"]))
    f_contact = elastic_term(Kc, d)[0]
    f_el, law = elastic_term(Km, d)
    f_visc = viscous_term(Km, vn, None)
    touching = d < ri + rj
    xi_after = st["xi"].copy()
    F, slip = tangential_term(Km, vt, touching, xi_after, law)
    w = np.array((ri, rj)) / (ri + rj)
    return dict(dx=dx, dy=dy, d=d, nx=nx, ny=ny, dvx=dvx, rv=rv, vn=vn, vt=vt, f_contact=f_contact, f_el=f_el,
                law=law, f_visc=f_visc, touching=touching, F=F, slip=slip, xi_after=xi_after, w=w, Km=Km)


class GeometryTest(unittest.TestCase):
    """d, n, t, the minimum image and the relative velocities of the API are the engine's, bit for bit."""

    def test_against_vectorised(self):
        pairs, st, _ = random_pairs()
        v = vectorised(st)
        crossing = 0
        for p, (a, b) in enumerate(pairs):
            self.assertEqual(a.relative_vector(b), [v["dx"][p], v["dy"][p]])
            self.assertEqual(a.lee_edwards_relative_vector(b), [v["dx"][p], v["dy"][p]])
            self.assertEqual(a.d(b), v["d"][p])
            self.assertEqual(a.n(b), [v["nx"][p], v["ny"][p]])
            self.assertEqual(a.tangential_vector(b), [-v["ny"][p], v["nx"][p]])
            self.assertEqual(a.relative_speed(b), v["rv"][:, p].tolist())
            self.assertEqual(a.lee_edwards_relative_speed(b), v["rv"][:, p].tolist())
            self.assertEqual(a.tangential_speed(b), v["vt"][p])
            # seen from j: the vector and the velocity change sign, the slip speed does not (symmetric)
            self.assertEqual(b.relative_vector(a), [-v["dx"][p], -v["dy"][p]])
            self.assertEqual(b.tangential_speed(a), v["vt"][p])
            for q in (0, 1):
                self.assertIsInstance(a.relative_vector(b)[q], float)
            crossing += v["dvx"][p] != 0
        self.assertGreater(crossing, 3)   # the set exercises the sheared boundary

    def test_sheared_boundary_analytic(self):
        reg = Force_register()
        a = _sphere(100.0, L - 3.0, 10.0, 0.0, True, reg)
        b = _sphere(120.0, 4.0, 10.0, 0.0, True, reg)
        a.xspeed, b.xspeed, b.yspeed = 1.0, 2.0, -0.5
        # j's image above the cell sits at (x_j + Ly·γ, y_j + Ly) and moves with vx_j + Ly·γ̇
        dx, dy = a.relative_vector(b)
        self.assertAlmostEqual(dx, 120.0 + L * SHEAR - 100.0, delta=1e-12 * L)
        self.assertAlmostEqual(dy, 7.0, delta=1e-12 * L)
        self.assertEqual(a.d(b), math.hypot(dx, dy))
        vx, vy = a.relative_speed(b)
        self.assertAlmostEqual(vx, 2.0 + L * RATE - 1.0, delta=1e-12 * L * RATE)
        self.assertEqual(vy, -0.5)
        # and the reverse image (below) from j
        self.assertEqual(b.relative_vector(a), [-dx, -dy])
        self.assertEqual(a.lee_edwards_closest_to_zero(20.0, 7.0 - L), [20.0 + L * SHEAR, 7.0])
        # without Lees-Edwards the plain difference
        a.use_lees_edwards = False
        self.assertEqual(a.relative_vector(b), [20.0, 7.0 - L])
        self.assertEqual(a.relative_speed(b), [1.0, -0.5])

    def test_without_spin_and_helpers(self):
        """A frictionless sphere's slip speed is the translational part ``Δv·t``; n·d, the raw distance, the
        neighbour test of spheres alone."""
        pairs, st, _ = random_pairs()
        v = vectorised(st)
        (ri, rj) = st["r"]
        no_spin = slip_speed(v["rv"], v["nx"], v["ny"], ri, rj, 0.0, 0.0)
        for p, (a, b) in enumerate(pairs[:16]):
            fa, fb = (SphereLeesEdwards("grey", s.x, s.y, 2 * s.r, size_x=L, size_y=L) for s in (a, b))
            for f, s in ((fa, a), (fb, b)):
                f.xspeed, f.yspeed, f.shear, f.shear_rate = s.xspeed, s.yspeed, SHEAR, RATE
            self.assertEqual(fa.tangential_speed(fb), no_spin[p])
            self.assertEqual(a.relative_position(b), [v["nx"][p] * v["d"][p], v["ny"][p] * v["d"][p]])
            self.assertAlmostEqual(a.d_euclidian(b), math.hypot(b.x - a.x, b.y - a.y), delta=1e-12 * L)
            fa.test_neighbor_relation(fb)
            self.assertEqual(fa.findNeighborIndex(fb), 0 if v["touching"][p] else -1)

    def test_random_normal_at_contact(self):
        reg = Force_register()
        a, b = _sphere(10.0, 10.0, 5.0, 0.0, True, reg), _sphere(10.0, 10.0, 5.0, 0.0, True, reg)
        n = a.n(b)
        self.assertAlmostEqual(math.hypot(*n), 1.0, delta=1e-15)


class CentralTermsTest(unittest.TestCase):
    """Elastic and viscous forces of the API: the vectorised terms bit for bit, and the closed forms."""

    def test_against_vectorised(self):
        for c in (0.0, 0.4, 1.0):
            for keep in (False, True):
                with self.subTest(c=c, keep=keep):
                    pairs, st, reg = random_pairs(c=c, keep=keep, seed=int(10 * c) + keep)
                    v = vectorised(st)
                    separated = 0
                    for p, (a, b) in enumerate(pairs):
                        self.assertEqual(a.get_elastic_force(b, K), v["f_contact"][p])
                        self.assertEqual(a.get_central_viscous_force(b, NU), v["f_visc"][p])
                        if st["perm"][p]:
                            self.assertEqual(a.get_elastic_force_permanent(b, K), v["f_el"][p])
                        f = v["f_el"][p]
                        want = [f * v["nx"][p], f * v["ny"][p]]
                        if not (st["perm"][p] or v["touching"][p]):
                            want = [0, 0]
                            separated += 1
                        x0, y0 = a.xforce, a.yforce
                        self.assertEqual(a.elastic_force(b, K), want)
                        self.assertEqual([a.xforce - x0, a.yforce - y0], want)
                        fv = v["f_visc"][p]
                        self.assertEqual(a.central_viscous_force(b, NU), [fv * v["nx"][p], fv * v["ny"][p]])
                    self.assertGreater(separated, 0)

    def test_closed_forms(self):
        pairs, st, _ = random_pairs(c=0.0)
        v = vectorised(st)
        (ri, rj) = st["r"]
        for p, (a, b) in enumerate(pairs):
            d, d0 = v["d"][p], ri[p] + rj[p]
            delta = d0 - d
            tol = 1e-12 * K * d0
            # linear law (eq. S1-5a): f = −k δ inside contact, 0 outside
            self.assertAlmostEqual(a.get_elastic_force(b, K), -K * delta if delta > 0 else 0.0, delta=tol)
            # divergent law (eq. S1-5b), c = 1: −k δ/(1 − δ/d0)
            a.central_repulsion_coefficient = 1.0
            if delta > 0:
                self.assertAlmostEqual(a.get_elastic_force(b, K), -K * delta / (1 - delta / d0), delta=tol)
            a.central_repulsion_coefficient = 0.0
            vn = float(np.dot(v["rv"][:, p], [v["nx"][p], v["ny"][p]]))
            if st["perm"][p]:
                de = st["d_eq"][p]
                if d > de:   # tensile law of a bond: k (d − d_eq) × the permanent ratio
                    self.assertAlmostEqual(a.get_elastic_force_permanent(b, K), K * (d - de) * PRC, delta=tol)
                self.assertAlmostEqual(a.get_central_viscous_force(b, NU), NU * vn * PRC, delta=1e-12 * NU * 40)
            else:
                self.assertAlmostEqual(a.get_central_viscous_force(b, NU), NU * vn, delta=1e-12 * NU * 40)

    def test_from_neighbors_sum_in_order(self):
        """A sphere with several relations: the sums of its pair forces in ``neighbors`` order."""
        reg = Force_register()
        me = _sphere(250.0, 490.0, 10.0, 0.4, False, reg)
        me.xspeed, me.yspeed, me.omega = 0.5, -1.0, 0.2
        others = [_sphere(262.0, 495.0, 8.0, 0.4, False, reg), _sphere(245.0 - L * SHEAR, 6.0, 9.0, 0.4, False, reg),
                  _sphere(236.0, 487.0, 7.0, 0.4, False, reg)]
        for q, s in enumerate(others):
            s.xspeed, s.yspeed, s.omega = -0.3 * q, 0.4, -0.1 * q
        me.establish_permanent_link(others[0])
        for s in others[1:]:
            me.neighbors.append(neighbor_relation_linkable(0, "stick", s))
            s.neighbors.append(neighbor_relation_linkable(0, "stick", me))
        for q in range(3):
            me.neighbors[q].friction_position = 0.3 * (q - 1)
        st = dict(x=(np.full(3, me.x), np.array([s.x for s in others])), y=(np.full(3, me.y), np.array([s.y for s in others])),
                  V=(np.array([[me.xspeed], [me.yspeed], [me.omega]]).repeat(3, 1),
                     np.array([[s.xspeed for s in others], [s.yspeed for s in others], [s.omega for s in others]])),
                  r=(np.full(3, me.r), np.array([s.r for s in others])), perm=np.array([True, False, False]),
                  d_eq=np.full(3, me.r + others[0].r), xi=np.array([[-0.3, 0.0, 0.3], [0.0, 0.0, 0.0]]), c=0.4,
                  keep=False)
        v = vectorised(st)
        me.elastic_force_from_neighbors(K)
        self.assertEqual(me.xforce, sum((v["f_el"] * v["nx"]).tolist()))
        self.assertEqual(me.yforce, sum((v["f_el"] * v["ny"]).tolist()))
        me.xforce = me.yforce = 0.0
        me.central_viscous_force_from_neighbors(NU)
        self.assertEqual(me.xforce, sum((v["f_visc"] * v["nx"]).tolist()))
        me.xforce = me.yforce = 0.0
        me.tangential_force_from_neighbors(NU_T, MU, K, K_T)
        ft = v["F"][0] / 2   # the visits from me: half of the first row each
        self.assertEqual(me.xforce, sum((-ft * v["ny"]).tolist()))
        self.assertEqual(me.torque, sum((v["d"] * ft * v["w"][0]).tolist()))
        for q, s in enumerate(others):
            self.assertEqual(s.torque, (v["d"] * ft * v["w"][1])[q])
        self.assertEqual(len(reg.pair_register), 3 + 3 + 2 * 3)   # one entry per central visit, two per tangential


class ReplacedLawsTest(unittest.TestCase):
    """Laws replaced through the class callbacks are the laws of the per-sphere API and of its Coulomb bound."""

    def setUp(self):
        saved = (CircleBasicElasticity.call_back_elastic_force_law, SphereLinkable.call_back_elastic_force_law_tensile)

        def restore():
            CircleBasicElasticity.call_back_elastic_force_law, SphereLinkable.call_back_elastic_force_law_tensile = saved
        self.addCleanup(restore)
        CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
        SphereLinkable.call_back_elastic_force_law_tensile = elastic_force_law_tensile_exponential

    def test_plateau_and_exponential_tensile(self):
        pairs, st, _ = random_pairs(c=0.4)
        v = vectorised(st)
        (ri, rj) = st["r"]
        checked = 0
        for p, (a, b) in enumerate(pairs):
            d, d0 = v["d"][p], ri[p] + rj[p]
            law = elastic_force_law_plateau(d, d0, K, 0.4)
            self.assertEqual(a.get_elastic_force(b, K), law)
            if st["perm"][p]:
                de = st["d_eq"][p]
                bond = (elastic_force_law_tensile_exponential(d, de, K) if d >= de
                        else elastic_force_law_plateau(d, de, K, 0.4)) * PRC
                self.assertEqual(a.get_elastic_force_permanent(b, K), bond)
                self.assertEqual(a.elastic_force(b, K), [bond * v["nx"][p], bond * v["ny"][p]])
            elif d < d0:
                # the Coulomb bound of the replaced law: a large history slips at exactly μ|law|
                a.neighbors[0].friction_position = 1e3
                self.assertEqual(abs(a.tangential_force(b, NU_T, MU, K, K_T)), abs(MU * law))
                self.assertEqual(a.neighbors[0].interface_type, "slip")
                checked += 1
        self.assertGreater(checked, 3)


class TangentialTest(unittest.TestCase):
    """The tangential visits of the API are the two rows of the engine's two-visit rule."""

    def test_two_visits_are_the_vectorised_rule(self):
        for keep in (False, True):
            with self.subTest(keep=keep):
                pairs, st, reg = random_pairs(keep=keep, seed=5 + keep)
                v = vectorised(st)
                slipped = bonds_beyond = 0
                for p, (a, b) in enumerate(pairs):
                    rel, back = a.neighbors[0], b.neighbors[0]
                    perm = st["perm"][p]
                    if not (perm or v["touching"][p]):
                        self.assertEqual(a.tangential_force(b, NU_T, MU, K, K_T), 0)
                        self.assertEqual((a.xforce, a.torque), (0.0, 0.0))
                        continue
                    f1 = a.tangential_force(b, NU_T, MU, K, K_T)
                    self.assertEqual(f1, v["F"][0][p])
                    f2 = b.tangential_force(a, NU_T, MU, K, K_T)
                    self.assertEqual(f2, v["F"][1][p])
                    self.assertEqual([rel.friction_position, back.friction_position], v["xi_after"][:, p].tolist())
                    fc = abs(MU * v["law"][p])
                    if perm:
                        self.assertEqual(rel.interface_type, "permanent")
                        bonds_beyond += abs(f1) > fc
                    else:
                        self.assertEqual(rel.interface_type, "slip" if v["slip"][p] else "stick")
                        self.assertEqual(back.interface_type, rel.interface_type)
                        # Coulomb bound: |F| ≤ μ|law|, reached when the visit slips
                        self.assertLessEqual(abs(f1), fc)
                        self.assertLessEqual(abs(f2), fc)
                        if v["slip"][p]:
                            self.assertEqual(abs(f2), fc)
                            self.assertEqual(rel.friction_position, 0.0)
                            slipped += 1
                    # forces and torques of the two half visits: the vectorised pair force to rounding
                    fx, fy, _, tq = pair_forces(0.0, (v["F"][0] + v["F"][1]) * 0.5, v["nx"], v["ny"], v["d"], v["w"])
                    scale = 1e-14 * (abs(f1) + abs(f2) + 1e-300)
                    self.assertAlmostEqual(a.xforce, fx[p], delta=scale)
                    self.assertAlmostEqual(a.yforce, fy[p], delta=scale)
                    self.assertAlmostEqual(b.xforce, -fx[p], delta=scale)
                    self.assertAlmostEqual(a.torque, tq[0][p], delta=scale * v["d"][p])
                    self.assertAlmostEqual(b.torque, tq[1][p], delta=scale * v["d"][p])
                self.assertGreater(slipped, 2)
                self.assertGreater(bonds_beyond, 0)   # a bond's spring is not bounded

    def test_parts_of_a_visit(self):
        pairs, st, _ = random_pairs(keep=False)
        v = vectorised(st)
        for p, (a, b) in enumerate(pairs):
            xi = st["xi"][0][p]
            touching = v["touching"][p]
            self.assertEqual(a.tangential_force_viscous(b, NU_T), NU_T * v["vt"][p] if touching else 0)
            self.assertEqual(a.tangential_force_elastic(b, K_T), K_T * xi if touching else 0)
            if st["perm"][p]:
                self.assertEqual(a.tangential_force_viscous_permanent(b, NU_T),
                                 NU_T * PRT * v["vt"][p] if touching else 0)
                self.assertEqual(a.tangential_force_elastic_permanent(b, K_T), K_T * PRT * xi)

    def test_couple_split_by_radii(self):
        pairs, st, reg = random_pairs()
        v = vectorised(st)
        for p, (a, b) in enumerate(pairs[:16]):
            f = 0.37 * (p - 7)
            a.distribute_tangential_couple(b, f)
            fx, fy, dF, tq = pair_forces(0.0, np.full(len(pairs), f), v["nx"], v["ny"], v["d"], v["w"])
            self.assertEqual([a.xforce, a.yforce], [fx[p], fy[p]])
            self.assertEqual([b.xforce, b.yforce], [-fx[p], -fy[p]])
            self.assertEqual([a.torque, b.torque], tq[:, p].tolist())
            # analytic: f·t on a, the torques d·f·r/(r_a + r_b) of the same sign adding to d·f (eq. S1-3)
            ra, rb, d = a.r, b.r, v["d"][p]
            tol = 1e-14 * abs(d * f) + 1e-300
            self.assertAlmostEqual(a.xforce, -f * v["ny"][p], delta=tol)
            self.assertAlmostEqual(a.torque, d * f * ra / (ra + rb), delta=tol)
            self.assertAlmostEqual(b.torque, d * f * rb / (ra + rb), delta=tol)
            self.assertAlmostEqual(a.torque + b.torque, d * f, delta=tol)
        # two forces and two torques registered per call
        self.assertEqual((len(reg.pair_register), len(reg.internal_moment_register)), (32, 32))


class MovementTest(unittest.TestCase):
    """ξ rule, drift, damping, kicks and wraps of the API are the engine's integration functions."""

    def test_move_integrates_xi_then_drifts(self):
        pairs, st, _ = random_pairs()
        v = vectorised(st)
        dt = 1e-3
        Vi, Vj = st["V"]
        (ri, rj) = st["r"]
        inc = xi_increments(Vi, Vj, v["dvx"], v["nx"], v["ny"], ri, rj, -v["dx"], -v["dy"], lambda x, y: (x, y))[0]
        for p, (a, _) in enumerate(pairs):
            rel = a.neighbors[0]
            if p % 5 == 0 and not st["perm"][p]:
                rel.interface_type = "slip"
            x, y, phi = a.x, a.y, a.phi
            a.move(dt)
            want = st["xi"][0][p] if rel.interface_type == "slip" else st["xi"][0][p] + inc[p] * dt
            self.assertEqual(rel.friction_position, want)
            self.assertEqual((a.x, a.y, a.phi), (x + Vi[0][p] * dt, y + Vi[1][p] * dt, phi + Vi[2][p] * dt))
            # the increment is the slip speed of the pair (ξ̇ = v_t, Appendix B.2)
            self.assertEqual(inc[p], v["vt"][p])

    def test_cool_kick_wrap(self):
        reg = Force_register()
        s = _sphere(30.0, 400.0, 10.0, 0.0, True, reg)
        s.xspeed, s.yspeed, s.omega = 2.0, -1.0, 0.5
        f, kappa = 0.8, 0.3
        u = RATE * (400.0 - L / 2)
        s.cool(f, kappa)
        vel = np.array([[2.0], [-1.0]])
        damp(vel, flow_velocity(np.array([400.0]), L, RATE), f)
        self.assertEqual([s.xspeed, s.yspeed], vel[:, 0].tolist())
        self.assertAlmostEqual(s.xspeed - u, f * (2.0 - u), delta=1e-12 * abs(u))     # peculiar velocity × f
        self.assertAlmostEqual(s.omega, kappa * u + f * (0.5 - kappa * u), delta=1e-12 * abs(u))
        plain = _sphere(30.0, 400.0, 10.0, 0.0, True, reg)
        plain.use_lees_edwards = False   # plain damping: v·f, ω·f
        plain.xspeed, plain.yspeed, plain.omega = 2.0, -1.0, 0.5
        plain.cool(f)
        self.assertEqual((plain.xspeed, plain.yspeed, plain.omega), (2.0 * f, -1.0 * f, 0.5 * f))
        s.xforce, s.yforce, s.torque = 3.0, -6.0, 1.5
        v0, w0 = [s.xspeed, s.yspeed], s.omega
        s.do_linear_acceleration(0.01)
        s.do_rotational_acceleration(0.01)
        want = np.array([v0]).T
        kick(want, np.array([[3.0], [-6.0]]), s.m, 0.01)
        self.assertEqual([s.xspeed, s.yspeed], want[:, 0].tolist())
        self.assertAlmostEqual(s.omega, w0 + 1.5 * 0.01 / s.inertia, delta=1e-15)
        self.assertEqual((s.xforce, s.yforce, s.torque), (0.0, 0.0, 0.0))
        self.assertEqual(reg.total_particle_force_register[0][1], [3.0, -6.0])
        # leaving through the top: re-enters at the bottom, x − Ly·γ (wrapped), vx − Ly·γ̇
        s.x, s.y = 30.0, L + 2.0
        vx = s.xspeed
        s.boundary_conditions(L, L)
        self.assertAlmostEqual(s.y, 2.0, delta=1e-12 * L)
        self.assertAlmostEqual(s.x, (30.0 - L * SHEAR) % L, delta=1e-12 * L)
        self.assertAlmostEqual(s.xspeed, vx - L * RATE, delta=1e-12 * L * RATE)
        self.assertEqual(s.lee_edwards_positive(-5.0, -3.0), [(-5.0 + L * SHEAR) % L, L - 3.0])
        s.use_lees_edwards = False   # plain periodic wrap, no velocity change
        s.x, s.y = -5.0, L + 1.0
        vx = s.xspeed
        s.boundary_conditions(L, L)
        self.assertEqual((s.x, s.y, s.xspeed), (L - 5.0, 1.0, vx))


class ScriptOf102Test(unittest.TestCase):
    """A 1.0.2 script with integer coordinates and speeds: every method runs and returns Python floats."""

    def test_integer_inputs(self):
        a, b = SphereLinkable("grey", 100, 100, 20), SphereLinkable("grey", 115, 100, 20)
        a.test_neighbor_relation(b)
        b.test_neighbor_relation(a)
        self.assertEqual((a.d(b), a.n(b), a.relative_speed(b), a.tangential_speed(b)), (15.0, [1.0, 0.0], [0.0, 0.0], 0.0))
        self.assertEqual(a.get_elastic_force(b, 1), -5.0)   # linear law: −k δ, δ = 20 − 15
        self.assertEqual(a.elastic_force(b, 1), [-5.0, 0.0])
        b.yspeed = 2
        self.assertEqual(a.get_central_viscous_force(b, 1), 0.0)
        self.assertEqual(a.tangential_speed(b), 2.0)
        self.assertEqual(a.tangential_force(b, 1, 1, 1, 1), 2.0)   # ν_t v_t = 2 < μ|law| = 5: sticks
        self.assertEqual(a.neighbors[0].interface_type, "stick")
        self.assertEqual((a.yforce, b.yforce, a.torque, b.torque), (1.0, -1.0, 7.5, 7.5))   # d·f/2·r/(r + r)
        a.move(1)
        self.assertEqual((a.neighbors[0].friction_position, a.x), (2.0, 100.0))
        a.cool()
        a.do_linear_acceleration(1)
        a.do_rotational_acceleration(1)
        a.boundary_conditions(500, 500)
        for value in (a.d(b), a.get_elastic_force(b, 1), a.get_central_viscous_force(b, 1), a.tangential_speed(b),
                      a.tangential_force_viscous(b, 1), a.tangential_force_elastic(b, 1), a.tangential_force(b, 1, 1, 1, 1),
                      a.xspeed, a.yspeed, a.omega, a.x, a.y, a.xforce, a.torque, *a.relative_vector(b),
                      *a.lee_edwards_closest_to_zero(1, 2), *a.lee_edwards_positive(-1, 2)):
            self.assertIs(type(value), float)


class EnsembleForcePhaseTest(unittest.TestCase):
    """In an ensemble, the per-sphere force phase of a 1.0.2 script is the ensemble's own force phase."""

    def test_scenes(self):
        self._scenes()

    def test_scenes_with_replaced_laws(self):
        saved = (CircleBasicElasticity.call_back_elastic_force_law, SphereLinkable.call_back_elastic_force_law_tensile)
        try:
            CircleBasicElasticity.call_back_elastic_force_law = elastic_force_law_plateau
            SphereLinkable.call_back_elastic_force_law_tensile = elastic_force_law_tensile_exponential
            self._scenes()
        finally:
            CircleBasicElasticity.call_back_elastic_force_law, SphereLinkable.call_back_elastic_force_law_tensile = saved

    def test_routing_of_a_visit(self):
        """The per-sphere filters route a visit's entry by the step's rule (``pair_roles``): dropped on an
        immobile target, external from an immobile source or when the visit's minimum image removes a
        period — also at exactly Δx = +Lx/2, where the raw and image distances are equal — else internal."""
        ens = EnsembleLinkable(200.0, 200.0, 0, k=1, nu=0.01, k_t=1, nu_t=0.01, mu=0.1)
        for q, (x, y) in enumerate(((20.0, 100.0), (120.0, 100.0), (90.0, 100.0), (130.0, 5.0), (20.0, 150.0))):
            ens.sphereList.append(SphereLinkable("grey", x, y, 20, 1, q, force_register=ens, size_x=200.0, size_y=200.0))
        s = ens.sphereList
        ens.applyingShear = True          # sphere 3 (y = 5 < r) is a plate sphere
        for target, source, where in ((0, 2, 1), (2, 0, 1), (0, 1, 2), (1, 0, 1), (1, 3, 2), (3, 1, 0),
                                      (2, 4, 1), (4, 0, 1)):
            with self.subTest(target=target, source=source):
                self.assertEqual(ens._entry_of(s[target], s[source]), where)
        ens.applyingShear = False
        ens.shear = 0.25                  # the rows above and below are offset by Ly·γ = 50 µm
        s[0].y = 60.0                     # Δy = 90 < Ly/2: the same row
        self.assertEqual(ens._entry_of(s[0], s[4]), 1)
        s[0].y = 40.0                     # Δy = 110: the image one row down
        self.assertEqual(ens._entry_of(s[0], s[4]), 2)

    def _scenes(self):
        for name, spec in SCENES.items():
            with self.subTest(scene=name):
                mine, ref = two_sphere_scene(**spec), two_sphere_scene(**spec)
                ref.mechanical_simulation_step_calculate_forces()
                ref.record_total_particle_forces()
                mine.reset_force_register()
                for method, args in (("elastic_force_from_neighbors", (mine.k,)),
                                     ("central_viscous_force_from_neighbors", (mine.nu,)),
                                     ("tangential_force_from_neighbors", (mine.nu_t, mine.mu, mine.k, mine.k_t))):
                    for s in mine.sphereList:
                        getattr(s, method)(*args)
                mine.record_total_particle_forces()
                for q, (s, r) in enumerate(zip(mine.sphereList, ref.sphereList)):
                    scale = 1e-12 * max(1.0, max(abs(t.xforce) + abs(t.yforce) + abs(t.torque) for t in ref.sphereList))
                    for attr in ("xforce", "yforce", "torque"):
                        self.assertAlmostEqual(getattr(s, attr), getattr(r, attr), delta=scale, msg=f"{name} {q} {attr}")
                    for rs, rr in zip(s.neighbors, r.neighbors):
                        self.assertEqual((rs.interface_type, rs.friction_position),
                                         (rr.interface_type, rr.friction_position), f"{name} {q}")
                for attr in ("pair_register", "external_force_register", "internal_moment_register",
                             "external_moment_register", "total_particle_force_register", "unbalanced_moment_register"):
                    got, want = getattr(mine.force_register, attr), getattr(ref.force_register, attr)
                    self.assertEqual(len(got), len(want), f"{name}: {attr}")
                    values = [np.ravel(e[-1]) for e in want]
                    scale = 1e-12 * max([float(np.max(np.abs(x))) for x in values] + [1e-300])
                    idx = {id(s): q for q, s in enumerate(mine.sphereList)}
                    idx_ref = {id(s): q for q, s in enumerate(ref.sphereList)}
                    for g, w in zip(got, want):
                        self.assertEqual([idx[id(x)] for x in g[:-1]], [idx_ref[id(x)] for x in w[:-1]], f"{name}: {attr}")
                        np.testing.assert_allclose(np.ravel(g[-1]), np.ravel(w[-1]), rtol=0, atol=scale)


if __name__ == "__main__":
    unittest.main()
