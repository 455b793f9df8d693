"""Lees-Edwards box: minimum image, wrap and affine flow over arrays (docs/design.md).

Every function takes per-element box lengths and offsets (arrays or scalars), so one call
serves pairs or spheres of many replicas with different boxes and strains.  Lengths in µm,
velocities in µm/s.  Periods are removed one at a time (as the reference does) in a bounded
number of passes.
"""
import numpy as np

__all__ = ["min_image", "wrap", "flow_velocity", "MAX_PASSES"]

#: one-period passes of :func:`min_image` and :func:`wrap` before the rest is folded in closed form
#: (floor): a protocol needs at most one or two, so ordinary states keep the exact subtractions of the
#: reference, and no coordinate, however large or infinite, makes a loop run longer
MAX_PASSES = 4


def _count(v, half):
    """−1, 0 or +1 per element as float: a period to subtract (``v ≥ half``) or to add (``v < −half``)."""
    return (v >= half).astype(float) - (v < -half)


def min_image(dx, dy, Lx, Ly, shift):
    """Lees-Edwards minimum image of raw differences ``x_j − x_i`` (eq. of docs/design.md, reference §3.1).

    The y image is chosen first and moves x by ``shift = Ly·γ``; intervals are half-open,
    ``[−L/2, L/2)``.  Returns ``(dx, dy, ky, kx)``: the image separation and the numbers of
    y and x periods removed (floats; ``ky`` gives the velocity correction ``−Ly·γ̇·ky``).

    At most :data:`MAX_PASSES` one-period passes, then the rest is folded in closed form, so
    the cost does not grow with the size of a separation.
    """
    ky_total = np.zeros(np.shape(dx))
    for _ in range(MAX_PASSES):
        ky = _count(dy, Ly / 2)
        if not ky.any():
            break
        dy = dy - Ly * ky
        dx = dx - shift * ky
        ky_total += ky
    else:  # absurd separation: fold the rest at once (non-finite values become NaN for the guard)
        ky = np.floor((dy + Ly / 2) / Ly)
        dy = dy - Ly * ky
        dx = dx - shift * ky
        ky_total += ky
    kx_total = np.zeros(np.shape(dx))
    for _ in range(MAX_PASSES):
        kx = _count(dx, Lx / 2)
        if not kx.any():
            break
        dx = dx - Lx * kx
        kx_total += kx
    else:
        kx = np.floor((dx + Lx / 2) / Lx)
        dx = dx - Lx * kx
        kx_total += kx
    return dx, dy, ky_total, kx_total


def wrap(x, y, vx, Lx, Ly, shift, rate):
    """Bring positions into ``[0, Lx) × [0, Ly)`` in place (reference §3.3).

    Crossing ``y = Ly`` moves x by ``−shift`` (``shift = Ly·γ`` after the strain update) and
    vx by ``−Ly·γ̇``; crossing ``y = 0`` the reverse.  ``Lx``, ``Ly``, ``shift`` and ``rate``
    are per-sphere arrays.  Returns True if anything moved.
    """
    moved = False
    for _ in range(MAX_PASSES):
        up = (y >= Ly).astype(float) - (y < 0)
        if not up.any():
            break
        moved = True
        y -= Ly * up
        x -= shift * up
        vx -= (Ly * rate) * up
    else:  # absurd coordinate: fold the rest at once (non-finite values become NaN for the guard)
        up = np.floor(y / Ly)
        y -= Ly * up
        x -= shift * up
        vx -= (Ly * rate) * up
    for _ in range(MAX_PASSES):
        right = (x >= Lx).astype(float) - (x < 0)
        if not right.any():
            break
        moved = True
        x -= Lx * right
    else:
        x -= Lx * np.floor(x / Lx)
    return moved


def flow_velocity(y, Ly, rate):
    """x velocity ``γ̇ (y − Ly/2)`` of the affine shear flow at height y (µm/s, reference §4.4)."""
    return (y - Ly / 2) * rate
