"""Run a sweep: resumable, one results row per finished run, on any ``concurrent.futures.Executor``.

Layout of ``DIR`` (docs/sweeps.md)::

    DIR/sweep.json                          the SPEC of the folder's sweep (canonical form, SHA-256)
    DIR/results.csv                         one row per finished run (ok or failed)
    DIR/results.schema.json                 type, unit and description of every column of the table
    DIR/results.parquet                     the same, typed, when pyarrow is installed (rewritten at the end)
    DIR/<reference stem><run_id>.txt        e.g. dermal_filler0.01_f_3963.3_strain_0.2_nr_3fa9c2e1b0d4.txt
    DIR/runs/<owner>/<run_id>/              scratch folder of a running run of one driving process

A run writes into its scratch folder; when it has finished, the worker renames its files into
``DIR`` (companions first, the file last), then the driving process appends its row.  A run is
finished when its row is in a table, the row is this run's (id, seed, parameters, numbers), and
its file — if it saves one — exists in ``DIR`` and is complete; anything else runs again (and the
sweep says why).  Rows are appended in completion order; when the sweep has finished, the table
is rewritten (atomically, under its lock) in SPEC order, rows of other segments after.  A sweep killed at any moment leaves, at worst, a scratch folder (removed by the
next sweep) and, for the run that was being published, a file without row: the rerun writes the
same file under the same name, so ``DIR`` never holds two files of one run.
"""
__docformat__ = "numpy"
import contextlib
import dataclasses
import itertools
import json
import logging
import os
import re
import sys

import numpy as np

from ..protocols import PROTOCOLS
from .cost import estimate_cost, estimate_point_cost, format_cost
from .locks import FolderBusyError, ScratchOwner, folder_lock, foreign_entries, refuse_links
from .pool import pool_context, run_jobs
from .progress import SweepProgress
from .record import RECORD_NAME, canonical_spec, check_record, extended_runs, read_record, spec_hash, write_record
from .spec import SweepRuns, SweepSpec, load_spec, parse_spec, spec_runs
from .schema import SCHEMA_NAME, typed_row
from .table import (REJECTED_SUFFIX, TABLE_NAME, append_row, check_table, check_table_header, read_rows, reject_lines, row_line,
                    remove_dead_temporaries, row_problem, sort_table, table_columns, task_table_name,
                    write_parquet, write_schema, write_table)
from .tasks import execute_batch, execute_run
from ..run.batch import batches, check_backend
from ..simulation.formats import run_file_identity, verify_run
from ..simulation.output import sidecar_path
from ..simulation.provenance import identity_parameters

__all__ = ["Sweep", "SweepOutcome", "run_sweep", "execute_run", "execute_batch", "SweepProgress", "FolderBusyError"]

_log = logging.getLogger(__name__)
#: the tables of a sweep folder: results.csv and the job-array tasks' results.task-000I-of-000K.csv
_TABLE_NAME = re.compile(r"^results(\.task-\d+-of-\d+)?\.csv$")
#: pending runs grouped into batches at a time (``batch_size``): bounded memory for any sweep size
_BATCH_CHUNK = 4096


@dataclasses.dataclass
class SweepOutcome:
    """A finished run: its :class:`~particleShear.sweep.spec.SweepRun`, its table row(s), and its result.

    Parameters
    ----------
    run : SweepRun
        The run (parameters, seed, run id).
    row : dict
        Its row of ``results.csv`` (status ``ok`` or ``failed``, moduli in Pa, parameters, ...),
        values typed as the worker produced them (floats, ints, bools, the spawn key a list);
        the first step's row for a one-packing sweep.
    result : SimulationResult or None, optional
        The :class:`~particleShear.run.api.SimulationResult` (of any protocol; None for a
        failed run); its per-step ``series`` are kept only with ``keep_series=True``.
    rows : list of dict, optional
        Every row of the run: one per step of a one-packing sweep (``sweep_position`` 0, 1, ...),
        else ``[row]`` (the default).
    """

    run: object
    row: dict
    result: object = None
    rows: list = None

    def __post_init__(self):
        if self.rows is None:
            self.rows = [self.row]

    @property
    def ok(self):
        """True when the run succeeded (``row["status"] == "ok"``)."""
        return self.row["status"] == "ok"


