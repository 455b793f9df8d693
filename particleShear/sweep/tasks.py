"""What a sweep's worker runs: one task (a picklable dict) or a batch of them, and the publication of the files.

A task is ``{"run_id", "index", "repetition", "parameters", "seed_entropy", "spawn_key", "out_dir",
"scratch_dir", "keep_series"}`` and, for a sweep's or a series' run, ``"checked"``: its point's
:class:`~particleShear.run.validation.CheckedPoint`, from which the worker makes the run's
:class:`~particleShear.run.validation.RunParameters` without validating it again (a task without
it is validated here).  A run writes into its scratch folder
``scratch_dir/<run id>/`` (cleared first: leftovers of a killed attempt); when it has finished,
the worker renames its files into ``out_dir`` under the run id (companions first, the file
itself last, :func:`publish`).  A failing run never raises: it becomes a ``failed`` row, and so
does a run whose file could not be written (``write_error``, e.g. a full disk) — its moduli are
kept in the row and in the result.
"""
__docformat__ = "numpy"
import json
import os
import re
import shutil
import time

import numpy as np

from .._version import __version__
from ..simulation.output import SIDECAR_SUFFIX, run_file_stem
from .table import atomic_text
from ..run import api
from ..run.batch import measure_replicas
from ..run.validation import validated_run

__all__ = ["execute_run", "execute_batch", "failed_row", "publish", "error_text"]


def publish(run_dir, out_dir, produced, run_id):
    """Move a run's files from its scratch folder into ``out_dir``, named ``<stem><run_id>...``.

    ``produced`` is the file the run wrote (``<stem><k>.<ext>``); every entry of the scratch
    folder starting with ``<stem><k>`` (sidecar, image folder) moves with it, the file itself
    last, so a file in ``out_dir`` always has its companions.

    Parameters
    ----------
    run_dir : str
        The run's scratch folder.
    out_dir : str
        The sweep folder.
    produced : str
        Path of the file the run wrote (in ``run_dir``).
    run_id : str
        The run id that replaces the file number.

    Returns
    -------
    str
        The new path of ``produced``.
    """
    base = os.path.basename(produced)
    m = re.match(r"^(.*_)(\d+)(\.[A-Za-z][A-Za-z0-9.]*)$", base)   # <stem><k><.ext>; μ may hold dots
    if m:
        head, new_head = m.group(1) + m.group(2), m.group(1) + run_id
    else:
        head = os.path.splitext(base)[0]
        new_head = head + "_" + run_id
    entries = sorted(e for e in os.listdir(run_dir) if e.startswith(head) and not e.endswith(".part"))
    entries.sort(key=lambda e: e == base)          # the file last
    final = None
    for e in entries:
        target = os.path.join(out_dir, new_head + e[len(head):])
        src = os.path.join(run_dir, e)
        if e == head + SIDECAR_SUFFIX:               # the sidecar names its file: the published name
            _rename_in_sidecar(src, os.path.basename(new_head + base[len(head):]))
        if os.path.islink(target):
            os.remove(target)                          # the link, never what it points to
        elif os.path.isdir(src) and os.path.isdir(target):
            shutil.rmtree(target)
        os.replace(src, target)
        if e == base:
            final = target
    return final


def _rename_in_sidecar(path, name):
    with open(path, encoding="utf-8") as fh:
        meta = json.load(fh)
    meta["file"] = name
    with atomic_text(path) as fh:
        json.dump(meta, fh, indent=1)


def error_text(exc):
    """``"<type>: <message>"`` on one line: every character that is not printable becomes a space.

    A results row is one line of the table; a line break, carriage return or other separator
    (``\\x0b``, U+2028, ...) inside a message must not split it or break the CSV reader.

    Parameters
    ----------
    exc : BaseException

    Returns
    -------
    str
    """
    return "".join(c if c.isprintable() else " " for c in f"{type(exc).__name__}: {exc}")


def failed_row(task, exc, wall):
    """The ``failed`` row of a task: its parameters and seed, ``error`` = ``"<type>: <message>"``.

    Parameters
    ----------
    task : dict
        The task.
    exc : BaseException
        Why it failed.
    wall : float
        Seconds spent (s).

    Returns
    -------
    dict
    """
    row = {"run_id": task["run_id"], "status": "failed", "error": error_text(exc),
           "repetition": int(task.get("repetition", 0))}
    row.update(task["parameters"])
    row.update(seed_entropy=task["seed_entropy"], spawn_key=list(task["spawn_key"]), package_version=__version__,
               wall_time_s=wall, output_path="")
    return row


