"""Run a sweep: resumable, one results row per finished run, on any ``concurrent.futures.Executor``.

Layout of ``DIR`` (docs/sweeps.md)::

    DIR/results.csv                         one row per finished run (ok or failed)
    DIR/results.parquet                     the same, when pyarrow is installed (rewritten at the end)
    DIR/<reference stem><run_id>.txt        e.g. dermal_filler0.01_f_3963.3_strain_0.2_nr_3fa9c2e1b0d4.txt
    DIR/runs/<run_id>/                      scratch folder of a running run (removed when it ends)

A run writes into its scratch folder (``root_folder``); when it has finished, the worker renames
its files into ``DIR`` (companions first, the ``.txt`` last), then the driving process appends its
row.  A run is finished when its row is in a table and its file exists.  A sweep killed at any
moment leaves, at worst, a scratch folder (cleared when the run starts again) and, for the run
that was being published, a file without row: the rerun writes the same file under the same name,
so ``DIR`` never holds two ``.txt`` files of one run.
"""
__docformat__ = "numpy"
import concurrent.futures
import contextlib
import dataclasses
import os
import re
import shutil
import sys
import time

import numpy as np

from .cost import estimate_cost, format_cost
from .spec import SweepSpec, expand_runs, load_spec, parse_spec
from .table import (TABLE_NAME, append_row, read_rows, repair_table, table_columns, task_table_name, write_parquet,
                    write_table)

__all__ = ["Sweep", "SweepOutcome", "run_sweep", "execute_run", "SweepProgress"]

_TABLE_GLOB = re.compile(r"^results(\.task-\d+-of-\d+)?\.csv$")


@dataclasses.dataclass
class SweepOutcome:
    """A finished run: its :class:`~particleShear.sweep.spec.SweepRun`, its table row, and its result.

    Parameters
    ----------
    run : SweepRun
        The run (parameters, seed, run id).
    row : dict
        Its row of ``results.csv`` (status ``ok`` or ``failed``, moduli in Pa, parameters, ...).
    result : SimulationResult or None, optional
        The :class:`~particleShear.run.api.SimulationResult` (None for a failed run);
        its per-step ``series`` are kept only with ``keep_series=True``.
    """

    run: object
    row: dict
    result: object = None

    @property
    def ok(self):
        """True when the run succeeded (``row["status"] == "ok"``)."""
        return self.row["status"] == "ok"


def _publish(run_dir, out_dir, produced, run_id):
    """Move a run's files from its scratch folder into ``out_dir``, named ``<stem><run_id>...``.

    ``produced`` is the text file the run wrote (``<stem><k>.txt``); every entry of the scratch
    folder starting with ``<stem><k>`` (sidecars, other formats, the image folder) moves with it,
    the file itself last.  Returns the new path of ``produced``.
    """
    base = os.path.basename(produced)
    m = re.match(r"^(.*_)(\d+)(\.[A-Za-z][A-Za-z0-9.]*)$", base)   # <stem><k><.ext>; μ may hold dots
    if m:
        head, new_head = m.group(1) + m.group(2), m.group(1) + run_id
    else:
        head = os.path.splitext(base)[0]
        new_head = head + "_" + run_id
    entries = sorted(e for e in os.listdir(run_dir) if e.startswith(head) and not e.endswith(".part"))
    entries.sort(key=lambda e: e == base)          # the text file last
    final = None
    for e in entries:
        target = os.path.join(out_dir, new_head + e[len(head):])
        src = os.path.join(run_dir, e)
        if os.path.isdir(src) and os.path.isdir(target):
            shutil.rmtree(target)
        os.replace(src, target)
        if e == base:
            final = target
    return final


def _failed_row(task, exc, wall):
    from .. import __version__
    row = {"run_id": task["run_id"], "status": "failed", "error": f"{type(exc).__name__}: {exc}".replace("\n", " ")}
    row.update(task["parameters"])
    row.update(seed_entropy=task["seed_entropy"], spawn_key=list(task["spawn_key"]), package_version=__version__,
               wall_time_s=wall, output_path="")
    return row


