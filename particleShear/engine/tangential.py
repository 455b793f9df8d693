"""Tangential two-visit rule over arrays (reference §2.6-2.8, Appendix B.3), written once.

Used by the engine's step and by the documented canvas classes alike.  Forces in
mg·µm·s⁻² per m depth, ξ in µm, velocities in µm/s.
"""
import numpy as np

__all__ = ["tangential_two_pass"]


def tangential_two_pass(vt, touching, xi, kt_i, kt_j, nut_i, nut_j, f_coulomb):
    """Two-visit tangential force of each pair (§2.6-2.8, B.3), transient contacts and bonds alike.

    ``vt`` is the slip velocity, ``xi`` the (2, P) array of ξ_ij, ξ_ji, ``kt_*``/``nut_*``
    the effective constants of each visit, ``f_coulomb`` the Coulomb bound (``inf``
    for permanent pairs, which never slip).  The viscous part acts only on touching
    pairs.  Visit 1 (from i) sees ξ_ij; visit 2 (from j) sees ξ_ji, reset to 0 if
    visit 1 slipped; a slip in either visit resets both histories.  Both visits are
    evaluated as the two rows of one (2, P) array.  Updates ``xi`` in place and
    returns ``(F, slip2)``: the scalar forces of the two visits (rows, both along
    t_ij as seen from i) and the final slip flag.
    """
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
        ft = np.empty_like(xi)
        np.multiply(kt_i, xi[0], out=ft[0])
        np.multiply(kt_j, xi[1], out=ft[1])
    if ftv_j is ftv_i:
        ft += ftv_i
    else:
        ft[0] += ftv_i
        ft[1] += ftv_j
    a = np.abs(ft)
    slip1 = a[0] > f_coulomb
    any_slip1 = np.count_nonzero(slip1)
    if any_slip1:
        # visit 2 sees ξ_ji = 0 after a slip in visit 1
        np.copyto(ft[1], ftv_j, where=slip1)
        np.abs(ft[1], out=a[1])
    slip2 = a[1] > f_coulomb
    F = np.copysign(np.minimum(a, f_coulomb, out=a), ft, out=a)
    if any_slip1:
        slip2_or_1 = slip1 | slip2
        np.copyto(xi, 0.0, where=slip2_or_1)
    elif np.count_nonzero(slip2):
        np.copyto(xi, 0.0, where=slip2)
    return F, slip2
