"""Snapshots that explain themselves: caption, scale bar, legend, periodic images, vector files, movie.

The pixel checks use the drawing rules themselves as the definition: 1 canvas pixel = 1 µm at
scale 1, y drawn downwards, discs filled with the configured volume colour (default "grey" =
(128, 128, 128)), the Lees-Edwards image above the cell shifted by +Ly·γ in x.
"""
import glob
import os
import tempfile
import types
import unittest
import xml.etree.ElementTree as ET

import numpy as np

from particleShear import EnsembleLinkable, SphereLinkable
from particleShear.simulation.drawing import (CAPTION_HEIGHT, PillowRenderer, make_renderer,
                                              scale_bar_length)

GREY = (128, 128, 128)
WHITE = (255, 255, 255)


def one_disc_scene(x, y, r, shear=0.0, size=500):
    """A minimal ensemble-like object: one disc, no pairs, Lees-Edwards strain ``shear``."""
    a = {"x": np.array([float(x)]), "y": np.array([float(y)]), "r": np.array([float(r)]), "phi": np.zeros(1)}
    return types.SimpleNamespace(_a=a, _pairs=None, size_x=size, size_y=size, t=0.125, shear=shear,
                                 _le_shift=lambda: size * shear, graphical_output_configuration=None)


def two_bonded_spheres():
    ens = EnsembleLinkable(500, 500, 0, k=1, nu=1, k_t=1, nu_t=1, mu=0.01)
    a = SphereLinkable("grey", 150, 200, 120, 1, 1, force_register=ens)
    b = SphereLinkable("grey", 220, 260, 120, 1, 2, force_register=ens)
    ens.sphereList.append(a)
    ens.sphereList.append(b)
    a.establish_permanent_link(b)
    ens.mechanical_simulation_step_calculate_forces()
    return ens


class TestPeriodicImages(unittest.TestCase):
    def test_disc_crossing_the_left_edge_appears_on_the_right(self):
        img = PillowRenderer().render(one_disc_scene(5, 250, 20), caption=False)
        self.assertEqual(img.size, (500, 500))
        self.assertEqual(img.getpixel((2, 250)), GREY)      # the disc itself
        self.assertEqual(img.getpixel((495, 250)), GREY)    # its image at x + Lx = 505 reaches 485..525
        self.assertEqual(img.getpixel((250, 250)), WHITE)   # nothing in between
        self.assertEqual(img.getpixel((495, 100)), WHITE)

    def test_lees_edwards_image_above_is_shifted_by_Ly_gamma(self):
        # disc at (100, 5), γ = 0.1: image at y + 500 lies at x + 50 = 150, reaching y = 485 .. 499
        img = PillowRenderer().render(one_disc_scene(100, 5, 20, shear=0.1), caption=False)
        self.assertEqual(img.getpixel((100, 2)), GREY)
        self.assertEqual(img.getpixel((150, 495)), GREY)
        self.assertEqual(img.getpixel((100, 495)), WHITE)   # an unsheared image would be here

    def test_disc_inside_the_cell_is_drawn_once(self):
        ens = one_disc_scene(250, 250, 20)
        text = PillowRenderer().vector(ens, "svg")
        circles = [e for e in ET.fromstring(text).iter() if e.tag.endswith("circle")]
        self.assertEqual(len(circles), 1)
        text = PillowRenderer().vector(one_disc_scene(5, 5, 20), "svg")  # a corner: 4 copies
        circles = [e for e in ET.fromstring(text).iter() if e.tag.endswith("circle")]
        self.assertEqual(len(circles), 4)


class TestCaption(unittest.TestCase):
    def test_caption_strip_has_text_scale_bar_and_legend_colours(self):
        img = PillowRenderer().render(two_bonded_spheres(), step=7)
        self.assertEqual(img.size, (500, 500 + CAPTION_HEIGHT))
        strip = np.asarray(img)[500:]
        colours = {tuple(c) for c in strip.reshape(-1, 3)}
        for name, rgb in (("red (sticking)", (255, 0, 0)), ("green (slipping)", (0, 128, 0)),
                          ("blue (bond)", (0, 0, 255))):
            self.assertIn(rgb, colours, name + " legend swatch missing")
        # text of the first row: dark pixels in the top-left corner of the strip
        self.assertGreater(int((strip[2:20, :200].sum(axis=2) < 200).sum()), 50)
        # scale bar: a black bar of exactly L µm = L pixels on row 30 starting at x = 6
        L = scale_bar_length(500)
        self.assertEqual(L, 100)
        row = strip[30]
        black = np.flatnonzero(row.sum(axis=1) == 0)
        self.assertEqual(black[0], 6)
        run_end = black[0] + np.flatnonzero(np.diff(black) > 1)[0] if np.any(np.diff(black) > 1) else black[-1]
        self.assertEqual(run_end - 6 + 1, L + 1)  # Pillow draws both end points

    def test_bond_between_spheres_is_blue_in_the_picture(self):
        img = PillowRenderer().render(two_bonded_spheres(), caption=False)
        # the bond is the centre-to-centre segment (150, 200) → (220, 260); its midpoint:
        self.assertEqual(img.getpixel((185, 230)), (0, 0, 255))


