"""``doParticleShearSimulationSeries`` on the sweep machinery: its runs as a sweep without a SPEC.

With a ``root_folder`` the series is a resumable sweep into it (rows in ``results.csv``, files
named with run ids; no ``sweep.json``, since a series has no SPEC); without one its runs go
through the same worker pool (:func:`~particleShear.sweep.pool.run_jobs`) and write nothing.
"""
__docformat__ = "numpy"
import os

from .pool import pool_context, run_jobs
from .runner import Sweep
from .table import TABLE_NAME, table_columns
from ..run.api import SimulationResult
from ..run.batch import batches
from ..run.rheometer import normalize_protocol
from ..simulation.provenance import run_identity
from .spec import SweepRun, sweep_parameter_defaults, uses_protocols

__all__ = ["run_series", "series_parameters"]


def _from_runs(runs, out_dir):
    """A :class:`Sweep` over an explicit list of SweepRun (used by the series; no SPEC, no record)."""
    sweep = Sweep.__new__(Sweep)
    sweep.spec = None
    sweep.out_dir = os.path.abspath(os.fspath(out_dir))
    sweep.task_index = sweep.task_count = None
    sweep.extend = False
    sweep.runs = list(runs)
    sweep.columns = table_columns(list(sweep.runs[0].parameters) if sweep.runs else None)
    sweep.table_path = os.path.join(sweep.out_dir, TABLE_NAME)
    sweep._run_cache = {}
    return sweep


def _result_from_rows(rows, run, out_dir):
    """A light result of a run finished in an earlier call, from its typed rows (moduli or the protocol's
    values, measures, time scales, parameters, seed, path; no series: :meth:`SimulationResult.from_rows`)."""
    row = rows[0]
    path = os.path.join(out_dir, os.path.basename(row["output_path"])) if row.get("output_path") else None
    result = SimulationResult.from_rows(rows, run.parameters, run.seed_entropy, run.spawn_key, path)
    result.repetition, result.run_id = run.repetition, run.run_id
    return result


def series_parameters(kwargs):
    """The complete parameter set a series records for one run (``SimulationResult.parameters``).

    Every parameter a SPEC may set, defaults filled in, from the run's keyword arguments; the
    folder, seed and console choice of the series are not part of it.  With a protocol parameter
    (docs/protocols.md) the protocol parameters are part of it, and a one-packing sweep's first
    value is put in ``theAmplitude`` (``relative_frequency``), as a sweep does.

    Parameters
    ----------
    kwargs : dict
        Keyword arguments of :func:`~particleShear.doParticleShearSimulation` for the run.

    Returns
    -------
    dict
    """
    given = {n: v for n, v in kwargs.items() if n not in ("root_folder", "seed", "verbose")}
    if not uses_protocols(given):          # the oscillatory series: its table keeps its columns
        return dict(sweep_parameter_defaults(), **given)
    return normalize_protocol(dict(sweep_parameter_defaults(protocols=True), **given))


def run_series(all_kwargs, root_folder="", executor=None, max_workers=None, batch_size=None, repetitions=None,
               checked=None):
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
    repetitions : sequence of int, optional
        ``repetitions[k]``: the repetition of run k (the ``repetition`` column; default 0 each).
    checked : sequence of CheckedPoint, optional
        ``checked[k]``: the checked arguments of run k (:func:`particleShear.run.validation.checked_point`
        of ``all_kwargs[k]``): its worker measures the run from them without validating it again
        (default None: each worker validates its run).

    Returns
    -------
    list of SimulationResult
        In the order of ``all_kwargs``.

    Raises
    ------
    RuntimeError
        If any run failed (after all have finished), naming the first failed run.
    """
    runs = []
    for k, kw in enumerate(all_kwargs):
        ss = kw["seed"]
        params = series_parameters(kw)
        rep = 0 if repetitions is None else int(repetitions[k])
        runs.append(SweepRun(index=k, point=k, repetition=rep, parameters=params, seed_entropy=ss.entropy,
                             spawn_key=tuple(ss.spawn_key), run_id=run_identity(params, ss.entropy, ss.spawn_key),
                             checked=None if checked is None else checked[k]))
    results = [None] * len(runs)
    failures = []
    if root_folder:
        sweep = _from_runs(runs, root_folder)
        done = sweep.finished_rows()
        pos = {r.run_id: i for i, r in enumerate(runs)}
        for i, r in enumerate(runs):
            rows = done.get(r.run_id)
            rows = rows if isinstance(rows, list) or rows is None else [rows]
            if rows and rows[0]["status"] == "ok":
                results[i] = _result_from_rows(rows, r, sweep.out_dir)
        for outcome in sweep.as_completed(executor=executor, workers=max_workers, keep_series=True,
                                          retry_failed=True, progress=False, batch_size=batch_size):
            if outcome.ok:
                results[pos[outcome.run.run_id]] = outcome.result
            else:
                failures.append(outcome.row)
    else:
        tasks = [{"run_id": r.run_id, "index": r.index, "repetition": r.repetition, "parameters": r.parameters,
                  "seed_entropy": r.seed_entropy, "spawn_key": r.spawn_key, "out_dir": "", "keep_series": True,
                  "batched": batch_size is not None, **({} if r.checked is None else {"checked": r.checked})}
                 for r in runs]
        if batch_size is None:
            jobs = [[t] for t in tasks]
        else:
            jobs = [[tasks[i] for i in g] for g in batches([r.parameters for r in runs], batch_size)]
        n_workers = min(max_workers or os.cpu_count() or 1, len(jobs))
        for job, outcomes in run_jobs(jobs, executor=executor, workers=n_workers,
                                      mp_context=pool_context(r.parameters for r in runs) if executor is None
                                      else None):
            for task, (row, result) in zip(job, outcomes):
                results[task["index"]] = result
                row = row[0] if isinstance(row, list) else row
                if row["status"] != "ok":
                    failures.append(row)
    if failures:
        first = failures[0]
        raise RuntimeError(f"{len(failures)} of {len(runs)} runs of the series failed; first: run "
                           f"{first['run_id']} (theAmplitude={first['theAmplitude']}, theMu={first['theMu']}): "
                           f"{first['error']}")
    return results
