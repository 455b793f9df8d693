"""The progress lines of a sweep: one line per finished run (a tqdm bar on a terminal when installed)."""
__docformat__ = "numpy"
import sys
import time

__all__ = ["SweepProgress"]

#: the column whose value a progress line shows, per protocol (the oscillatory run's G′)
_SHOWN = {"steady": ("stress_surface", "σ", "Pa"), "relaxation": ("G_plateau_surface", "G_plateau", "Pa"),
          "creep": ("creep_rate", "creep rate", "1/s")}


def _shown(row):
    name, label, unit = _SHOWN.get(row.get("protocol") or "", ("Gp_surface", "G'", "Pa"))
    return f"{label}={float(row[name]):.6g} {unit}"


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
    """

    def __init__(self, total, already=0, stream=None):
        self.total, self.done, self.failed = total, already, 0
        self.started = 0
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
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
        elapsed = time.perf_counter() - self.t0
        rate = self.started / elapsed if elapsed > 0 else float("inf")
        eta = (self.total - self.done) / rate if rate > 0 else float("inf")
        if self._bar is not None:
            self._bar.update(1)
            self._bar.set_postfix(failed=self.failed)
            return
        row = outcome.row
        tail = _shown(row) if outcome.ok else row["error"][:80]
        self.stream.write(f"[sweep] {self.done}/{self.total} done, {self.failed} failed, {rate:.3g} runs/s, "
                          f"ETA {eta:.0f} s | {row['run_id']} {row['status']} {float(row['wall_time_s']):.2f} s "
                          f"{tail}\n")
        self.stream.flush()

    def close(self):
        """Close the tqdm bar, if one is shown (lines need no closing)."""
        if self._bar is not None:
            self._bar.close()
