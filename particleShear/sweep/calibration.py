"""Projected wall time of a sweep calibrated on this machine (``--dry-run``, docs/sweeps.md).

:func:`measure_calibration` times a representative point of the sweep here: the same run cut
to a few hundred protocol steps at two lengths (their difference is the cost per step, the rest
the fixed cost of a run: constitution, pre-equilibration, files), repeated for a spread, and a
batch of a few replicas of the longer one (the per-run cost of a batch against a single run).
:func:`load_or_measure` keeps the result in a JSON cache per host, package version and
calibrated configuration (:func:`calibration_key`, :func:`cache_path`).
:func:`project_cost` scales the calibration to every point (its protocol steps; its N by the
shape of the documented per-step costs of :mod:`.cost`), to batches of ``batch_size`` runs and
to ``workers`` processes on the cores of this machine, and returns the range.
"""
__docformat__ = "numpy"
import hashlib
import json
import math
import os
import socket
import tempfile
import time
import warnings

from .._version import __version__
from ..protocols import PROTOCOLS
from .cost import _constitution_seconds, _human_s, _step_seconds, cost_backend, run_seconds, run_steps
from ..analysis.measures import MeasurementWarning
from ..run.api import doParticleShearSimulation
from ..run.batch import run_batch, schedule_key
from ..run.rheometer import PROTOCOL_DEFAULTS, normalize_protocol, protocol_steps

__all__ = ["cache_path", "calibration_key", "measure_calibration", "load_or_measure", "project_cost",
           "format_projection", "representative_point", "MIN_SPREAD", "CALIBRATION_BUDGET_S"]

#: smallest relative half-width of the printed range (the scatter of a shared machine between runs)
MIN_SPREAD = 0.3
#: wall-clock budget (s) of one calibration, whatever the SPEC: with the SPEC's own checks, a dry run
#: stays under a minute
CALIBRATION_BUDGET_S = 40.0
#: parameters of a point that decide its calibration (the rest does not change the cost per step)
_KEY_PARAMETERS = ("N", "bimodal_factor", "packing_fraction", "theMu", "do_permanent_links", "cut_lines",
                   "saveData", "saveStressTensorData", "file_format", "integrator", "backend",
                   "relative_transversal_link_strength", "theAmplitude", "relative_viscosity", "time_step_factor",
                   "protocol")


def cache_path():
    """Path of the calibration cache: ``$PARTICLESHEAR_CACHE_DIR/calibration.json``, else the user's cache dir.

    Returns
    -------
    str
        ``$PARTICLESHEAR_CACHE_DIR``, ``$XDG_CACHE_HOME/particleShear`` or ``~/.cache/particleShear``,
        joined with ``calibration.json``.
    """
    base = os.environ.get("PARTICLESHEAR_CACHE_DIR")
    if not base:
        base = os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
                            "particleShear")
    return os.path.join(base, "calibration.json")


def calibration_key(p, steps, replicas, host=None, version=None):
    """Cache key of a calibration: host, package version and the calibrated configuration.

    Parameters
    ----------
    p : dict
        Complete parameters of the calibrated point.
    steps : int
        Protocol steps of the longer calibration run.
    replicas : int
        Replicas of the calibration batch.
    host : str, optional
        Host name (default ``socket.gethostname()``).
    version : str, optional
        Package version (default ``particleShear.__version__``).

    Returns
    -------
    str
        ``"host|version|<16 hex digits of SHA-256 over the configuration>"``.
    """
    if host is None:
        host = socket.gethostname()
    if version is None:
        version = __version__
    config = {k: repr(p.get(k)) for k in _KEY_PARAMETERS}
    config.update(steps=int(steps), replicas=int(replicas))
    digest = hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:16]
    return f"{host}|{version}|{digest}"


def representative_point(points, counts):
    """The point of the largest total projected cost (static model), the one a calibration times.

    Parameters
    ----------
    points : sequence of dict
        Complete parameters of each point.
    counts : sequence of int
        Runs of each point.

    Returns
    -------
    dict
        One of ``points`` (the first one when every count is 0).
    """
    best, best_cost = points[0], -1.0
    for p, n in zip(points, counts):
        c = int(n) * run_seconds(p)
        if c > best_cost:
            best, best_cost = p, c
    return best


