"""The stroboscopic observer and its measures (docs/microstructure.md).

Geometry tests are exact statements (affine maps, rigid motions, a hand-built contact graph) checked
to rounding; the run tests use N = 40 spheres and 3 shear periods.
"""
import math
import os
import unittest

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.analysis.microstructure import MICRO_COLUMNS, irreversibility_onset, micro_measures
from particleShear.engine.box import min_image, wrap
from particleShear.engine.microstructure import (Stroboscope, contact_changes, contact_keys, d2min, force_histogram,
                                                 non_affine_displacement, rattler_free, snapshot_steps)

L = 100.0
#: rounding scale of a position of size L: a few ulps of L, squared for D²_min
EPS = 64 * np.finfo(float).eps * L


def _cloud(n=60, seed=0):
    """Random positions in the L × L cell (2, n)."""
    return np.random.default_rng(seed).uniform(0, L, (2, n))


def _wrapped(pos, gamma):
    x, y = pos[0].copy(), pos[1].copy()
    wrap(x, y, np.zeros_like(x), L, L, L * gamma, 0.0)
    return np.array((x, y))


class TestNonAffine(unittest.TestCase):

    def test_affine_shear_across_the_boundaries_is_zero(self):
        # x moves by Δγ (y − L/2): spheres near the top and bottom leave the cell through x
        # (and are wrapped); the non-affine part is zero to rounding
        p0 = _cloud()
        g0, g1 = 0.05, 0.65
        p1 = _wrapped(np.array((p0[0] + (g1 - g0) * (p0[1] - L / 2), p0[1])), g1)
        self.assertTrue((p1[0] != p0[0] + (g1 - g0) * (p0[1] - L / 2)).any())      # some were wrapped
        u = non_affine_displacement(p0, p1, g0, g1, L, L)
        self.assertLess(np.abs(u).max(), EPS)
        # D²_min of the unwrapped motion: the shear acts on the pair vectors, those through the
        # sheared boundary included
        self.assertLess(np.nanmax(d2min(p0, u, L, L, g0, 30.0, dgamma=g1 - g0)), EPS ** 2)
        # the same motion given as a displacement field of the wrapped positions is not affine
        # across the boundary (a neighbour's image is L away): the rule above is needed
        field = np.array(((g1 - g0) * (p0[1] - L / 2), np.zeros(p0.shape[1])))
        self.assertGreater(np.nanmax(d2min(p0, field, L, L, g0, 30.0)), 1.0)

    def test_translation_through_the_sheared_boundary_is_unwrapped(self):
        # a rigid translation of 0.3 L in y (below L/2): spheres crossing y = L re-enter shifted by
        # −L·γ in x; unwrapping gives the translation back for every sphere
        p0 = _cloud()
        g = 0.37
        shift = np.array((0.2 * L, 0.3 * L))
        p1 = _wrapped(p0 + shift[:, None], g)
        u = non_affine_displacement(p0, p1, g, g, L, L)
        self.assertLess(np.abs(u - shift[:, None]).max(), EPS)


class TestD2min(unittest.TestCase):

    def test_rigid_rotation_and_translation_give_zero(self):
        rng = np.random.default_rng(1)
        p0 = 40 + 20 * rng.random((2, 30))          # a neighbourhood far from the cell's edges
        c = p0.mean(axis=1, keepdims=True)
        a = 0.4
        R = np.array(((math.cos(a), -math.sin(a)), (math.sin(a), math.cos(a))))
        disp = R @ (p0 - c) + c - p0 + np.array(((3.0,), (-2.0,)))
        D = d2min(p0, disp, 1000.0, 1000.0, 0.0, 15.0)
        self.assertTrue(np.isfinite(D).all())
        self.assertLess(D.max(), (64 * np.finfo(float).eps * 100) ** 2)

    def test_displaced_centre_of_a_symmetric_ring(self):
        # neighbours on a ring at rest, the centre moved by δ: d¹ = d⁰ − δ, Σ d⁰ = 0, so J = 1 and
        # the mean residual is |δ|² exactly
        k = np.arange(8)
        ring = 50 + 5 * np.array((np.cos(k * np.pi / 4), np.sin(k * np.pi / 4)))
        p0 = np.concatenate((np.array([[50.0], [50.0]]), ring), axis=1)
        delta = np.array((0.3, -0.4))
        disp = np.zeros_like(p0)
        disp[:, 0] = delta
        D = d2min(p0, disp, L, L, 0.0, 6.0)
        self.assertAlmostEqual(D[0], 0.25, delta=1e-12)
        self.assertTrue((D[1:] > 0).all())

    def test_collinear_neighbours_are_undefined(self):
        p0 = np.array(((10.0, 12.0, 14.0), (10.0, 10.0, 10.0)))
        self.assertTrue(np.isnan(d2min(p0, np.zeros_like(p0), L, L, 0.0, 3.0)).all())


