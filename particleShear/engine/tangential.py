"""Tangential two-visit rule over arrays (docs/engine.md, "One step"), written once.

Used by the engine's step and by the documented canvas classes alike, on the array namespace of
its inputs (NumPy or CuPy, :mod:`.xp`).  Forces in mg·µm·s⁻² per m depth, ξ in µm, velocities
in µm/s.
"""
__docformat__ = "numpy"

import numpy as np

from .xp import array_namespace, select

__all__ = ["two_visit_rule", "coulomb_clip", "tangential_two_pass"]


def coulomb_clip(ft, a, fc):
    """A trial tangential force clipped to the Coulomb bound: ``copysign(min(|ft|, fc), ft)``.

    Parameters
    ----------
    ft : ndarray or float
        Trial force ``k_t·ξ + ν_t·v_t`` (mg·µm·s⁻² per m depth).
    a : ndarray or float
        Its magnitude ``|ft|`` (computed once by the caller, who also compares it with the bound).
    fc : ndarray or float
        Coulomb bound (≥ 0; ``inf`` for a bond).

    Returns
    -------
    ndarray or float
    """
    return np.copysign(np.minimum(a, fc), ft)


def two_visit_rule(vt, touching, xi_ij, xi_ji, kt_i, kt_j, nut_i, nut_j, f_coulomb):
    """The two-visit tangential rule of one pair (or of arrays of pairs), a pure expression.

    The reference visits each pair twice per step, once from each sphere, and each visit
    applies half of its force.  Each visit's trial force is ``k_t·ξ + ν_t·v_t`` (the viscous part
    on touching pairs only), clipped to ``f_coulomb`` (:func:`coulomb_clip`).  Visit 1 (from i)
    sees ξ_ij; visit 2 (from j) sees ξ_ji, or 0 if visit 1 slipped; a slip in either visit resets
    both histories.  Written with arithmetic, ``abs/minimum/copysign`` and
    :func:`~particleShear.engine.xp.select` only (docs/backends.md, "One law, two drivers"): the
    NumPy engine calls it on arrays (:func:`tangential_two_pass`), the compiled driver on numbers.

    Parameters
    ----------
    vt : ndarray or float
        Tangential slip velocity along ``t_ij`` seen from i (µm/s).
    touching : ndarray or float
        1 where the pair overlaps geometrically (``d < r_i + r_j``), else 0.
    xi_ij, xi_ji : ndarray or float
        Tangential displacement histories of the two visits (µm).
    kt_i, kt_j : ndarray or float
        Tangential spring constants of visits 1 and 2 (mg·s⁻² per m depth).
    nut_i, nut_j : ndarray or float
        Tangential viscosities of visits 1 and 2 (mg·s⁻¹ per m depth).
    f_coulomb : ndarray or float
        Coulomb bound ``|μ·F_elastic|`` (mg·µm·s⁻² per m depth, ≥ 0; ``inf`` for bonds).

    Returns
    -------
    F_i, F_j : ndarray or float
        Tangential forces of the two visits (along ``t_ij`` seen from i; mg·µm·s⁻² per m depth).
    slip : ndarray of bool or bool
        The final slip flag (visit 2 exceeded the bound).
    reset : ndarray of bool or bool
        Whether the histories are reset to 0 (a slip in either visit).
    """
    # the viscous part on touching pairs only: ×1 is exact; ×0 gives a zero whose sign may differ
    # from +0, which changes nothing downstream (added to k_t·ξ, and ξ is never −0)
    v = vt * touching
    ftv_i = nut_i * v
    ftv_j = nut_j * v
    ft_i = kt_i * xi_ij + ftv_i
    a_i = np.abs(ft_i)
    slip_i = a_i > f_coulomb
    ft_j = select(slip_i, ftv_j, kt_j * xi_ji + ftv_j)     # visit 2 sees ξ_ji = 0 after a slip in visit 1
    a_j = np.abs(ft_j)
    slip_j = a_j > f_coulomb
    return coulomb_clip(ft_i, a_i, f_coulomb), coulomb_clip(ft_j, a_j, f_coulomb), slip_j, slip_i | slip_j


def tangential_two_pass(vt, touching, xi, kt_i, kt_j, nut_i, nut_j, f_coulomb):
    """Two-visit tangential force of each pair (:func:`two_visit_rule` over arrays); resets ``xi`` in place.

    Parameters
    ----------
    vt : ndarray (P,)
        Tangential slip velocity of each pair along ``t_ij`` seen from i (µm/s).
    touching : ndarray (P,) of float or bool
        1 where the pair overlaps geometrically (``d < r_i + r_j``), else 0.
    xi : ndarray (2, P)
        Tangential displacement histories ξ_ij, ξ_ji (µm); reset to 0 in place on slip.
    kt_i, kt_j : ndarray (P,) or float
        Effective tangential spring constants of visits 1 and 2 (mg·s⁻² per m depth).
    nut_i, nut_j : ndarray (P,) or float
        Effective tangential viscosities of visits 1 and 2 (mg·s⁻¹ per m depth).
    f_coulomb : ndarray (P,) or float
        Coulomb bound ``|μ·F_elastic|`` of each pair (mg·µm·s⁻² per m depth, ≥ 0; ``inf``
        for permanent pairs, which never slip).

    Returns
    -------
    F : tuple of two ndarray (P,)
        Scalar tangential forces of the two visits (both along ``t_ij`` as seen from i;
        mg·µm·s⁻² per m depth).
    slip2 : ndarray of bool (P,)
        The final slip flag (visit 2 exceeded the bound).
    """
    F_i, F_j, slip, reset = two_visit_rule(vt, touching, xi[0], xi[1], kt_i, kt_j, nut_i, nut_j, f_coulomb)
    xp = array_namespace(xi, vt)
    # NumPy: skip the reset when nothing slipped (free to know on the host); a device resets unconditionally
    if not isinstance(xi, np.ndarray) or xp.count_nonzero(reset):
        xp.copyto(xi, 0.0, where=reset)
    return (F_i, F_j), slip
