"""Tangential two-visit rule over arrays (docs/design.md, "One step"), written once.

Used by the engine's step and by the documented canvas classes alike, on the array namespace of
its inputs (NumPy or CuPy, :mod:`.xp`).  Forces in mg·µm·s⁻² per m depth, ξ in µm, velocities
in µm/s.
"""
__docformat__ = "numpy"

import numpy as np

from .xp import array_namespace

__all__ = ["tangential_two_pass"]


def tangential_two_pass(vt, touching, xi, kt_i, kt_j, nut_i, nut_j, f_coulomb):
    """Two-visit tangential force of each pair, transient contacts and bonds alike (docs/design.md).

    The reference visits each pair twice per step, once from each sphere, and each visit
    applies half of its force; this function evaluates both visits at once as the two rows of
    one (2, P) array.  Each visit's force is ``k_t·ξ + ν_t·v_t``, clipped to ``f_coulomb``.
    The viscous part acts only on touching pairs.  Visit 1 (from i) sees ξ_ij; visit 2
    (from j) sees ξ_ji, reset to 0 if visit 1 slipped; a slip in either visit resets both
    histories.  The torque split of the resulting force is eq. S1-3 (done by the caller).

    Parameters
    ----------
    vt : ndarray (P,)
        Tangential slip velocity of each pair along ``t_ij`` seen from i (µm/s).
    touching : ndarray (P,) of float or bool
        1 where the pair overlaps geometrically (``d < r_i + r_j``), else 0.
    xi : ndarray (2, P)
        Tangential displacement histories ξ_ij, ξ_ji (µm); reset to 0 in place on slip.
    kt_i, kt_j : ndarray (P,) or float
        Effective tangential spring constants of visits 1 and 2 (mg·s⁻² per m depth); pass
        the same object twice when they are equal (one multiplication then).
    nut_i, nut_j : ndarray (P,) or float
        Effective tangential viscosities of visits 1 and 2 (mg·s⁻¹ per m depth); the same
        object twice when equal.
    f_coulomb : ndarray (P,) or float
        Coulomb bound ``|μ·F_elastic|`` of each pair (mg·µm·s⁻² per m depth, ≥ 0; ``inf``
        for permanent pairs, which never slip).

    Returns
    -------
    F : ndarray (2, P)
        Scalar tangential forces of the two visits (rows, both along ``t_ij`` as seen from i;
        mg·µm·s⁻² per m depth).
    slip2 : ndarray of bool (P,)
        The final slip flag (visit 2 exceeded the bound).
    """
    xp = array_namespace(xi, vt)
    on_host = isinstance(xi, np.ndarray)   # NumPy: skip the resets when nothing slipped (free to know on the host)
    # viscous part on touching pairs only: ×1 is exact; ×0 gives a zero whose sign may differ from
    # +0, which changes nothing downstream (added to k_t·ξ, and ξ is never −0)
    ftv_i = nut_i * vt
    ftv_i *= touching
    if nut_j is nut_i:
        ftv_j = ftv_i
    else:
        ftv_j = nut_j * vt
        ftv_j *= touching
    if kt_j is kt_i:
        ft = kt_i * xi
    else:
        ft = xp.empty_like(xi)
        xp.multiply(kt_i, xi[0], out=ft[0])
        xp.multiply(kt_j, xi[1], out=ft[1])
    if ftv_j is ftv_i:
        ft += ftv_i
    else:
        ft[0] += ftv_i
        ft[1] += ftv_j
    a = xp.abs(ft)
    slip1 = a[0] > f_coulomb
    any_slip1 = xp.count_nonzero(slip1) if on_host else True   # a device resets where-masked, unconditionally
    if any_slip1:
        # visit 2 sees ξ_ji = 0 after a slip in visit 1
        xp.copyto(ft[1], ftv_j, where=slip1)
        xp.abs(ft[1], out=a[1])
    slip2 = a[1] > f_coulomb
    F = xp.copysign(xp.minimum(a, f_coulomb, out=a), ft, out=a)
    if any_slip1:
        slip2_or_1 = slip1 | slip2
        xp.copyto(xi, 0.0, where=slip2_or_1)
    elif xp.count_nonzero(slip2):
        xp.copyto(xi, 0.0, where=slip2)
    return F, slip2
