"""Remaining-time estimates of the progress lines, on fake clocks (no wall time is measured).

A run's phase (``particleShear.run.cli.ProgressLine``) and a sweep
(``particleShear.sweep.progress.SweepProgress``) each estimate the time left; every estimate
shown after 10 % of the work lies within 1.5× of the true remaining time of the simulated
schedule, the first one included (the former estimates were ~5× and ~4× too high there).
"""
import io
import re
import types
import unittest

from particleShear.run.cli import ProgressLine
from particleShear.sweep.progress import RemainingTime, SweepProgress, sweep_remaining_s


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def phase_schedule(total, startup, per_step, every=50, jitter=0.0):
    """(step, elapsed at its report) of a phase whose first step costs ``startup`` s more than the
    others (``per_step`` s each, ± ``jitter`` alternating): a report every ``every`` steps and at the end."""
    t, out = 0.0, []
    for step in range(1, total + 1):
        t += per_step * (1 + (jitter if step % 2 else -jitter)) + (startup if step == 1 else 0.0)
        if step == 1 or step % every == 0 or step == total:
            out.append((step, t))
    return out


class TestRunPhase(unittest.TestCase):
    def shown(self, schedule, total):
        """(step, estimate shown, true remaining) of every line ProgressLine writes (a terminal)."""
        stream = io.StringIO()
        stream.isatty = lambda: True
        clock = Clock()
        line = ProgressLine(stream, clock=clock)
        end, rows = schedule[-1][1], []
        for step, elapsed in schedule:
            clock.t = elapsed
            start = len(stream.getvalue())
            line("protocol", step, total, elapsed)
            text = stream.getvalue()[start:]
            m = re.search(r"remaining ~\s*([0-9.]+) s", text)
            rows.append((step, float(m.group(1)) if m else None, end - elapsed))
        return rows

    def test_estimates_within_one_and_a_half_after_ten_percent(self):
        # the default run's protocol: its first step costs ~5 steps (measured 2.6 ms against 0.53 ms)
        for jitter in (0.0, 0.3):
            with self.subTest(jitter=jitter):
                total = 13439
                rows = self.shown(phase_schedule(total, startup=4 * 5.3e-4, per_step=5.3e-4, jitter=jitter), total)
                self.assertIsNone(rows[0][1])           # the first report has no rate: no estimate
                checked = 0
                for step, shown, true in rows:
                    if step >= 0.1 * total and step < total:
                        self.assertIsNotNone(shown)
                        # the line shows 0.1 s: allow its rounding
                        self.assertLessEqual(shown, 1.5 * true + 0.05, (step, shown, true))
                        self.assertGreaterEqual(shown, true / 1.5 - 0.05, (step, shown, true))
                        checked += 1
                self.assertGreater(checked, 200)

    def test_the_first_step_is_not_a_rate(self):
        est = RemainingTime()
        self.assertIsNone(est.update(1, 100, 5.0))          # start-up 5 s, then 0.1 s a step
        self.assertAlmostEqual(est.update(11, 100, 6.0), 89 * 0.1)
        # a rate from the origin (elapsed·left/done) would say 6.0·89/11 = 48.5 s here
        est.reset()
        self.assertIsNone(est.update(1, 10, 0.5))            # a new phase starts a new rate

    def test_a_log_gets_the_first_estimate_of_a_phase(self):
        stream, clock = io.StringIO(), Clock()
        line = ProgressLine(stream, clock=clock)
        for step, elapsed in phase_schedule(1000, startup=0.05, per_step=1e-3, every=100):
            clock.t = elapsed
            line("protocol", step, 1000, elapsed)
        lines = stream.getvalue().splitlines()
        self.assertIn("remaining ~   –", lines[0])                 # the phase's first report
        first = float(re.search(r"remaining ~\s*([0-9.]+) s", lines[1]).group(1))
        self.assertAlmostEqual(first, 0.9, delta=0.05)             # 900 steps of 1 ms left at step 100


class TestSweep(unittest.TestCase):
    @staticmethod
    def outcome(i, wall):
        return types.SimpleNamespace(ok=True, row={"run_id": f"r{i}", "status": "ok", "wall_time_s": wall,
                                                   "Gp_surface": 1.0, "protocol": "oscillatory"})

    def etas(self, walls, workers, told=True):
        """(runs done, ETA, true remaining) after each finished run of a pool of ``workers`` workers that
        each take the next run when free; ``told``: the progress is told the number of workers."""
        import heapq
        clock = Clock()
        show = SweepProgress(len(walls), 0, io.StringIO(), workers=workers if told else None, clock=clock)
        free = [0.0] * workers
        ends = []
        for i, w in enumerate(walls):            # the run starts on the worker free first
            start = heapq.heappop(free)
            heapq.heappush(free, start + w)
            ends.append((start + w, i))
        ends.sort()
        out = []
        for k, (t, i) in enumerate(ends):
            clock.t = t
            show(self.outcome(i, walls[i]))
            out.append((k + 1, show.eta, ends[-1][0] - t))
        return out

    def test_eta_within_one_and_a_half_after_ten_percent(self):
        # 40 runs of 8–12 s (a fixed spread), 1, 2 or 4 workers; checked from the first finished run on
        # while more than one run's wall time is left (below it, the last runs' own length decides)
        walls = [10.0 * (1 + 0.2 * ((7 * i) % 5 - 2) / 2) for i in range(40)]
        for workers in (1, 2, 4):
            with self.subTest(workers=workers):
                rows = self.etas(walls, workers)
                checked = 0
                for done, eta, true in rows:
                    if true >= max(walls):   # the first line included
                        self.assertLessEqual(eta, 1.5 * true, (done, eta, true))
                        self.assertGreaterEqual(eta, true / 1.5, (done, eta, true))
                        checked += 1
                self.assertGreater(checked, 25)
                self.assertEqual(rows[-1][1], 0.0)
        # workers not told (an executor): one worker is observed exactly
        for done, eta, true in self.etas(walls, 1, told=False)[4:-2]:
            self.assertLessEqual(eta, 1.5 * true)
            self.assertGreaterEqual(eta, true / 1.5)

    def test_first_wave_of_four_workers(self):
        # the first of 4 parallel 10 s runs finishes at 10 s: 19 runs left take 4 more waves (40 s;
        # the 3 others of the first wave finish now); runs counted per second said 190 s
        self.assertAlmostEqual(sweep_remaining_s(19, [10.0], workers=4), 43.75)
        self.assertAlmostEqual(sweep_remaining_s(19, [10.0], workers=1), 190.0)   # one worker: 19 whole runs
        self.assertIsNone(sweep_remaining_s(5, []))
        self.assertEqual(sweep_remaining_s(0, []), 0.0)


if __name__ == "__main__":
    unittest.main()
