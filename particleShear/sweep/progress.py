"""The progress lines of a sweep: one line per finished run (a tqdm bar on a terminal when installed)."""
__docformat__ = "numpy"
import sys
import time

from ..protocols import PROTOCOLS

__all__ = ["SweepProgress", "RemainingTime", "sweep_remaining_s"]

def _shown(row):
    """``label=value unit`` of a finished row: the column its protocol's ``shown`` names
    (:mod:`particleShear.protocols`; the oscillatory run's G′)."""
    proto = PROTOCOLS.get(row.get("protocol") or "oscillatory", PROTOCOLS["oscillatory"])
    name, label, unit = proto.shown or (proto.required_numbers[0], proto.required_numbers[0],
                                        proto.columns.get(proto.required_numbers[0], ("", ""))[1])
    return f"{label}={float(row[name]):.6g} {unit}".rstrip()


class RemainingTime:
    """Remaining time of a phase of work, from its rate measured after its first report.

    The first report of a phase carries its start-up (the first step allocates, a worker
    imports): a rate taken from it over-estimates the rest (~5× at the first step of a default
    run).  So the rate is the work done since the first report over the time since it, and there
    is no estimate before a second report: remaining = (total − done) · (t − t₁)/(done − done₁).
    For work of constant cost per unit the estimate is exact from the second report on.

    Call :meth:`update` with each report of a phase; a new phase starts with :meth:`reset`.
    """

    def __init__(self):
        self.reset()

    def reset(self):
        """Forget the origin: the next report starts a new phase."""
        self._origin = None

    def update(self, done, total, elapsed):
        """The remaining time after a report, or None while there is no rate yet.

        Parameters
        ----------
        done : float
            Units of work finished (steps, runs).
        total : float
            Units of work of the phase.
        elapsed : float
            Seconds since the phase started (any origin: only differences are used).

        Returns
        -------
        float or None
            Seconds left (0 once ``done`` reaches ``total``); None at the first report of a phase
            before that (no rate yet).
        """
        if total and done >= total:
            return 0.0
        if self._origin is None or done < self._origin[0]:
            self._origin = (done, elapsed)
        d0, t0 = self._origin
        if done <= d0 or elapsed <= t0:
            return None
        return max(total - done, 0) * (elapsed - t0) / (done - d0)


def sweep_remaining_s(left, wall_times, workers=None, elapsed=None):
    """Remaining wall time of a sweep, from its runs' mean wall time, the runs left and the workers.

    With ``p = min(workers, left)`` runs in parallel, the run just started by the worker that
    finished and ``p − 1`` others in flight (half done on average), the work left is
    ``mean · (left − (p − 1)/2)`` shared by ``p`` workers.  A rate counted from finished runs
    would be ``workers``× too slow at the first wave (the first of 4 parallel runs finishing at
    T gives 1 run per T, not 4); the mean wall time does not depend on when runs finish.

    Parameters
    ----------
    left : int
        Runs still to finish.
    wall_times : sequence of float
        Wall time (s) of each run finished so far in this call.
    workers : int, optional
        Runs in parallel; None (an executor whose workers are not known): the concurrency
        observed, ``sum(wall_times)/elapsed`` (≥ 1), which is low until the first wave finished.
    elapsed : float, optional
        Seconds since the sweep started (used when ``workers`` is None).

    Returns
    -------
    float or None
        Seconds left (0 when no run is left); None before any run finished.
    """
    if left <= 0:
        return 0.0
    if not wall_times:
        return None
    mean = sum(wall_times) / len(wall_times)
    if workers is None:
        workers = sum(wall_times) / elapsed if elapsed else 1.0
    p = max(1.0, min(float(workers), float(left)))
    return mean * max(left - (p - 1) / 2, 0.5) / p


class SweepProgress:
    """One line per finished run: done/failed/total, rate, ETA (a tqdm bar on a terminal when installed).

    Call it with each :class:`SweepOutcome`; :meth:`close` at the end.

    Parameters
    ----------
    total : int
        Number of runs of the sweep (or of this task's share).
    already : int, optional
        Runs finished before this call (resumed sweep), counted as done (default 0).
    stream : file-like, optional
        Where the lines go (default ``sys.stderr``); a terminal gets a tqdm bar when installed.
    workers : int, optional
        Runs in parallel (the ETA: :func:`sweep_remaining_s`); None: the concurrency observed.
    clock : callable, optional
        Seconds (default ``time.perf_counter``; tests pass a fake clock).
    """

    def __init__(self, total, already=0, stream=None, workers=None, clock=time.perf_counter):
        self.total, self.done, self.failed = total, already, 0
        self.started = 0
        self.workers, self.clock, self.walls = workers, clock, []
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = clock()
        self._bar = None
        if hasattr(self.stream, "isatty") and self.stream.isatty():
            try:
                from tqdm import tqdm
                self._bar = tqdm(total=total, initial=already, file=self.stream, unit="run")
            except ImportError:
                pass

    def __call__(self, outcome):
        self.done += 1
        self.started += 1
        self.failed += not outcome.ok
        elapsed = self.clock() - self.t0
        rate = self.started / elapsed if elapsed > 0 else float("inf")
        try:
            self.walls.append(float(outcome.row["wall_time_s"]))
        except (KeyError, TypeError, ValueError):
            pass
        walls = [w for w in self.walls if w == w and w >= 0]
        self.eta = sweep_remaining_s(self.total - self.done, walls, self.workers, elapsed)
        if self._bar is not None:
            self._bar.update(1)
            self._bar.set_postfix(failed=self.failed)
            return
        row = outcome.row
        tail = _shown(row) if outcome.ok else row["error"][:80]
        self.stream.write(f"[sweep] {self.done}/{self.total} done, {self.failed} failed, {rate:.3g} runs/s, "
                          f"ETA {'–' if self.eta is None else f'{self.eta:.0f} s'} | {row['run_id']} {row['status']} {float(row['wall_time_s']):.2f} s "
                          f"{tail}\n")
        self.stream.flush()

    def close(self):
        """Close the tqdm bar, if one is shown (lines need no closing)."""
        if self._bar is not None:
            self._bar.close()