class TestContacts(unittest.TestCase):

    def test_rattlers_removed_iteratively(self):
        # K4 on spheres 0-3 (3 contacts each); sphere 4 touches 0, 5 and 6, which touch only 4 and
        # each other: 5 and 6 (2 contacts) go in the first round, then 4 (1 left) in the second; 7 is free
        i = [0, 0, 0, 1, 1, 2, 4, 4, 4, 5]
        j = [1, 2, 3, 2, 3, 3, 0, 5, 6, 6]
        Z, rattlers = rattler_free(i, j, 8)
        self.assertEqual(Z, 3.0)                      # 6 contacts among 4 spheres
        self.assertEqual(list(np.flatnonzero(rattlers)), [4, 5, 6, 7])
        Z4, r4 = rattler_free(i, j, 8, min_contacts=4)
        self.assertTrue(math.isnan(Z4) and r4.all())  # frictionless rule: nothing is rigid

    def test_bad_input_names_the_parameter(self):
        with self.assertRaisesRegex(ValueError, "min_contacts=0"):
            rattler_free([0], [1], 2, min_contacts=0)
        with self.assertRaisesRegex(ValueError, "contact indices"):
            rattler_free([0], [2], 2)
        with self.assertRaisesRegex(ValueError, "threshold"):
            Stroboscope(1e-3, 1.0, 0, 3, threshold=0)
        with self.assertRaisesRegex(ValueError, "cutoff"):
            Stroboscope(1e-3, 1.0, 0, 3, cutoff=float("nan"))

    def test_made_and_broken(self):
        a = contact_keys([0, 1, 2], [1, 2, 3], 10)
        b = contact_keys([2, 1, 5], [1, 3, 6], 10)        # (1, 2) kept, order and direction free
        self.assertEqual(contact_changes(a, b), (2, 2))

    def test_force_histogram_is_a_density(self):
        f = np.random.default_rng(2).exponential(3.0, 500)
        h = force_histogram(f)
        width = np.diff(np.linspace(0, 6, 31))
        self.assertAlmostEqual(float((h * width).sum()), 1.0, places=12)

    def test_snapshots_one_period_apart(self):
        self.assertEqual(snapshot_steps(0.01, 1.0, 1, 3), [100, 200, 300, 400])


KW = dict(N=40, periods=3, pre_periods=1, post_periods=1, doDrawing=False, saveData=False, plotStress=False,
          verbose=False, seed=3, return_result=True, do_permanent_links=False)


