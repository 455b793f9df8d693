"""Observers: watching a run never changes it (particleShear.engine.observers, simulation.observers).

* The loops of the measurement call an observer after every step whose count is a multiple of
  its ``every`` and after the last step of each phase, with the phase's name and length.
* An observer that reads everything there is to read (the view of its replica, the record so
  far) every step leaves the record bit-identical to the unobserved run: observers only read.
* The view of a replica draws what the documented ensemble draws for the same state (the
  renderers' own definition of the picture).
* A drawn run (live-window settings, stress window, snapshots and movie written through the
  headless renderer) gives the t, γ, γ̇, stresses, G′ and G″ of the same seed with nothing
  drawn, bit for bit; its snapshots are 1.0.2's names and cadence, valid images of the
  documented size, and each shows the clock and strain of its step.
* A batch of two drawn replicas writes, per replica, exactly the snapshot files of its single run
  (each replica's observers see their replica only).
"""
import glob
import os
import re
import tempfile
import unittest

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.engine.observers import Observer, check_observers
from particleShear.base.engine_adapter import state_from_ensembles
from particleShear.engine.step import BatchEngine, pre_equilibrate, pre_equilibration_blocks, protocol
from particleShear.run.batch import run_batch
from particleShear.simulation.drawing import CAPTION_HEIGHT, PillowRenderer
from particleShear.simulation.observers import ReplicaScene, ReplicaView
from particleShear.simulation.scene import scene_geometry
from particleShearTest.test_engine import constituted

#: ~560 protocol steps of 20 spheres, crosslinked and cut (the quick scene of test_batch.py)
QUICK = dict(N=20, relative_frequency=0.2, pre_periods=0.5, periods=1, post_periods=0.5, cut_lines=2, verbose=False)
DRAWN = dict(doDrawing=True, plotStress=True, saveOutputImages=True, renderer="pillow")
HEADLESS = dict(doDrawing=False, plotStress=False, saveOutputImages=False)


class Counter(Observer):
    """Records every call."""

    def __init__(self, every):
        Observer.__init__(self, every)
        self.calls = []

    def observe(self, engine, phase, step, total):
        self.calls.append((phase, step, total))


class Reader(Observer):
    """Reads the whole view of replica 0 and the record so far at every step (what a drawing reads)."""

    def __init__(self):
        Observer.__init__(self, 1)
        self.scene = ReplicaScene()
        self.bound = None
        self.sums = []

    def observe(self, engine, phase, step, total):
        if self.bound is not engine:
            self.scene.bind(engine, 0)
            self.bound = engine
        v = self.scene(engine)
        g = scene_geometry(v)           # what a picture reads: spheres, contacts, bonds (Lees-Edwards images)
        self.sums.append(sum(float(g[k].sum()) for k in ("x", "y", "r", "phi", "chords", "links"))
                         + int(g["chord_state"].sum()) + v.t + v.shear)
        if phase == "protocol":
            self.sums.append(float(self.scene.samples(engine, 0, step).sum()))


def measured(seed, observers=()):
    """Pre-equilibration and protocol of one constituted replica in the engine, with ``observers``."""
    _, ens, sc = constituted(seed, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)
    eng = BatchEngine(state_from_ensembles([ens]), skin_factor=0.2)
    pre_equilibrate(eng, sc["N_pre"], sc["dt"], sc["dt_max"], sc["cool"], observers=observers)
    return protocol(eng, sc["dt"], sc["f"], [sc["A"]], sc["cool"], 0.5, 1, 0.5, observers=observers), sc


class TestLoopsCallObservers(unittest.TestCase):
    def test_called_at_their_period_and_after_the_last_step(self):
        c1, c7 = Counter(1), Counter(7)
        rec, sc = measured(5, (c1, c7))
        n_pre = sum(b[0] for b in pre_equilibration_blocks(sc["N_pre"], sc["dt"], sc["dt_max"])) + 3 * sc["N_pre"]
        n = len(rec["t"])
        self.assertGreater(n, 100)
        expected1 = ([("pre-equilibration", k, n_pre) for k in range(1, n_pre + 1)]
                     + [("protocol", k, n) for k in range(1, n + 1)])
        self.assertEqual(c1.calls, expected1)
        self.assertNotEqual(n_pre % 7, 0)       # the extra call after the last step is exercised
        expected7 = ([("pre-equilibration", k, n_pre) for k in range(7, n_pre + 1, 7)] + [("pre-equilibration", n_pre, n_pre)]
                     + [("protocol", k, n) for k in range(7, n + 1, 7)]
                     + ([("protocol", n, n)] if n % 7 else []))
        self.assertEqual(c7.calls, expected7)

    def test_reading_everything_every_step_changes_nothing(self):
        plain, _ = measured(6)
        reader = Reader()
        watched, _ = measured(6, (reader,))
        self.assertGreater(len(reader.sums), 2 * len(plain["t"]))
        self.assertTrue(np.all(np.isfinite(reader.sums)))
        self.assertEqual(sorted(plain), sorted(watched))
        for key in plain:
            self.assertEqual(plain[key].tobytes(), watched[key].tobytes(), key)

    def test_bad_observers_are_refused_by_name(self):
        for every in (0, -1, 1.5, True, None):
            with self.subTest(every=every):
                class Bad:
                    def observe(self, *a):
                        pass
                bad = Bad()
                bad.every = every
                with self.assertRaisesRegex(ValueError, r"every=.* is out of range: allowed an integer >= 1"):
                    check_observers([bad])
        with self.assertRaisesRegex(ValueError, "every="):
            Observer(0)
        silent = type("Silent", (), {"every": 1})()
        with self.assertRaisesRegex(ValueError, "no observe"):
            check_observers([silent])