def _shortened(p, steps, root):
    """``p`` with its protocol cut to about ``steps`` steps (never longer than its own), output to ``root``.

    "oscillatory": no baseline periods and at most ``steps`` steps of excitation; another protocol
    by its ``shorten`` (:mod:`particleShear.protocols`: a steady run's strain of ``steps`` steps at
    its rate; a relaxation's ramp kept and its hold cut; a creep's hold cut; a sweep's first two
    values, no baseline periods, its excitation periods cut so that both steps together take about
    ``steps`` steps), kept as it is when it has none.
    """
    proto = p.get("protocol") or "oscillatory"
    view = dict(doDrawing=False, plotStress=False, saveOutputImages=False, root_folder=root, verbose=False)
    if proto == "oscillatory":
        per_period = max(1, run_steps(dict(p, pre_periods=0, periods=1, post_periods=0)))
        return dict(p, pre_periods=0, post_periods=0, periods=min(float(p["periods"]), steps / per_period), **view)
    shorten = PROTOCOLS[proto].shorten
    if shorten is None:
        return dict(p, **view)
    q = normalize_protocol({**PROTOCOL_DEFAULTS, "time_step_factor": 1.0, **p})
    return dict(p, **shorten(q, protocol_steps(q), steps, lambda q2: protocol_steps(normalize_protocol(q2))), **view)


def _calibration_runs(run):
    """``run`` with the :class:`~particleShear.analysis.measures.MeasurementWarning` of its arguments silenced.

    The calibration's runs are shortened by the calibration (:func:`_shortened`: a fraction of
    a period, no baseline): a warning about those values would name values the user never set.
    The user's own values were checked, and warned about, when the sweep was expanded.
    """

    def quiet(arg):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeasurementWarning)
            return run(arg)
    return quiet


def _measure_items(p, steps, repeats, replicas, timer, run, batch, root, deadline):
    """The calibration's measurements, one at a time: ``("pair", (per_step, fixed, single))`` per
    repeat and one ``("batch", seconds)`` after the first pair; stops early (``("stopped", why)``)
    when the next one would end after ``deadline`` (predicted from the ones measured)."""
    run, batch = _calibration_runs(run), _calibration_runs(batch)
    short, long_ = _shortened(p, int(steps) // 4, root), _shortened(p, int(steps), root)
    s_short, s_long = run_steps(short), run_steps(long_)
    yield "steps", s_long
    plan = [("pair", 0), ("batch", None)] + [("pair", k) for k in range(1, int(repeats))]
    pair_s = None
    for kind, k in plan:
        if pair_s is not None:
            need = pair_s if kind == "pair" else int(replicas) * pair_s
            if timer() + need > deadline:
                yield "stopped", f"the next {kind} would pass the budget"
                return
        if kind == "batch":
            t0 = timer()
            batch([dict(long_, seed=100 + b) for b in range(int(replicas))])
            yield "batch", timer() - t0
            continue
        times = []
        t_pair = timer()
        for kw in (short, long_):
            t0 = timer()
            result = run(dict(kw, seed=k))
            times.append(timer() - t0)
        pair_s = timer() - t_pair
        protocol_s = (getattr(result, "timings", None) or {}).get("protocol")
        if protocol_s:   # the run timed its own protocol: the cost per step without the noise of a difference
            c = float(protocol_s) / max(s_long, 1)
        else:
            c = max((times[1] - times[0]) / max(s_long - s_short, 1), 0.0)
        yield "pair", (c, max(times[1] - c * s_long, 0.0), times[1])


def _assemble(p, replicas, budget_s, items, why=None):
    """The calibration dict of the measurements ``items`` (``why``: why it stopped early, or None)."""
    pairs = [v for kind, v in items if kind == "pair"]
    if not pairs:
        return None
    steps = next(v for kind, v in items if kind == "steps")
    batch_s = next((v for kind, v in items if kind == "batch"), None)
    why = why or next((v for kind, v in items if kind == "stopped"), None)
    return {"N": int(p["N"]), "protocol": p.get("protocol") or "oscillatory", "steps": int(steps),
            "per_step_s": [c for c, _, _ in pairs], "fixed_s": [f for _, f, _ in pairs],
            "single_s": [t for _, _, t in pairs], "replicas": int(replicas),
            "batch_s": None if batch_s is None else float(batch_s), "budget_s": float(budget_s),
            "complete": why is None, "stopped": why or ""}


def _default_run(kw):
    return doParticleShearSimulation(**dict(kw, return_result=True))


def _default_batch(kws):
    return run_batch(kws)


def _child(conn, p, steps, repeats, replicas, root, budget_s):
    """A calibration process: every measurement sent to ``conn`` as it is made, then ``("done", None)``."""
    import warnings
    warnings.simplefilter("ignore")
    try:
        deadline = time.perf_counter() + budget_s
        for item in _measure_items(p, steps, repeats, replicas, time.perf_counter, _default_run, _default_batch,
                                   root, deadline):
            conn.send(item)
        conn.send(("done", None))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent, which keeps what was measured
        try:
            conn.send(("error", f"{type(exc).__name__}: {exc}"))
        except Exception:   # noqa: BLE001
            pass
    finally:
        conn.close()


def _measure_bounded(p, steps, repeats, replicas, budget_s):
    """:func:`_measure_items` in a child process, ended at ``budget_s`` wall seconds whatever it is doing."""
    import multiprocessing as mp
    ctx = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    items, why, failed = [], None, None
    with tempfile.TemporaryDirectory(prefix="particleShear-calibration-") as root:
        parent, child = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_child, args=(child, p, steps, repeats, replicas, root, budget_s), daemon=True)
        t_end = time.perf_counter() + budget_s
        proc.start()
        child.close()
        try:
            while True:
                left = t_end - time.perf_counter()
                if left <= 0:
                    why = f"the {budget_s:g} s budget ran out"
                    break
                if not parent.poll(min(left, 0.5)):
                    if not proc.is_alive() and not parent.poll(0):
                        why = "the calibration process ended"
                        break
                    continue
                try:
                    kind, value = parent.recv()
                except EOFError:
                    why = why or "the calibration process ended"
                    break
                if kind == "done":
                    break
                if kind == "error":
                    why, failed = f"a calibration run failed ({value})", value
                    break
                items.append((kind, value))
        finally:
            if proc.is_alive():
                proc.terminate()
                proc.join(5)
                if proc.is_alive():
                    proc.kill()
            proc.join(5)
            parent.close()
    if failed and not any(kind == "pair" for kind, _ in items):
        raise RuntimeError(f"a calibration run failed: {failed}")
    if not any(kind == "steps" for kind, _ in items):
        items.append(("steps", run_steps(_shortened(p, int(steps), ""))))
    return _assemble(p, replicas, budget_s, items, why)


