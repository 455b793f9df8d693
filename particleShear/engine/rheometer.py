"""The one recording loop of the rheometer's protocols other than the oscillation (docs/protocols.md).

Each such protocol (:mod:`particleShear.protocols`, one file each) is a *rate schedule* — the
strain rate γ̇ of every replica at every step — or a *controller* that chooses γ̇ from the stresses
of the steps before (creep's); :func:`shear_record` drives either through the one step
(:meth:`~particleShear.engine.step.BatchEngine.step`) after the plates' pre-equilibration
(:func:`~particleShear.engine.step.pre_equilibrate`).  The one-packing amplitude and frequency
sweeps are sequences of the oscillatory protocol (:func:`~particleShear.engine.step.protocol`) on
the same engine (:mod:`particleShear.run.rheometer`).

Every rule is elementwise per replica, so a replica's record does not depend on its companions:
a batched replica is bit-identical to its single run.  Replicas of one batch may need different
numbers of steps (different rates or strains): the batch runs the longest and each replica's
record is cut at its own length by the run layer (steps after a replica's end change nothing
before it).

Recorded per step (the convention of :func:`~particleShear.engine.step.protocol`): the clock
``t`` (s) and strain γ at the start of the step, the rate γ̇ (1/s) of the step and the shear
stresses τ_internal, τ_surface (Pa) of the forces at the start of the step.  With
``tensors_every = k`` the first normal-stress difference ``N1 = σ_xx − σ_yy`` of the overall
tensor (eq. S1-24, in the sign convention of the reported shear stress τ = −σ_xy of the
tensor, i.e. ``N1 = −(T_xx − T_yy)`` of the tensor ``T``) is recorded every k steps
(NaN in the other rows).
"""
__docformat__ = "numpy"

import math

from .numba_step import run_block
from .observers import check_observers, notify
from .stress import TENSORS
from .xp import to_host

__all__ = ["shear_record", "OVERALL"]

#: index of the overall stress tensor (eq. S1-24) in the engine's tensor registry
OVERALL = [t.name for t in TENSORS].index("overall_stress_tensor")


def _quiet(*args):
    pass


#: the longest block of steps in one compiled call (:func:`_block_end`): the progress is reported
#: between blocks, and the block's rates are one (BLOCK, B) array
BLOCK = 256