class TestReplicaView(unittest.TestCase):
    def test_view_draws_what_the_ensemble_draws(self):
        # before any step the state is the ensemble's: the same SVG, the renderer being the definition
        _, ens, _ = constituted(8, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)
        ens.shear = 0.13          # a Lees-Edwards shift, so the periodic images are exercised
        eng = BatchEngine(state_from_ensembles([ens]))
        view = ReplicaView(eng, 0, ens.graphical_output_configuration)
        r = PillowRenderer()
        self.assertIn("circle", r.vector(ens, "svg", step=3))
        self.assertEqual(r.vector(view, "svg", step=3), r.vector(ens, "svg", step=3))

    def test_view_shows_its_replica_of_a_batch(self):
        ens = [constituted(s, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)[1] for s in (9, 10)]
        eng = BatchEngine(state_from_ensembles(ens))
        r = PillowRenderer()
        for b in (0, 1):
            self.assertEqual(r.vector(ReplicaView(eng, b), "svg"), r.vector(ens[b], "svg"))
        self.assertNotEqual(r.vector(ReplicaView(eng, 0), "svg"), r.vector(ReplicaView(eng, 1), "svg"))

    def test_scene_refuses_an_engine_it_is_not_bound_to(self):
        _, ens, _ = constituted(8)
        a, b = (BatchEngine(state_from_ensembles([ens])) for _ in range(2))
        scene = ReplicaScene()
        scene.bind(a, 0)
        self.assertIs(scene(a).engine, a)
        with self.assertRaisesRegex(ValueError, "bound"):
            scene(b)


def same_series(test, a, b):
    test.assertEqual(a.G_surface, b.G_surface)
    test.assertEqual(a.G_internal, b.G_internal)
    test.assertEqual(sorted(a.series), sorted(b.series))
    for key in a.series:
        test.assertEqual(np.asarray(a.series[key]).tobytes(), np.asarray(b.series[key]).tobytes(), key)


