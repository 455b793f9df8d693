"""The linear law of particleShear 1.0.2 (the default): the blend of eqs. S1-5a and S1-5b.

``F = −k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)`` (eq. S1-6 caps ``d0/d`` at 1000): the
arithmetic is :func:`particleShear.engine.laws.central_law`, which the engine evaluates from
prepared constants (:func:`~particleShear.engine.laws.central_constants`) and the documented
callback ``elastic_force_law`` shares.  No parameters of its own; the radii are not read.
"""
__docformat__ = "numpy"

from ..laws import central_law, register_law

__all__ = ["linear", "PARAMETERS", "LAW"]

POSITION = 0
#: the law has no parameters of its own
PARAMETERS = ()


def linear(d, d0, r_i, r_j, k, c):
    """Linear/divergent blend: ``−k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)`` (eqs. S1-5a, S1-5b, S1-6).

    Parameters
    ----------
    d, d0 : ndarray or float
        Centre distance and contact distance (µm).
    r_i, r_j : ndarray or float
        Radii (µm; not read).
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Central repulsion coefficient in [0, 1].

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` as if in contact (mg·µm·s⁻² per m depth; ≤ 0 for ``d ≤ d0``).
    """
    return central_law(d, d0, k, c)


LAW = register_law("linear", linear, PARAMETERS, radii=True, built_in=True)
