"""The measurement's loops over the engine's one step: the fixed-boundary pre-equilibration and the
oscillatory protocol of a batch (docs/engine.md, "One step").

:func:`pre_equilibrate` (plates fixed: coarse levels from ``dt_max``, then 2N and N steps at
``dt``) and :func:`protocol` (recording t, γ, γ̇, τ_internal and τ_surface of every replica and
step) call :meth:`~.step.BatchEngine.step` and, after the steps, the observers
(:mod:`.observers`).  Units: s, Hz, Pa.
"""
__docformat__ = "numpy"

import math

import numpy as np

from ..checks import finite, positive
from .observers import check_observers, notify
from .rheometer import shear_record

__all__ = ["pre_equilibrate", "protocol", "pre_equilibration_blocks", "relaxation_levels", "MAX_LEVELS"]


#: most coarse levels of one relaxation (halving a finite step reaches any dt > 0 in fewer)
MAX_LEVELS = 2100


def relaxation_levels(dt, dt_max):
    """Coarse levels of a relaxation: ``(level_dt, cool)`` from ``dt_max`` halving while above ``dt``.

    The damping factor starts at 0.5 and moves halfway to 1 at every halving (the classes'
    rule, repeated halving of ``dt_max``); the levels of ``free_pre_equilibration`` and of the
    measurement's pre-equilibration (:func:`pre_equilibration_blocks`).

    Parameters
    ----------
    dt : float
        Final time step (s), > 0.
    dt_max : float
        Step of the first level (s), finite.

    Returns
    -------
    list of tuple
        ``(level_dt, cool)`` per level; empty when ``dt_max <= dt``.

    Raises
    ------
    ValueError
        If ``dt`` is not a finite number > 0 or ``dt_max`` is not finite (TypeError: not a real
        number).
    """
    dt, dt_max = positive("dt", dt), finite("dt_max", dt_max)
    levels = []
    level_dt, cf = dt_max, 0.5
    while level_dt > dt and len(levels) < MAX_LEVELS:
        levels.append((level_dt, cf))
        level_dt /= 2
        cf = (1 + cf) / 2
    return levels


def pre_equilibration_blocks(N, dt, dt_max):
    """Coarse levels of the pre-equilibration: ``(steps, dt, cool)``, :func:`relaxation_levels` with
    ``int(N/2)`` steps each.

    Parameters
    ----------
    N : int
        Steps per level scale of the pre-equilibration (the reference's ``N``).
    dt : float
        Final time step (s, > 0); levels stop once halving reaches it.
    dt_max : float
        Largest time step (s), the first level.

    Returns
    -------
    list of tuple
        ``(steps, level_dt, cool)`` per level; empty when ``dt_max ≤ dt``.

    Raises
    ------
    ValueError
        As :func:`relaxation_levels`.
    """
    return [(int(N / 2), level_dt, cf) for level_dt, cf in relaxation_levels(dt, dt_max)]


def _quiet(*args):
    pass