def execute_run(task):
    """Run one sweep task (a picklable dict) in the calling process; return ``(row, result or None)``.

    Never raises for a failing simulation: the exception becomes a ``failed`` row.

    Parameters
    ----------
    task : dict
        ``run_id``, ``index``, ``parameters`` (complete, of ``doParticleShearSimulation``),
        ``seed_entropy``, ``spawn_key``, ``out_dir`` (sweep folder; "" writes nothing) and
        ``keep_series`` (bool: keep the per-step series in the result).

    Returns
    -------
    tuple
        ``(row, result)``: the results-table row (dict) and the SimulationResult, or None
        when the run failed.
    """
    from ..run.api import doParticleShearSimulation
    t0 = time.perf_counter()
    run_dir, kwargs = None, None
    try:
        run_dir, kwargs = _prepare(task)
        result = doParticleShearSimulation(**kwargs)
        return _finish_run(task, result, time.perf_counter() - t0)
    except Exception as exc:  # a failed run is a row, never the end of the sweep
        return _failed_row(task, exc, time.perf_counter() - t0), None
    finally:
        if run_dir:
            shutil.rmtree(run_dir, ignore_errors=True)


def _prepare(task):
    """``(run_dir, kwargs)`` of a task: its empty scratch folder ("" when it writes nothing) and its call."""
    p = task["parameters"]
    writes = bool(task["out_dir"]) and bool(p.get("saveData") or p.get("saveOutputImages"))
    run_dir = os.path.join(task["out_dir"], "runs", task["run_id"]) if writes else ""
    if writes:
        shutil.rmtree(run_dir, ignore_errors=True)      # leftovers of a killed attempt
        os.makedirs(run_dir)
    ss = np.random.SeedSequence(task["seed_entropy"], spawn_key=tuple(task["spawn_key"]))
    return run_dir, dict(p, root_folder=run_dir, seed=ss, return_result=True, verbose=False)


def _finish_run(task, result, wall_time_s):
    """Publish a finished run's files under its run id; return ``(row, result)``."""
    result.parameters = dict(task["parameters"])
    if result.output_path:
        run_dir = os.path.dirname(result.output_path)
        image_folder = result.image_folder
        result.output_path = _publish(run_dir, task["out_dir"], result.output_path, task["run_id"])
        if image_folder:
            result.image_folder = result.output_path + "_images_folder"
    row = result.to_dict()
    if row["run_id"] != task["run_id"]:  # pragma: no cover - identity must not depend on the process
        raise RuntimeError(f"run id {row['run_id']} differs from the sweep's {task['run_id']}")
    row["output_path"] = os.path.abspath(result.output_path) if result.output_path else ""
    row["wall_time_s"] = wall_time_s
    if not task.get("keep_series"):
        result.series = {}
    return row, result


def execute_batch(tasks):
    """Run sweep tasks that share a step schedule as one batch of replicas; ``[(row, result), ...]`` in order.

    The replicas are measured together (:func:`particleShear.run.batch.run_batch`), each
    bit-identical to its single run, so the rows equal those of :func:`execute_run`.  If the
    batch fails (one replica diverging stops the batch), every task runs again on its own, so
    that only the failing run becomes a ``failed`` row.

    Parameters
    ----------
    tasks : list of dict
        As for :func:`execute_run`.

    Returns
    -------
    list of tuple
        ``(row, result or None)`` per task, in the given order.
    """
    from ..run.batch import run_batch
    t0 = time.perf_counter()
    prepared = []
    try:
        prepared = [_prepare(task) for task in tasks]
        results = run_batch([kw for _, kw in prepared])
        wall = (time.perf_counter() - t0) / len(tasks)
        return [_finish_run(task, result, wall) for task, result in zip(tasks, results)]
    except Exception:  # noqa: BLE001 - one bad replica: run them one by one (failed rows where they fail)
        for run_dir, _ in prepared:
            if run_dir:
                shutil.rmtree(run_dir, ignore_errors=True)
        return [execute_run(task) for task in tasks]
    finally:
        for run_dir, _ in prepared:
            if run_dir:
                shutil.rmtree(run_dir, ignore_errors=True)


def _pool_context(parameters):
    """Start method of the default worker pool: "spawn" when a run uses a device backend.

    The parent has initialised CUDA when it checked ``backend="cupy"``, and a forked child
    cannot use CUDA after that; fresh ("spawn") workers can.  NumPy runs keep the platform's default.

    Parameters
    ----------
    parameters : iterable of dict
        The runs' keyword arguments.

    Returns
    -------
    multiprocessing context or None
    """
    import multiprocessing
    if any(p.get("backend", "numpy") != "numpy" for p in parameters):
        return multiprocessing.get_context("spawn")
    return None


