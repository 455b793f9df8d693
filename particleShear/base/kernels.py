"""The Lees-Edwards box with the signatures of the documented classes (lengths µm, velocities µm/s).

Each function calls the engine (:mod:`particleShear.engine.box`) and keeps the conventions of
earlier versions (scalar box, an image velocity correction that is None when nothing wrapped, int
period counts).
"""
__docformat__ = "numpy"

import numpy as np

from ..engine import box as _box

__all__ = ["min_image", "le_wrap"]


def min_image(dx, dy, Lx, Ly, shift, shear_rate=0.0, passes=None, counts=False):
    """Lees-Edwards minimum image of raw differences: ``(dx, dy, dvx)``, with ``counts`` also ``(ky, kx)``.

    The y image is chosen first and moves x by ``shift``; each result lies in ``[−L/2, L/2)``.  Periods
    are subtracted one at a time as in the reference (bit-identical), beyond the engine's
    ``MAX_PASSES`` in closed form.  ``dvx = −Ly·γ̇·ky`` (µm/s) is the x velocity of j's image relative to j, None when no
    pair wrapped in y or γ̇ = 0; ``ky, kx`` (int8) are the periods subtracted per pair, both None when
    a pair needed more than one or a difference was not finite.

    Parameters
    ----------
    dx, dy : array_like (P,)
        Raw differences ``x_j − x_i``, ``y_j − y_i`` (µm).
    Lx, Ly : float
        Box lengths (µm).
    shift : float
        Lees-Edwards offset ``Ly·γ`` (µm).
    shear_rate : float
        γ̇ (1/s).
    passes : tuple of two int, optional
        Ignored (the passes stop when one moves nothing).
    counts : bool
        Also return the period counts.
    """
    Ly = float(Ly)
    dx, dy, ky, kx = _box.min_image(np.asarray(dx, dtype=float), np.asarray(dy, dtype=float),
                                    float(Lx), Ly, float(shift))
    rate_shift = Ly * float(shear_rate)
    dvx = -rate_shift * ky if rate_shift != 0 and ky.any() else None
    if not counts:
        return dx, dy, dvx
    # a count of several periods (or NaN) cannot reproduce the repeated subtraction bit for bit
    if (np.abs(ky) <= 1).all() and (np.abs(kx) <= 1).all():
        return dx, dy, dvx, ky.astype(np.int8), kx.astype(np.int8)
    return dx, dy, dvx, None, None


def le_wrap(x, y, vx, Lx, Ly, shift, shear_rate):
    """Wrap positions into ``[0, Lx) × [0, Ly)`` in place; return True if any moved by a period.

    Crossing y = Ly moves x by ``−shift`` and vx by ``−Ly·γ̇`` (the reverse through y = 0); an
    infinite coordinate comes out NaN.

    Parameters
    ----------
    x, y, vx : ndarray (N,)
        Positions (µm) and x velocities (µm/s).
    Lx, Ly : float
        Box lengths (µm).
    shift : float
        Lees-Edwards offset ``Ly·γ`` (µm).
    shear_rate : float
        γ̇ (1/s).
    """
    return bool(_box.wrap(x, y, vx, float(Lx), float(Ly), float(shift), float(shear_rate)))