def measure_calibration(p, steps=400, repeats=3, replicas=4, timer=time.perf_counter, run=None, batch=None,
                        budget_s=None):
    """Time a representative point here: cost per step, fixed cost per run, batch ratio; bounded in time.

    Runs ``p`` (its output written to a temporary folder) with its protocol cut to about
    ``steps//4`` and ``steps`` steps (every protocol: oscillation periods, a steady run's strain,
    a relaxation's or creep's hold, a sweep's list and periods; :func:`_shortened`), then one
    batch of ``replicas`` runs of the longer schedule, then the other ``repeats - 1`` pairs.
    The cost per step is the longer run's own protocol timing (``result.timings["protocol"]``)
    when ``run`` returns a result with one, else the difference of the two runs' wall times over
    their difference in steps; the fixed cost is the rest of the longer run's wall time.

    The calibration takes at most ``budget_s`` seconds whatever the point: a measurement that
    the ones before it predict to end past the budget is not started, and with the default
    ``run`` and ``batch`` the measurements run in a child process that is ended when the budget
    runs out (a first run longer than the budget included).  What was measured by then is the
    calibration (``complete`` False, ``stopped`` says why); nothing measured gives None.

    Parameters
    ----------
    p : dict
        Complete parameters of ``doParticleShearSimulation`` of the point.
    steps : int, optional
        Protocol steps of the longer run (default 400; ≥ 8).
    repeats : int, optional
        Timed pairs of runs (default 3; ≥ 1): the spread of the samples.
    replicas : int, optional
        Replicas of the timed batch (default 4; ≥ 2).
    timer : callable, optional
        Clock in seconds (default ``time.perf_counter``; tests inject a fake one).
    run : callable, optional
        ``run(kwargs)`` runs one simulation (default ``doParticleShearSimulation(**kwargs)``).
    batch : callable, optional
        ``batch(list_of_kwargs)`` runs a batch (default ``particleShear.run.batch.run_batch``).
    budget_s : float, optional
        Wall-clock budget in seconds (default :data:`CALIBRATION_BUDGET_S`; > 0).

    Returns
    -------
    dict or None
        ``N``, ``protocol``, ``steps`` (of the longer run), ``per_step_s`` and ``fixed_s`` (one
        sample per finished repeat), ``single_s`` (the longer runs' wall times), ``replicas``,
        ``batch_s`` (the batch's wall time; None when not measured), ``budget_s``, ``complete``
        and ``stopped`` (why it stopped early, else ""); None when not one pair of runs finished
        within the budget.

    Raises
    ------
    ValueError
        For ``steps < 8``, ``repeats < 1``, ``replicas < 2`` or ``budget_s <= 0``.
    RuntimeError
        When the first calibration run fails in the child process (its error named).
    """
    if int(steps) < 8:
        raise ValueError(f"steps={steps!r} is invalid: allowed an integer >= 8")
    if int(repeats) < 1:
        raise ValueError(f"repeats={repeats!r} is invalid: allowed an integer >= 1")
    if int(replicas) < 2:
        raise ValueError(f"replicas={replicas!r} is invalid: allowed an integer >= 2")
    budget_s = CALIBRATION_BUDGET_S if budget_s is None else float(budget_s)
    if not (math.isfinite(budget_s) and budget_s > 0):
        raise ValueError(f"budget_s={budget_s!r} is invalid: allowed a number of seconds > 0")
    if run is None and batch is None:
        return _measure_bounded(p, steps, repeats, replicas, budget_s)
    run = run or _default_run
    batch = batch or _default_batch
    with tempfile.TemporaryDirectory(prefix="particleShear-calibration-") as root:
        items = list(_measure_items(p, steps, repeats, replicas, timer, run, batch, root, timer() + budget_s))
    return _assemble(p, replicas, budget_s, items)


