"""Executing a sweep's jobs: a bounded window of tasks in flight, workers that never outlive the sweep.

A *job* is a list of tasks (one run, or the runs of one batch of replicas) executed by
:func:`~particleShear.sweep.tasks.execute_run` or :func:`~particleShear.sweep.tasks.execute_batch`.
:func:`run_jobs` submits them lazily, at most ``window`` at a time, so a sweep of any size holds
only the futures in flight (memory and the cancellation on Ctrl-C stay bounded).

The default executor is a process pool whose workers

* ignore SIGINT (Ctrl-C reaches the driving process, which lets the running runs finish), and
* watch their parent: when the driving process dies (SIGKILL, SIGTERM, a crash) they exit within
  :data:`WATCH_INTERVAL_S`, so they never hold a sweep's folder or CPU after it is gone.

A worker that dies while running (the out-of-memory killer, a signal) breaks the pool; the jobs
that were in flight are then run again, each in a process of its own (``workers`` at a time,
:func:`isolated`), so the run that kills its process is identified and becomes a ``failed`` row
("the worker process running this run was killed by SIGKILL …") while the others finish
normally; a batch whose process dies is split into its runs first.  The sweep then goes on in a
fresh pool.  With another executor (Dask, threads, MPI), an exception of the executor for a job
(a lost Dask worker, say) becomes a ``failed`` row of each of its runs; a broken process pool
that is not ours fails the runs in flight and stops the sweep with a ``RuntimeError`` (finished
rows kept).
"""
__docformat__ = "numpy"
import concurrent.futures
import os
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool

from . import tasks as _tasks
from ..engine.xp import get_backend

__all__ = ["run_jobs", "isolated", "pool_context", "WorkerDied", "SweepTerminated", "WATCH_INTERVAL_S", "worker_init", "new_pool",
           "terminate"]

#: seconds between a worker's checks that its driving process is alive
WATCH_INTERVAL_S = 0.2
#: jobs in flight on an executor that is not ours (Dask, MPI, threads): enough for large clusters, bounded
EXTERNAL_WINDOW = 10_000


class SweepTerminated(BaseException):
    """Raised in the driving process by SIGTERM (the sweep CLI's handler): stop at once, keep the rows.

    A BaseException, so that no ``except Exception`` on the way turns it into a failed run.
    """


class WorkerDied(RuntimeError):
    """The worker process that ran a run died (out-of-memory killer, a signal) before returning."""


def _watch_parent(parent_pid, start_method):
    """Return when the driving process is gone.

    A forked worker's parent is the driving process: its parent id changes when it dies (the
    worker is re-parented).  A spawned or forkserver worker has another parent (the fork server)
    but holds the read end of a pipe whose write end only the driving process holds
    (``multiprocessing.parent_process().sentinel``): it becomes readable when that process dies.
    """
    if start_method == "fork":
        while os.getppid() == parent_pid:
            time.sleep(WATCH_INTERVAL_S)
        return
    import multiprocessing
    import multiprocessing.connection
    parent = multiprocessing.parent_process()
    if parent is None or getattr(parent, "sentinel", None) is None:  # pragma: no cover - not a child
        while os.getppid() == parent_pid:
            time.sleep(WATCH_INTERVAL_S)
        return
    multiprocessing.connection.wait([parent.sentinel])


def _watchdog(parent_pid, start_method):
    _watch_parent(parent_pid, start_method)
    os._exit(1)   # the sweep is gone: stop at once (its scratch folder is removed by the next sweep)


