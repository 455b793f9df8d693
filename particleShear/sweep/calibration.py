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

from .cost import _step_seconds, run_steps

__all__ = ["cache_path", "calibration_key", "measure_calibration", "load_or_measure", "project_cost",
           "format_projection", "representative_point", "MIN_SPREAD"]

#: smallest relative half-width of the printed range (the scatter of a shared machine between runs)
MIN_SPREAD = 0.3
#: parameters of a point that decide its calibration (the rest does not change the cost per step)
_KEY_PARAMETERS = ("N", "bimodal_factor", "packing_fraction", "theMu", "do_permanent_links", "cut_lines",
                   "saveData", "saveStressTensorData", "file_format", "integrator", "backend",
                   "relative_transversal_link_strength", "theAmplitude", "relative_viscosity", "time_step_factor")


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
        from .. import __version__ as version
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
    from .cost import run_seconds
    best, best_cost = points[0], -1.0
    for p, n in zip(points, counts):
        c = int(n) * run_seconds(p)
        if c > best_cost:
            best, best_cost = p, c
    return best


def _shortened(p, steps, root):
    per_period = max(1, run_steps(dict(p, pre_periods=0, periods=1, post_periods=0)))
    return dict(p, pre_periods=0, post_periods=0, periods=min(float(p["periods"]), steps / per_period),
                doDrawing=False, plotStress=False, saveOutputImages=False, root_folder=root, verbose=False)


def measure_calibration(p, steps=400, repeats=3, replicas=4, timer=time.perf_counter, run=None, batch=None):
    """Time a representative point here: cost per step, fixed cost per run, batch ratio.

    Runs ``p`` (its output written to a temporary folder) with the protocol cut to ``steps//4``
    and to ``steps`` steps, ``repeats`` times each, then one batch of ``replicas`` runs of the
    longer schedule.  The cost per step is the longer run's own protocol timing
    (``result.timings["protocol"]``) when ``run`` returns a result with one, else the difference
    of the two runs' wall times over their difference in steps; the fixed cost is the rest of
    the longer run's wall time.

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

    Returns
    -------
    dict
        ``N``, ``steps`` (of the longer run), ``per_step_s`` and ``fixed_s`` (one sample per
        repeat), ``single_s`` (the longer runs' wall times), ``replicas`` and ``batch_s`` (the
        batch's wall time).

    Raises
    ------
    ValueError
        For ``steps < 8``, ``repeats < 1`` or ``replicas < 2``.
    """
    if int(steps) < 8:
        raise ValueError(f"steps={steps!r} is invalid: allowed an integer >= 8")
    if int(repeats) < 1:
        raise ValueError(f"repeats={repeats!r} is invalid: allowed an integer >= 1")
    if int(replicas) < 2:
        raise ValueError(f"replicas={replicas!r} is invalid: allowed an integer >= 2")
    if run is None:
        from ..run.api import doParticleShearSimulation

        def run(kw):
            return doParticleShearSimulation(**kw, return_result=True)
    if batch is None:
        from ..run.batch import run_batch as batch
    per_step, fixed, single = [], [], []
    with tempfile.TemporaryDirectory(prefix="particleShear-calibration-") as root:
        short, long_ = _shortened(p, int(steps) // 4, root), _shortened(p, int(steps), root)
        s_short, s_long = run_steps(short), run_steps(long_)
        for k in range(int(repeats)):
            times = []
            for kw in (short, long_):
                t0 = timer()
                result = run(dict(kw, seed=k))
                times.append(timer() - t0)
            protocol_s = (getattr(result, "timings", None) or {}).get("protocol")
            if protocol_s:   # the run timed its own protocol: the cost per step without the noise of a difference
                c = float(protocol_s) / max(s_long, 1)
            else:
                c = max((times[1] - times[0]) / max(s_long - s_short, 1), 0.0)
            per_step.append(c)
            fixed.append(max(times[1] - c * s_long, 0.0))
            single.append(times[1])
        t0 = timer()
        batch([dict(long_, seed=100 + b) for b in range(int(replicas))])
        batch_s = timer() - t0
    return {"N": int(p["N"]), "steps": int(s_long), "per_step_s": per_step, "fixed_s": fixed,
            "single_s": single, "replicas": int(replicas), "batch_s": float(batch_s)}


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
    tuple of (dict, bool)
        The calibration and whether it came from the cache.
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
    if b <= 1 or single <= 0:
        return 1.0
    r = cal["batch_s"] / (cal["replicas"] * single)          # measured fraction at the calibrated size
    c1 = min(max((cal["replicas"] * r - 1) / (cal["replicas"] - 1), 0.05), 1.0)
    return min((1 - c1) / b + c1, 1.0)


def project_cost(points, counts, cal, workers=1, batch_size=None, cores=None, schedule=None):
    """Projected CPU and wall time of ``counts[i]`` runs of each point, from a calibration ``cal``.

    A run of point p costs ``fixed·(N_p/N_c)^0.7 + steps_p·per_step·s(N_p)/s(N_c)`` (``N_c`` the
    calibrated N, ``s`` the shape of the documented per-step cost, ``steps_p`` its protocol
    steps).  With ``batch_size`` the runs of one step schedule go in batches of up to
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
        from ..run.batch import schedule_key as schedule
    groups = {}
    for i, (p, n) in enumerate(zip(points, counts)):
        if int(n) > 0:
            key = schedule(p) if batch_size else i
            groups.setdefault(key, []).append((p, int(n)))

    def totals(per_step, fixed):
        cpu = longest = 0.0
        tasks = 0
        for members in groups.values():
            cost = sum(n * (fixed * (float(p["N"]) / n_c) ** 0.7
                            + run_steps(p) * per_step * _step_seconds(float(p["N"])) / _step_seconds(n_c))
                       for p, n in members)
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
    from .cost import _human_s
    batched = f", batches of up to {batch_size}" if batch_size else ""
    return (f"calibrated here: ~{_human_s(c['cpu_s'])} CPU = ~{_human_s(c['wall_s'])} wall "
            f"(range {_human_s(c['wall_low_s'])} – {_human_s(c['wall_high_s'])}) on {c['parallel']} of {workers} "
            f"worker(s){batched}, {c['tasks']} task(s)")