class TestDrawnRunEqualsHeadless(unittest.TestCase):
    def test_drawn_run_gives_the_numbers_of_the_headless_run(self):
        from PIL import Image
        headless = doParticleShearSimulation(seed=3, return_result=True, **QUICK, **HEADLESS)
        with tempfile.TemporaryDirectory() as d:
            drawn = doParticleShearSimulation(d, seed=3, return_result=True, imageFileType="png", saveOutputMovie=True,
                                              **QUICK, **DRAWN)
            same_series(self, headless, drawn)
            for key in ("t", "strain", "strain_rate", "stress_internal", "stress_surface"):
                self.assertIn(key, drawn.series)
            # 1.0.2's cadence and names: protocol step indices 0, image_N, 2·image_N, ...
            n = drawn.N_steps
            image_N = int(n / 200) if n > 200 else 1
            files = sorted(os.path.basename(f) for f in glob.glob(os.path.join(drawn.image_folder, "image*.png")))
            self.assertEqual(files, ["image%07d.png" % k for k in range(0, n, image_N)])
            self.assertEqual(len(files), drawn.n_images)
            self.assertGreater(len(files), 100)
            for name in (files[0], files[len(files) // 2], files[-1]):
                path = os.path.join(drawn.image_folder, name)
                self.assertGreater(os.path.getsize(path), 2000)        # a picture, not an empty file
                self.assertLess(os.path.getsize(path), 2_000_000)
                with Image.open(path) as im:
                    im.verify()
                with Image.open(path) as im:
                    self.assertEqual(im.format, "PNG")
                    self.assertEqual(im.size, (500, 500 + CAPTION_HEIGHT))   # the 500 µm cell at 1 px/µm + caption
                    self.assertGreater(len(im.convert("RGB").getcolors(1 << 20)), 3)   # discs, bonds, caption
            with Image.open(os.path.join(drawn.image_folder, "movie.gif")) as gif:
                self.assertEqual(gif.n_frames, len(files))

    def test_each_snapshot_shows_the_clock_and_strain_after_its_step(self):
        # snapshot i is the state after step i: the clock t[i + 1] and strain γ[i + 1] of the series
        with tempfile.TemporaryDirectory() as d:
            res = doParticleShearSimulation(d, seed=4, return_result=True, imageFileType="svg",
                                            **dict(QUICK, theAmplitude=0.3), **DRAWN)
            t, g = np.asarray(res.series["t"]), np.asarray(res.series["strain"])
            files = sorted(glob.glob(os.path.join(res.image_folder, "image*.svg")))
            self.assertGreater(len(files), 100)
            checked = 0
            for path in files[:: max(1, len(files) // 10)]:
                i = int(re.search(r"image(\d{7})\.svg$", path).group(1))
                if i + 1 >= len(t):
                    continue
                with open(path, encoding="utf-8") as fh:
                    text = fh.read()
                self.assertIn(f"t = {t[i + 1]:.4g} s", text)
                self.assertIn(f"\u03b3 = {g[i + 1]:+.4f}", text)
                self.assertIn(f"step {i}", text)
                checked += 1
            self.assertGreater(checked, 5)
            self.assertGreater(np.ptp(g), 0.3)       # the strains shown differ from frame to frame


class DotCanvas:
    """A stress window's canvas and root that keep every dot (centre and colour)."""

    def __init__(self):
        self.dots = []
        self.canvas, self.tk = self, self
        self.updates = 0

    def create_oval(self, x0, y0, x1, y1, fill=None, outline=None):
        self.dots.append(((x0 + x1) / 2, (y0 + y1) / 2, fill))

    def update(self):
        self.updates += 1

    def draw_axes(self, *a):
        pass


class TestPhasesOneByOneUseTheObservers(unittest.TestCase):
    def test_snapshots_and_stress_dots_of_run_protocol(self):
        # a script's pre_equilibrate and run_protocol call the experiment's observers too
        from particleShear.simulation.experiment import OscillatoryShearExperiment
        _, ens, sc = constituted(11, theMu=0.05, do_permanent_links=True, cut_lines=2, theAmplitude=0.2)
        with tempfile.TemporaryDirectory() as d:
            exp = OscillatoryShearExperiment(ens, sc["dt"], sc["f"], sc["A"], False, dt_max=sc["dt_max"],
                                             imageOutputFolder=d, imageBaseFileName="image", imageFileType="svg",
                                             plotStress=True)
            exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods = 0.5, 1, 0.5
            exp.renderer = PillowRenderer()
            exp.stress_window = window = DotCanvas()
            ens.applyingShear = True
            exp.pre_equilibrate(sc["N_pre"], sc["cool"])
            ens.t = 0
            n = exp.run_protocol(sc["cool"])
            image_N = int(n / 200) if n > 200 else 1
            self.assertEqual(sorted(os.listdir(d)), ["image%07d.svg" % k for k in range(0, n, image_N)])
            self.assertEqual(exp.n_images_saved, len(range(0, n, image_N)))
        rec = exp.plotter.arrays()
        self.assertEqual(len(window.dots), 3 * n)
        self.assertEqual(window.updates, n)
        p = exp._make_plotter(1.0)      # the mapping: y = offset − (value − value(0))·scale (EvaluationHandlerPlotter)
        for colour, key, scale in (("red", "stress_internal", p.y_scale_force), ("blue", "stress_surface", p.y_scale_force),
                                   ("green", "strain", p.y_scale_strain)):
            y = np.array([dot[1] for dot in window.dots if dot[2] == colour])
            v = rec[key] - (rec[key][0] if key != "strain" else 0.0)
            np.testing.assert_allclose(y, exp.height / 2 - v * scale, rtol=0, atol=1e-9 * (1 + np.max(np.abs(y))))
        x = np.array([dot[0] for dot in window.dots if dot[2] == "green"])
        T_total = (exp.periods + exp.baseline_pre_periods + exp.baseline_post_periods) / exp.f
        np.testing.assert_allclose(x, rec["t"] * exp.width / T_total, rtol=1e-12, atol=1e-9)


class TestBatchOfDrawnReplicas(unittest.TestCase):
    def test_each_replica_writes_the_snapshots_of_its_single_run(self):
        runs = [dict(QUICK, seed=1, theAmplitude=0.2, theMu=0.01), dict(QUICK, seed=2, theAmplitude=0.3, theMu=0.05)]
        with tempfile.TemporaryDirectory() as d_single, tempfile.TemporaryDirectory() as d_batch:
            single = [doParticleShearSimulation(d_single, return_result=True, imageFileType="svg", **kw, **DRAWN)
                      for kw in runs]
            batch = run_batch([dict(kw, root_folder=d_batch, imageFileType="svg", **DRAWN) for kw in runs])
            pictures = []
            for s, b in zip(single, batch):
                same_series(self, s, b)
                self.assertEqual(s.n_images, b.n_images)
                names = sorted(os.listdir(s.image_folder))
                self.assertEqual(names, sorted(os.listdir(b.image_folder)))
                self.assertGreater(len(names), 100)
                for name in names:
                    with open(os.path.join(s.image_folder, name), "rb") as f1, \
                            open(os.path.join(b.image_folder, name), "rb") as f2:
                        self.assertEqual(f1.read(), f2.read(), name)
                with open(os.path.join(s.image_folder, names[-1]), "rb") as fh:
                    pictures.append(fh.read())
            self.assertNotEqual(pictures[0], pictures[1])     # two replicas, two pictures


if __name__ == "__main__":
    unittest.main()
