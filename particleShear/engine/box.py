"""Lees-Edwards box: minimum image, wrap and affine flow over arrays (docs/engine.md).

Every function takes per-element box lengths and offsets (arrays or scalars), so one call
serves pairs or spheres of many replicas with different boxes and strains.  Lengths in µm,
velocities in µm/s.  Periods are removed one at a time (as the reference does) in a bounded
number of passes.  The functions take the array namespace of their inputs (NumPy or CuPy,
:mod:`.xp`): on NumPy a pass loop stops as soon as nothing moved; on a device, where knowing
that would need a host read, every pass runs (a pass that moves nothing changes no value).
"""
__docformat__ = "numpy"

import contextlib

import numpy as np

from .xp import array_namespace, backend_of, maximum, minimum, select

__all__ = ["period_count", "folded", "min_image", "wrap", "flow_velocity", "inside_cell", "inside_half_cell", "in_intervals", "MAX_PASSES"]

#: one-period passes of :func:`min_image` and :func:`wrap` before the rest is folded in closed form
#: (floor): a protocol needs at most one or two, so ordinary states keep the exact subtractions of the
#: reference, and no coordinate, however large or infinite, makes a loop run longer
MAX_PASSES = 4


def period_count(v, half, minus_half):
    """−1, 0 or +1 as float: a period to subtract (``v ≥ half``) or to add (``v < minus_half``).

    The one pass of :func:`min_image` (``half = L/2``, ``minus_half = −L/2``) and of :func:`wrap`
    (``half = L``, ``minus_half = 0``); a pure expression, so the compiled step
    (:mod:`particleShear.engine.numba_step`) calls it on numbers.

    Parameters
    ----------
    v : ndarray or float
        Separations or coordinates (µm).
    half, minus_half : ndarray or float
        The interval ``[minus_half, half)`` (µm).

    Returns
    -------
    ndarray or float
    """
    return select(v >= half, 1.0, 0.0) - select(v < minus_half, 1.0, 0.0)


def in_intervals(dx, dy, Lx, Ly):
    """Where a separation lies in ``[−Lx/2, Lx/2) × [−Ly/2, Ly/2)``, the intervals of :func:`min_image`.

    The complement of :func:`period_count`'s rule on both axes: there :func:`min_image` removes no
    period and returns the separation unchanged.

    Parameters
    ----------
    dx, dy : ndarray
        Separations (µm).
    Lx, Ly : float or ndarray
        Box lengths (µm).

    Returns
    -------
    ndarray of bool
    """
    hx, hy = Lx / 2, Ly / 2
    return (dx < hx) & (dx >= -hx) & (dy < hy) & (dy >= -hy)


def _accumulate(total, k):
    """Running count of periods removed: the first pass's counts themselves, then their sum."""
    return k if total is None else total + k


def _quiet_invalid(xp):
    """Suppress NumPy's "invalid value" warning (inf − inf → NaN, reported by the guard); devices do not warn."""
    errstate = getattr(xp, "errstate", None)
    return errstate(invalid="ignore") if errstate is not None else contextlib.nullcontext()


def folded(v, L, lo, hi):
    """``v`` brought into ``[lo, hi)`` (``hi = lo + L``) in closed form: ``(folded v, periods removed)``.

    The pure expression of :func:`_fold` (numbers or arrays; the compiled step calls it on numbers).

    Parameters
    ----------
    v : ndarray or float
        Separations or coordinates (µm).
    L : ndarray or float
        The period (µm).
    lo, hi : ndarray or float
        The interval (µm).

    Returns
    -------
    tuple
        The folded value and the number of periods removed (float).
    """
    k = select((v >= hi) | (v < lo), np.floor((v - lo) / L), 0.0)
    return minimum(maximum(v - L * k, lo), np.nextafter(hi, lo)), k


def _fold(v, L, lo, hi, xp):
    """``v`` brought into ``[lo, hi)`` (``hi = lo + L``) in closed form; returns ``(folded v, periods removed)``.

    The whole periods ``k = floor((v − lo)/L)`` are removed from the elements outside the
    interval only (0 elsewhere, also for NaN, which stays NaN for the stability guard; an
    infinite element becomes NaN).  ``v − k·L`` can round onto ``hi`` or just outside for a
    coordinate of many periods; it is then clipped into ``[lo, hi)``, an adjustment of rounding
    size that changes no period count (so no Lees-Edwards carry), which keeps the post-condition
    of :func:`min_image` and :func:`wrap` for any finite input.
    """
    with _quiet_invalid(xp):
        return folded(v, L, lo, hi)


