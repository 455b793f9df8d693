"""The stability guard's rule, written once for the engine and the documented classes.

A replica is *sound* while its state is finite, its kinetic energy relative to the affine flow
stays below a bound, and no transient contact has closed to less than a fraction of its contact
distance (the divergent law, eq. S1-5b, is then hundreds of times stiffer than at contact and the
explicit step starts to pump energy).  :meth:`~particleShear.engine.step.BatchEngine._check`
applies the rule to every replica of a batch; :class:`~particleShear.base.stability.StabilityGuard`
applies it to an ensemble of the documented classes (a batch of one) and names the sphere or
pair at fault.  Neither changes the physics.

Units: µm, s, mg per m depth; energies in mg·µm²·s⁻² per m depth.
"""
__docformat__ = "numpy"

import math

from .xp import array_namespace, select

__all__ = ["SOUND", "NON_FINITE", "KINETIC_ENERGY", "INTERPENETRATION", "kinetic_term", "energy_bound", "verdict_code",
           "transient_ratio", "verdict", "transient_ratios",
           "closest_transient"]

#: verdict codes, in the order they are tested (the first that holds is reported)
SOUND, NON_FINITE, KINETIC_ENERGY, INTERPENETRATION = 0, 1, 2, 3


def kinetic_term(m, u, vy, inertia, omega):
    """Twice the kinetic energy of a sphere relative to the flow, ``m |u|² + I ω²`` (pure).

    Parameters
    ----------
    m, inertia : ndarray or float
        Mass (mg per m depth) and moment of inertia (mg·µm² per m depth).
    u, vy : ndarray or float
        Peculiar x velocity ``v_x − γ̇ (y − Ly/2)`` and y velocity (µm/s).
    omega : ndarray or float
        Spin (rad/s).

    Returns
    -------
    ndarray or float
        mg·µm²·s⁻² per m depth.
    """
    return m * (u * u + vy * vy) + inertia * omega * omega


def energy_bound(N, k, r_mean, m_sum, rate_max, Ly):
    """The default bound of a replica's kinetic energy, ``N·k'·r_mean² + Σ m (γ̇_max·Ly/2)²`` (pure; see :func:`verdict`).

    Parameters
    ----------
    N : int
        Spheres per replica.
    k, r_mean, m_sum, rate_max, Ly : ndarray (B,) or float
        Spring constant, mean radius (µm), total mass, largest |γ̇| seen (1/s) and cell height (µm).

    Returns
    -------
    ndarray or float
    """
    plate = rate_max * Ly / 2
    return N * select(k > 0, k, 1.0) * (r_mean * r_mean) + m_sum * plate * plate


def verdict_code(finite, ke, bound, closest, min_distance_ratio):
    """The verdict code of a replica from its checks, in the order of the rule (pure; see :func:`verdict`).

    Parameters
    ----------
    finite : ndarray of bool or bool
        The state is finite.
    ke, bound : ndarray or float
        Kinetic energy relative to the flow and its bound.
    closest : ndarray or float
        Smallest ``d/(r_i + r_j)`` of a transient contact.
    min_distance_ratio : float
        Its smallest allowed value.

    Returns
    -------
    ndarray of int or int
        :data:`NON_FINITE`, :data:`KINETIC_ENERGY`, :data:`INTERPENETRATION` or :data:`SOUND`.
    """
    return select(~finite, NON_FINITE, select(ke > bound, KINETIC_ENERGY,
                                               select(closest < min_distance_ratio, INTERPENETRATION, SOUND)))


def transient_ratio(d, d0, active, trans):
    """``d/d0`` of a transient relation, inf otherwise (pure; see :func:`transient_ratios`).

    Parameters
    ----------
    d, d0 : ndarray or float
        Distance and contact distance (µm).
    active, trans : ndarray of bool or bool
        A relation; a candidate that is no bond.

    Returns
    -------
    ndarray or float
    """
    return select(active & trans, d / d0, math.inf)


