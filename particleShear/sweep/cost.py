"""Projected size and cost of a sweep, from the time-step rule and documented per-step costs.

The number of protocol steps of a run is exact (the rule of ``time_steps_from_model`` and
``protocol_steps``: ``τ`` cancels, so no ensemble is built).  Wall times use static per-step costs
of the run's backend (``backend``, ``"auto"`` resolved as a run resolves it), measured on a quiet
2-core CI-class machine: NumPy (``benchmarks/bench_step.py``) 285 µs per step at N = 150, 645 µs at
N = 1,000, 5.6 ms at N = 10,000, constitution 0.53 s · (N/150)^0.7; Numba 35 µs, 165 µs, 1.9 ms,
constitution 0.085 s · (N/150)^0.93 (NumPy's figures over the ratios of the two backends measured
in one run of whole runs at each N: protocol 8.1×, 3.9×, 2.9×; constitution 6.5×, 3.4×, 2.5×).
Steps are interpolated log-log, extrapolated with the nearest slope; a backend without figures
(a device) is projected at NumPy's.  A loaded machine measures up to 2× more
(docs/performance.md), which is why ``--dry-run`` calibrates on the machine at hand.  Disk: the text format writes about
723 bytes per step with the tensor table and a ≈ 4 kB header (measured, docs/sweeps.md); the file of another
protocol about 110 bytes per step.  Every protocol counts its own steps (:func:`run_steps`).
"""
__docformat__ = "numpy"
import math

from ..engine.xp import resolve_backend
from ..linkable.builders import time_steps_from_model
from ..simulation.experiment import protocol_steps
from ..run.api import doParticleShearSimulation
from ..run.rheometer import PROTOCOL_DEFAULTS, normalize_protocol, protocol_steps as steps_of

__all__ = ["cost_backend", "run_steps", "run_seconds", "run_bytes", "estimate_cost", "estimate_point_cost", "format_cost"]

#: (N, s per protocol step) of each backend (module docstring)
_STEP_COST = {"numpy": ((150, 285e-6), (1000, 645e-6), (10000, 5.6e-3)),
              "numba": ((150, 35e-6), (1000, 165e-6), (10000, 1.9e-3))}
#: (s at N = 150, exponent of N/150) of a constitution on each backend
_CONSTITUTION = {"numpy": (0.53, 0.7), "numba": (0.085, 0.93)}
_BYTES_PER_STEP = 723
_HEADER_BYTES = 4000
_PROTOCOL_BYTES_PER_STEP = 110   # another protocol's text file: 103 B per row (creep), 105 (steady, N1), measured


def run_steps(p):
    """Protocol steps of a run with parameters ``p``: its own protocol's.

    Parameters
    ----------
    p : dict
        Complete parameters of ``doParticleShearSimulation`` (``bimodal_factor``, ``theMu``,
        ``relative_transversal_link_strength``, ``theAmplitude``, ``relative_viscosity``,
        ``periods``, ``pre_periods``, ``post_periods``, ``relative_frequency``; optional
        ``time_step_factor``, default 1; optional ``protocol`` and its parameters,
        docs/protocols.md).

    Returns
    -------
    int
        "oscillatory" (the default): ``int((periods + pre + post)/f / dt)`` with the time step
        of the model's rule; another protocol: its steps
        (:func:`particleShear.run.rheometer.protocol_steps`: a steady run's strain over its
        rate, a hold's time, the sum over a sweep's steps).
    """
    proto = p.get("protocol") or "oscillatory"
    if proto != "oscillatory":
        st = steps_of(normalize_protocol({**PROTOCOL_DEFAULTS, "time_step_factor": 1.0, **p}))
        return int(sum(st["segments"])) if "segments" in st else int(st["steps"])
    dt, _ = time_steps_from_model(1.0, p["bimodal_factor"], p["theMu"], p["relative_transversal_link_strength"],
                                  p["theAmplitude"], p["relative_viscosity"])
    dt *= float(p.get("time_step_factor", 1.0))
    return protocol_steps(p["periods"], p["pre_periods"], p["post_periods"], p["relative_frequency"], dt)


def cost_backend(p):
    """The backend whose static costs project a run with parameters ``p``: its ``backend``
    (``"auto"`` resolved as the run resolves it, :func:`~particleShear.engine.xp.resolve_backend`),
    NumPy's for a backend without figures.

    Parameters
    ----------
    p : dict
        Parameters of ``doParticleShearSimulation`` (``backend`` optional, default ``"auto"``).

    Returns
    -------
    str
        A key of :data:`_STEP_COST`.
    """
    name = resolve_backend(p.get("backend") or "auto")
    return name if name in _STEP_COST else "numpy"


def _constitution_seconds(N, backend="numpy"):
    t0, power = _CONSTITUTION[backend]
    return t0 * (N / 150) ** power


def _step_seconds(N, backend="numpy"):
    pts = _STEP_COST[backend]
    if N <= pts[1][0]:
        (n0, t0), (n1, t1) = pts[0], pts[1]
    else:
        (n0, t0), (n1, t1) = pts[1], pts[2]
    slope = math.log(t1 / t0) / math.log(n1 / n0)
    return t0 * (N / n0) ** slope