def load_or_measure(p, steps=400, repeats=3, replicas=4, path=None, host=None, version=None, refresh=False,
                    **measure):
    """The cached calibration of ``p`` on this host and version, measured (and cached) when missing.

    Parameters
    ----------
    p : dict
        Complete parameters of the point.
    steps, repeats, replicas : int, optional
        As :func:`measure_calibration`.
    path : str, optional
        Cache file (default :func:`cache_path`).
    host, version : str, optional
        As :func:`calibration_key`.
    refresh : bool, optional
        Measure again and replace the cached entry (``--calibrate``; default False).
    **measure
        Passed to :func:`measure_calibration` (``timer``, ``run``, ``batch``).

    Returns
    -------
    tuple of (dict or None, bool)
        The calibration (None when not one pair of runs finished within the budget of
        :func:`measure_calibration`; not cached) and whether it came from the cache.
    """
    path = path or cache_path()
    key = calibration_key(p, steps, replicas, host=host, version=version)
    cache = {}
    try:
        with open(path, encoding="utf-8") as fh:
            cache = json.load(fh)
    except (OSError, ValueError):
        cache = {}
    if not refresh and isinstance(cache, dict) and isinstance(cache.get(key), dict):
        return cache[key], True
    cal = measure_calibration(p, steps=steps, repeats=repeats, replicas=replicas, **measure)
    if cal is None:      # nothing measured within the budget: nothing to keep
        return None, False
    cache = cache if isinstance(cache, dict) else {}
    cache[key] = cal
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        tmp = f"{path}.{os.getpid()}.part"
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(cache, fh, indent=1, sort_keys=True)
        os.replace(tmp, path)
    except OSError:
        pass   # an unwritable cache only costs the next dry run another calibration
    return cal, False


