"""Creep: the plate stress held at ``creep_stress`` (Pa) for ``hold_time``·τ (docs/protocols.md).

One step at rest (the residual stress σ_res), then γ̇ chosen every step by a
proportional-integral controller on the filtered plate stress so that it follows the applied σ₀
(:class:`CreepController`), the way a stress-controlled rheometer drives its motor.  The summary
is J(t) = γ(t)/σ₀ on a log grid, the final creep rate, σ₀/γ̇ and the strain plateau.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..parameter_entry import Parameter
from . import MAX_STRAIN_PER_STEP, positive, register_protocol

__all__ = ["PROTOCOL", "PARAMETERS", "CreepController", "CREEP_MODULUS_FRACTION"]

POSITION = 3
SIGNATURE = True
#: the controller's modulus scale, as a fraction of Young_modulus_spheres when creep_modulus is None
#: (the default packing has G′ ≈ 0.14 E, so the closed loop settles in about one response time)
CREEP_MODULUS_FRACTION = 0.125

PARAMETERS = (
    Parameter('hold_time', 200.0, 'float', unit='τ', role='protocol:creep', batch='shared', keyword_only=True, doc='``protocol="relaxation"`` and ``"creep"``: duration of the hold, in units of τ; allowed 0 < value <= 1e9 within the step limit'),
    Parameter('creep_stress', None, 'float', unit='Pa', role='protocol:creep', keyword_only=True, nullable=True, doc='``protocol="creep"`` (required there): applied shear stress σ₀ in Pa, > 0'),
    Parameter('creep_modulus', None, 'float', unit='Pa', role='protocol:creep', keyword_only=True, nullable=True, doc='``protocol="creep"``: modulus scale G_c (Pa) of the stress controller; None: Young_modulus_spheres/8 (docs/protocols.md)'),
    Parameter('creep_response_time', 5.0, 'float', unit='τ', role='protocol:creep', batch='shared', keyword_only=True, doc='``protocol="creep"``: response time T_c of the stress controller in units of τ; allowed >= 10 time steps'),
)

_P = "; empty unless protocol is 'creep'"
COLUMNS = {
    "residual_stress": ("float", "Pa", "plate stress σ_res of the packing at rest before the step strain or "
                        "stress (the origin of G(t); a solid creeps by (σ₀ − σ_res)/G)"
                        "; empty unless protocol is 'relaxation' or 'creep'"),
    "creep_rate": ("float", "1/s", "final creep rate dγ/dt over the last 20 % of the hold" + _P),
    "creep_rate_se": ("float", "1/s", "standard error of creep_rate (5 sub-windows)" + _P),
    "creep_viscosity": ("float", "Pa·s", "creep_stress/creep_rate (inf when the strain does not grow)" + _P),
    "strain_plateau": ("float", "1", "strain γ(t) − γ(0) over the last 20 % of the hold (its plateau for a solid)" + _P),
    "strain_plateau_se": ("float", "1", "standard error of strain_plateau by block averaging" + _P),
    "stress_tracking": ("float", "1", "(mean plate stress over the second half of the hold − σ₀)/σ₀" + _P),
}


def check(q):
    """``hold_time``, ``creep_stress`` (required), ``creep_modulus`` (or None) and ``creep_response_time`` > 0.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).

    Raises
    ------
    ValueError, TypeError
        Naming the parameter, its value and the allowed range.
    """
    positive("hold_time", q["hold_time"], 1e9)
    if q["creep_stress"] is None:
        raise ValueError("creep_stress=None is invalid with protocol='creep': give the applied stress σ₀ in Pa "
                         "(> 0; flag --creep-stress)")
    positive("creep_stress", q["creep_stress"], 1e12)
    if q["creep_modulus"] is not None:
        positive("creep_modulus", q["creep_modulus"], 1e15)
    positive("creep_response_time", q["creep_response_time"], 1e9)


def check_steps(q, steps):
    """A controller response time of at least 10 steps.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range.
    """
    dtr = steps["dt_over_tau"]
    T = float(q["creep_response_time"])
    if T < 10 * dtr:
        raise ValueError(f"creep_response_time={T!r} is out of range: the controller needs >= 10 steps per "
                         f"response time, allowed >= {10 * dtr:.4g} (flag --creep-response-time)")


def steps(q, dt_over_tau):
    """``steps``: the hold over the time step, rounded up (its first step at rest).

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    dt_over_tau : callable
        ``dt_over_tau(amplitude=None)``: the protocol time step in units of τ (at ``theAmplitude`` or the amplitude given).

    Returns
    -------
    dict
        ``dt_over_tau`` and the protocol's counts (module docstring of :mod:`particleShear.protocols`).
    """
    dtr = dt_over_tau()
    return {"dt_over_tau": dtr, "steps": int(math.ceil(float(q["hold_time"]) / dtr))}


def room(q, steps, steps_ok):
    """``hold_time`` shortens a creep run.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    steps_ok : float
        The most steps the run may take.

    Returns
    -------
    tuple of str
        ``(parameter, allowed text)``.
    """
    room = steps_ok * steps["dt_over_tau"]
    return "hold_time", f"hold_time <= {max(room, 0.0):.4g}"


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


def schedule(kws, steps, tau, dt, backend):
    """The controller of every replica (σ₀, G_c per replica; T_c shared), |γ̇| <= MAX_STRAIN_PER_STEP/dt.

    Parameters
    ----------
    kws : list of dict
        The arguments of the batch's replicas, in batch order.
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    tau : float
        Model time constant τ (s).
    dt : float
        Time step (s).
    backend : Backend
        The batch's array backend (``asarray``, ``xp``).

    Returns
    -------
    dict
        ``n_steps``, ``rate_of(i)`` (γ̇ of every replica at step i, 1/s) and optionally ``after_step``, ``tensors_every``.
    """
    G_c = [k["creep_modulus"] if k["creep_modulus"] is not None else
           CREEP_MODULUS_FRACTION * k["Young_modulus_spheres"] for k in kws]
    ctl = CreepController(backend.xp, backend.asarray(np.asarray([k["creep_stress"] for k in kws], dtype=float)),
                          backend.asarray(np.asarray(G_c, dtype=float)), kws[0]["creep_response_time"] * tau, dt,
                          MAX_STRAIN_PER_STEP / dt)
    return {"n_steps": steps[0]["steps"], "rate_of": ctl.rate_of, "after_step": ctl.after_step}


def summary(kw, series, tau, steps, stats):
    """J(t), the final creep rate, σ₀/γ̇, the strain plateau and the stress tracking (module docstring).

    Parameters
    ----------
    kw : dict
        The run's arguments.
    series : dict of ndarray
        The replica's record (:func:`particleShear.engine.rheometer.shear_record`).
    tau : float
        Model time constant τ (s).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    stats : namespace
        :data:`particleShear.run.rheometer_analysis.STATS` (estimators, statistics, verdict checks).

    Returns
    -------
    tuple of dict
        ``(scalars, curves, checks)``: column → value, ``name → (t, y, y_sem)``, check → bool or None.
    """
    t = series["t"]
    out, curves = {}, {}
    s0 = kw["creep_stress"]
    gam = series["strain"] - series["strain"][0]
    out["creep_stress"] = s0
    rate, rate_se = stats.final_rate(t, gam)
    out["creep_rate"], out["creep_rate_se"] = rate, rate_se
    out["creep_viscosity"] = s0 / rate if rate > 0 else math.inf
    ba = stats.plateau(t, gam)
    out["strain_plateau"], out["strain_plateau_se"] = ba.mean, ba.sem
    half = t >= t[-1] / 2
    res0 = float(series["stress_surface"][0])      # step 0 at rest: the residual stress
    out["residual_stress"] = res0
    out["stress_tracking"] = float((series["stress_surface"][half].mean() - s0) / s0)
    tm, jm, js, _ = stats.log_grid(t, gam / s0)
    curves["J"] = (tm, jm, js)
    dt = float(t[1] - t[0]) if len(t) >= 2 else math.nan
    checks = stats.verdicts.creep_checks(t, series["strain_rate"], out["stress_tracking"], MAX_STRAIN_PER_STEP / dt,
                                         kw["hold_time"], kw["creep_response_time"])
    return out, curves, checks


def values(s):
    """``[final creep rate, σ₀/γ̇]``.

    Parameters
    ----------
    s : dict
        The run's summary.

    Returns
    -------
    list of float
    """
    return [s["creep_rate"], s["creep_viscosity"]]


def shorten(q, steps, n, steps_of):
    """The hold cut to ``n`` steps.

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    steps : dict or list of dict
        The protocol's step counts (its ``steps``; for ``schedule`` and ``segments`` one per replica, in batch order).
    n : int
        About how many steps the cut protocol takes.
    steps_of : callable
        ``steps_of(q)``: the step counts of other arguments.

    Returns
    -------
    dict
        The parameters to change.
    """
    return {"hold_time": min(float(q["hold_time"]), n * steps["dt_over_tau"])}


PROTOCOL = register_protocol("creep", parameters=PARAMETERS,
                             shorten=shorten, shown=("creep_rate", "creep rate", "1/s"),
                             header=("creep_stress", "creep_modulus", "creep_response_time", "hold_time"), file_name=("stress", "creep_stress"),
                             required=("creep_rate", "strain_plateau"), steps=steps, check=check, check_steps=check_steps,
                             schedule=schedule, summary=summary, values=values, columns=COLUMNS,
                             checks=("stress_held", "rate_unsaturated", "hold_sufficient"), room=room,
                             quantities={"creep_rate": "1/s", "creep_viscosity": "Pa·s", "strain_plateau": "1",
                                         "residual_stress": "Pa"},
                             doc="a constant applied stress")
