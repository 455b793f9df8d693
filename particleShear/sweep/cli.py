"""``python -m particleShear sweep SPEC --out DIR``: run, resume, dry-run or merge a sweep (docs/sweeps.md)."""
__docformat__ = "numpy"
import argparse
import contextlib
import logging
import os
import sys

from ..messages import console_messages

_log = logging.getLogger(__name__)

__all__ = ["main", "build_parser"]


def build_parser():
    """Parser of ``python -m particleShear sweep`` (flags described in docs/sweeps.md).

    Returns
    -------
    argparse.ArgumentParser
        Positional ``SPEC``; ``--out DIR`` (required), ``--workers``, ``--dask``, ``--scheduler``,
        ``--task-index``/``--task-count``, ``--merge``, ``--dry-run``, ``--calibrate``,
        ``--retry-failed``, ``--keep-going``, ``--quiet``, ``--backend``.
    """
    p = argparse.ArgumentParser(prog="particleShear sweep",
                                description="Run (or resume) every run of a sweep SPEC (.toml or .json) into DIR; "
                                            "one row per run in DIR/results.csv.")
    a = p.add_argument
    a("spec", metavar="SPEC", help="sweep specification: tables [parameters], [grid], [[zip]], [seeds]")
    a("--out", metavar="DIR", required=True, help="output folder (created; the same DIR resumes)")
    a("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    a("--batch-size", type=int, default=None, metavar="B",
      help="measure runs of one step schedule (same N, time-step rule, protocol) in batches of up to B "
           "replicas, one task each; rows identical to unbatched runs (default: one task per run)")
    a("--backend", default=None, metavar="NAME",
      help="array backend of every run: numpy, or cupy (a CUDA GPU; needs `pip install cupy-cuda12x`; runs "
           "without drawing); sets the SPEC's backend (default: the SPEC's, numpy)")
    a("--dask", action="store_true", help="run on a dask.distributed LocalCluster of --workers processes")
    a("--scheduler", metavar="ADDRESS", default=None, help="run on an existing Dask cluster (e.g. tcp://host:8786)")
    a("--task-index", type=int, default=None, metavar="I", help="job-array task I (0-based) of --task-count K")
    a("--task-count", type=int, default=None, metavar="K", help="number of job-array tasks sharing the sweep")
    a("--merge", action="store_true", help="merge the per-task tables into DIR/results.csv and exit")
    a("--dry-run", action="store_true", help="print the size and projected cost, run nothing")
    a("--calibrate", action="store_true", help="with --dry-run: time one shortened run here and scale the projection")
    a("--retry-failed", action="store_true", help="run again the runs whose row says failed")
    a("--keep-going", action="store_true", help="exit 0 even when runs failed (default: exit 1)")
    a("--quiet", action="store_true", help="no progress lines")
    return p


def _positive(name, flag, v):
    if v is not None and v < 1:
        raise ValueError(f"{name}={v!r} ({flag}) is invalid: allowed an integer >= 1")


def main(argv=None):
    """Entry point of ``python -m particleShear sweep``.

    Status lines are INFO messages of the logger ``particleShear.sweep.cli``, shown on stdout.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``sweep`` (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 ok, 1 some runs failed (or unfinished after ``--merge``), 2 invalid
        input (message naming the flag on stderr), 130 interrupted.
    """
    args = build_parser().parse_args(argv)
    with console_messages(stream=sys.stdout):
        return _main(args)


def _main(args):
    from .cost import format_cost
    from .runner import Sweep
    try:
        _positive("workers", "--workers", args.workers)
        _positive("batch_size", "--batch-size", args.batch_size)
        if args.dask and args.scheduler:
            raise ValueError("--dask and --scheduler exclude each other: --dask starts a cluster, "
                             "--scheduler joins one")
        sweep = Sweep(args.spec, args.out, task_index=args.task_index, task_count=args.task_count,
                      backend=args.backend)
    except (ValueError, TypeError) as exc:
        print(f"particleShear sweep: invalid input: {exc}", file=sys.stderr)
        return 2
    workers = args.workers or os.cpu_count() or 1
    if args.merge:
        n, missing = sweep.merge()
        _log.info(f"merged {n} rows into {os.path.join(sweep.out_dir, 'results.csv')}; {missing} runs not finished")
        return 0 if missing == 0 else 1
    if args.dry_run:
        _log.info(f"sweep {args.spec}: {sweep.spec.n_points} points x {sweep.spec.repetitions} repetitions")
        all_c, todo_c = sweep.cost(workers), sweep.cost(workers, pending_only=True)
        if args.calibrate:
            from .cost import calibrate
            factor = calibrate(sweep.runs[0].parameters)
            _log.info(f"calibration: a shortened first run took {factor:.2f} x the documented per-step cost")
            for c in (all_c, todo_c):
                c["cpu_s"] *= factor
                c["wall_s"] *= factor
        _log.info("all runs:   " + format_cost(all_c))
        _log.info("still to run: " + format_cost(todo_c))
        return 0
    failed = 0
    with contextlib.ExitStack() as stack:
        executor = None
        if args.dask or args.scheduler:
            try:
                from dask.distributed import Client, LocalCluster
            except ImportError:
                print("particleShear sweep: --dask/--scheduler need dask.distributed: pip install "
                      "'particleShear[dask]'", file=sys.stderr)
                return 2
            if args.scheduler:
                client = stack.enter_context(Client(args.scheduler))
            else:
                cluster = stack.enter_context(LocalCluster(n_workers=workers, threads_per_worker=1,
                                                           processes=True, dashboard_address=None))
                client = stack.enter_context(Client(cluster))
            executor = client.get_executor()
        try:
            for outcome in sweep.as_completed(executor=executor, workers=None if executor else workers,
                                              retry_failed=args.retry_failed, progress=not args.quiet,
                                              batch_size=args.batch_size):
                failed += not outcome.ok
        except KeyboardInterrupt:
            done = len(sweep.finished_rows())
            print(f"\nparticleShear sweep: interrupted; {done} finished rows kept in {sweep.table_path}; "
                  "run the same command again to resume", file=sys.stderr)
            return 130
        except RuntimeError as exc:
            print(f"particleShear sweep: {exc}", file=sys.stderr)
            return 2
    rows = sweep.rows()
    n_failed = sum(r["status"] == "failed" for r in rows)
    _log.info(f"{len(rows)} of {len(sweep.my_runs())} runs finished ({n_failed} failed); table: {sweep.table_path}")
    return 1 if (n_failed and not args.keep_going) else 0