def execute_run(task):
    """Run one sweep task in the calling process; return ``(row, result or None)``.

    Never raises for a failing simulation: the exception becomes a ``failed`` row.

    Parameters
    ----------
    task : dict
        ``run_id``, ``index``, ``repetition`` (of its point; default 0), ``parameters`` (complete,
        of ``doParticleShearSimulation``),
        ``seed_entropy``, ``spawn_key``, ``out_dir`` (sweep folder; "" writes nothing),
        ``scratch_dir`` (this driving process's scratch folder), ``keep_series`` (bool) and, for a
        sweep's or a series' run, ``checked`` (its point's :class:`~particleShear.run.validation.CheckedPoint`:
        the run is measured without validating it again, :func:`particleShear.run.api.measure_run`).

    Returns
    -------
    tuple
        ``(row, result)``: the results-table row (dict; a list of the rows of a sweep protocol's
        steps) and the SimulationResult, or None
        when the run failed before its moduli were known.
    """
    t0 = time.perf_counter()
    run_dir = None
    try:
        run_dir, run = _prepare(task)
        result = api.measure_run(run)
        return _finish_run(task, result, time.perf_counter() - t0)
    except Exception as exc:  # a failed run is a row, never the end of the sweep
        return failed_row(task, exc, time.perf_counter() - t0), None
    finally:
        if run_dir:
            shutil.rmtree(run_dir, ignore_errors=True)


def _prepare(task):
    """``(run_dir, run)`` of a task: its empty scratch folder ("" when it writes nothing) and its
    :class:`~particleShear.run.validation.RunParameters` (made from the task's checked point, else validated)."""
    p = task["parameters"]
    writes = bool(task["out_dir"]) and bool(p.get("saveData") or p.get("saveOutputImages"))
    run_dir = ""
    if writes:
        run_dir = os.path.join(task.get("scratch_dir") or os.path.join(task["out_dir"], "runs"), task["run_id"])
        shutil.rmtree(run_dir, ignore_errors=True)      # leftovers of a killed attempt of this owner
        os.makedirs(run_dir)
    ss = np.random.SeedSequence(task["seed_entropy"], spawn_key=tuple(task["spawn_key"]))
    checked = task.get("checked")
    if checked is None:      # a task without its checked arguments: validated here
        return run_dir, validated_run(dict(p, root_folder=run_dir, seed=ss, return_result=True, verbose=False))
    # a sweep's run: its point was checked once (the SPEC's check), its id computed by the sweep; a series'
    # run: checked once by the series
    return run_dir, checked.run(run_dir, ss, return_result=True, verbose=False, run_id=task["run_id"])


def _finish_run(task, result, wall_time_s):
    """Publish a finished run's files under its run id; return ``(row, result)``.

    ``row`` is a dict, or the list of the rows of a one-packing sweep (one per step).

    The row's ``output_path`` is relative to the sweep folder (the folder can be moved or
    copied); the result's is absolute.  A run whose file could not be written is a ``failed``
    row naming the write error, its moduli kept.
    """
    result.parameters = dict(task["parameters"])
    result.repetition = int(task.get("repetition", 0))
    if result.output_path:
        run_dir = os.path.dirname(result.output_path)
        image_folder, produced = result.image_folder, result.output_path
        result.output_path = publish(run_dir, task["out_dir"], result.output_path, task["run_id"])
        if image_folder:  # published beside the file: its name after the run's name, renamed as the file
            tail = os.path.basename(image_folder)[len(os.path.basename(run_file_stem(produced))):]
            result.image_folder = run_file_stem(result.output_path) + tail
    rows = result.rows()          # one row, or one per step of a sweep protocol
    if "protocol" in task["parameters"]:   # a table with protocol columns: an oscillatory row says so too
        for row in rows:
            if row.get("protocol") in (None, ""):
                row["protocol"] = task["parameters"]["protocol"] or "oscillatory"
    err = result.write_error
    for row in rows:
        if row["run_id"] != task["run_id"]:  # pragma: no cover - identity must not depend on the process
            raise RuntimeError(f"run id {row['run_id']} differs from the sweep's {task['run_id']}")
        row["output_path"] = os.path.relpath(result.output_path, task["out_dir"]) if result.output_path else ""
        row["wall_time_s"] = wall_time_s
        if err is not None:
            row.update(status="failed", error="write failed: " + error_text(err),
                       output_path="")
    if err is not None:
        rows = rows[:1]          # a failed run has one row (its values kept in the result)
    row = rows[0] if len(rows) == 1 else rows
    if not task.get("keep_series"):
        result.series = {}
    return row, result


def execute_batch(tasks):
    """Run sweep tasks that share a step schedule as one batch of replicas; ``[(row, result), ...]`` in order.

    The replicas are measured together (:func:`particleShear.run.batch.measure_replicas`, the
    measurement of :func:`~particleShear.run.batch.run_batch`; the tasks are one batch of
    :func:`~particleShear.run.batch.batches`, so their schedule is not compared again), each
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
    t0 = time.perf_counter()
    prepared = []
    try:
        prepared = [_prepare(task) for task in tasks]
        results = measure_replicas([run for _, run in prepared])   # grouped by the driving process
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