def two_particles_and_a_loose_sphere():
    """Spheres 0–1 bonded (one particle), 2–3 bonded (another), 4 without a bond; radius 30 µm."""
    ens = EnsembleLinkable(500, 500, 0, k=1, nu=1, k_t=1, nu_t=1, mu=0.01)
    pos = [(100, 100), (150, 130), (350, 100), (400, 130), (250, 400)]
    s = [SphereLinkable("grey", x, y, 60, 1, k + 1, force_register=ens) for k, (x, y) in enumerate(pos)]
    for sp in s:
        ens.sphereList.append(sp)
    s[0].establish_permanent_link(s[1])
    s[2].establish_permanent_link(s[3])
    ens.mechanical_simulation_step_calculate_forces()
    return ens


def components(n, i, j):
    """Connected components by union-find (independent of the package's label propagation)."""
    parent = list(range(n))

    def root(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for a, b in zip(i, j):
        parent[root(a)] = root(b)
    return [root(a) for a in range(n)]


class TestParticleColours(unittest.TestCase):
    def test_each_particle_its_colour_loose_spheres_grey(self):
        img = PillowRenderer().render(two_particles_and_a_loose_sphere(), caption=False)
        # points inside one disc only, away from the bond lines (centre to centre) and the outlines
        first = img.getpixel((75, 100)), img.getpixel((175, 130))
        second = img.getpixel((325, 100)), img.getpixel((425, 130))
        self.assertEqual(first[0], first[1])                 # one particle, one colour
        self.assertEqual(second[0], second[1])
        self.assertNotEqual(first[0], second[0])             # two particles, two colours
        for c in (first[0], second[0]):
            self.assertNotIn(c, (GREY, WHITE))
        self.assertEqual(img.getpixel((250, 400)), GREY)     # no bond: grey as before
        self.assertEqual(img.getpixel((250, 420)), GREY)

    def test_colours_of_a_crosslinked_run_are_per_particle_and_stable(self):
        """Every SVG snapshot of a real run: the circle fills against the bond graph of the ensemble."""
        from unittest import mock
        from particleShear import doParticleShearSimulation
        from particleShear.simulation.drawing import periodic_offsets
        frames = []
        original = PillowRenderer.vector

        def recording(renderer, ens, fmt, step=None):
            text = original(renderer, ens, fmt, step)
            pt, a = ens.pair_table, ens.sphere_arrays     # the run's replica, as the renderer sees it
            perm = pt.state == 2                             # PERMANENT
            frames.append(dict(svg=text, x=a["x"].copy(), y=a["y"].copy(), r=a["r"].copy(),
                               i=pt.i[perm].copy(), j=pt.j[perm].copy(), shift=ens.size_y * ens.shear,
                               L=(ens.size_x, ens.size_y)))
            return text

        with tempfile.TemporaryDirectory() as d, mock.patch.object(PillowRenderer, "vector", recording):
            doParticleShearSimulation(d, N=12, cut_lines=2, pre_periods=0.25, periods=0.5, post_periods=0.25,
                                      doDrawing=False, plotStress=False, saveOutputImages=True, imageFileType="svg",
                                      seed=3, verbose=False)
        self.assertGreater(len(frames), 2)
        fills_per_frame = []
        for fr in (frames[0], frames[len(frames) // 2], frames[-1]):
            circles = [(float(e.get("cx")), float(e.get("cy")), e.get("fill"))
                       for e in ET.fromstring(fr["svg"]).iter() if e.tag.endswith("circle")]
            fills = []
            for x, y in zip(fr["x"], fr["y"]):   # the fill of a drawn copy of each sphere
                for ox, oy in periodic_offsets(*fr["L"], fr["shift"]):
                    hit = [c for c in circles if abs(c[0] - (x + ox)) < 0.01 and abs(c[1] - (y + oy)) < 0.01]
                    if hit:
                        fills.append(hit[0][2])
                        break
            self.assertEqual(len(fills), len(fr["x"]))
            fills_per_frame.append(fills)
            comp = components(len(fr["x"]), fr["i"].tolist(), fr["j"].tolist())
            bonded = set(fr["i"].tolist()) | set(fr["j"].tolist())
            roots = sorted({comp[k] for k in bonded})
            self.assertGreaterEqual(len(roots), 2)           # cut_lines=2: at least two particles
            colour_of = {}
            for k in range(len(comp)):
                if k in bonded:
                    colour_of.setdefault(comp[k], set()).add(fills[k])
                else:
                    self.assertEqual(fills[k], "rgb(128, 128, 128)")
            for root in roots:
                self.assertEqual(len(colour_of[root]), 1)    # one particle, one colour
            if len(roots) <= 11:                             # the palette's size: distinct colours
                self.assertEqual(len({next(iter(colour_of[root])) for root in roots}), len(roots))
        for fills in fills_per_frame[1:]:
            self.assertEqual(fills, fills_per_frame[0])      # the same colour of every sphere in every frame


class TestStressWindowTicks(unittest.TestCase):
    def test_nice_ticks_are_round_and_cover_the_range(self):
        from particleShear.simulation.drawing import nice_ticks
        ticks = nice_ticks(0, 0.00113, 8)   # a protocol of 1.13 ms
        self.assertEqual(ticks[0], 0)
        steps = np.diff(ticks)
        np.testing.assert_allclose(steps, steps[0])
        self.assertAlmostEqual(steps[0], 2e-4)          # 1, 2 or 5 × 10^k
        self.assertLessEqual(ticks[-1], 0.00113)
        self.assertGreater(ticks[-1] + steps[0], 0.00113)
        self.assertEqual(nice_ticks(-250, 250, 5), [-200, -100, 0, 100, 200])
        self.assertEqual(nice_ticks(1, 1), [])


    def test_axes_of_the_live_window_match_the_plotter_mapping(self):
        """draw_axes on a recording canvas (no Tk): ticks where the plotter puts those values."""
        from particleShear.simulation.drawing import StressPlotWindow

        class Canvas:
            def __init__(self):
                self.texts, self.lines = [], []

            def create_text(self, x, y, text="", **k):
                self.texts.append((x, y, text))

            def create_line(self, *xy, **k):
                self.lines.append(xy)

        w = StressPlotWindow.__new__(StressPlotWindow)   # no Tk window
        w.width, w.height, w.canvas = 1000, 500, Canvas()
        T, A, fs = 0.004, 0.2, 2.0                        # 4 ms protocol, 2 px per Pa
        w.draw_axes(T, 1000 / T, fs, 30 / A, A, t_on=0.001, t_off=0.003)
        texts = {t: (x, y) for x, y, t in w.canvas.texts}
        self.assertIn("time t (s)", texts)
        self.assertIn("stress − stress(0) (Pa)", texts)
        self.assertAlmostEqual(texts["0.002"][0], 500 + 2)          # t = 2 ms at x = t·x_scale (+2 px offset)
        self.assertAlmostEqual(texts["100"][1], 250 - 100 * fs)     # 100 Pa at y = H/2 − τ·scale
        self.assertAlmostEqual(texts["\u03b3 = +0.2"][1], 250 - 30)  # strain A drawn 30 px above the axis
        self.assertIn((250.0, 0, 250.0, 500), w.canvas.lines)        # excitation start t_on = 1 ms
        for label in ("internal (stress tensor)", "surface (plate forces)", "strain \u03b3"):
            self.assertIn(label, texts)


class TestFiles(unittest.TestCase):
    def test_eps_and_svg_are_vector(self):
        ens = two_bonded_spheres()
        with tempfile.TemporaryDirectory() as d:
            r = PillowRenderer()
            r.save(ens, os.path.join(d, "a.ps"), "ps", step=3)
            r.save(ens, os.path.join(d, "a.svg"), "svg", step=3)
            with open(os.path.join(d, "a.ps"), "rb") as fh:
                eps = fh.read().decode("ascii")
            self.assertTrue(eps.startswith("%!PS-Adobe-3.0 EPSF-3.0"))
            self.assertEqual(eps.count(" D\n"), 2)                # two discs as arcs, no bitmap
            self.assertNotIn("image", eps)
            self.assertIn("step 3", eps)
            self.assertLess(len(eps), 20000)
            root = ET.parse(os.path.join(d, "a.svg")).getroot()
            texts = " ".join(e.text or "" for e in root.iter() if e.tag.endswith("text"))
            self.assertIn("step 3", texts)
            self.assertIn("100 \u00b5m", texts)
            self.assertEqual(os.listdir(d).count("a.ps"), 1)
            self.assertFalse([f for f in os.listdir(d) if f.endswith(".part")])

    def test_renderer_for_snapshots_without_drawing(self):
        self.assertIsInstance(make_renderer(False, True), PillowRenderer)
        self.assertIsNone(make_renderer(False, False))


class TestRunImagesAndMovie(unittest.TestCase):
    def test_images_without_doDrawing_and_movie_has_one_frame_per_snapshot(self):
        from PIL import Image
        from particleShear import doParticleShearSimulation
        with tempfile.TemporaryDirectory() as d:
            res = doParticleShearSimulation(d, N=12, cut_lines=2, pre_periods=0.25, periods=0.5, post_periods=0.25,
                                            doDrawing=False, plotStress=False, saveOutputImages=True,
                                            imageFileType="png", saveOutputMovie=True, seed=3, verbose=False,
                                            return_result=True)
            frames = sorted(glob.glob(os.path.join(res.image_folder, "image*.png")))
            self.assertGreater(len(frames), 10)
            self.assertEqual(len(frames), res.n_images)
            with Image.open(os.path.join(res.image_folder, "movie.gif")) as gif:
                self.assertEqual(gif.n_frames, len(frames))
            with Image.open(frames[-1]) as im:
                self.assertEqual(im.size, (500, 500 + CAPTION_HEIGHT))

    def test_movie_needs_images(self):
        from particleShear import doParticleShearSimulation
        with self.assertRaisesRegex(ValueError, "saveOutputMovie"):
            doParticleShearSimulation("", saveOutputMovie=True, doDrawing=False, verbose=False)


if __name__ == "__main__":
    unittest.main()