def verdict(B, x, yc, vx, vy, omega, rate_s, m, inertia, r, k, Ly, rate_max, closest, min_distance_ratio=0.05,
            max_kinetic_energy=None):
    """The guard's verdict of each replica: ``(code, ke, bound)``, arrays (B,).

    ``ke = ½ Σ (m |u|² + I ω²)`` with the peculiar velocity ``u = (v_x − γ̇ (y − L_y/2), v_y)``;
    ``bound = N·k'·r_mean² + Σ m (γ̇_max·L_y/2)²`` — every sphere compressed by its mean radius,
    plus twice the energy of every sphere at the fastest plate speed seen — with ``k' = k`` for
    ``k > 0`` and 1 otherwise (a replica without springs is not failed for any motion), or
    ``max_kinetic_energy`` where given.  ``code`` is :data:`NON_FINITE` if a position, velocity
    or spin is not finite, else :data:`KINETIC_ENERGY` if ``ke > bound``, else
    :data:`INTERPENETRATION` if ``closest < min_distance_ratio``, else :data:`SOUND`.

    Parameters
    ----------
    B : int
        Number of replicas; the sphere arrays hold B rows of N spheres each.
    x, yc, vx, vy, omega : array (B·N,)
        x and the height above the centre line ``y − Ly/2`` (µm), velocities (µm/s) and spins (rad/s).
    rate_s : array (B·N,) or float
        Shear rate γ̇ of each sphere's replica (1/s).
    m, inertia, r : array (B·N,)
        Masses, moments of inertia and radii.
    k : array (B,)
        Spring constant of each replica (eq. S1-8).
    Ly : array (B,)
        Cell height of each replica (µm).
    rate_max : array (B,)
        Largest ``|γ̇|`` seen so far (1/s).
    closest : array (B,)
        Smallest ``d/(r_i + r_j)`` of a transient contact (:func:`closest_transient`; inf: none).
    min_distance_ratio : float
        Smallest allowed ``closest``.
    max_kinetic_energy : float or None
        A fixed bound instead of the default one.

    Returns
    -------
    tuple of arrays (B,)
        ``(code, ke, bound)``.
    """
    xp = array_namespace(x)
    N = len(x) // B
    state = xp.stack((x, yc, vx, vy, omega)).reshape(5, B, N)
    finite = xp.isfinite(state).all(axis=(0, 2))
    ke = 0.5 * kinetic_term(m, vx - yc * rate_s, vy, inertia, omega).reshape(B, N).sum(axis=1)
    if max_kinetic_energy is None:
        bound = energy_bound(N, k, r.reshape(B, N).mean(axis=1), m.reshape(B, N).sum(axis=1), rate_max, Ly)
    else:
        bound = xp.full(B, float(max_kinetic_energy))
    return verdict_code(finite, ke, bound, closest, min_distance_ratio), ke, bound


def transient_ratios(C, d, active):
    """``d/(r_i + r_j)`` of each transient contact (a relation that is no bond), inf for the other candidates.

    Parameters
    ----------
    C : PairConstants
        The candidates (``d0``, ``trans``).
    d : array (P,)
        Distance of each candidate (µm).
    active : array of bool (P,)
        Relations (touching or bonded).
    """
    return transient_ratio(d, C.d0, active, C.trans)


def closest_transient(C, d, active):
    """Smallest ``d/(r_i + r_j)`` of a transient contact (no bond) of each replica: array (B,), inf where none.

    One reduction over each replica's own contiguous segment of candidates.

    Parameters
    ----------
    C : PairConstants
        The candidates (``d0``, ``trans``, the segments).
    d : array (P,)
        Distance of each candidate (µm).
    active : array of bool (P,)
        Relations (touching or bonded).
    """
    xp = array_namespace(d)
    ratio = transient_ratios(C, d, active)
    if C.replica_sum is not None:       # a device: the padded gather (inf for a replica without pairs)
        return C.replica_sum.minimum(ratio)
    closest = xp.full(C.B, math.inf)
    if C.P:
        closest[C.seg_rep_b] = xp.minimum.reduceat(ratio, C.seg_starts_b)
    return closest