def worker_init(parent_pid, start_method="fork"):
    """Initializer of the default pool's workers: ignore SIGINT, default SIGTERM, exit with the driver.

    The driving process handles Ctrl-C (it lets running runs finish) and may have a SIGTERM
    handler of its own (the CLI's); a worker must not inherit either, so that the driver can stop
    it, and it exits as soon as the driving process ``parent_pid`` is gone (:func:`_watch_parent`).

    Parameters
    ----------
    parent_pid : int
        The driving process.
    start_method : str, optional
        ``"fork"``, ``"spawn"`` or ``"forkserver"``: how the worker was started (default "fork").
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    threading.Thread(target=_watchdog, args=(parent_pid, start_method), daemon=True,
                     name="particleShear-watch").start()


def _start_method(mp_context):
    import multiprocessing
    return (mp_context or multiprocessing.get_context()).get_start_method()


def new_pool(workers, mp_context=None):
    """A process pool of ``workers`` workers initialised by :func:`worker_init`.

    Parameters
    ----------
    workers : int
        Number of worker processes (≥ 1).
    mp_context : multiprocessing context, optional
        Start method (``"spawn"`` for device backends); default the platform's.

    Returns
    -------
    concurrent.futures.ProcessPoolExecutor
    """
    return concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=mp_context, initializer=worker_init,
                                                  initargs=(os.getpid(), _start_method(mp_context)))


def _call(job):
    """``(function, argument)`` that executes ``job``: one run, or a batch of replicas."""
    if len(job) == 1 and not job[0].get("batched"):
        return _tasks.execute_run, job[0]
    return _tasks.execute_batch, job


def _submit(executor, job):
    fn, arg = _call(job)
    return executor.submit(fn, arg)


def _outcomes(job, value):
    return [value] if len(job) == 1 and not job[0].get("batched") else list(value)


def terminate(pool):
    """Kill the worker processes of a process pool at once (SIGTERM of the sweep: stop now).

    Parameters
    ----------
    pool : concurrent.futures.ProcessPoolExecutor
        The pool (its private process table; nothing happens for an executor without one).
    """
    for p in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            p.kill()
        except Exception:  # noqa: BLE001 - already gone
            pass


def _death_text(exitcode):
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        why = " (e.g. the out-of-memory killer)" if -exitcode == signal.SIGKILL else ""
        return f"the worker process running this run was killed by {name}{why}"
    return f"the worker process running this run exited with status {exitcode} before returning"


def _isolated_child(conn, job, parent_pid, start_method):
    worker_init(parent_pid, start_method)
    fn, arg = _call(job)
    conn.send(_outcomes(job, fn(arg)))
    conn.close()


def isolated(jobs, mp_context=None, workers=1):
    """Run jobs each in a process of its own, ``workers`` at a time; yield ``(job, outcomes)`` as each ends.

    Used after a worker died: a job whose process dies again is the culprit.  A single run then
    becomes a ``failed`` row (:class:`WorkerDied`, naming the signal); a batch is split and its
    runs are isolated in turn, so only the run that kills its process fails.

    Parameters
    ----------
    jobs : list of list of dict
        The jobs that were in flight when a worker died.
    mp_context : multiprocessing context, optional
        Start method (default the platform's).
    workers : int, optional
        Processes at a time (default 1).

    Yields
    ------
    tuple
        ``(job, [(row, result or None), ...])``.
    """
    import multiprocessing
    import multiprocessing.connection
    ctx = mp_context or multiprocessing.get_context()
    queue = list(jobs)
    running = {}                      # receiving end -> (process, job, start time)
    try:
        while queue or running:
            while queue and len(running) < max(1, workers):
                job = queue.pop(0)
                recv, send = ctx.Pipe(duplex=False)
                proc = ctx.Process(target=_isolated_child, daemon=True,
                                   args=(send, job, os.getpid(), ctx.get_start_method()))
                proc.start()
                send.close()
                running[recv] = (proc, job, time.perf_counter())
            ready = multiprocessing.connection.wait(list(running) + [p.sentinel for p, _, _ in running.values()])
            for recv in [r for r in running if r in ready or running[r][0].sentinel in ready]:
                proc, job, t0 = running.pop(recv)
                try:
                    value = recv.recv()
                except (EOFError, OSError):       # the process died before it could answer
                    value = None
                finally:
                    recv.close()
                    proc.join()
                if value is not None:
                    yield job, value
                elif len(job) > 1 or job[0].get("batched"):
                    queue.extend([dict(t, batched=False)] for t in job)      # split the batch
                else:
                    why = WorkerDied(_death_text(proc.exitcode))
                    yield job, [(_tasks.failed_row(job[0], why, time.perf_counter() - t0), None)]
    finally:
        for recv, (proc, _, _) in running.items():
            proc.kill()
            proc.join()
            recv.close()


def pool_context(parameters):
    """Start method of the default worker pool: "spawn" when a run uses a device backend.

    The parent has initialised CUDA when it checked ``backend="cupy"``, and a forked child
    cannot use CUDA after that; fresh ("spawn") workers can.  Runs on the host (``"numpy"``,
    ``"numba"``, and ``"auto"`` resolved to one of them) keep the platform's default.

    Parameters
    ----------
    parameters : iterable of dict
        The runs' keyword arguments.

    Returns
    -------
    multiprocessing context or None
    """
    import multiprocessing
    names = {p.get("backend", "auto") for p in parameters}
    if any(not get_backend(name).host for name in names):
        return multiprocessing.get_context("spawn")
    return None


def run_jobs(jobs, executor=None, workers=1, mp_context=None, window=None):
    """Execute ``jobs`` (an iterable of lists of tasks); yield ``(job, [(row, result), ...])`` as each finishes.

    Parameters
    ----------
    jobs : iterable of list of dict
        The jobs, consumed lazily (at most ``window`` in flight).  A job of one task without
        ``batched`` is one run; any other job is a batch of replicas.
    executor : concurrent.futures.Executor, optional
        Where the jobs run (not shut down here); default a process pool of ``workers`` owned by
        this call (see the module docstring).
    workers : int, optional
        Workers of the default pool (≥ 1).
    mp_context : multiprocessing context, optional
        Start method of the default pool.
    window : int, optional
        Jobs in flight at most (default: ``workers + 1`` for the default pool,
        :data:`EXTERNAL_WINDOW` for another executor).

    Yields
    ------
    tuple
        ``(job, outcomes)``: the job and one ``(row, result or None)`` per task, in the job's order.
        On KeyboardInterrupt the queued jobs are cancelled, the running ones finish (default
        pool) and are yielded, then the interrupt propagates.  On any other BaseException the
        default pool's workers are killed at once.
    """
    own = executor is None
    window = window or ((workers + 1) if own else EXTERNAL_WINDOW)
    source = iter(jobs)
    inflight = {}
    pool = new_pool(workers, mp_context) if own else None
    ex = pool if own else executor
    exhausted = broken_external = False
    try:
        while True:
            while not exhausted and not broken_external and len(inflight) < window:
                try:
                    job = next(source)
                except StopIteration:
                    exhausted = True
                    break
                inflight[_submit(ex, job)] = job
            if not inflight:
                return
            done, _ = concurrent.futures.wait(list(inflight), return_when=concurrent.futures.FIRST_COMPLETED)
            lost = []
            for fut in [f for f in inflight if f in done]:       # submission order
                job = inflight.pop(fut)
                try:
                    value = fut.result()
                except BrokenProcessPool as exc:
                    if not own:     # not ours to replace: its runs fail, and nothing more can be submitted
                        yield job, [(_tasks.failed_row(t, exc, 0.0), None) for t in job]
                        broken_external = True
                        continue
                    lost.append(job)
                    continue
                except Exception as exc:  # noqa: BLE001 - the executor lost the job: its runs fail, the sweep goes on
                    yield job, [(_tasks.failed_row(t, exc, 0.0), None) for t in job]
                    continue
                yield job, _outcomes(job, value)
            if lost:
                # the pool is broken: every job still in flight is lost with it, unless it finished
                for fut, job in list(inflight.items()):
                    if fut.done() and not fut.cancelled() and fut.exception() is None:
                        yield job, _outcomes(job, fut.result())
                    else:
                        lost.append(job)
                inflight.clear()
                pool.shutdown(wait=True, cancel_futures=True)
                yield from isolated(lost, mp_context, workers)     # each job alone: find the culprit
                pool = ex = new_pool(workers, mp_context)
            if broken_external and not inflight:
                raise RuntimeError("the executor's process pool is broken (a worker process died): the runs in "
                                   "flight are failed rows, the finished rows are kept; run the sweep again with a "
                                   "new executor to resume")
    except KeyboardInterrupt:
        for fut in inflight:
            fut.cancel()
        if own:                                   # our workers ignore SIGINT: let the running runs finish
            try:
                pool.shutdown(wait=True, cancel_futures=True)
            except BaseException:                 # a second Ctrl-C (or SIGTERM): stop at once
                terminate(pool)
                raise
            for fut, job in inflight.items():
                if fut.done() and not fut.cancelled() and fut.exception() is None:
                    yield job, _outcomes(job, fut.result())
        raise
    except BaseException:
        for fut in inflight:
            fut.cancel()
        if own:
            terminate(pool)
        raise
    finally:
        if own and pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)   # the workers have finished or been killed
