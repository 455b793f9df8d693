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
that were in flight are then run again one run at a time, each in a fresh single-worker pool, so
the run that kills its worker is identified and becomes a ``failed`` row ("the worker process
running this run died …") while the others finish normally; the sweep goes on in a fresh pool.
With another executor (Dask, threads, MPI), an exception of the executor for a job (a lost Dask
worker, say) becomes a ``failed`` row of each of its runs.
"""
__docformat__ = "numpy"
import concurrent.futures
import os
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool

from . import tasks as _tasks

__all__ = ["run_jobs", "WorkerDied", "SweepTerminated", "WATCH_INTERVAL_S", "worker_init", "new_pool"]

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


def _watch_parent(parent_pid):
    while os.getppid() == parent_pid:
        time.sleep(WATCH_INTERVAL_S)
    os._exit(1)   # the sweep is gone: stop at once (its scratch folder is removed by the next sweep)


def worker_init(parent_pid):
    """Initializer of the default pool's workers: ignore SIGINT, exit when ``parent_pid`` is gone.

    Parameters
    ----------
    parent_pid : int
        The driving process.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="particleShear-watch").start()


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
    return concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=mp_context,
                                                  initializer=worker_init, initargs=(os.getpid(),))


def _submit(executor, job):
    if len(job) == 1 and not job[0].get("batched"):
        return executor.submit(_tasks.execute_run, job[0])
    return executor.submit(_tasks.execute_batch, job)


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
            p.terminate()
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


def _solo_child(conn, task, parent_pid):
    worker_init(parent_pid)
    conn.send(_tasks.execute_run(task))
    conn.close()


def _solo(task, mp_context):
    """Run one task alone in a fresh worker process; ``(row, result)``, a failed row if the process dies."""
    import multiprocessing
    import multiprocessing.connection
    ctx = mp_context or multiprocessing.get_context()
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_solo_child, args=(send, dict(task, batched=False), os.getpid()), daemon=True)
    t0 = time.perf_counter()
    proc.start()
    send.close()
    try:
        multiprocessing.connection.wait([recv, proc.sentinel])
        try:
            value = recv.recv()
        except (EOFError, OSError):   # the process died before it could answer
            proc.join()
            return _tasks.failed_row(task, WorkerDied(_death_text(proc.exitcode)), time.perf_counter() - t0), None
        proc.join()
        return value
    except BaseException:
        proc.kill()
        proc.join()
        raise
    finally:
        recv.close()


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
    exhausted = False
    try:
        while True:
            while not exhausted and len(inflight) < window:
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
                except BrokenProcessPool:
                    if not own:
                        raise
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
                for job in lost:                                  # one run at a time: find the culprit
                    for task in job:
                        yield [dict(task, batched=False)], [_solo(task, mp_context)]
                pool = ex = new_pool(workers, mp_context)
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
