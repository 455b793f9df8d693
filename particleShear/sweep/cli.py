"""``python -m particleShear sweep SPEC --out DIR``: run, resume, dry-run or merge a sweep (docs/sweeps.md)."""
__docformat__ = "numpy"
import contextlib
import logging
import os
import sys

from ..messages import console_messages
from ..run.guard import SuggestingParser, shorten_values
from ..signals import sigterm_raises
from .calibration import (CALIBRATION_BUDGET_S, cache_path, format_projection, load_or_measure, project_cost,
                          representative_point)
from .cost import format_cost
from .locks import FolderBusyError
from .pool import SweepTerminated
from .runner import Sweep

_log = logging.getLogger(__name__)

__all__ = ["main", "build_parser"]


def build_parser():
    """Parser of ``python -m particleShear sweep`` (flags described in docs/sweeps.md).

    Returns
    -------
    particleShear.run.guard.SuggestingParser
        Positional ``SPEC``; ``--out DIR`` (required), ``--workers``, ``--dask``, ``--scheduler``,
        ``--task-index``/``--task-count``, ``--merge``, ``--dry-run``, ``--calibrate``, ``--no-calibrate``,
        ``--retry-failed``, ``--keep-going``, ``--quiet``, ``--backend``, ``--extend``.
    """
    p = SuggestingParser(prog="particleShear sweep",  # no prefix abbreviations; unknown flags get suggestions
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
      help="array backend of every run: auto (the environment variable PARTICLESHEAR_BACKEND when set, else "
           "numba where Numba can be imported, else numpy), numpy, numba (each step compiled, bit-identical; "
           "`pip install particleShear[fast]`), or cupy (a CUDA GPU; needs `pip install cupy-cuda12x`); "
           "sets the SPEC's backend (default: the SPEC's, auto)")
    a("--dask", action="store_true", help="run on a dask.distributed LocalCluster of --workers processes")
    a("--scheduler", metavar="ADDRESS", default=None, help="run on an existing Dask cluster (e.g. tcp://host:8786)")
    a("--task-index", type=int, default=None, metavar="I", help="job-array task I (0-based) of --task-count K")
    a("--task-count", type=int, default=None, metavar="K", help="number of job-array tasks sharing the sweep")
    a("--merge", action="store_true", help="merge the per-task tables into DIR/results.csv and exit")
    a("--dry-run", action="store_true", help="print the size and projected cost, run nothing")
    a("--calibrate", action="store_true",
      help="with --dry-run: measure the calibration again even when one is cached (default: use the cache)")
    a("--no-calibrate", action="store_true",
      help="with --dry-run: only the static model of documented per-step costs, no timed run here")
    a("--retry-failed", action="store_true", help="run again the runs whose row says failed")
    a("--extend", action="store_true",
      help="DIR holds a sweep of another SPEC: add this SPEC's new runs to it and keep its rows (default: refuse)")
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
        Exit status (:data:`EXIT_STATUS`): 0 ok, 1 some runs failed (or unfinished after
        ``--merge``), 2 invalid input (message naming the flag on stderr), 3 DIR is in use by
        another live sweep, 4 the sweep folder cannot be written (a full disk), 130 interrupted
        (Ctrl-C), 143 terminated (SIGTERM).
    """
    args = build_parser().parse_args(argv)
    with console_messages(stream=sys.stdout), _sigterm_stops_the_sweep():
        return _main(args)


#: the exit statuses of ``particleShear sweep``
EXIT_STATUS = {"ok": 0, "runs failed": 1, "invalid input": 2, "folder busy": 3, "folder not writable": 4,
               "interrupted": 130, "terminated": 143}


def _sigterm_stops_the_sweep():
    """SIGTERM (a scheduler's walltime, ``kill``) stops the sweep at once: workers killed, rows kept, 143."""
    return sigterm_raises(SweepTerminated)


def _check_scheduler(address):
    """``--scheduler ADDRESS`` before any work: dask.distributed importable, ADDRESS a scheduler address."""
    import re
    if not re.match(r"^(tcp|tls|inproc|ucx|ws|wss)://[^\s/:]+(:\d{1,5})?/?$", address or ""):
        raise ValueError(f"scheduler={address!r} (--scheduler) is invalid: allowed a Dask scheduler address such "
                         "as tcp://host:8786")


def _dask_client(args, workers, stack):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ValueError("--dask/--scheduler need dask.distributed: pip install 'particleShear[dask]'") from None
    if args.scheduler:
        return stack.enter_context(Client(args.scheduler, timeout="30s"))
    cluster = stack.enter_context(LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                               dashboard_address=None))
    return stack.enter_context(Client(cluster))