def _ignore_sigint():
    """Worker initializer: Ctrl-C reaches only the driving process, which then stops cleanly."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)


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
        tail = f"G'={float(row['Gp_surface']):.6g} Pa" if outcome.ok else row["error"][:80]
        self.stream.write(f"[sweep] {self.done}/{self.total} done, {self.failed} failed, {rate:.3g} runs/s, "
                          f"ETA {eta:.0f} s | {row['run_id']} {row['status']} {float(row['wall_time_s']):.2f} s "
                          f"{tail}\n")
        self.stream.flush()

    def close(self):
        """Close the tqdm bar, if one is shown (lines need no closing)."""
        if self._bar is not None:
            self._bar.close()


#: seconds to wait for the table lock (a killed sweep's worker may still be exiting)
LOCK_WAIT_S = 15.0


@contextlib.contextmanager
def _table_lock(path, wait_s=None):
    """Exclusive advisory lock on ``path + '.lock'``, released by the OS when its holders die.

    Forked workers inherit it, so a worker of a killed sweep keeps it until it has exited;
    we wait up to ``LOCK_WAIT_S`` for it, then refuse (another sweep writes this table).
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: no lock
        yield
        return
    wait_s = LOCK_WAIT_S if wait_s is None else wait_s
    fd = os.open(path + ".lock", os.O_WRONLY | os.O_CREAT, 0o644)
    try:
        deadline = time.monotonic() + wait_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() >= deadline:
                    raise RuntimeError(f"another sweep is writing {path!r}; wait for it or use another "
                                       "--out DIR") from None
                time.sleep(0.05)
        yield
    finally:
        os.close(fd)