def min_image(dx, dy, Lx, Ly, shift):
    """Lees-Edwards minimum image of raw differences ``x_j − x_i`` (docs/engine.md, "State").

    The pair vector of a step is the separation to the nearest periodic image of j.  The y
    image is chosen first and moves x by ``shift = Ly·γ`` (the offset of the image rows
    above and below); intervals are half-open, ``[−L/2, L/2)``.  All arguments broadcast
    against each other, so one call serves the pairs of many replicas.

    Parameters
    ----------
    dx, dy : ndarray or float
        Raw differences ``x_j − x_i``, ``y_j − y_i`` of the pairs' positions (µm).
    Lx, Ly : ndarray or float
        Box lengths of each pair's replica (µm, > 0), per element or shared.
    shift : ndarray or float
        Lees-Edwards offset ``Ly·γ`` of each pair's replica (µm).

    Returns
    -------
    dx, dy : ndarray
        The minimum-image separation (µm), each in ``[−L/2, L/2)``.
    ky, kx : ndarray of float
        Numbers of y and x periods removed (``ky`` gives the image velocity correction
        ``−Ly·γ̇·ky`` in µm/s).

    Notes
    -----
    Periods are subtracted one at a time, as in the reference (so the result is bit-identical
    to its loop, which differs from ``dx − k·Lx`` by an ulp when ``|k| ≥ 2``), for at most
    :data:`MAX_PASSES` passes; what is still outside then is folded in closed form and clipped
    into the interval against rounding, so the cost does not grow with the size of a separation
    and the result is inside the intervals for any finite input.  A separation already inside
    both (:func:`in_intervals`) is returned unchanged where the offset is finite.  A NaN stays NaN
    (count 0); an infinite difference becomes NaN.  This is the one minimum image of the package (the
    engine, the documented classes, the per-sphere API, cuts and drawings call it).
    """
    be = backend_of(dx, dy)
    xp = be.xp
    hy, hx = Ly / 2, Lx / 2          # the interval bounds, computed once for all passes
    mhy, mhx = -hy, -hx
    ky_total = kx_total = None
    for _ in range(MAX_PASSES):
        ky = period_count(dy, hy, mhy)
        if be.host and not ky.any():
            break
        dy = dy - Ly * ky
        dx = dx - shift * ky
        ky_total = _accumulate(ky_total, ky)
    else:  # absurd separation (or a device, which ran every pass): fold what is still outside at once
        dy, ky = _fold(dy, Ly, mhy, hy, xp)
        with _quiet_invalid(xp):
            dx = dx - shift * ky
        ky_total = _accumulate(ky_total, ky)
    for _ in range(MAX_PASSES):
        kx = period_count(dx, hx, mhx)
        if be.host and not kx.any():
            break
        dx = dx - Lx * kx
        kx_total = _accumulate(kx_total, kx)
    else:
        dx, kx = _fold(dx, Lx, mhx, hx, xp)
        kx_total = _accumulate(kx_total, kx)
    if ky_total is None:
        ky_total = xp.zeros(getattr(dx, "shape", ()))
    if kx_total is None:
        kx_total = xp.zeros(getattr(dx, "shape", ()))
    return dx, dy, ky_total, kx_total


def inside_cell(x, y, Lx, Ly):
    """Whether every position lies in the cell ``[0, Lx) × [0, Ly)`` (host arrays; False for a NaN).

    The test before a wrap: with every sphere inside, :func:`wrap` has nothing to do.

    Parameters
    ----------
    x, y : ndarray (n,)
        Positions (µm).
    Lx, Ly : ndarray (n,) or float
        Box lengths of each sphere's replica (µm).

    Returns
    -------
    bool
    """
    xp = array_namespace(x)
    for v, L in ((y, Ly), (x, Lx)):
        if not (xp.minimum.reduce(v, initial=xp.inf) >= 0 and (v < L).all()):
            return False
    return True