def _block_end(engine, i, n_steps, after_step, observers):
    """Where a compiled block of steps from step ``i`` ends (``i``: none), for the compiled backend.

    A block holds steps whose rate does not depend on the steps before (no controller
    ``after_step``); its steps that sample every tensor sum their rows in the compiled step
    (:func:`~particleShear.engine.numba_step.run_block`).  It ends at the latest after the first
    step an observer is due after, and after :data:`BLOCK` steps; the first block is the first step
    alone, so that the progress is reported after it, as the pre-equilibration reports its first step."""
    if not engine.backend.compiled or after_step is not None:
        return i
    j = min(n_steps, i + BLOCK if i else 1)      # (step 1 alone: the phase's first progress call)
    for ob in observers:          # (observers are notified after the steps that are multiples of their every)
        j = min(j, (i // ob.every + 1) * ob.every)
    return j


def _samples_tensors(i, n_steps, tensors_every, keep_tensors, end_tensors):
    """Whether step ``i`` samples every tensor: an N1 step, a kept history, or a first or last step."""
    return bool(tensors_every) and i % tensors_every == 0 or keep_tensors or \
        end_tensors and (i == 0 or i == n_steps - 1)


def _record_tensors(rec, i, n_steps, T, tensors_every, keep_tensors, end_tensors):
    """Record what step ``i`` keeps of its tensors ``T`` (B, 9, 2, 2): N1 of the overall tensor, the
    history, the first and last tensors."""
    if tensors_every and i % tensors_every == 0:
        O = T[:, OVERALL]
        rec["N1"][i] = -(O[:, 0, 0] - O[:, 1, 1])
    if keep_tensors:
        rec["tensors"][i] = T
    if end_tensors and i == 0:
        rec["first_tensors"] = T.copy()
    if end_tensors and i == n_steps - 1:
        rec["last_tensors"] = T.copy()


def shear_record(engine, dt, cool, n_steps, rate_of, tensors_every=0, say=_quiet, report=_quiet, observers=(),
                 after_step=None, keep_tensors=False, end_tensors=False, total=None):
    """Step every replica ``n_steps`` times at the rates ``rate_of`` gives, recording the series:
    the one recording loop of every protocol, the oscillation included
    (:func:`~particleShear.engine.loops.protocol` is its cosine schedule).

    At step i: ``γ̇ = rate_of(i)`` (set with ``set_rate``, keeping each sphere's velocity
    relative to the flow), record t, γ, γ̇, step with the stresses sampled, record them, then
    ``after_step(i, tau_internal, tau_surface)`` when given (a controller's update).  The clock
    is reset to 0 at the start; the strain continues from its current value.  ``rate_of`` is
    called once per step, in order.

    Parameters
    ----------
    engine : BatchEngine
        The engine of the batch (pre-equilibrated); advanced in place, plates on.
    dt : float
        Time step (s), shared by the replicas.
    cool : float
        Damping factor per step (1 = none).
    n_steps : int
        Steps to record (≥ 0).
    rate_of : callable
        ``rate_of(i) -> array (B,)``: γ̇ of every replica at step i (1/s), on the state's backend.
    tensors_every : int, default 0
        Record N1 of the overall tensor every this many steps (0: never).
    say, report : callable
        The console message and ``report(step, total)`` after every step.
    observers : sequence
        Observers (:mod:`particleShear.engine.observers`), called with phase ``"protocol"``;
        ``engine.record`` holds the record as it fills.
    after_step : callable or None
        ``after_step(i, tau_internal, tau_surface)`` after each step (arrays (B,) on the backend).
    keep_tensors : bool, default False
        Also record every tensor of the registry at every step ("tensors", (n_steps, B, 9, 2, 2), Pa).
    end_tensors : bool, default False
        Also record every tensor at the first and the last step ("first_tensors",
        "last_tensors", (B, 9, 2, 2), Pa).
    total : int, optional
        The number of steps the console message announces (default ``n_steps``; a protocol
        stopped early announces its whole length).

    Returns
    -------
    dict of numpy.ndarray (n_steps, B)
        "t", "strain", "strain_rate", "stress_internal", "stress_surface" and, with
        ``tensors_every``, "N1" (Pa; NaN where not sampled), with the tensors asked for.
    """
    check_observers(observers)
    s, xp = engine.s, engine.xp
    s.applying_shear = True
    s.t[...] = 0.0
    names = ["t", "strain", "strain_rate", "stress_internal", "stress_surface"] + (["N1"] if tensors_every else [])
    rec = {name: xp.empty((n_steps, s.B)) for name in names}
    if tensors_every:
        rec["N1"][...] = math.nan
    if keep_tensors:
        rec["tensors"] = xp.empty((n_steps, s.B, len(TENSORS), 2, 2))
    say("Start application shear protocol, total N= " + str(n_steps if total is None else total) + " steps")
    engine.begin_phase("protocol", rec)        # (observers read the record's rows written so far)
    i = 0
    pending = []        # rates of a block's steps that the compiled block left to the loop below
    sampled = lambda k: _samples_tensors(k, n_steps, tensors_every, keep_tensors, end_tensors)    # noqa: E731
    while i < n_steps:
        j = i if pending else _block_end(engine, i, n_steps, after_step, observers)
        if j > i:       # steps without controller or observer in one compiled block (numba_step.run_block)
            rates = [rate_of(k) for k in range(i, j)]           # (rate_of once per step, in order)
            want = [sampled(k) for k in range(i, j)]
            T = xp.empty((j - i, s.B, len(TENSORS), 2, 2)) if any(want) else None
            done = run_block(engine, xp.stack(rates), cool, dt, rec, i, tensors=want, tensor_out=T)
            for k in range(done):
                if want[k]:
                    _record_tensors(rec, i + k, n_steps, T[k], tensors_every, keep_tensors, end_tensors)
            i += done
            if done:
                report(i, n_steps)
                notify(observers, engine, "protocol", i, n_steps)
            if i == j:
                continue
            pending = rates[done:]
        engine.set_rate(pending.pop(0) if pending else rate_of(i))
        rec["t"][i] = s.t
        rec["strain"][i] = s.gamma
        rec["strain_rate"][i] = s.rate
        out = engine.step(cool, dt, sample="tensors" if sampled(i) else True)
        rec["stress_internal"][i] = out[0]
        rec["stress_surface"][i] = out[1]
        if len(out) > 2:
            _record_tensors(rec, i, n_steps, out[2], tensors_every, keep_tensors, end_tensors)
        if after_step is not None:
            after_step(i, out[0], out[1])
        report(i + 1, n_steps)
        notify(observers, engine, "protocol", i + 1, n_steps)
        i += 1
    engine.flush()
    engine.end_phase()
    return {name: to_host(v, "series") for name, v in rec.items()}