class Sweep:
    """A sweep of ``spec`` into the folder ``out_dir``, every run validated on construction.

    Parameters
    ----------
    spec : str, os.PathLike, dict or SweepSpec
        A SPEC file (.toml/.json), its parsed dict, or a :class:`SweepSpec`.
    out_dir : str
        Output folder (created when missing).
    task_index, task_count : int, optional
        Job-array share: this process runs the runs with ``index % task_count == task_index``
        and writes its rows to its own table, merged later by :meth:`merge`.
    backend : str, optional
        Array backend of every run (``--backend``), set as the SPEC's ``[parameters] backend``:
        "numpy" or "cupy" (a CUDA GPU; runs without drawing).  It is part of each run's
        identity, so a sweep measured on the GPU does not resume the rows of a NumPy sweep.
        Default: the SPEC's (``"numpy"`` unless it sets one).
    """

    def __init__(self, spec, out_dir, *, task_index=None, task_count=None, backend=None):
        if isinstance(spec, SweepSpec):
            self.spec = spec
        elif isinstance(spec, dict):
            self.spec = parse_spec(spec)
        else:
            self.spec = load_spec(spec)
        if backend is not None:
            from ..run.batch import check_backend
            try:
                check_backend(backend)
            except ValueError as exc:
                raise ValueError(str(exc).replace(f"backend={backend!r}", f"backend={backend!r} (--backend)", 1)) \
                    from None
            if "backend" in self.spec.grid or any("backend" in z for z in self.spec.zips):
                raise ValueError(f"backend={backend!r} (--backend) conflicts with the SPEC, which varies backend")
            self.spec = dataclasses.replace(self.spec, parameters=dict(self.spec.parameters, backend=backend))
        if (task_index is None) != (task_count is None):
            raise ValueError("task_index and task_count (--task-index, --task-count) go together")
        if task_count is not None:
            if isinstance(task_count, bool) or not isinstance(task_count, int) or task_count < 1:
                raise ValueError(f"task_count={task_count!r} (--task-count) is invalid: allowed an integer >= 1")
            if isinstance(task_index, bool) or not isinstance(task_index, int) or not 0 <= task_index < task_count:
                raise ValueError(f"task_index={task_index!r} (--task-index) is out of range: allowed "
                                 f"0 <= value < {task_count}")
        if not isinstance(out_dir, (str, os.PathLike)) or not os.fspath(out_dir):
            raise ValueError(f"out_dir={out_dir!r} (--out) is invalid: allowed a folder path")
        self.out_dir = os.path.abspath(os.fspath(out_dir))
        if os.path.exists(self.out_dir) and not os.path.isdir(self.out_dir):
            raise ValueError(f"out_dir={out_dir!r} (--out) is invalid: it is a file")
        self.task_index, self.task_count = task_index, task_count
        self.runs = expand_runs(self.spec)          # validates every run before any work
        self.columns = table_columns(list(self.runs[0].parameters) if self.runs else None)
        name = TABLE_NAME if task_count is None else task_table_name(task_index, task_count)
        self.table_path = os.path.join(self.out_dir, name)

    # -- state ---------------------------------------------------------------------------------
    def my_runs(self):
        """The runs of this process (all, or this task's share)."""
        if self.task_count is None:
            return list(self.runs)
        return [r for r in self.runs if r.index % self.task_count == self.task_index]

    def _tables(self):
        if not os.path.isdir(self.out_dir):
            return []
        return sorted(os.path.join(self.out_dir, e) for e in os.listdir(self.out_dir) if _TABLE_GLOB.match(e))

    def _file_exists(self, path):
        return bool(path) and (os.path.exists(path)
                               or os.path.exists(os.path.join(self.out_dir, os.path.basename(path))))

    def finished_rows(self, retry_failed=False):
        """``{run_id: row}`` of this sweep's finished runs, over all tables of ``out_dir``.

        Parameters
        ----------
        retry_failed : bool, optional
            True: rows with status ``failed`` do not count as finished (default False).

        Returns
        -------
        dict
        """
        ids = {r.run_id for r in self.runs}
        done = {}
        for path in self._tables():
            for row in read_rows(path):
                rid = row.get("run_id")
                if rid not in ids or rid in done:
                    continue
                if row.get("status") == "ok":
                    wants_file = row.get("saveData") == "True"
                    if not wants_file or self._file_exists(row.get("output_path")):
                        done[rid] = row
                elif row.get("status") == "failed" and not retry_failed:
                    done[rid] = row
        return done

    def pending(self, retry_failed=False):
        """This process's runs that have not finished, in sweep order.

        Parameters
        ----------
        retry_failed : bool, optional
            True: failed runs count as pending (default False).

        Returns
        -------
        list of SweepRun
        """
        done = self.finished_rows(retry_failed)
        return [r for r in self.my_runs() if r.run_id not in done]

    def cost(self, workers=1, pending_only=False):
        """:func:`~particleShear.sweep.cost.estimate_cost` of the (pending) runs.

        Parameters
        ----------
        workers : int, optional
            Parallel workers for the wall-time projection (default 1).
        pending_only : bool, optional
            True: only the runs not yet finished (default False: this process's whole share).

        Returns
        -------
        dict
            As :func:`~particleShear.sweep.cost.estimate_cost`.
        """
        return estimate_cost(self.pending() if pending_only else self.my_runs(), workers)

    # -- running -------------------------------------------------------------------------------
    def _task(self, run, keep_series):
        return {"run_id": run.run_id, "index": run.index, "parameters": run.parameters,
                "seed_entropy": run.seed_entropy, "spawn_key": run.spawn_key, "out_dir": self.out_dir,
                "keep_series": bool(keep_series)}

    def as_completed(self, executor=None, workers=None, keep_series=False, retry_failed=False, progress=True,
                     stream=None, batch_size=None):
        """Run the pending runs; yield a :class:`SweepOutcome` per run as it finishes (completion order).

        Each row is appended to the table (fsynced) before it is yielded.
        On KeyboardInterrupt the queued runs are cancelled and the interrupt propagates; the
        rows written so far are kept and a rerun resumes.

        Parameters
        ----------
        executor : concurrent.futures.Executor, optional
            Where the runs execute (not shut down here; e.g. a Dask client's executor);
            default a ``ProcessPoolExecutor(workers)`` owned by this call.
        workers : int, optional
            Processes of the default executor (≥ 1, ``--workers``; default: all cores).
        keep_series : bool, optional
            Keep the per-step series in each outcome's result (default False: moduli only).
        retry_failed : bool, optional
            Run again the runs whose row says ``failed`` (default False).
        progress : bool or callable, optional
            True (default): one line per run on ``stream``; False: silent; a callable is
            called with each :class:`SweepOutcome`.
        stream : file-like, optional
            Where progress lines go (default ``sys.stderr``).
        batch_size : int, optional
            Group pending runs that share a step schedule (``particleShear.run.batch.schedule_key``)
            into batches of up to ``batch_size`` runs, one task each (``--batch-size``); the rows
            are those of unbatched runs, bit for bit.  Default None: one task per run.

        Yields
        ------
        SweepOutcome
            One per finished run, in completion order.

        Raises
        ------
        ValueError
            If ``workers`` is not an integer ≥ 1 (before any run starts).
        """
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
            raise ValueError(f"workers={workers!r} (--workers) is invalid: allowed an integer >= 1")
        if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int)
                                       or batch_size < 1):
            raise ValueError(f"batch_size={batch_size!r} (--batch-size) is invalid: allowed an integer >= 1")
        stream = stream if stream is not None else sys.stderr
        os.makedirs(self.out_dir, exist_ok=True)
        with _table_lock(self.table_path):
            repair_table(self.table_path)
            todo = self.pending(retry_failed)
            ids = {r.run_id for r in todo}
            rows = read_rows(self.table_path)
            if any(row.get("run_id") in ids for row in rows):   # stale rows (failed to retry, file lost)
                write_table(self.table_path, [r for r in rows if r.get("run_id") not in ids], self.columns)
            n_mine = len(self.my_runs())
            if progress is True:
                c = estimate_cost(todo, workers or os.cpu_count())
                stream.write(f"[sweep] {n_mine} runs in this share, {n_mine - len(todo)} already finished; "
                             f"to run: {format_cost(c)}\n")
                stream.flush()
                show = SweepProgress(n_mine, n_mine - len(todo), stream)
            else:
                show = progress if callable(progress) else None
            if not todo:
                if show is not None and hasattr(show, "close"):
                    show.close()
                self._finish()
                return
            own = executor is None
            if own:
                executor = concurrent.futures.ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint,
                                                                  mp_context=_pool_context(r.parameters for r in todo))
            futures, recorded = {}, set()
            try:
                by_id = {r.run_id: r for r in todo}
                if batch_size is None:
                    futures = {executor.submit(execute_run, self._task(r, keep_series)): [r.run_id] for r in todo}
                else:
                    from ..run.batch import batches
                    groups = batches([r.parameters for r in todo], batch_size)
                    futures = {executor.submit(execute_batch, [self._task(todo[i], keep_series) for i in g]):
                               [todo[i].run_id for i in g] for g in groups}
                recorded = set()
                for fut in concurrent.futures.as_completed(futures):
                    done = fut.result()
                    for run_id, (row, result) in zip(futures[fut], [done] if batch_size is None else done):
                        append_row(self.table_path, row, self.columns)
                        outcome = SweepOutcome(by_id[run_id], row, result)
                        if show is not None:
                            show(outcome)
                        yield outcome
                    recorded.add(fut)
            except KeyboardInterrupt:
                for fut in futures:
                    fut.cancel()
                if own:                 # our workers ignore SIGINT: let the running runs finish
                    stream.write("[sweep] interrupted: waiting for the running runs to finish "
                                 "(Ctrl-C again to stop at once)\n")
                    stream.flush()
                    executor.shutdown(wait=True, cancel_futures=True)
                for fut in futures:     # runs that finished meanwhile: keep their rows (their files exist)
                    if fut not in recorded and fut.done() and not fut.cancelled() and fut.exception() is None:
                        for row, _ in ([fut.result()] if batch_size is None else fut.result()):
                            append_row(self.table_path, row, self.columns)
                raise
            except BaseException:
                for fut in futures:
                    fut.cancel()
                raise
            finally:
                if show is not None and hasattr(show, "close"):
                    show.close()
                if own:
                    executor.shutdown(wait=True, cancel_futures=True)
            self._finish()

    def _finish(self):
        scratch = os.path.join(self.out_dir, "runs")
        with contextlib.suppress(OSError):
            os.rmdir(scratch)   # only when empty
        if self.task_count is None:
            write_parquet(self.table_path)

    def run(self, **kwargs):
        """Run the pending runs; return every finished row in sweep order.

        Parameters
        ----------
        **kwargs
            The options of :meth:`as_completed` (``executor``, ``workers``, ``keep_series``,
            ``retry_failed``, ``progress``, ``stream``).

        Returns
        -------
        list of dict
            As :meth:`rows`.
        """
        for _ in self.as_completed(**kwargs):
            pass
        return self.rows()

    def rows(self):
        """Finished rows of this sweep in sweep order (dicts of strings, as read back from the tables)."""
        done = self.finished_rows()
        return [done[r.run_id] for r in self.runs if r.run_id in done]

    def merge(self):
        """Merge every table of ``out_dir`` into ``results.csv`` (one row per run, sweep order).

        Rows of other sweeps in ``results.csv`` are kept; the task tables are removed after the
        merged table has been written.

        Returns
        -------
        tuple of int
            ``(n_rows, n_missing)``: rows of this sweep written, runs not finished yet.
        """
        path = os.path.join(self.out_dir, TABLE_NAME)
        with _table_lock(path):
            done = self.finished_rows()
            ours = [done[r.run_id] for r in self.runs if r.run_id in done]
            ids = {r.run_id for r in self.runs}
            others = [row for row in read_rows(path) if row.get("run_id") not in ids]
            write_table(path, others + ours, self.columns)
            for t in self._tables():
                if t != path:
                    os.remove(t)
                    with contextlib.suppress(OSError):
                        os.remove(t + ".lock")
            write_parquet(path)
        return len(ours), len(self.runs) - len(ours)


