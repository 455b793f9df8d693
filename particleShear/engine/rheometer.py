"""The rheometer's other protocols on a batch: steady shear, stress relaxation, creep (docs/protocols.md).

Each protocol is a *rate schedule* — the strain rate γ̇ of every replica at every step — driven
through the one step (:meth:`~particleShear.engine.step.BatchEngine.step`) by one recording loop,
:func:`shear_record`, after the plates' pre-equilibration
(:func:`~particleShear.engine.step.pre_equilibrate`):

- :func:`steady_shear` — a constant γ̇ per replica from the first step (``set_rate`` moves every
  sphere onto the new flow, so the start is no velocity shock);
- :func:`stress_relaxation` — a ramp at the constant rate ``γ₀/t_ramp`` for ``n_ramp`` steps,
  then γ̇ = 0 (the strain is held at γ₀);
- :func:`creep` — γ̇ chosen every step by a proportional-integral controller on the filtered
  plate stress so that it follows the applied σ₀ (:class:`CreepController`), the way a
  stress-controlled rheometer drives its motor.

The one-packing amplitude and frequency sweeps are sequences of the oscillatory protocol
(:func:`~particleShear.engine.step.protocol`) on the same engine (:mod:`particleShear.run.rheometer`).

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

import numpy as np

from .observers import check_observers, notify
from .stress import TENSORS
from .xp import to_host

__all__ = ["shear_record", "steady_shear", "stress_relaxation", "creep", "CreepController", "OVERALL"]

#: index of the overall stress tensor (eq. S1-24) in the engine's tensor registry
OVERALL = [t.name for t in TENSORS].index("overall_stress_tensor")


def _quiet(*args):
    pass


def shear_record(engine, dt, cool, n_steps, rate_of, tensors_every=0, say=_quiet, report=_quiet, observers=(),
                 after_step=None):
    """Step every replica ``n_steps`` times at the rates ``rate_of`` gives, recording the series.

    At step i: ``γ̇ = rate_of(i)`` (set with ``set_rate``, keeping each sphere's velocity
    relative to the flow), record t, γ, γ̇, step with the stresses sampled, record them, then
    ``after_step(i, tau_internal, tau_surface)`` when given (a controller's update).  The clock
    is reset to 0 at the start; the strain continues from its current value.

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

    Returns
    -------
    dict of numpy.ndarray (n_steps, B)
        "t", "strain", "strain_rate", "stress_internal", "stress_surface" and, with
        ``tensors_every``, "N1" (Pa; NaN where not sampled).
    """
    check_observers(observers)
    s, xp = engine.s, engine.xp
    s.applying_shear = True
    s.t = xp.zeros(s.B)
    names = ["t", "strain", "strain_rate", "stress_internal", "stress_surface"] + (["N1"] if tensors_every else [])
    rec = {name: xp.empty((n_steps, s.B)) for name in names}
    if tensors_every:
        rec["N1"][...] = math.nan
    engine.record = rec
    say("Start application shear protocol, total N= " + str(n_steps) + " steps")
    engine.phase = "protocol"
    engine.step_count = 0
    for i in range(n_steps):
        engine.set_rate(rate_of(i))
        rec["t"][i] = s.t
        rec["strain"][i] = s.gamma
        rec["strain_rate"][i] = s.rate
        tensors = bool(tensors_every) and i % tensors_every == 0
        out = engine.step(cool, dt, sample="tensors" if tensors else True)
        rec["stress_internal"][i] = out[0]
        rec["stress_surface"][i] = out[1]
        if tensors:
            T = out[2][:, OVERALL]
            rec["N1"][i] = -(T[:, 0, 0] - T[:, 1, 1])
        if after_step is not None:
            after_step(i, out[0], out[1])
        report(i + 1, n_steps)
        notify(observers, engine, "protocol", i + 1, n_steps)
    engine.flush()
    engine.record = None
    return {name: to_host(v, "series") for name, v in rec.items()}


def steady_shear(engine, dt, cool, rate, n_steps, tensors_every=10, **loop):
    """Constant shear rate γ̇ per replica for ``n_steps`` steps (flow curves, docs/protocols.md).

    Parameters
    ----------
    engine : BatchEngine
        The pre-equilibrated batch.
    dt : float
        Time step (s).
    cool : float
        Damping factor per step.
    rate : array_like (B,)
        γ̇ of each replica (1/s).
    n_steps : int
        Steps (the longest replica's).
    tensors_every : int, default 10
        N1 sampling period in steps (the overall tensor costs about one step).
    **loop
        ``say``, ``report``, ``observers`` of :func:`shear_record`.

    Returns
    -------
    dict of numpy.ndarray (n_steps, B)
        The record of :func:`shear_record`.
    """
    R = engine.backend.asarray(np.asarray(rate, dtype=float))
    return shear_record(engine, dt, cool, n_steps, lambda i: R, tensors_every, **loop)


def stress_relaxation(engine, dt, cool, gamma0, n_ramp, n_hold, **loop):
    """One step at rest, a strain ramp to γ₀ in ``n_ramp`` steps at the rate ``γ₀/(n_ramp·dt)``, then ``n_hold`` steps at γ̇ = 0.

    The step at rest records the residual stress of the packing, the origin of G(t).

    Parameters
    ----------
    engine : BatchEngine
        The pre-equilibrated batch.
    dt : float
        Time step (s).
    cool : float
        Damping factor per step.
    gamma0 : array_like (B,)
        Step strain γ₀ of each replica.
    n_ramp, n_hold : int
        Steps of the ramp (≥ 1) and of the hold.
    **loop
        ``say``, ``report``, ``observers`` of :func:`shear_record`.

    Returns
    -------
    dict of numpy.ndarray (1 + n_ramp + n_hold, B)
        The record of :func:`shear_record`.
    """
    xp = engine.xp
    ramp = engine.backend.asarray(np.asarray(gamma0, dtype=float) / (n_ramp * dt))
    zero = xp.zeros(engine.s.B)
    return shear_record(engine, dt, cool, 1 + n_ramp + n_hold, lambda i: ramp if 1 <= i <= n_ramp else zero, **loop)


class CreepController:
    """Proportional-integral control of the strain rate that holds the plate stress at σ₀.

    Per replica, step 0 at rest measures the residual plate stress σ_res (the filter's start);
    from step 1 on, with the error ``e = σ₀ − σ̄`` of the filtered plate stress σ̄ (τ_surface,
    the stress a rheometer's motor feels):

    ``γ̇ = (e + I/T_i)/η_c``,   ``I ← I + e·dt``   (not while γ̇ is at its bound: no wind-up),

    with the controller viscosity ``η_c = G_c·T_c`` (a modulus scale G_c, the response time
    T_c) and ``T_i = T_c``; σ̄ follows τ_surface with the time constant ``T_f = T_c/5``
    (``σ̄ ← σ̄ + (τ − σ̄)·dt/T_f``).  γ̇ is bounded by ``±rate_max``.  For a Kelvin–Voigt solid
    (σ = Gγ + ηγ̇) the closed loop is linear with characteristic polynomial
    ``(η_c + η)s² + (G + η/T_i)s + G/T_i`` (filter neglected), all coefficients positive:
    stable, no steady-state error, settling in ≈ (η_c + η)/G; for a flowing sample (σ = ηγ̇)
    the integral term removes the steady error in ≈ T_i (η_c + η)/η.  The measured tracking
    is in docs/protocols.md.

    Parameters
    ----------
    xp : module
        Array namespace of the batch.
    sigma0 : array (B,)
        Applied stress of each replica (Pa).
    G_c : array (B,)
        Modulus scale of each replica (Pa).
    T_c : float
        Response time (s).
    dt : float
        Time step (s).
    rate_max : float
        Largest |γ̇| (1/s).
    """

    def __init__(self, xp, sigma0, G_c, T_c, dt, rate_max):
        self.xp = xp
        self.sigma0 = sigma0
        self.eta_c = G_c * T_c
        self.T_i = T_c
        self.alpha = min(1.0, dt / (T_c / 5))
        self.dt = dt
        self.rate_max = rate_max
        self.filtered = xp.zeros_like(sigma0)
        self.residual = xp.zeros_like(sigma0)
        self.integral = xp.zeros_like(sigma0)
        self.rate = xp.zeros_like(sigma0)

    def rate_of(self, i):
        """γ̇ of step i (1/s) from the filtered stress of the steps before it; 0 at step 0.

        Step 0 runs at rest and measures the residual plate stress σ_res of the packing (a finite
        packing carries one after pre-equilibration, docs/protocols.md), which starts the filter;
        the controller holds the total plate stress at σ₀, as a stress-controlled rheometer does.

        Parameters
        ----------
        i : int
            Step index.

        Returns
        -------
        array (B,)
            The strain rate of each replica (1/s).
        """
        xp = self.xp
        if i == 0:
            return self.rate
        e = self.sigma0 - self.filtered
        trial = self.integral + e * self.dt
        # the integral advances only where its rate is within the bound (no wind-up)
        self.integral = xp.where(xp.abs(e + trial / self.T_i) <= self.rate_max * self.eta_c, trial, self.integral)
        self.rate = xp.clip((e + self.integral / self.T_i) / self.eta_c, -self.rate_max, self.rate_max)
        return self.rate

    def after_step(self, i, tau_internal, tau_surface):
        """Filter the plate stress of the step just taken.

        Parameters
        ----------
        i : int
            Step index (unused).
        tau_internal, tau_surface : array (B,)
            Shear stresses of the step (Pa); the plate's, ``tau_surface``, is the controlled one.
        """
        if i == 0:     # at rest: the residual stress, the origin of the applied stress
            self.residual = tau_surface
            self.filtered = tau_surface
            return
        self.filtered = self.filtered + (tau_surface - self.filtered) * self.alpha


def creep(engine, dt, cool, sigma0, G_c, T_c, n_steps, rate_max, **loop):
    """Constant applied shear stress σ₀ per replica for ``n_steps`` steps, held by :class:`CreepController`.

    Parameters
    ----------
    engine : BatchEngine
        The pre-equilibrated batch.
    dt : float
        Time step (s).
    cool : float
        Damping factor per step.
    sigma0 : array_like (B,)
        Applied stress of each replica (Pa, > 0).
    G_c : array_like (B,)
        The controller's modulus scale per replica (Pa).
    T_c : float
        The controller's response time (s).
    n_steps : int
        Steps.
    rate_max : float
        Bound of |γ̇| (1/s).
    **loop
        ``say``, ``report``, ``observers`` of :func:`shear_record`.

    Returns
    -------
    dict of numpy.ndarray (n_steps, B)
        The record of :func:`shear_record`.
    """
    be = engine.backend
    ctl = CreepController(engine.xp, be.asarray(np.asarray(sigma0, dtype=float)),
                          be.asarray(np.asarray(G_c, dtype=float)), T_c, dt, rate_max)
    return shear_record(engine, dt, cool, n_steps, ctl.rate_of, after_step=ctl.after_step, **loop)