def _n_rows(run):
    """Rows of an ``ok`` run in the table: one per step of a one-packing sweep, else one."""
    n_rows = PROTOCOLS[run.parameters.get("protocol", "oscillatory")].n_rows
    return 1 if n_rows is None else n_rows(run.parameters)


def _flat(items):
    """The rows of ``(run, row or [rows])`` items, in order."""
    return [r for _, row in items for r in (row if isinstance(row, list) else [row])]


def _spec_doc(spec):
    """The SPEC as a document of its tables (original types), for the folder's record."""
    return {"parameters": dict(spec.parameters), "grid": {k: list(v) for k, v in spec.grid.items()},
            "zip": [{k: list(v) for k, v in g.items()} for g in spec.zips],
            "seeds": {"root": spec.root, "repetitions": spec.repetitions}}


def _run_key(run):
    """What makes two runs of a folder's segments one run (:func:`~.record.extended_runs`)."""
    return json.dumps(identity_parameters(run.parameters), sort_keys=True), run.repetition, run.seed_entropy


class _Share:
    """The runs ``k`` with ``k % count == index`` of a sequence of runs, as a lazy sequence."""

    def __init__(self, runs, index, count):
        self.runs, self.index, self.count = runs, index, count

    def __len__(self):
        n = len(self.runs)
        return 0 if self.index >= n else (n - 1 - self.index) // self.count + 1

    def __getitem__(self, j):
        if not 0 <= j < len(self):
            raise IndexError(j)
        return self.runs[self.index + j * self.count]

    def __iter__(self):
        return (self.runs[k] for k in range(self.index, len(self.runs), self.count))