def run_sweep(spec, out_dir, *, executor=None, workers=None, task_index=None, task_count=None, keep_series=False,
              retry_failed=False, progress=True, stream=None, batch_size=None):
    """Run (or resume) the sweep ``spec`` into ``out_dir``; return its finished rows in sweep order.

    The layout of ``out_dir`` and of the table is described in docs/sweeps.md.

    Parameters
    ----------
    spec : str, os.PathLike, dict or SweepSpec
        A SPEC file (.toml/.json), its parsed dict, or a :class:`SweepSpec`.
    out_dir : str or os.PathLike
        Output folder (created when missing); the same folder resumes the sweep.
    executor : concurrent.futures.Executor, optional
        Where the runs execute (not shut down here); default a process pool of ``workers``.
    workers : int, optional
        Processes of the default executor (≥ 1; default: all cores).
    task_index, task_count : int, optional
        Job-array share: this process runs the runs with ``index % task_count == task_index``
        into its own table (merge with :meth:`Sweep.merge` / ``--merge``).
    keep_series : bool, optional
        Keep the per-step series of each run in memory (default False).
    retry_failed : bool, optional
        Run again the runs whose row says ``failed`` (default False).
    progress : bool or callable, optional
        True (default): one line per run on ``stream``; False: silent; or a callable(outcome).
    stream : file-like, optional
        Where progress lines go (default ``sys.stderr``).
    batch_size : int, optional
        Measure runs that share a step schedule in batches of up to ``batch_size`` replicas, one
        task each (``--batch-size``; rows identical to unbatched runs).  Default None.

    Returns
    -------
    list of dict
        The finished rows in sweep order (dicts of strings).

    Raises
    ------
    ValueError
        An invalid SPEC or run (naming the parameter), before any run starts.
    """
    return Sweep(spec, out_dir, task_index=task_index, task_count=task_count).run(
        executor=executor, workers=workers, keep_series=keep_series, retry_failed=retry_failed,
        progress=progress, stream=stream, batch_size=batch_size)