def wrap(x, y, vx, Lx, Ly, shift, rate):
    """Bring positions into ``[0, Lx) × [0, Ly)`` in place (Lees-Edwards wrap, docs/engine.md).

    A sphere leaving through the top re-enters at the bottom in the image frame that moves
    with the flow: crossing ``y = Ly`` moves x by ``−shift`` (``shift = Ly·γ`` after the strain
    update) and vx by ``−Ly·γ̇``; crossing ``y = 0`` the reverse.  Then x is wrapped into
    ``[0, Lx)``.  The velocity correction is the reference's ``vx += (y' − y)·γ̇`` with ``y`` and
    ``y'`` the heights before and after the wrap (exactly ``∓Ly·γ̇`` for one crossing; the
    same number as the reference's also for several), on the spheres that moved: the others keep
    their x and velocity to the bit (a ``−0.0`` included, whatever the offset), so a replica's
    trajectory does not depend on whether a sphere of another replica of its batch crossed.

    Parameters
    ----------
    x, y, vx : ndarray (B·N,)
        Positions (µm) and x velocities (µm/s) of the spheres, modified in place.
    Lx, Ly : ndarray (B·N,) or float
        Box lengths of each sphere's replica (µm).
    shift : ndarray (B·N,) or float
        Lees-Edwards offset ``Ly·γ`` of each sphere's replica (µm).
    rate : ndarray (B·N,) or float
        Shear rate γ̇ of each sphere's replica (1/s).

    Returns
    -------
    bool or None
        True if any sphere was moved by a period; None on a device (knowing it needs a host read).

    Notes
    -----
    Periods are subtracted one at a time, as in the reference, for at most :data:`MAX_PASSES`
    passes per axis; what is still outside then is folded in closed form and clipped into the
    cell against rounding, so the cost is O(1) in the size of a coordinate and every finite
    position ends inside the cell.  A NaN coordinate stays NaN (and is not moved); an infinite
    one becomes NaN, which the stability guard reports.  Unlike the reference's sequential
    loops (first every ``y ≥ Ly`` pass, then every ``y < 0`` pass), each pass tests both sides,
    so a coordinate a hair below 0 that rounds onto ``L`` ends at 0, inside the half-open cell.
    This is the one wrap of the package (the engine, the documented classes and the per-sphere API
    call it).
    """
    be = backend_of(x, y)
    xp = be.xp
    if be.host and inside_cell(x, y, Lx, Ly):
        return False          # the common step: nothing crossed (three reductions per axis, not five)
    moved = False if be.host else None
    y0 = None if be.host else y.copy()   # heights before the wrap, for the velocity correction
    for _ in range(MAX_PASSES):
        up = period_count(y, Ly, 0.0)
        if be.host:
            if not up.any():
                break
            if y0 is None:
                y0 = y.copy()
            moved = True
        y -= Ly * up
        x[...] = xp.where(up != 0, x - shift * up, x)     # (a sphere not moved keeps its x to the bit)
    else:  # absurd coordinate (or a device, which ran every pass): fold what is still outside at once
        y[...], up = _fold(y, Ly, 0.0, Ly, xp)
        with _quiet_invalid(xp):
            x[...] = xp.where(up != 0, x - shift * up, x)
    if y0 is not None:      # a sphere moved by a period takes the flow's velocity difference; the others keep theirs
        with _quiet_invalid(xp):
            vx[...] = xp.where(y != y0, vx + (y - y0) * rate, vx)
    for _ in range(MAX_PASSES):
        right = period_count(x, Lx, 0.0)
        if be.host:
            if not right.any():
                break
            moved = True
        x -= Lx * right
    else:
        x[...], _ = _fold(x, Lx, 0.0, Lx, xp)
    return moved


def flow_velocity(y, Ly, rate):
    """x velocity ``γ̇ (y − Ly/2)`` of the affine shear flow at height y.

    The imposed flow field: the centre line of the cell is at rest, the top moves with
    ``+γ̇·Ly/2``.  Damping acts on the velocity relative to it (docs/engine.md).

    Parameters
    ----------
    y : ndarray or float
        Heights (µm).
    Ly : ndarray or float
        Box height of each element's replica (µm).
    rate : ndarray or float
        Shear rate γ̇ (1/s).

    Returns
    -------
    ndarray or float
        The flow's x velocity (µm/s).
    """
    return (y - Ly / 2) * rate


def inside_half_cell(dx, dy, Lx, Ly):
    """Whether raw coordinate differences stay below half the cell in x and in y.

    A bond whose raw differences do so does not cross the periodic boundary: it is *physical*
    (``physical_neighbors_only`` of the compact particles).

    Parameters
    ----------
    dx, dy : ndarray or float
        Raw differences of the two spheres' coordinates (µm).
    Lx, Ly : float
        Box lengths (µm).

    Returns
    -------
    ndarray of bool or bool
    """
    return (abs(dx) < Lx / 2) & (abs(dy) < Ly / 2)