def _main(args):
    try:
        _positive("workers", "--workers", args.workers)
        _positive("batch_size", "--batch-size", args.batch_size)
        if args.dask and args.scheduler:
            raise ValueError("--dask and --scheduler exclude each other: --dask starts a cluster, "
                             "--scheduler joins one")
        if args.scheduler is not None:
            _check_scheduler(args.scheduler)
        if args.dask or args.scheduler:
            import importlib.util
            if importlib.util.find_spec("distributed") is None:
                raise ValueError("--dask/--scheduler need dask.distributed: pip install 'particleShear[dask]'")
        if args.merge and not os.path.isdir(args.out):
            raise ValueError(f"out_dir={args.out!r} (--out) is invalid for --merge: no such folder")
        sweep = Sweep(args.spec, args.out, task_index=args.task_index, task_count=args.task_count,
                      backend=args.backend, extend=args.extend)
    except (ValueError, TypeError) as exc:
        print(f"particleShear sweep: invalid input: {shorten_values(exc)}", file=sys.stderr)
        return 2
    workers = args.workers or os.cpu_count() or 1
    try:
        if args.merge:
            n, missing = sweep.merge()
            _log.info(f"merged {n} rows into {os.path.join(sweep.out_dir, 'results.csv')}; {missing} runs not "
                      "finished")
            for table, why in sweep.kept_tables:
                _log.info(f"kept {table}: {why}")
            return 0 if missing == 0 else 1
        if args.dry_run:
            return _dry_run(args, sweep, workers)
        return _run(args, sweep, workers)
    except ValueError as exc:   # a table or record that cannot be used: refused before any run
        print(f"particleShear sweep: invalid input: {shorten_values(exc)}", file=sys.stderr)
        return 2
    except FolderBusyError as exc:
        print(f"particleShear sweep: {exc}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print(f"\nparticleShear sweep: interrupted; {_kept(sweep, args)}", file=sys.stderr)
        return 130
    except SweepTerminated:
        print(f"particleShear sweep: terminated; {_kept(sweep, args)}", file=sys.stderr)
        return 143
    except OSError as exc:   # the sweep folder itself cannot be written (a full disk, permissions)
        kept = "the rows written so far are kept; " if os.path.isfile(sweep.table_path) else ""
        print(f"particleShear sweep: cannot write the sweep folder {sweep.out_dir}: {exc}; {kept}free the space "
              "and run the same command again to resume", file=sys.stderr)
        return 4


def _kept(sweep, args):
    """What an interrupted sweep leaves: its table when there is one, else that nothing was written."""
    if args.dry_run:
        return "dry run: nothing was written"
    if os.path.isfile(sweep.table_path):
        return f"the rows in {sweep.table_path} are kept; run the same command again to resume"
    return "no run finished, no table written; run the same command again to start"


def _dry_run(args, sweep, workers):
    _log.info(f"sweep {args.spec}: {sweep.spec.n_points} points x {sweep.spec.repetitions} repetitions")
    all_c, todo_c = sweep.cost(workers), sweep.cost(workers, pending_only=True)
    _log.info("all runs:   " + format_cost(all_c) + " [static model]")
    _log.info("still to run: " + format_cost(todo_c) + " [static model]")
    if args.no_calibrate or not hasattr(sweep.runs, "points"):
        return 0
    points = sweep.runs.points
    counts = sweep._point_counts()
    todo = sweep._point_counts(sweep._classify()[0].values())
    p = representative_point(points, counts)
    proto = p.get("protocol") or "oscillatory"
    try:
        cal, cached = load_or_measure(p, refresh=args.calibrate)
    except RuntimeError as exc:
        _log.info(f"calibration failed on the point (N={p['N']}, protocol {proto}): {exc}; no calibrated "
                  "projection (the static model above stands)")
        return 0
    if cal is None:
        _log.info(f"calibration stopped: no shortened run of the point (N={p['N']}, protocol {proto}) finished "
                  f"within the {CALIBRATION_BUDGET_S:g} s budget; no calibrated projection (the static model above "
                  "stands; a run here takes longer than that)")
        return 0
    how = "cached calibration" if cached else "calibration"
    med = {k: sorted(cal[k])[len(cal[k]) // 2] for k in ("per_step_s", "fixed_s", "single_s")}
    if cal.get("batch_s") is not None:
        batch = (f"batch of {cal['replicas']}: {cal['batch_s'] / (cal['replicas'] * med['single_s']):.2f} of a "
                 "single run per run")
    else:
        batch = "no batch measured (a batch counts as single runs)"
    partial = "" if cal.get("complete", True) else \
        f"; partial, stopped at the {cal.get('budget_s', CALIBRATION_BUDGET_S):g} s budget: {cal.get('stopped')}"
    _log.info(f"{how} (point N={p['N']}, protocol {proto}, shortened to {cal['steps']:,} protocol steps, "
              f"{len(cal['per_step_s'])} samples{partial}): {1e6 * med['per_step_s']:.0f} us per step, "
              f"{med['fixed_s']:.2f} s fixed per run; {batch} (cache {cache_path()})")
    for label, c in (("all runs:   ", counts), ("still to run: ", todo)):
        _log.info(label + format_projection(project_cost(points, c, cal, workers=workers,
                                                         batch_size=args.batch_size), workers, args.batch_size))
    return 0


def _run(args, sweep, workers):
    with contextlib.ExitStack() as stack:
        executor = None
        if args.dask or args.scheduler:
            executor = _dask_client(args, workers, stack).get_executor()
        for _ in sweep.as_completed(executor=executor, workers=None if executor else workers,
                                    retry_failed=args.retry_failed, progress=not args.quiet,
                                    batch_size=args.batch_size):
            pass
    rows = sweep.rows()
    status = {}                     # one status per run: a one-packing sweep writes a row per step
    for r in rows:
        status[r["run_id"]] = "failed" if r["status"] == "failed" else status.get(r["run_id"], r["status"])
    n_failed = sum(v == "failed" for v in status.values())
    shown = f", {len(rows)} rows" if len(rows) != len(status) else ""
    _log.info(f"{len(status)} of {len(sweep.my_runs())} runs finished ({n_failed} failed){shown}; table: "
              f"{sweep.table_path}")
    return 1 if (n_failed and not args.keep_going) else 0