def _from_runs(runs, out_dir):
    """A :class:`Sweep` over an explicit list of SweepRun (used by the series)."""
    sweep = Sweep.__new__(Sweep)
    sweep.spec = None
    sweep.out_dir = os.path.abspath(os.fspath(out_dir))
    sweep.task_index = sweep.task_count = None
    sweep.runs = list(runs)
    sweep.columns = table_columns(list(sweep.runs[0].parameters) if sweep.runs else None)
    sweep.table_path = os.path.join(sweep.out_dir, TABLE_NAME)
    return sweep


def _result_from_row(row, run):
    """A light SimulationResult of a run finished in an earlier call (moduli, parameters, seed, path)."""
    from ..run.api import SimulationResult
    g = tuple(float(row[c]) for c in ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal"))
    return SimulationResult(G_surface=g[:2], G_internal=g[2:], stress_surface=(), stress_internal=(),
                            parameters=dict(run.parameters), seed=run.seed_entropy, spawn_key=tuple(run.spawn_key),
                            timings={"total": float(row["wall_time_s"])}, output_path=row["output_path"] or None)


def series_parameters(kwargs):
    """The complete parameter set a series records for one run (``SimulationResult.parameters``).

    Every parameter a SPEC may set, defaults filled in, from the run's keyword arguments; the
    folder, seed and console choice of the series are not part of it.

    Parameters
    ----------
    kwargs : dict
        Keyword arguments of :func:`~particleShear.doParticleShearSimulation` for the run.

    Returns
    -------
    dict
    """
    from .spec import sweep_parameter_defaults
    return dict(sweep_parameter_defaults(),
                **{n: v for n, v in kwargs.items() if n not in ("root_folder", "seed", "verbose")})


def run_series(all_kwargs, root_folder="", executor=None, max_workers=None, batch_size=None):
    """Run the keyword sets of ``doParticleShearSimulationSeries`` on the sweep machinery; results in order.

    Parameters
    ----------
    all_kwargs : list of dict
        ``all_kwargs[k]`` holds every argument of run k, its ``seed`` a ``numpy.random.SeedSequence``.
    root_folder : str, optional
        With a folder the runs form a resumable sweep into it (see :class:`Sweep`); "" (default)
        writes nothing.
    executor : concurrent.futures.Executor, optional
        Where the runs execute (not shut down here); default a process pool owned by this call.
    max_workers : int, optional
        Processes of the default pool (default: all cores).
    batch_size : int, optional
        Runs sharing a step schedule measured in batches of up to ``batch_size`` (one task each).

    Returns
    -------
    list of SimulationResult
        In the order of ``all_kwargs``.

    Raises
    ------
    RuntimeError
        If any run failed (after all have finished), naming the first failed run.
    """
    from ..simulation.provenance import run_identity
    from .spec import SweepRun
    runs = []
    for k, kw in enumerate(all_kwargs):
        ss = kw["seed"]
        params = series_parameters(kw)
        runs.append(SweepRun(index=k, point=k, repetition=0, parameters=params, seed_entropy=ss.entropy,
                             spawn_key=tuple(ss.spawn_key), run_id=run_identity(params, ss.entropy, ss.spawn_key)))
    results = [None] * len(runs)
    failures = []
    if root_folder:
        sweep = _from_runs(runs, root_folder)
        done = sweep.finished_rows()
        pos = {r.run_id: i for i, r in enumerate(runs)}
        for i, r in enumerate(runs):
            if r.run_id in done and done[r.run_id]["status"] == "ok":
                results[i] = _result_from_row(done[r.run_id], r)
        for outcome in sweep.as_completed(executor=executor, workers=max_workers, keep_series=True,
                                          retry_failed=True, progress=False, batch_size=batch_size):
            if outcome.ok:
                results[pos[outcome.run.run_id]] = outcome.result
            else:
                failures.append(outcome.row)
    else:
        own = executor is None
        if own:
            executor = concurrent.futures.ProcessPoolExecutor(max_workers=max_workers,
                                                              mp_context=_pool_context(r.parameters for r in runs))
        try:
            tasks = [{"run_id": r.run_id, "index": r.index, "parameters": r.parameters,
                      "seed_entropy": r.seed_entropy, "spawn_key": r.spawn_key, "out_dir": "",
                      "keep_series": True} for r in runs]
            if batch_size is None:
                groups = [[i] for i in range(len(tasks))]
                futures = [executor.submit(execute_run, tasks[i]) for i in range(len(tasks))]
            else:
                from ..run.batch import batches
                groups = batches([r.parameters for r in runs], batch_size)
                futures = [executor.submit(execute_batch, [tasks[i] for i in g]) for g in groups]
            for g, fut in zip(groups, futures):
                for i, (row, result) in zip(g, [fut.result()] if batch_size is None else fut.result()):
                    results[i] = result
                    if row["status"] != "ok":
                        failures.append(row)
        finally:
            if own:
                executor.shutdown(wait=True, cancel_futures=True)
    if failures:
        first = failures[0]
        raise RuntimeError(f"{len(failures)} of {len(runs)} runs of the series failed; first: run "
                           f"{first['run_id']} (theAmplitude={first['theAmplitude']}, theMu={first['theMu']}): "
                           f"{first['error']}")
    return results
