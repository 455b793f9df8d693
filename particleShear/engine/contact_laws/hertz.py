r"""The Hertz law of two elastic spheres of unequal radii, in the model's units.

.. math::

   F = -s\,k\,\sqrt{R^*}\,\delta^{3/2} / \ell,\qquad R^* = \frac{r_i r_j}{r_i + r_j},\qquad
   \delta = \max(d_0 - d, 0)                                                       \tag{H-1}

with ``s = hertz_scale`` (dimensionless), ``k`` the model's spring constant (mg·s⁻² per m depth,
``k = π E/8``, eq. S1-8) and ``ℓ = 1 µm`` the model's unit of length: the Hertz force
``F = k_H √R* δ^{3/2}`` of two spheres with ``k_H = s·k/ℓ`` (mg·s⁻²·µm⁻¹ per m depth), so that
``√R*·δ^{3/2}/ℓ`` is a length (µm) and ``F`` a force per m depth (mg·µm·s⁻² per m), negative
(repulsive) for an overlap, 0 at contact (``d = d0``) and beyond (the caller discards it there).
The Hertz scaling is kept exactly: ``F ∝ √R*`` at a given overlap and ``F ∝ δ^{3/2}``.  The
repulsion coefficient ``c`` of the linear law is not read (the Hertz law replaces the compressive
law of contacts and of compressed bonds, ``d0 = d_eq`` for those).

Default ``hertz_scale = 0.05``: the stiffness of (H-1), ``dF/dδ = 1.5·s·k·√(R*δ)/ℓ``, equals the
linear law's ``k`` where ``√(R*δ) = 1/(1.5 s) µm = 13.3 µm``; in the default packing (N = 150,
φ = 1.5 in a 500 × 500 µm cell, bimodal factor 1.4: radii ≈ 23.5 and 33 µm, ``R*`` ≈ 14 µm) that
is an overlap ``δ`` ≈ 13 µm ≈ 0.2·d0, and over overlaps 0.05·d0 … 0.5·d0 the ratio of the Hertz
to the linear stiffness stays within about 0.5 … 1.5 — the same order of magnitude, so the default time
step (chosen from ``k``) stays stable.
"""
__docformat__ = "numpy"

import numpy as np

from ...parameter_entry import Parameter
from ..laws import register_law
from ..xp import maximum

__all__ = ["hertz", "PARAMETERS", "LAW"]

PARAMETERS = (
    Parameter('hertz_scale', 0.05, 'float', unit='1', low=0, high=1000.0, low_open=True, role='law:hertz',
              doc='Scale s of the Hertz law F = −s·k·√R*·δ^{3/2}/(1 µm) of ``contact_law="hertz"`` '
                  '(eq. H-1, docs/engine.md), dimensionless'),
)


def hertz(d, d0, r_i, r_j, k, c, hertz_scale):
    """Hertz force of two spheres: ``−s·k·√R*·δ^{3/2}/(1 µm)``, ``R* = r_i r_j/(r_i + r_j)``, ``δ = max(d0 − d, 0)`` (eq. H-1).

    Parameters
    ----------
    d : ndarray or float
        Centre distance (µm).
    d0 : ndarray or float
        Contact distance (µm): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    r_i, r_j : ndarray or float
        Radii of the two spheres (µm, > 0).
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Repulsion coefficient of the linear law (not read).
    hertz_scale : ndarray or float
        ``s``, dimensionless (> 0).

    Returns
    -------
    ndarray or float
        Central force on i along ``n_ij`` (mg·µm·s⁻² per m depth): < 0 (repulsive) for ``d < d0``,
        0 for ``d ≥ d0``.
    """
    overlap = maximum(d0 - d, 0.0)
    reduced = r_i * r_j / (r_i + r_j)
    return -hertz_scale * k * np.sqrt(reduced) * overlap * np.sqrt(overlap)


LAW = register_law("hertz", hertz, PARAMETERS, radii=True, built_in=True)