def _batch_fraction(cal, b):
    """Per-run cost of a batch of ``b`` runs / a single run: a fixed share ``c0`` and a per-replica share ``c1``."""
    single = sorted(cal["single_s"])[len(cal["single_s"]) // 2]
    if b <= 1 or single <= 0 or cal.get("batch_s") is None:   # no batch measured: a run costs a single run
        return 1.0
    r = cal["batch_s"] / (cal["replicas"] * single)          # measured fraction at the calibrated size
    c1 = min(max((cal["replicas"] * r - 1) / (cal["replicas"] - 1), 0.05), 1.0)
    return min((1 - c1) / b + c1, 1.0)


def project_cost(points, counts, cal, workers=1, batch_size=None, cores=None, schedule=None):
    """Projected CPU and wall time of ``counts[i]`` runs of each point, from a calibration ``cal``.

    A run of point p costs ``fixed·c(N_p)/c(N_c) + steps_p·per_step·s(N_p)/s(N_c)`` (``N_c`` the
    calibrated N, ``c`` and ``s`` the shapes in N of the documented constitution and per-step
    costs of the point's backend, :mod:`~particleShear.sweep.cost`; ``steps_p`` its protocol steps).  With ``batch_size`` the runs of one step schedule go in batches of up to
    ``batch_size``; a batch of b runs costs ``b·(c0/b + c1)`` single runs, with ``c0 + c1 = 1``
    fitted to the calibration batch.  Wall time is CPU / min(workers, cores, tasks), at least
    the longest task.

    Parameters
    ----------
    points : sequence of dict
        Complete parameters of each point.
    counts : sequence of int
        Runs of each point.
    cal : dict
        As :func:`measure_calibration` returns it.
    workers : int, optional
        Worker processes (default 1).
    batch_size : int, optional
        ``--batch-size`` (default None: one task per run).
    cores : int, optional
        Cores of this machine (default ``os.cpu_count()``).
    schedule : callable, optional
        Step-schedule key of a point (default ``particleShear.run.batch.schedule_key``).

    Returns
    -------
    dict
        ``cpu_s``, ``wall_s`` (central values), ``wall_low_s``, ``wall_high_s`` (the spread of
        the calibration samples, at least ±:data:`MIN_SPREAD`), ``tasks``, ``parallel`` (the
        processes that share the work).
    """
    cores = int(cores or os.cpu_count() or 1)
    workers = max(1, int(workers or 1))
    n_c = float(cal["N"])
    samples = [(c, f) for c, f in zip(cal["per_step_s"], cal["fixed_s"])]
    mid = sorted(range(len(samples)), key=lambda i: cal["single_s"][i])[len(samples) // 2]
    if schedule is None and batch_size:
        schedule = schedule_key
    groups = {}
    for i, (p, n) in enumerate(zip(points, counts)):
        if int(n) > 0:
            key = schedule(p) if batch_size else i
            groups.setdefault(key, []).append((p, int(n)))

    def totals(per_step, fixed):
        cpu = longest = 0.0
        tasks = 0
        for members in groups.values():
            cost = sum(n * (fixed * _constitution_seconds(float(p["N"]), be) / _constitution_seconds(n_c, be)
                            + run_steps(p) * per_step * _step_seconds(float(p["N"]), be) / _step_seconds(n_c, be))
                       for p, n in members for be in (cost_backend(p),))
            runs = sum(n for _, n in members)
            if batch_size:
                n_batches = math.ceil(runs / batch_size)
                cost *= _batch_fraction(cal, runs / n_batches)
            else:
                n_batches = runs
            cpu += cost
            tasks += n_batches
            longest = max(longest, cost / n_batches)
        parallel = max(1, min(workers, cores, tasks))
        return cpu, max(cpu / parallel, longest), tasks, parallel

    cpu, wall, tasks, parallel = totals(*samples[mid])
    walls = [totals(c, f)[1] for c, f in samples]
    low = min(min(walls), wall * (1 - MIN_SPREAD))
    high = max(max(walls), wall * (1 + MIN_SPREAD))
    return {"cpu_s": cpu, "wall_s": wall, "wall_low_s": low, "wall_high_s": high, "tasks": tasks,
            "parallel": parallel}


def format_projection(c, workers, batch_size=None):
    """One line: the calibrated CPU time and the wall-time range on ``workers`` processes.

    Parameters
    ----------
    c : dict
        As :func:`project_cost` returns it.
    workers : int
        The requested workers.
    batch_size : int, optional
        ``--batch-size``, named in the line when given.

    Returns
    -------
    str
    """
    batched = f", batches of up to {batch_size}" if batch_size else ""
    return (f"calibrated here: ~{_human_s(c['cpu_s'])} CPU = ~{_human_s(c['wall_s'])} wall "
            f"(range {_human_s(c['wall_low_s'])} – {_human_s(c['wall_high_s'])}) on {c['parallel']} of {workers} "
            f"worker(s){batched}, {c['tasks']} task(s)")