def pre_equilibrate(engine, N, dt, dt_max, cool, say=_quiet, report=_quiet, observers=()):
    """Relax with the plates fixed: coarse levels from ``dt_max``, 2N steps at ``dt`` (damping
    0.98), N steps at ``dt`` with ``cool`` and γ̇ reset to 0 by assignment (docs/engine.md).

    Parameters
    ----------
    engine : BatchEngine
        The engine of the batch; its state is relaxed in place (plates on, step count reset).
    N : int
        Steps per level scale (the reference's pre-equilibration ``N``).
    dt : float
        Final time step (s).
    dt_max : float
        Time step of the first coarse level (s), see :func:`pre_equilibration_blocks`.
    cool : float
        Damping factor per step of the last N steps.
    say : callable
        ``say(message)`` receives the reference's console messages.
    report : callable
        ``report(step, total)`` is called after the first step and after each run of steps between
        the observers' steps (progress; after every step with an observer of ``every`` 1).
    observers : sequence, default ()
        Observers (:mod:`particleShear.engine.observers`): each is called as
        ``observe(engine, "pre-equilibration", step, total)`` after every step that is a multiple
        of its ``every`` and after the last step; they only read the state.

    Returns
    -------
    int
        The steps run.

    Raises
    ------
    ValueError
        For an observer without an int ``every`` ≥ 1 or an ``observe`` method (before any step).
    EngineInstability
        If a guarded replica becomes unstable.
    """
    check_observers(observers)
    s = engine.s
    s.applying_shear = True
    engine.begin_phase("pre-equilibration")
    blocks = pre_equilibration_blocks(N, dt, dt_max)
    total = sum(b[0] for b in blocks) + 3 * int(N)
    say("Pre-equilibration under experimental conditions, Steps per dt: " + str(N) + " max dt " + str(dt_max)
        + " final dt " + str(dt))
    step = 0
    phase = engine.phase

    def run(n, cf, level_dt):
        # n steps, in runs that end where an observer is due (engine.steps: compiled blocks on Numba)
        nonlocal step
        end = step + n
        while step < end:
            first = 1 if step == 0 else end       # (step 1 alone: the phase's first progress call)
            stop = min([end, first] + [(step // ob.every + 1) * ob.every for ob in observers])
            engine.steps(stop - step, cf, level_dt)
            step = stop
            report(step, total)
            notify(observers, engine, phase, step, total)

    for n, level_dt, cf in blocks:
        say("dt= " + str(level_dt))
        run(n, cf, level_dt)
    say("  Setting final dt= " + str(dt))
    run(2 * int(N), 0.98, dt)
    s.rate[...] = 0.0       # direct assignment, no velocity adjustment (γ̇ is 0 here; no step changes it)
    run(int(N), cool, dt)
    engine.flush()
    return step


def protocol(engine, dt, f, amplitudes, cool, pre, periods, post, keep_tensors=False, say=_quiet, report=_quiet,
             observers=(), stop=None):
    """The oscillatory protocol of every replica, clock reset to 0 (docs/engine.md).

    Every step first sets γ̇ = ``A·2πf·cos(2π(f t − pre))`` during the shear periods (0 in the
    baselines), so the strain follows ``A·sin(2π(f t − pre))``, then records and steps.

    Parameters
    ----------
    engine : BatchEngine
        The engine of the batch, after :func:`pre_equilibrate`; advanced in place.
    dt : float
        Time step (s), shared by the replicas.
    f : float
        Excitation frequency (Hz).
    amplitudes : array_like (B,)
        Strain amplitude of each replica.
    cool : float
        Damping factor per step.
    pre, periods, post : float
        Baseline periods before, shear periods, baseline periods after.
    keep_tensors : bool
        Also record every tensor of the registry ("tensors", (n_steps, B, 9, 2, 2)).
    say, report : callable
        Receive the reference's console message and ``(step, total)`` after every step.
    observers : sequence, default ()
        Observers (:mod:`particleShear.engine.observers`): each is called as
        ``observe(engine, "protocol", step, total)`` after every step that is a multiple of its
        ``every`` and after the last step; while the protocol runs, ``engine.record`` holds the
        record below as it fills (rows ``0 … step − 1`` written, on the state's backend).
        They only read the state.
    stop : int, optional
        Stop after that many steps (default: the whole protocol, ``int((periods + pre + post)/f/dt)``
        steps); the record then holds those steps, "last_tensors" of the last one run.

    Returns
    -------
    dict of numpy.ndarray (n_steps, B)
        "t", "strain", "strain_rate", "stress_internal", "stress_surface" of every step, and
        "first_tensors", "last_tensors" (B, 9, 2, 2): every tensor at the first and last step.
        Times in s, strain dimensionless, strain rate in 1/s, stresses and tensors in Pa.  The
        record is kept on the state's backend and copied to the host once, at the end.

    Raises
    ------
    ValueError
        For an observer without an int ``every`` ≥ 1 or an ``observe`` method (before any step).
    EngineInstability
        If a guarded replica becomes unstable.
    """
    xp = engine.xp             # (the observers are checked by shear_record, before any step)
    T_total = (periods + pre + post) / f
    n_steps = total = int(T_total / dt)
    if stop is not None:
        n_steps = max(0, min(int(stop), n_steps))
    lo = pre / (f * dt)
    hi = (periods + pre) / (f * dt)
    A = engine.backend.asarray(np.asarray(amplitudes, dtype=float))
    zero = xp.zeros(engine.s.B)
    clock = [0.0]              # the clock of every replica, kept on the host too (same additions of dt)

    def rate_of(i):
        t = clock[0]
        clock[0] = t + dt      # = s.t[b] after the step, for every b (same dt, same schedule)
        if lo <= i <= hi:
            return A * math.cos(2 * math.pi * (t * f - pre)) * 2 * math.pi * f
        return zero

    return shear_record(engine, dt, cool, n_steps, rate_of, say=say, report=report, observers=observers,
                        keep_tensors=keep_tensors, end_tensors=True, total=total)