class TestStroboscopicRuns(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.off = doParticleShearSimulation(theAmplitude=0.02, **KW)
        cls.small = doParticleShearSimulation(theAmplitude=0.02, stroboscopic=True, **KW)
        cls.large = doParticleShearSimulation(theAmplitude=0.5, stroboscopic=True, **KW)

    def test_observer_does_not_change_the_run(self):
        self.assertIsNone(self.off.microstructure)
        self.assertEqual(self.off.G_surface, self.small.G_surface)
        self.assertEqual(self.off.G_internal, self.small.G_internal)
        for key in ("stress_surface", "stress_internal"):
            np.testing.assert_array_equal(self.off.series[key], self.small.series[key])
        self.assertEqual(self.off.run_id, self.small.run_id)
        self.assertTrue(all(self.off.measures[c] is None for c in MICRO_COLUMNS))     # empty: not evaluated

    def test_small_amplitude_returns_large_does_not(self):
        # after the transient cycle the jammed packing returns to its stroboscopic state: the
        # non-affine displacement per cycle is far below r² (measured ~1e-5 r²; the bound 1e-3 r²
        # is 0.03 r rms); at γ₀ = 0.5 the spheres rearrange by ~r per cycle
        m = self.small.microstructure
        self.assertEqual(len(m["msd"]), 3)
        self.assertLess(self.small.measures["irreversibility"], 1e-3)
        self.assertEqual(self.small.measures["moved_fraction"], 0.0)
        self.assertEqual(self.small.measures["contact_change_rate"], 0.0)
        self.assertGreater(self.large.measures["irreversibility"], 0.1)
        self.assertGreater(self.large.measures["contact_change_rate"], 0.0)
        # a dense 2D packing: rattler-free Z between the frictional isostatic 3 and the hexagonal 6
        for r in (self.small, self.large):
            self.assertTrue(3 <= r.measures["Z_rattler_free"] <= 6)

    def test_strain_is_the_same_at_every_snapshot(self):
        g = self.large.microstructure["gamma"]
        self.assertLess(np.abs(g - g[0]).max(), 1e-9)

    def test_a_replica_of_a_batch_equals_its_single_run(self):
        from particleShear.run.batch import run_batch
        batch = run_batch([dict(KW, theAmplitude=0.5, stroboscopic=True), dict(KW, theAmplitude=0.02, seed=4)])
        a, b = batch[0].microstructure, self.large.microstructure
        self.assertIsNone(batch[1].microstructure)
        for key in ("msd", "d2min", "made", "broken", "Z", "force_pdf", "positions"):
            np.testing.assert_array_equal(a[key], b[key])

    # -- pictures (docs/microstructure.md, "Pictures") ---------------------------------------------
    def test_pictures_one_per_cycle_and_a_gif_of_the_cycles(self):
        import tempfile
        from PIL import Image
        n_c = len(self.large.microstructure["msd"])
        with tempfile.TemporaryDirectory() as d:
            made = self.large.microstructure_pictures(d)
            self.assertEqual([os.path.basename(p) for p in made["pictures"]],
                             [f"cycle_{c:03d}.png" for c in range(1, n_c + 1)])
            self.assertTrue(all(os.path.getsize(p) > 0 for p in made["pictures"]))
            with Image.open(made["gif"]) as gif:
                self.assertEqual(gif.n_frames, n_c)
            made = self.large.microstructure_pictures(os.path.join(d, "na"), colour_by="non_affine", gif=False)
            self.assertEqual(len(made["pictures"]), n_c)
            self.assertIsNone(made["gif"])

    def test_thickest_chain_is_the_largest_normal_force(self):
        import tempfile
        from PIL import Image
        from particleShear.simulation.microstructure_pictures import CHAIN_COLOUR, picture_primitives
        m, cycle = self.large.microstructure, 1
        discs, segs = picture_primitives(m, cycle)
        fn = m["normal_force"][cycle + 1]
        widest = max(segs, key=lambda sg: sg[4])
        self.assertEqual(widest[5], int(np.argmax(fn)))
        # widths proportional to the forces, and a segment joins the centres of the pair in contact
        ratios = [w / fn[k] for *_, w, k in segs]
        self.assertLess(max(ratios) / min(ratios) - 1, 1e-12)
        pos = m["positions"][cycle + 1]
        Lx, Ly = m["Lx"], m["Ly"]
        for x1, y1, x2, y2, w, k in segs:
            i, j = m["contact_i"][cycle + 1][k], m["contact_j"][cycle + 1][k]
            self.assertAlmostEqual(math.hypot(x2 - x1, y2 - y1),
                                   float(np.hypot(*min_image(pos[0, j] - pos[0, i], pos[1, j] - pos[1, i], Lx, Ly,
                                                             m["shift"][cycle + 1])[:2])), places=9)
        # in the written picture, the middle of the widest segment (an image inside the cell) is chain-coloured
        k_max = widest[5]
        mid = [((a + c) / 2, (b + d) / 2) for a, b, c, d, _, k in segs if k == k_max]
        mx, my = next(p for p in mid if 0 < p[0] < Lx and 0 < p[1] < Ly)
        with tempfile.TemporaryDirectory() as d:
            path = self.large.microstructure_pictures(d, gif=False)["pictures"][cycle]
            with Image.open(path) as img:
                scale = img.width / Lx
                px = img.convert("RGB").getpixel((int(mx * scale), int(my * scale)))
        self.assertEqual("#%02x%02x%02x" % px, CHAIN_COLOUR)

    def test_sphere_of_the_largest_d2min_has_the_top_colour(self):
        from particleShear.simulation.microstructure_pictures import NAN_FILL, VIRIDIS, picture_primitives
        m = self.large.microstructure
        q = np.where(np.isfinite(m["d2min"]), m["d2min"], -np.inf)
        cycle, i = np.unravel_index(int(np.argmax(q)), q.shape)
        discs, _ = picture_primitives(m, int(cycle))
        x, y = m["positions"][cycle + 1][:, i]
        fill = next(f for X, Y, r, f in discs if abs(X - x) < 1e-9 and abs(Y - y) < 1e-9)
        self.assertEqual(fill, VIRIDIS[-1])
        undefined = ~np.isfinite(m["d2min"][cycle])          # neighbours on a line: the NaN fill
        self.assertEqual(NAN_FILL in [f for X, Y, r, f in discs], bool(undefined.any()))

    def test_pictures_bad_input_names_the_parameter(self):
        import io
        import tempfile
        from contextlib import redirect_stderr
        from particleShear.run.cli import main
        from particleShear.simulation.microstructure_pictures import picture_primitives
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaisesRegex(ValueError, "stroboscopic=True"):
                self.off.microstructure_pictures(d)
            with self.assertRaisesRegex(ValueError, "colour_by='x' is invalid"):
                self.large.microstructure_pictures(d, colour_by="x")
            with self.assertRaisesRegex(ValueError, r"cycle=3 is out of range: allowed an integer 0 <= cycle <= 2"):
                picture_primitives(self.large.microstructure, 3)
            with self.assertRaisesRegex(ValueError, "scale=0 is out of range"):
                self.large.microstructure_pictures(d, scale=0)
            err = io.StringIO()
            with redirect_stderr(err):
                rc = main(["--N", "30", "--periods", "0.5", "--stroboscopic-pictures", d, "--quiet"])
            self.assertEqual(rc, 2)
            self.assertIn("--stroboscopic-pictures with --periods 0.5 is invalid", err.getvalue())
            self.assertEqual(os.listdir(d), [])


class TestOnset(unittest.TestCase):

    def test_onset_of_a_power_law_by_log_interpolation(self):
        # irr = (A/0.1)² crosses 0.01 at A = 0.01 exactly between the amplitudes 0.005 and 0.02
        A = np.repeat([0.002, 0.005, 0.02, 0.05], 4)
        irr = (A / 0.1) ** 2 * np.tile([0.9, 1.1, 1.0, 1.0], 4)
        out = irreversibility_onset(A, irr, n_boot=200)
        self.assertAlmostEqual(out["onset"], 0.01, delta=1e-12)
        self.assertTrue(0.005 <= out["low"] <= out["onset"] <= out["high"] <= 0.02)
        self.assertEqual(out["flag"], "")

    def test_never_reached_and_bad_input(self):
        out = irreversibility_onset([0.1, 0.2], [1e-5, 1e-4], n_boot=10)
        self.assertTrue(math.isnan(out["onset"]))
        self.assertEqual(out["flag"], "above_range")
        with self.assertRaisesRegex(ValueError, "threshold"):
            irreversibility_onset([0.1], [1.0], threshold=-1)
        with self.assertRaisesRegex(ValueError, "amplitude"):
            irreversibility_onset([0.0], [1.0])

    def test_onset_beside_the_sweep_summary(self):
        from particleShear.analysis.microstructure import onset_summary
        A = np.repeat([0.002, 0.005, 0.02, 0.05, 0.2], 3)
        Gp = 100 / (1 + (A / 0.05) ** 2) * np.tile([0.95, 1.0, 1.05], 5)
        Gpp = 10 + 0 * A
        out = onset_summary(A, Gp, Gpp, (A / 0.1) ** 2, n_boot=50)
        self.assertAlmostEqual(out["onset"]["onset"], 0.01, delta=1e-12)
        for name in ("flow_point", "softening_strain", "linear_limit_10"):
            self.assertEqual(len(out[name]), 3)
        self.assertTrue(0.05 < out["flow_point"][0] < 0.2)     # G′ = 10 between these amplitudes

    def test_micro_measures_without_observer_are_nan(self):
        self.assertTrue(all(v is None for v in micro_measures(None).values()))


class TestSweepSpec(unittest.TestCase):
    """``stroboscopic`` in a SPEC: an output option, the run ids of the same SPEC without it."""

    BASE = dict(N=30, relative_frequency=0.5, pre_periods=0.5, periods=3, post_periods=0.5, doDrawing=False,
                plotStress=False, saveData=False)

    def _ids(self, doc):
        from particleShear.sweep import expand_runs, parse_spec
        return [r.run_id for r in expand_runs(parse_spec(doc))]

    def test_run_ids_unchanged_in_parameters_grid_and_zip(self):
        seeds = {"root": 3, "repetitions": 2}
        plain = {"parameters": dict(self.BASE), "grid": {"theAmplitude": [0.02, 0.3]}, "seeds": seeds}
        fixed = {"parameters": dict(self.BASE, stroboscopic=True), "grid": {"theAmplitude": [0.02, 0.3]},
                 "seeds": seeds}
        grid = {"parameters": dict(self.BASE), "grid": {"theAmplitude": [0.02, 0.3], "stroboscopic": [True]},
                "seeds": seeds}
        zipped = {"parameters": dict(self.BASE), "zip": [{"theAmplitude": [0.02, 0.3], "stroboscopic": [False, True]}],
                  "seeds": seeds}
        ids = self._ids(plain)
        self.assertEqual(len(set(ids)), 4)
        for doc in (fixed, grid, zipped):
            self.assertEqual(self._ids(doc), ids)
        with self.assertRaisesRegex((ValueError, TypeError), "stroboscopic='yes'"):
            self._ids({"parameters": dict(self.BASE, stroboscopic="yes"), "seeds": seeds})

    def test_sweep_fills_the_columns_and_does_not_split_groups(self):
        import tempfile
        from particleShear.analysis.cli import grouping_columns
        from particleShear.sweep import run_sweep
        from particleShear.sweep.schema import load_results
        doc = {"parameters": dict(self.BASE), "zip": [{"theAmplitude": [0.02, 0.3], "stroboscopic": [False, True]}],
               "seeds": {"root": 3, "repetitions": 1}}
        plain = {"parameters": dict(self.BASE), "grid": {"theAmplitude": [0.02, 0.3]},
                 "seeds": {"root": 3, "repetitions": 1}}
        with tempfile.TemporaryDirectory() as out:
            run_sweep(doc, out, workers=1, progress=False)
            rows = load_results(out, as_frame=False)
            header = list(rows[0])
        self.assertEqual([r["run_id"] for r in rows], self._ids(plain))
        self.assertEqual([r["status"] for r in rows], ["ok", "ok"])
        self.assertTrue(all(rows[0][c] is None for c in MICRO_COLUMNS))      # off: not evaluated
        self.assertTrue(all(rows[1][c] is not None and math.isfinite(rows[1][c]) for c in MICRO_COLUMNS))
        self.assertGreater(rows[1]["irreversibility"], 0.0)
        self.assertIn("stroboscopic", header)
        self.assertNotIn("stroboscopic", grouping_columns(header))           # one analysis group


if __name__ == "__main__":
    unittest.main()
