"""Integration of one Euler step: kick, plates, damping, the sequential ξ rule, drift (eqs. S1-10 … S1-12).

Two kinds of function, each operation written once:

- **pure expressions** (:func:`velocity_change`, :func:`half_velocity_change`, :func:`plate_velocity`,
  :func:`damped`, :func:`flow_shifted`, :func:`xi_rates`): values in, values out, on arrays or on
  numbers, evaluated by the NumPy step and by the compiled step (:mod:`particleShear.engine.numba_step`)
  alike (docs/backends.md, "One law, two drivers");
- **the NumPy step's array operations** built from them, in the array namespace of their inputs
  (NumPy or CuPy), on the rows they are given (a sphere block of B·N columns, or the N spheres of
  one ensemble: the batch engine's :meth:`~particleShear.engine.step.BatchEngine.step` and the
  documented canvases' ``mechanical_simulation_step_calculate_acceleration`` and
  ``…_calculate_movement`` call them).  :func:`kick`, :func:`plates_follow`, :func:`damp`,
  :func:`shift_flow`, :func:`remove_mean_velocity` and :func:`drift` update those rows in place
  (the state's arrays are updated, never replaced); :func:`half_kick`, :func:`mobile_mask` and
  :func:`xi_increments` return new arrays (the caller adds the ξ increments to ξ).

The order of a step (docs/engine.md, "One step"): forces → :func:`kick` → :func:`plates_follow`
→ :func:`damp` → :func:`xi_increments` (velocities after the kick and damping, positions of the force
phase) → :func:`drift` → strain → wrap (:func:`~particleShear.engine.box.wrap`) → clock.

Units: µm, s, mg per m depth; forces mg·µm·s⁻², torques mg·µm²·s⁻² per m depth.
"""
__docformat__ = "numpy"

from .xp import array_namespace, select

__all__ = ["velocity_change", "half_velocity_change", "plate_velocity", "flow_shifted", "damped", "xi_rates", "kick", "half_kick", "mobile_mask", "plates_follow", "damp", "shift_flow", "remove_mean_velocity",
           "xi_increments", "drift"]


def velocity_change(f, w, dt):
    """The kick of one velocity component by its force: ``F·dt/m`` (or ``T·dt/I``), a pure expression.

    :func:`kick` adds it on arrays; the compiled step (:mod:`particleShear.engine.numba_step`) on numbers.

    Parameters
    ----------
    f : ndarray or float
        Force (mg·µm·s⁻² per m depth) or torque (mg·µm²·s⁻² per m depth).
    w : ndarray or float
        Mass (mg per m depth) or moment of inertia (mg·µm² per m depth).
    dt : float
        Time step (s).

    Returns
    -------
    ndarray or float
        µm/s (or rad/s).
    """
    step = f * dt
    step /= w
    return step


def half_velocity_change(f, w, dt):
    """The velocity Verlet predictor's half kick of one component: ``F·dt/(2m)`` (pure; see :func:`half_kick`).

    Parameters
    ----------
    f, w : ndarray or float
        Force and mass (or torque and moment of inertia).
    dt : float
        Time step (s).

    Returns
    -------
    ndarray or float
    """
    h = f * dt
    h /= 2 * w
    return h


def plate_velocity(yc, plate_speed):
    """The x velocity of a plate sphere: ``+γ̇·Ly/2`` above the centre line, ``−γ̇·Ly/2`` below (pure).

    Parameters
    ----------
    yc : ndarray or float
        Height above the centre line (µm).
    plate_speed : ndarray or float
        ``γ̇·Ly/2`` (µm/s).

    Returns
    -------
    ndarray or float
    """
    return select(yc > 0, 1.0, -1.0) * plate_speed


def damped(v, flow, cool):
    """SLLOD-like damping of an x velocity: ``u + (v_x − u)·f`` (pure; see :func:`damp`).

    Parameters
    ----------
    v : ndarray or float
        x velocity (µm/s).
    flow : ndarray or float
        The affine flow's velocity u there (µm/s).
    cool : float
        Damping factor f.

    Returns
    -------
    ndarray or float
    """
    v = v - flow
    v *= cool
    v += flow
    return v


def xi_rates(rvx, rvy, nx, ny, mx, my, spin, rvx_ji):
    """``dξ_ij/dt`` and ``dξ_ji/dt`` of one pair or of arrays of pairs (the sequential rule, a pure expression).

    See :func:`xi_increments`, which composes the arguments; the compiled step calls it on numbers.

    Parameters
    ----------
    rvx, rvy : ndarray or float
        ``v_j − v_i + Δv_image`` (µm/s).
    nx, ny : ndarray or float
        Unit normal of the force phase.
    mx, my : ndarray or float
        Unit vector of ``R`` (the pair seen from j after i moved).
    spin : ndarray or float
        ``r_i ω_i + r_j ω_j`` (µm/s).
    rvx_ji : ndarray or float
        x relative velocity of the second visit (``rvx`` unless R was taken to another image).

    Returns
    -------
    inc_ij, inc_ji : ndarray or float
        µm/s.
    """
    return rvx * -ny + rvy * nx - spin, rvx_ji * my - rvy * mx - spin


