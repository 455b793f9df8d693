"""Blow-up detection: stop a diverging integration with a clear error instead of silent NaNs."""
__docformat__ = "numpy"

import math

import numpy as np

from ..engine.guard import INTERPENETRATION, KINETIC_ENERGY, NON_FINITE, verdict

__all__ = ["SimulationInstabilityError", "StabilityGuard"]


class SimulationInstabilityError(RuntimeError):
    """The integration diverged; every argument is stored under its own name.

    Parameters
    ----------
    message : str
        The explanation (the exception's text).
    step, phase : int, str or None
        Step and phase (e.g. pre-equilibration or shear) at which it was detected.
    pair : tuple of int or None
        The worst sphere ``(k,)`` or pair ``(i, j)`` (``sphereList`` indices).
    suggested_dt : float or None
        A time step (s) likely to be stable.
    reason : str or None
        The short cause (non-finite state, kinetic energy bound, interpenetration).
    """

    def __init__(self, message, step=None, phase=None, pair=None, suggested_dt=None, reason=None):
        RuntimeError.__init__(self, message)
        vars(self).update(step=step, phase=phase, pair=pair, suggested_dt=suggested_dt, reason=reason)


class StabilityGuard:
    """Checks finiteness, peculiar kinetic energy and interpenetration of an ensemble (never changes the physics).

    The rule is the engine's guard, :func:`particleShear.engine.guard.verdict`, on the ensemble as a
    batch of one; this class names the sphere or pair at fault and suggests a time step.

    Parameters
    ----------
    min_distance_ratio : float
        Smallest allowed ``d / (r_i + r_j)`` of a transient contact (0.05: the divergent law is
        then ~400× stiffer than at contact and the explicit step starts to pump energy).
    max_kinetic_energy : float or None
        Bound on the kinetic energy relative to the affine flow (mg·µm²/s² per m); None uses
        ``N·k·r_mean² + Σ m (γ̇_max·Ly/2)²`` (every sphere compressed by its radius, plus twice the
        energy of every sphere at the largest plate speed seen; k taken as 1 where it is 0).
    interval : int
        Check every ``interval``-th step (a blow-up grows by orders of magnitude per step).
    """

    def __init__(self, min_distance_ratio=0.05, max_kinetic_energy=None, interval=4):
        self.min_distance_ratio = min_distance_ratio
        self.max_kinetic_energy = max_kinetic_energy
        self.interval = max(1, int(interval))
        self._rate_max = 0.0

    def suggested_dt(self, ens, dt):
        """Return the time step (s) to suggest: half ``dt``, at most 5 % of ``sqrt(m_min/k)``.

        Parameters
        ----------
        ens : canvas
            The ensemble (masses, ``k`` and ``k_t`` are read).
        dt : float or None
            The current time step (s); None or 0 when unknown.
        """
        a = ens._a
        k = max(float(getattr(ens, "k", 0) or 0), float(getattr(ens, "k_t", 0) or 0), 1e-300)
        m_min = float(a["m"].min()) if len(a["m"]) else 1.0
        return min(dt / 2, 0.05 * math.sqrt(m_min / k)) if dt else 0.05 * math.sqrt(m_min / k)

    def check(self, ens, step=None, phase=None, dt=None):
        """Raise :class:`SimulationInstabilityError` if ``ens`` has diverged (checked every ``interval``-th step).

        Parameters
        ----------
        ens : canvas
        step : int or None
            Current step; None checks unconditionally.
        phase : str or None
            Name of the phase, for the message.
        dt : float or None
            Current time step (s), for the message and the suggestion.
        """
        if step is not None and step % self.interval:
            return
        a = ens._a
        if not len(a["x"]):
            return
        rate = float(getattr(ens, "shear_rate", 0) or 0)
        self._rate_max = max(self._rate_max, abs(rate))
        closest = ens._closest_contact() if hasattr(ens, "_closest_contact") else None
        x, y, vx, vy, om = a["x"], a["y"], a["xspeed"], a["yspeed"], a["omega"]
        code, ke, bound = (float(v[0]) for v in verdict(
            1, x, y - ens.size_y / 2, vx, vy, om, rate, a["m"], a["inertia"], a["r"],
            np.array([float(getattr(ens, "k", 0) or 0)]), np.array([float(ens.size_y)]), np.array([self._rate_max]),
            np.array([math.inf if closest is None else closest[0]]), self.min_distance_ratio,
            self.max_kinetic_energy))
        if code == NON_FINITE:
            k = int(np.flatnonzero(~(np.isfinite(x) & np.isfinite(y) & np.isfinite(vx) & np.isfinite(vy)
                                     & np.isfinite(om)))[0])
            self._fail(ens, step, phase, dt, f"non-finite state of sphere {k}: (x, y) = ({float(x[k])!r}, "
                       f"{float(y[k])!r}) µm, (vx, vy) = ({float(vx[k])!r}, {float(vy[k])!r}) µm/s, "
                       f"ω = {float(om[k])!r} rad/s", pair=(k,))
        if code == KINETIC_ENERGY:
            u = vx - rate * (y - ens.size_y / 2)
            worst = int(np.argmax(a["m"] * (u * u + vy * vy)))
            self._fail(ens, step, phase, dt, f"kinetic energy {ke:.3g} exceeds the bound {bound:.3g}",
                       pair=(worst,))
        if code == INTERPENETRATION:
            ratio, i, j = closest
            self._fail(ens, step, phase, dt, f"spheres {i} and {j} interpenetrate (d/(r_i+r_j) = {ratio:.3g})",
                       pair=(i, j))

    def _fail(self, ens, step, phase, dt, reason, pair=None):
        sdt = self.suggested_dt(ens, dt)
        msg = (f"simulation became unstable at step {step} of phase {phase!r}: {reason}"
               + (f"; worst pair/sphere {pair}" if pair else "")
               + (f"; time step {dt:.4g} s, try dt <= {sdt:.4g} s" if dt else f"; try dt <= {sdt:.4g} s"))
        raise SimulationInstabilityError(msg, step=step, phase=phase, pair=pair, suggested_dt=sdt, reason=reason)