def run_seconds(p):
    """Projected single-core wall time (s) of one run: constitution plus protocol steps.

    Parameters
    ----------
    p : dict
        Complete parameters of ``doParticleShearSimulation`` (as for :func:`run_steps`, plus
        ``N``, the number of spheres).

    Returns
    -------
    float
        Seconds on the reference machine of docs/performance.md, on the run's backend
        (:func:`cost_backend`).
    """
    N, backend = float(p["N"]), cost_backend(p)
    return _constitution_seconds(N, backend) + run_steps(p) * _step_seconds(N, backend)


def run_bytes(p):
    """Projected bytes written by one run (text format; 0 without ``saveData``).

    Parameters
    ----------
    p : dict
        Complete parameters of ``doParticleShearSimulation`` (as for :func:`run_steps`;
        ``saveData`` and ``saveStressTensorData`` decide what is written).

    Returns
    -------
    int
        ≈ 4 kB header plus 723 bytes per protocol step with the tensor table; another protocol
        than "oscillatory" (its own file, docs/protocols.md): ≈ 4 kB plus 110 bytes per step.
    """
    if not p.get("saveData"):
        return 0
    if (p.get("protocol") or "oscillatory") != "oscillatory":
        return _HEADER_BYTES + _PROTOCOL_BYTES_PER_STEP * run_steps(p)
    return _HEADER_BYTES + (_BYTES_PER_STEP * run_steps(p) if p.get("saveStressTensorData", True) else 0)


def estimate_cost(runs, workers=1):
    """Totals over ``runs``: runs, steps, bytes, CPU seconds, wall seconds.

    Parameters
    ----------
    runs : iterable of SweepRun or dict
        The runs (their ``parameters``) or complete parameter dicts.
    workers : int, optional
        Number of parallel workers the wall time is divided by (default 1; values < 1 count as 1).

    Returns
    -------
    dict
        ``{"runs", "steps", "bytes", "cpu_s", "wall_s", "workers"}`` (seconds in s).
    """
    params = [getattr(r, "parameters", r) for r in runs]
    cpu = sum(run_seconds(p) for p in params)
    return {"runs": len(params), "steps": sum(run_steps(p) for p in params),
            "bytes": sum(run_bytes(p) for p in params), "cpu_s": cpu,
            "wall_s": cpu / max(1, int(workers or 1)), "workers": max(1, int(workers or 1))}


def estimate_point_cost(points, counts, workers=1):
    """:func:`estimate_cost` of ``counts[p]`` runs of each point ``points[p]``, without enumerating the runs.

    A run's cost depends on its parameters only (not on its seed), so a sweep of any number of
    repetitions is sized in the time of its points.

    Parameters
    ----------
    points : sequence of dict
        Complete parameters of each point.
    counts : sequence of int
        Runs of each point (≥ 0).
    workers : int, optional
        Parallel workers for the wall time (default 1).

    Returns
    -------
    dict
        As :func:`estimate_cost`.
    """
    runs = steps = nbytes = 0
    cpu = 0.0
    for p, n in zip(points, counts):
        n = int(n)
        if n <= 0:
            continue
        runs += n
        steps += n * run_steps(p)
        nbytes += n * run_bytes(p)
        cpu += n * run_seconds(p)
    w = max(1, int(workers or 1))
    return {"runs": runs, "steps": steps, "bytes": nbytes, "cpu_s": cpu, "wall_s": cpu / w, "workers": w}


def _human_bytes(b):
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if b < 1000 or unit == "TB":
            return f"{b:.3g} {unit}"
        b /= 1000


def _human_s(s):
    if s < 120:
        return f"{s:.1f} s"
    if s < 7200:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.1f} h"


def format_cost(c):
    """One line: ``runs, steps, disk, CPU time, wall time on the given workers``.

    Parameters
    ----------
    c : dict
        Totals as :func:`estimate_cost` returns them.

    Returns
    -------
    str
        The line, with human units (kB/MB/GB; s/min/h).
    """
    return (f"{c['runs']} runs, {c['steps']:,} protocol steps, disk ~{_human_bytes(c['bytes'])}, "
            f"projected ~{_human_s(c['cpu_s'])} CPU = ~{_human_s(c['wall_s'])} on {c['workers']} worker(s) "
            f"(~{c['cpu_s'] / 3600:.3g} CPU-hours)")


def calibrate(p, target_steps=2000):
    """Measured / projected wall time of a shortened run of ``p`` on this machine (a factor for the projection).

    Runs ``p`` once without output, its protocol cut to about ``target_steps`` steps (one
    excitation period at most, no baseline periods), and compares the measured wall time
    with :func:`run_seconds` of that shortened run.

    Parameters
    ----------
    p : dict
        Complete parameters of ``doParticleShearSimulation`` of a representative run.
    target_steps : int, optional
        About how many protocol steps the shortened run takes (default 2000).

    Returns
    -------
    float
        Measured wall time divided by the projected one (1 = the documented costs hold here).
    """
    import time
    per_period = max(1, run_steps(dict(p, pre_periods=0, periods=1, post_periods=0)))
    short = dict(p, pre_periods=0, post_periods=0, periods=min(1.0, target_steps / per_period), saveData=False,
                 saveOutputImages=False, doDrawing=False, plotStress=False)
    t0 = time.perf_counter()
    doParticleShearSimulation(**short, seed=0, verbose=False)
    return (time.perf_counter() - t0) / run_seconds(short)