def kick(vel, frc, weights, dt):
    """Kick every velocity by its force and reset the forces: ``v += F·dt/m``, ``ω += T·dt/I``.

    Parameters
    ----------
    vel : ndarray (k, n)
        Velocity rows (``vx, vy`` and, with k = 3, ``ω``) in µm/s and rad/s, modified in place.
    frc : ndarray (k, n)
        The matching force rows (``F_x, F_y`` and torque), set to 0 afterwards.
    weights : ndarray (k, n)
        ``(m, m, I)`` of every sphere (mg and mg·µm² per m depth), or ``(m, m)`` for k = 2.
    dt : float
        Time step (s).
    """
    vel += velocity_change(frc, weights, dt)
    frc[...] = 0.0


def half_kick(frc, weights, dt, mobile=None):
    """The velocity Verlet predictor's half kick ``F·dt/(2m)`` (and ``T·dt/(2I)``) of every sphere.

    The force phase of the next step sees the velocities moved half a kick ahead (the classes'
    ``integrator="verlet"``); plate spheres get no linear half kick.

    Parameters
    ----------
    frc : ndarray (k, n)
        Force rows ``F_x, F_y`` (and, with k = 3, the torque) of the last force phase.
    weights : ndarray (k, n)
        ``(m, m)`` or ``(m, m, I)`` of every sphere (mg and mg·µm² per m depth).
    dt : float
        Time step (s).
    mobile : ndarray of bool (n,), optional
        The mobile spheres; the others get 0 in the linear rows.  None: every sphere is mobile.

    Returns
    -------
    ndarray (k, n)
        Half kicks of the velocity rows (µm/s, and rad/s for ω).
    """
    h = half_velocity_change(frc, weights, dt)
    if mobile is not None:
        h[:2] = array_namespace(h).where(mobile, h[:2], 0.0)
    return h


def mobile_mask(r, y, Ly):
    """Which spheres move freely while the plates are on: ``r < y < Ly − r`` (docs/engine.md).

    A sphere overlapping ``y = 0`` or ``y = Ly`` is glued to its plate (:func:`plates_follow`); the
    same rule decides which pair forces count as external (eq. S1-16).

    Parameters
    ----------
    r, y : ndarray (n,) or float
        Radii and heights (µm).
    Ly : ndarray (n,) or float
        Cell height of each sphere's replica (µm).

    Returns
    -------
    ndarray of bool (n,) or bool
    """
    mob = r < y
    mob &= y < Ly - r
    return mob


def plates_follow(vx, vy, immobile, yc, plate_speed):
    """Immobile (plate) spheres take the velocity of their plate and no y velocity (docs/engine.md).

    A sphere overlapping ``y = 0`` or ``y = Ly`` while the shear is applied is glued to its plate:
    ``vx = ±γ̇·Ly/2`` (+ above the centre line), ``vy = 0``.  Applied after :func:`kick`, which
    gives the mobile spheres exactly the reference kick.

    Parameters
    ----------
    vx, vy : ndarray (n,)
        Velocities (µm/s), modified in place.
    immobile : ndarray of bool (n,)
        The plate spheres.
    yc : ndarray (n,)
        Height above the cell's centre line, ``y − Ly/2`` (µm).
    plate_speed : ndarray (n,) or float
        ``γ̇·Ly/2`` of each sphere's replica (µm/s).
    """
    xp = array_namespace(vx)
    plate = plate_velocity(yc, plate_speed)
    xp.copyto(vy, 0.0, where=immobile)
    xp.copyto(vx, plate, where=immobile)


def damp(vel, flow, cool):
    """Damp the velocity relative to the affine flow and the spin: ``v_x ← u + (v_x − u)·f``, ``v_y, ω ← f·…``.

    SLLOD-like damping (docs/engine.md): only the peculiar velocity loses ``1 − f`` per step, so
    a steady shear flow ``u = γ̇ (y − Ly/2)`` is not slowed down.

    Parameters
    ----------
    vel : ndarray (k, n)
        Velocity rows ``vx, vy`` (and ``ω``), modified in place.
    flow : ndarray (n,) or None
        The flow velocity ``u`` at each sphere (µm/s); None when there is no flow (γ̇ = 0), which
        multiplies the rows by ``f`` without subtracting and adding 0.
    cool : float
        Damping factor ``f`` of this step (1 = no damping).
    """
    if flow is None:
        vel *= cool
        return
    vel[0] = damped(vel[0], flow, cool)
    vel[1:] *= cool


def shift_flow(vx, omega, yc, delta):
    """A change ``Δγ̇`` of the shear rate without a velocity shock: ``v_x += (y − Ly/2)·Δγ̇``, ``ω −= Δγ̇/2``.

    Every sphere keeps its velocity relative to the affine flow and its spin relative to the
    flow's rotation rate ``−γ̇/2`` (docs/engine.md).  In place.

    Parameters
    ----------
    vx, omega : ndarray (n,)
        x velocities (µm/s) and spins (rad/s).
    yc : ndarray (n,)
        Heights above the cell's centre line, ``y − Ly/2`` (µm).
    delta : ndarray (n,) or float
        Change of the shear rate of each sphere's replica (1/s).
    """
    vx[...], omega[...] = flow_shifted(vx, omega, yc, delta)