class Sweep:
    """A sweep of ``spec`` into the folder ``out_dir``, every run validated on construction.

    Parameters
    ----------
    spec : str, os.PathLike, dict or SweepSpec
        A SPEC file (.toml/.json), its parsed dict, or a :class:`SweepSpec`.
    out_dir : str
        Output folder (created when the sweep first runs).  A folder keeps the SPEC it was made
        with (``DIR/sweep.json``): another SPEC is refused, naming what changed, unless ``extend``.
    task_index, task_count : int, optional
        Job-array share: this process runs the runs with ``index % task_count == task_index``
        and writes its rows to its own table, merged later by :meth:`merge`.
    backend : str, optional
        Array backend of every run (``--backend``), set as the SPEC's ``[parameters] backend``:
        "numpy", "numba", "auto" or "cupy" (a CUDA GPU).  It is part of each run's
        identity, so a sweep measured on the GPU does not resume the rows of a NumPy sweep.
        Default: the SPEC's (``"numpy"`` unless it sets one).
    extend : bool, optional
        ``--extend``: when ``out_dir`` holds a sweep of another SPEC, add this SPEC's new runs to
        it and keep its rows (docs/sweeps.md, "One folder, one sweep"); default False: refuse.

    Raises
    ------
    ValueError
        An invalid SPEC, run or option, or a folder of another SPEC — before any work.
    """

    def __init__(self, spec, out_dir, *, task_index=None, task_count=None, backend=None, extend=False):
        if isinstance(spec, SweepSpec):
            self.spec = spec
        elif isinstance(spec, dict):
            self.spec = parse_spec(spec)
        else:
            self.spec = load_spec(spec)
        if backend is not None:
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
        if not isinstance(extend, bool):
            raise ValueError(f"extend={extend!r} (--extend) is invalid: allowed True or False")
        if not isinstance(out_dir, (str, os.PathLike)) or not os.fspath(out_dir):
            raise ValueError(f"out_dir={out_dir!r} (--out) is invalid: allowed a folder path")
        self.out_dir = os.path.abspath(os.fspath(out_dir))
        if os.path.exists(self.out_dir) and not os.path.isdir(self.out_dir):
            raise ValueError(f"out_dir={out_dir!r} (--out) is invalid: it is a file")
        self.task_index, self.task_count, self.extend = task_index, task_count, extend
        self._own = spec_runs(self.spec)               # validates every point before any work
        self._canonical = canonical_spec(self.spec)
        self._load_runs()
        self.columns = table_columns(list(self.runs[0].parameters) if len(self.runs) else None)
        name = TABLE_NAME if task_count is None else task_table_name(task_index, task_count)
        self.table_path = os.path.join(self.out_dir, name)

    def _load_runs(self):
        """The folder's segments (its record, this SPEC checked against it) and the runs they make."""
        self._segments = self._check_folder()
        self._run_cache = {}
        self._order = None
        if len(self._segments) == 1:
            self.runs = self._own
            return
        me = spec_hash(self._canonical)              # an extended folder: the runs of every segment
        specs = [self.spec if spec_hash(seg["spec"]) == me else parse_spec(seg["doc"]) for seg in self._segments]
        self.runs = extended_runs(specs, [self._own if s is self.spec else spec_runs(s) for s in specs])
        # the folder's run id of each run of this SPEC -> its position in this SPEC (the table's order)
        folder_id = {_run_key(r): r.run_id for r in self.runs}
        self._order = {folder_id[_run_key(r)]: j for j, r in enumerate(self._own) if _run_key(r) in folder_id}

    def _check_folder(self):
        """The folder's segments (dicts ``spec``, ``doc``) with this SPEC last; refuse another SPEC."""
        rec = read_record(self.out_dir) if os.path.isdir(self.out_dir) else None
        mine = {"spec": self._canonical, "doc": _spec_doc(self.spec)}
        if rec is None:
            return [mine]
        segments = [{"spec": s["spec"], "doc": s.get("doc")} for s in rec["segments"]]
        if check_record(self.out_dir, [seg["spec"] for seg in segments], self._canonical, self.extend):
            return segments + [mine]
        return segments

    def _record(self):
        """Write the folder's record when it is new or extended, under the record's own lock.

        Processes with different tables (job-array tasks) share the record, so it has a lock of
        its own; when another process recorded or extended it since this sweep was made, the
        segments and runs are made again from what is there now (or the SPEC is refused).
        """
        with folder_lock(os.path.join(self.out_dir, RECORD_NAME), wait_s=30.0):
            rec = read_record(self.out_dir)
            seen = [spec_hash(seg["spec"]) for seg in self._segments]
            if rec is not None and [s["sha256"] for s in rec["segments"]] == seen:
                return
            if rec is not None and [s["sha256"] for s in rec["segments"]] != seen[:len(rec["segments"])]:
                self._load_runs()           # recorded or extended meanwhile by another process
                if [s["sha256"] for s in rec["segments"]] == [spec_hash(seg["spec"]) for seg in self._segments]:
                    return
            write_record(self.out_dir, [seg["spec"] for seg in self._segments],
                         docs=[seg["doc"] for seg in self._segments])

    # -- state ---------------------------------------------------------------------------------
    def my_runs(self):
        """The runs of this process (all, or this task's share), a sequence in sweep order."""
        if self.task_count is None:
            return self.runs
        return _Share(self.runs, self.task_index, self.task_count)

    def _tables(self):
        if not os.path.isdir(self.out_dir):
            return []
        return sorted(os.path.join(self.out_dir, e) for e in os.listdir(self.out_dir) if _TABLE_NAME.match(e))

    def _written_paths(self):
        """Every fixed path a sweep writes, replaces or cleans in ``DIR``: none may be a symbolic link."""
        out = self.out_dir
        tables = {self.table_path, os.path.join(out, TABLE_NAME)} | set(self._tables())
        paths = [os.path.join(out, "runs"), os.path.join(out, RECORD_NAME), os.path.join(out, RECORD_NAME + ".lock"),
                 os.path.join(out, SCHEMA_NAME), os.path.join(out, "results.parquet"),
                 os.path.join(out, ".results.parquet.part")]
        for t in sorted(tables):
            paths += [t, t + ".lock", t + REJECTED_SUFFIX]
        return paths

    def _run_of(self, row):
        """The run of this sweep that ``row`` claims to be (by its spawn key and id), or None."""
        rid = row.get("run_id")
        if not isinstance(self.runs, SweepRuns):
            if not self._run_cache:
                self._run_cache = {r.run_id: r for r in self.runs}
            return self._run_cache.get(rid)
        try:
            key = json.loads(row.get("spawn_key") or "")
            k = key[0] if isinstance(key, list) and len(key) == 1 else None
        except (ValueError, TypeError):
            return None
        if isinstance(k, bool) or not isinstance(k, int) or not 0 <= k < len(self.runs):
            return None
        run = self.runs[k]                 # made again (not kept): memory stays that of the points
        return run if run.run_id == rid else None

    def _file_problem(self, row, run=None):
        """Why the file of an ok row cannot be trusted (None when it is this run's, there and complete).

        The file and its sidecar must be regular files in ``DIR`` (not symbolic links), the
        sidecar must be there, and both the sidecar and the file's own header must name this run
        (run id, seed): a file copied from another run is refused with or without its sidecar.
        """
        path = row.get("output_path") or ""
        if not path:
            return "its row names no file"
        name = os.path.basename(path)
        full = os.path.join(self.out_dir, name)   # always in DIR, never elsewhere
        side = sidecar_path(full)
        for p in (full, side, full + ".json"):
            if os.path.islink(p):
                return f"{os.path.basename(p)} is a symbolic link (to {os.readlink(p)}), not a file of this sweep"
        if not os.path.isfile(full):
            return f"its file {name} is missing"
        try:
            meta = verify_run(full)
            header = run_file_identity(full)
        except ValueError as exc:
            return str(exc)
        if meta.get("run_id") not in (None, row.get("run_id")):
            return f"its file {name} is the file of run {meta.get('run_id')} (its sidecar says)"
        if header.get("run_id") not in (None, row.get("run_id")):
            return f"its file {name} is the file of run {header['run_id']} (its header says)"
        if run is not None:
            seed = {"seed_entropy": str(run.seed_entropy),
                    "spawn_key": "[" + ",".join(str(int(k)) for k in run.spawn_key) + "]"}
            for key, want in seed.items():
                if header.get(key) not in (None, want):
                    return f"its file {name} has the seed of another run ({key} {header[key]}, not {want})"
        if not (os.path.isfile(side) or os.path.isfile(full + ".json")):   # <stem>.json, or an older <file>.json
            return f"its file {name} has no sidecar {os.path.basename(side)}: it cannot be verified"
        return None

    def _classify(self, retry_failed=False):
        """``(done, distrusted)``: ``{run_id: (run, row)}`` finished, ``{run_id: (run, reason)}`` to run again.

        ``row`` is the list of a one-packing sweep's rows (one per step; the run counts only when
        every step has its row).  An ``ok`` row that is trustworthy (:func:`~.table.row_problem`, file verified) wins over
        any other row of the run, in any table; a ``failed`` row counts (unless ``retry_failed``)
        when the run has no ``ok`` row to distrust.
        """
        ok, failed, distrust, steps = {}, {}, {}, {}
        for path in self._tables():
            for row in read_rows(path):
                run = self._run_of(row)
                if run is None:
                    continue
                rid = run.run_id
                problem = row_problem(row, run)
                if problem is None and row["status"] == "ok" and run.parameters.get("saveData"):
                    problem = self._file_problem(row, run)
                if problem is not None:
                    if row.get("status") == "ok" or rid not in distrust:
                        distrust[rid] = (run, problem)
                    continue
                if row["status"] != "ok":
                    failed.setdefault(rid, (run, row))
                elif _n_rows(run) == 1:
                    ok.setdefault(rid, (run, row))
                else:                               # a step of a one-packing sweep
                    steps.setdefault(rid, (run, {}))[1].setdefault(int(row["sweep_position"]), row)
        for rid, (run, got) in steps.items():
            n = _n_rows(run)
            if sorted(got) == list(range(n)):
                ok.setdefault(rid, (run, [got[k] for k in range(n)]))
            elif rid not in ok:
                distrust[rid] = (run, f"rows of {len(got)} of its {n} sweep steps (positions {sorted(got)})")
        done = dict(ok)
        for rid, item in failed.items():
            if rid not in done and rid not in distrust and not retry_failed:
                done[rid] = item
        return done, {rid: v for rid, v in distrust.items() if rid not in ok}

    def finished_rows(self, retry_failed=False):
        """``{run_id: row}`` of this sweep's finished runs, over all tables of ``out_dir``.

        Parameters
        ----------
        retry_failed : bool, optional
            True: rows with status ``failed`` do not count as finished (default False).

        Returns
        -------
        dict
            Run id → row, typed as in :meth:`rows` (the list of its rows for a one-packing sweep
            that finished).
        """
        done, _ = self._classify(retry_failed)
        return {rid: [typed_row(r) for r in row] if isinstance(row, list) else typed_row(row)
                for rid, (_, row) in done.items()}

    def _mine(self, run):
        return self.task_count is None or run.index % self.task_count == self.task_index

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
        done, _ = self._classify(retry_failed)
        return [r for r in self.my_runs() if r.run_id not in done]

    def _point_counts(self, done=()):
        """Runs per point of this process's share, less the runs in ``done`` (single-SPEC sweeps)."""
        n_points = len(self.runs.points)
        if self.task_count is None:
            counts = np.full(n_points, self.runs.repetitions, dtype=np.int64)
        else:
            counts = np.zeros(n_points, dtype=np.int64)
            step = self.task_count * 1_000_000
            for a in range(self.task_index, len(self.runs), step):   # chunks: bounded memory
                counts += np.bincount(np.arange(a, min(a + step, len(self.runs)), self.task_count) % n_points,
                                      minlength=n_points)
        for run, _ in done:
            if self._mine(run):
                counts[run.point] -= 1
        return counts

    def cost(self, workers=1, pending_only=False):
        """:func:`~particleShear.sweep.cost.estimate_cost` of the (pending) runs, without enumerating them.

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
        done = self._classify()[0].values() if pending_only else ()
        if isinstance(self.runs, SweepRuns):
            return estimate_point_cost(self.runs.points, self._point_counts(done), workers)
        ids = {rid for rid in (r.run_id for r, _ in done)}
        return estimate_cost([r for r in self.my_runs() if r.run_id not in ids], workers)

    # -- running -------------------------------------------------------------------------------
    def _task(self, run, keep_series, scratch_dir, batched=False):
        task = {"run_id": run.run_id, "index": run.index, "repetition": run.repetition, "parameters": run.parameters,
                "seed_entropy": run.seed_entropy, "spawn_key": run.spawn_key, "out_dir": self.out_dir,
                "scratch_dir": scratch_dir, "keep_series": bool(keep_series), "batched": batched}
        if run.checked is not None:     # its point was checked: the worker does not validate it again
            task["checked"] = run.checked
        return task

    def _jobs(self, todo, keep_series, scratch_dir, batch_size, in_flight):
        """Jobs (lists of tasks) of the pending runs ``todo`` (an iterator), one run or one batch each.

        Each job's runs are put in ``in_flight`` (run index -> run) until their outcome is recorded.
        """
        if batch_size is None:
            for r in todo:
                in_flight[r.index] = r
                yield [self._task(r, keep_series, scratch_dir)]
            return
        while True:
            chunk = list(itertools.islice(todo, _BATCH_CHUNK))
            if not chunk:
                return
            for g in batches([r.parameters for r in chunk], batch_size):
                in_flight.update((chunk[i].index, chunk[i]) for i in g)
                yield [self._task(chunk[i], keep_series, scratch_dir, batched=True) for i in g]

    def _say(self, stream, progress, text):
        if progress is True:
            stream.write(f"[sweep] {text}\n")
            stream.flush()
        else:
            _log.warning(text)

    def as_completed(self, executor=None, workers=None, keep_series=False, retry_failed=False, progress=True,
                     stream=None, batch_size=None):
        """Run the pending runs; yield a :class:`SweepOutcome` per run as it finishes (completion order).

        Each row is appended to the table (fsynced) before it is yielded.  The table is checked
        (and repaired where it can be) and every finished row verified before any run starts;
        rows that cannot be trusted are said and their runs run again.  On KeyboardInterrupt the
        queued runs are cancelled and the interrupt propagates; the rows written so far are
        kept and a rerun resumes.

        Parameters
        ----------
        executor : concurrent.futures.Executor, optional
            Where the runs execute (not shut down here; e.g. a Dask client's executor);
            default a process pool of ``workers`` owned by this call, whose workers end with
            the driving process (:mod:`particleShear.sweep.pool`).
        workers : int, optional
            Processes of the default executor (≥ 1, ``--workers``; default: all cores; never
            more than there are pending runs).
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
            If ``workers`` or ``batch_size`` is not an integer ≥ 1, or a table cannot be used
            (before any run starts).
        FolderBusyError
            When another live sweep writes the same table.
        """
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
            raise ValueError(f"workers={workers!r} (--workers) is invalid: allowed an integer >= 1")
        if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int)
                                       or batch_size < 1):
            raise ValueError(f"batch_size={batch_size!r} (--batch-size) is invalid: allowed an integer >= 1")
        stream = stream if stream is not None else sys.stderr
        os.makedirs(self.out_dir, exist_ok=True)
        refuse_links(self._written_paths())
        with folder_lock(self.table_path):
            remove_dead_temporaries(self.out_dir)
            for note in self._check_tables(self.table_path):
                self._say(stream, progress, "repaired: " + note)
            foreign = foreign_entries(os.path.join(self.out_dir, "runs"))
            if foreign:
                shown = ", ".join(repr(n) for n in foreign[:10]) + (f" and {len(foreign) - 10} more"
                                                                   if len(foreign) > 10 else "")
                self._say(stream, progress, f"left alone in {os.path.join(self.out_dir, 'runs')}: {shown} (not "
                                            "made by a sweep; a sweep removes only its own scratch folders)")
            if self.spec is not None:
                self._record()
            write_schema(self.out_dir, self.columns)
            done, distrust = self._classify(retry_failed)
            for rid, (_, why) in sorted(distrust.items()):
                self._say(stream, progress, f"run {rid} runs again: {why}")
            rows = read_rows(self.table_path)
            retried = {row.get("run_id") for row in rows if row.get("status") == "failed"
                       and row.get("run_id") not in done and self._run_of(row) is not None}
            # duplicate rows (same run id and step) were set aside by _check_tables (table.check_table)
            stale = [row for row in rows if row.get("run_id") in distrust]
            if stale or retried:   # distrusted rows set aside, retried failures go
                reject_lines(self.table_path, [row_line(row, self.columns) for row in stale])
                write_table(self.table_path, [r for r in rows if r.get("run_id") not in distrust
                                              and r.get("run_id") not in retried], self.columns)
            mine = self.my_runs()
            n_mine = len(mine)
            n_todo = n_mine - sum(1 for run, _ in done.values() if self._mine(run))
            if progress is True:
                c = self._pending_cost(done, workers or os.cpu_count())
                stream.write(f"[sweep] {n_mine} runs in this share, {n_mine - n_todo} already finished; "
                             f"to run: {format_cost(c)}\n")
                stream.flush()
                show = SweepProgress(n_mine, n_mine - n_todo, stream,
                                     workers=None if executor is not None else min(workers or os.cpu_count() or 1,
                                                                                    max(n_todo, 1)))
            else:
                show = progress if callable(progress) else None
            try:
                if n_todo:
                    yield from self._execute((r for r in mine if r.run_id not in done), n_todo, executor, workers,
                                             keep_series, batch_size, show)
            finally:
                if show is not None and hasattr(show, "close"):
                    show.close()
            self._finish()

    def _pending_cost(self, done, workers):
        if isinstance(self.runs, SweepRuns):
            return estimate_point_cost(self.runs.points, self._point_counts(done.values()), workers)
        return estimate_cost([r for r in self.my_runs() if r.run_id not in done], workers)

    def _check_tables(self, own):
        """Check every table of the folder before any work: repair ``own`` (notes), refuse another header."""
        notes = check_table(own, self.columns)
        for t in self._tables():
            if t != own:
                check_table_header(t, self.columns)
        return notes

    def _execute(self, todo, n_todo, executor, workers, keep_series, batch_size, show):
        """Run the pending runs; append each row, then yield its outcome.

        An interrupt (Ctrl-C) raised while an outcome is being recorded or handled by the caller
        (outside :func:`~.pool.run_jobs`) is passed into it, so that the running runs finish and
        their rows are kept, as for an interrupt during the wait; the same when the caller stops
        iterating (the generator is closed).
        """
        owner = ScratchOwner(self.out_dir)
        points = self.runs.points if isinstance(self.runs, SweepRuns) else [r.parameters for r in self.runs]
        in_flight = {}      # the runs of the jobs submitted and not yet recorded (bounded by the pool's window)
        jobs = run_jobs(self._jobs(todo, keep_series, owner.path, batch_size, in_flight), executor=executor,
                        workers=min(workers or os.cpu_count() or 1, n_todo),
                        mp_context=pool_context(points) if executor is None else None)

        def record(item):
            job, outcomes = item
            done = []
            for task, (row, result) in zip(job, outcomes):
                rows = row if isinstance(row, list) else [row]
                append_row(self.table_path, rows, self.columns, checked=True)   # checked when opened
                run = in_flight.pop(task["index"])
                outcome = SweepOutcome(run, rows[0], result, rows)
                if show is not None:
                    show(outcome)
                done.append(outcome)
            return done

        try:
            interrupt = None
            while True:
                try:
                    item = next(jobs) if interrupt is None else jobs.throw(interrupt)
                except StopIteration:
                    return
                interrupt = None
                try:
                    for outcome in record(item):
                        yield outcome
                except KeyboardInterrupt as exc:    # in our code or the caller's: let the runs finish
                    interrupt = exc
        except GeneratorExit:                       # the caller stopped (break, Ctrl-C in its loop)
            try:
                item = jobs.throw(KeyboardInterrupt())
                while True:
                    record(item)
                    item = next(jobs)
            except (KeyboardInterrupt, StopIteration):
                pass
            raise
        finally:
            jobs.close()
            owner.close()

    def _finish(self):
        """End of a sweep, under the table lock: the table in SPEC order, the Parquet copy, no scratch root."""
        with contextlib.suppress(OSError):
            os.rmdir(os.path.join(self.out_dir, "runs"))   # only when empty
        sort_table(self.table_path, self.columns, self._spec_index)
        if self.task_count is None:
            write_parquet(self.table_path)

    def _spec_index(self, row):
        """The position of ``row``'s run in this SPEC (None for a row of another segment or of no run)."""
        order = getattr(self, "_order", None)
        if order is not None:                    # an extended folder: this SPEC's runs, in its order
            return order.get(row.get("run_id"))
        run = self._run_of(row)                  # one SPEC (or a series): the run's index
        return None if run is None else run.index

    def run(self, **kwargs):
        """Run the pending runs; return every finished row in sweep order.

        Parameters
        ----------
        **kwargs
            The options of :meth:`as_completed` (``executor``, ``workers``, ``keep_series``,
            ``retry_failed``, ``progress``, ``stream``, ``batch_size``).

        Returns
        -------
        list of dict
            As :meth:`rows`.
        """
        for _ in self.as_completed(**kwargs):
            pass
        return self.rows()

    def rows(self):
        """Finished rows of this sweep in sweep order, typed by the table's schema.

        Returns
        -------
        list of dict
            One dict per finished run (one per step of a one-packing sweep; column → value): moduli and measures float (None where
            empty), ``N``, ``repetition``, ``N_steps`` int, flags bool (``steady_state`` None
            when it cannot be judged), ``seed_entropy`` int, ``spawn_key`` a list of int,
            strings as strings (:mod:`particleShear.sweep.schema`).
        """
        done, _ = self._classify()
        return [typed_row(row) for row in _flat(sorted(done.values(), key=lambda item: item[0].index))]

    def merge(self):
        """Merge every table of ``out_dir`` into ``results.csv`` (one row per run, sweep order, others after).

        Each run's trustworthy ``ok`` row is preferred over any ``failed`` row, in whichever table
        it is.  Rows of other sweeps in ``results.csv`` are kept.  A task table is removed only
        when every row of it is merged (and its task is not running); otherwise it is kept and
        named in :attr:`kept_tables`.

        Returns
        -------
        tuple of int
            ``(n_rows, n_missing)``: rows of this sweep written (one per step of a one-packing
            sweep), runs not finished yet.

        Raises
        ------
        ValueError
            When ``out_dir`` holds no results table (nothing to merge) — before any work.
        """
        path = os.path.join(self.out_dir, TABLE_NAME)
        tables = self._tables()
        if not tables:
            raise ValueError(f"out_dir={self.out_dir!r} (--out) holds no results table to merge")
        self.kept_tables = []
        refuse_links(self._written_paths())
        with folder_lock(path):
            self._check_tables(path)
            write_schema(self.out_dir, self.columns)
            done, _ = self._classify()
            ours = _flat(sorted(done.values(), key=lambda item: item[0].index))
            merged = set(done)
            others = [row for row in read_rows(path) if row.get("run_id") not in merged]   # kept, never dropped
            write_table(path, ours + others, self.columns)
            for t in tables:
                if t == path:
                    continue
                try:
                    with folder_lock(t, wait_s=0):     # the task is not running: its table is final
                        unmerged = [row for row in read_rows(t) if row.get("run_id") not in merged]
                        if unmerged:
                            self.kept_tables.append((t, f"{len(unmerged)} row(s) not merged"))
                        else:
                            os.remove(t)
                except FolderBusyError:
                    self.kept_tables.append((t, "its task is still running"))
            write_parquet(path)
        return len(ours), len(self.my_runs()) - len(done)


def run_sweep(spec, out_dir, *, executor=None, workers=None, task_index=None, task_count=None, keep_series=False,
              retry_failed=False, progress=True, stream=None, batch_size=None, extend=False):
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
    extend : bool, optional
        When ``out_dir`` holds a sweep of another SPEC: add this SPEC's new runs and keep the
        folder's rows (``--extend``); default False refuses (see :class:`Sweep`).

    Returns
    -------
    list of dict
        The finished rows in sweep order, typed (:meth:`Sweep.rows`: floats, ints, bools, the
        spawn key a list; :mod:`particleShear.sweep.schema`).

    Raises
    ------
    ValueError
        An invalid SPEC or run (naming the parameter), before any run starts.
    """
    return Sweep(spec, out_dir, task_index=task_index, task_count=task_count, extend=extend).run(
        executor=executor, workers=workers, keep_series=keep_series, retry_failed=retry_failed,
        progress=progress, stream=stream, batch_size=batch_size)