def flow_shifted(vx, omega, yc, delta):
    """``(v_x + (y − Ly/2)·Δγ̇, ω − Δγ̇/2)``: the velocities after a change of the shear rate (pure; see :func:`shift_flow`).

    Parameters
    ----------
    vx, omega : ndarray or float
        x velocity (µm/s) and spin (rad/s).
    yc : ndarray or float
        Height above the cell's centre line (µm).
    delta : ndarray or float
        Change of the shear rate (1/s).

    Returns
    -------
    tuple
    """
    return vx + yc * delta, omega - delta / 2


def remove_mean_velocity(vel, B):
    """Subtract each replica's unweighted mean velocity from its spheres (``correct_linear_drift``).

    ``v ← v − Σ v / N`` per row over the N spheres of each replica (its contiguous columns).  The
    definition of the classes is the unweighted mean: with unequal masses the mean momentum is
    not removed exactly.  In place.

    Parameters
    ----------
    vel : ndarray (k, B·N)
        Velocity rows (µm/s).
    B : int
        Number of replicas.
    """
    k, n = vel.shape
    if not n:
        return
    N = n // B
    xp = array_namespace(vel)
    vel -= xp.repeat(vel.reshape(k, B, N).sum(axis=2) / N, N, axis=1)


def xi_increments(Vi, Vj, dvx, nx, ny, ri, rj, Rx, Ry, unit, dvx_ji=None):
    """Increments per unit time of the two tangential histories of a pair (sequential rule, Appendix B.2).

    The reference integrates ξ sphere by sphere after the kick: the relation i→j (i < j) is
    visited with both spheres at their positions of the force phase, the relation j→i with i
    already moved by ``v_i·dt``.  Both use the velocities after the kick and damping:

    * ``ξ̇_ij = (v_j − v_i + Δv_image)·t_ij − (r_i ω_i + r_j ω_j)``, ``t_ij = (−n_y, n_x)``;
    * ``ξ̇_ji = −(v_j − v_i + Δv_image)·t'_ji − (r_i ω_i + r_j ω_j)``, with ``t'_ji`` the tangent of
      the unit vector ``m`` along ``R = (x_i + v_i dt) − x_j`` (the pair vector seen from j after
      i moved).

    Parameters
    ----------
    Vi, Vj : ndarray (3, P)
        ``(vx, vy, ω)`` of spheres i and j of every pair (after the kick and damping).
    dvx : ndarray (P,) or float or None
        x velocity of j's image relative to j, ``−Ly·γ̇·k_y`` (µm/s); None or 0 when no pair
        interacts across the sheared boundary.
    nx, ny : ndarray (P,)
        Unit normal from i towards j of the force phase.
    ri, rj : ndarray (P,)
        Radii (µm).
    Rx, Ry : ndarray (P,)
        ``R = v_i·dt − D`` (µm), D the force phase's pair vector ``x_j − x_i``.
    unit : callable
        ``unit(Rx, Ry) -> (mx, my)``: the unit vector of R (with the random direction at
        ``|R| = 0`` of the caller's generator, see :func:`~particleShear.engine.forces.normals`).
    dvx_ji : ndarray (P,) or None
        x velocity of the image of i seen from j in the second visit, when R was taken to another
        image than the force phase's pair vector (a cell barely larger than a contact); None: the
        same image, i.e. ``−dvx``.

    Returns
    -------
    inc_ij, inc_ji : ndarray (P,)
        ``dξ_ij/dt`` and ``dξ_ji/dt`` (µm/s); the caller multiplies by ``dt`` on the relations that
        stick (0 on slipped ones and on candidates out of contact) and adds them to ξ.
    """
    rvx = Vj[0] - Vi[0]
    if dvx is not None:
        rvx = rvx + dvx
    rvy = Vj[1] - Vi[1]
    spin = ri * Vi[2] + rj * Vj[2]
    mx, my = unit(Rx, Ry)
    rvx_ji = rvx if dvx_ji is None else (Vj[0] - Vi[0]) - dvx_ji
    return xi_rates(rvx, rvy, nx, ny, mx, my, spin, rvx_ji)


def drift(pos, phi, vel, dt):
    """Drift and turn: ``x, y += (v_x, v_y)·dt``, ``φ += ω·dt`` (in place).

    Parameters
    ----------
    pos : ndarray (2, n)
        Positions (µm).
    phi : ndarray (n,) or None
        Orientations (rad); None to leave them (a canvas without spin).
    vel : ndarray (3, n) or (2, n)
        Velocities ``(vx, vy, ω)`` (µm/s, rad/s).
    dt : float
        Time step (s).
    """
    pos += vel[:2] * dt
    if phi is not None:
        phi += vel[2] * dt
