"""Small pure functions over arrays: Lees-Edwards geometry and pair terms (docs/design.md).

Every function takes and returns NumPy arrays (or scalars) and never touches an
ensemble; they are the hot path of a step and reusable by other back-ends.
Lengths in µm, velocities in µm/s, forces in mg·µm·s⁻² per m depth.
"""
__docformat__ = "numpy"

import numpy as np

# NumPy-only speed shims live in the namespace module (no private NumPy import here)
from .namespace import count_nonzero as _nz, where as _where

__all__ = ["min_image", "le_wrap", "pair_geometry", "tangential_two_pass", "MAX_LOOP_PASSES"]


#: one-period passes applied one at a time, as the reference does, before the closed form takes over;
#: ordinary coordinates (within a couple of periods of the cell) never reach it, so their results stay
#: bit-identical to the reference loop, while a huge coordinate costs O(1) instead of O(|x| / L) passes
MAX_LOOP_PASSES = 4


def _wrap_count(v, half):
    """−1, 0 or +1 per element: one period to subtract (``v ≥ half``) or add (``v < −half``)."""
    return (v >= half).view(np.int8) - (v < -half).view(np.int8)


def _periods_to_subtract(v, L, lo):
    """Whole periods ``k`` (float array) that bring ``v − k·L`` into ``[lo, lo + L)``; 0 where already there.

    The closed form for coordinates that one-period passes would need many iterations for;
    non-finite entries give NaN (``inf − inf``), which the stability guard and the step report.
    """
    with np.errstate(invalid="ignore", over="ignore"):
        k = np.floor((v - lo) / L)
    return np.where((v >= lo) & (v < lo + L), 0.0, k)


def _fold(v, L, lo):
    """``v`` brought into ``[lo, lo + L)`` with the closed form; returns (folded v, periods subtracted)."""
    k = _periods_to_subtract(v, L, lo)
    with np.errstate(invalid="ignore"):
        w = v - k * L
        # rounding of v − k·L can land one period off; a huge |v| can leave an ulp-sized excess
        w = np.where(w >= lo + L, w - L, w)
        w = np.where(w < lo, w + L, w)
        w = np.where(np.isfinite(w), np.clip(w, lo, np.nextafter(lo + L, lo)), w)
    return w, k


def min_image(dx, dy, Lx, Ly, shift, shear_rate=0.0, passes=None, counts=False):
    """Lees-Edwards minimum image of raw differences with the relative-speed correction of the image.

    The y image is chosen first and moves x by ``shift = Ly·γ``; intervals are
    half-open (``[-L/2, L/2)``) and periods are subtracted one at a time, as the
    reference does, so the result is bit-identical to it.  ``passes`` = (ny, nx)
    fixes the number of one-period passes when the caller knows the range of the
    differences (positions inside the cell); by default passes repeat until done.
    At most :data:`MAX_LOOP_PASSES` passes run per axis; what is still outside then
    (a difference of many periods, or a large shift) is folded in closed form, so the
    cost never depends on the size of a coordinate.

    Returns ``(dx, dy, dvx)`` where ``dvx`` is the x velocity correction of the
    image (``-Ly·γ̇`` per image above) — an array, or None when nothing wrapped in y.
    With ``counts`` also the numbers of y and x periods subtracted (int arrays or None).

    Parameters
    ----------
    dx, dy : array_like (P,)
        Raw differences ``x_j − x_i``, ``y_j − y_i`` of the pairs' positions (µm).
    Lx, Ly : float
        Box lengths (µm, > 0).
    shift : float
        Lees-Edwards offset ``Ly·γ`` (µm).
    shear_rate : float
        Shear rate γ̇ (1/s), for the image velocity correction ``dvx``.
    passes : tuple of two int, optional
        ``(ny, nx)`` one-period passes per axis (see :func:`in_cell_passes`); None: until done.
    counts : bool
        Also return the period counts.

    Returns
    -------
    dx, dy : ndarray (P,)
        Minimum-image separation (µm), each in ``[−L/2, L/2)``.
    dvx : ndarray (P,) or None
        x velocity of j's image relative to j (µm/s); None when no y pass was applied
        (nothing wrapped) or γ̇ = 0.
    ky, kx : ndarray (P,) or None
        Only with ``counts``: y and x periods subtracted per pair; both None when some pair
        needed more than one period (a count could not reproduce the result bit for bit).
    """
    dx = np.asarray(dx, dtype=float)
    dy = np.asarray(dy, dtype=float)
    Lx = float(Lx)
    Ly = float(Ly)
    shift = float(shift)
    hy = Ly / 2
    hx = Lx / 2
    rate_shift = Ly * float(shear_rate)
    dvx = None
    ky_total = None
    n_y = passes[0] if passes is not None else None
    p = 0
    many = False  # some difference needed more passes than the loop runs
    while p < (MAX_LOOP_PASSES if n_y is None else min(n_y, MAX_LOOP_PASSES)):
        ky = _wrap_count(dy, hy)
        if n_y is None and not _nz(ky):
            break
        dy = dy - Ly * ky
        dx = dx - shift * ky
        ky_total = ky if ky_total is None else ky_total + ky
        p += 1
    else:
        if n_y is None or n_y > MAX_LOOP_PASSES:
            dy, k = _fold(dy, Ly, -hy)
            if _nz(k):
                many = True
                dx = dx - shift * k
                ky_total = k if ky_total is None else ky_total + k
    if ky_total is not None and rate_shift != 0:
        dvx = -rate_shift * ky_total
    n_x = passes[1] if passes is not None else None
    p = 0
    kx_total = None
    while p < (MAX_LOOP_PASSES if n_x is None else min(n_x, MAX_LOOP_PASSES)):
        kx = _wrap_count(dx, hx)
        if n_x is None and not _nz(kx):
            break
        dx = dx - Lx * kx
        kx_total = kx if kx_total is None else kx_total + kx
        p += 1
    else:
        if n_x is None or n_x > MAX_LOOP_PASSES:
            dx, k = _fold(dx, Lx, -hx)
            if _nz(k):
                many = True
                kx_total = k if kx_total is None else kx_total + k
    if counts:
        # period counts per pair (zeros where nothing wrapped); None when some pair needed
        # several periods, whose repeated subtraction a count cannot reproduce bit for bit
        if ky_total is None:
            ky_total = np.zeros(dx.shape, np.int8)
        if kx_total is None:
            kx_total = np.zeros(dx.shape, np.int8)
        if many or np.abs(ky_total).max(initial=0) > 1 or np.abs(kx_total).max(initial=0) > 1:
            ky_total = kx_total = None
        return dx, dy, dvx, ky_total, kx_total
    return dx, dy, dvx


def in_cell_passes(Lx, shift, margin=0.01):
    """(ny, nx) one-period passes that suffice for differences of positions inside the cell.

    With both positions in ``[0, Lx) × [0, Ly)`` one y pass suffices; the y image moves x by
    up to ``|shift|``, so x needs ``|shift|/Lx`` more passes (rounded, plus one).

    Parameters
    ----------
    Lx : float
        Box width (µm, > 0).
    shift : float
        Lees-Edwards offset ``Ly·γ`` (µm).
    margin : float
        Fraction of a period added before rounding, a safety against rounding of ``shift/Lx``.

    Returns
    -------
    tuple of two int
        ``(ny, nx)``, to pass as :func:`min_image`'s ``passes``.
    """
    return 1, int(0.5 + abs(shift) / Lx + margin) + 1


def _wrap_axis(v, L, carry=None, carry_step=0.0):
    """Bring ``v`` into ``[0, L)`` in place, one period at a time for at most :data:`MAX_LOOP_PASSES` passes,
    then in closed form; ``carry`` (if given) moves by ``−carry_step`` per period subtracted."""
    for _ in range(MAX_LOOP_PASSES):
        m = v >= L
        if not _nz(m):
            break
        v[m] -= L
        if carry is not None:
            carry[m] -= carry_step
    for _ in range(MAX_LOOP_PASSES):
        m = v < 0
        if not _nz(m):
            break
        v[m] += L
        if carry is not None:
            carry[m] += carry_step
    out = ~((v >= 0) & (v < L))  # NaN counts as outside
    if _nz(out):
        w, k = _fold(v[out], L, 0.0)
        v[out] = w
        if carry is not None:
            with np.errstate(invalid="ignore"):
                carry[out] -= carry_step * k


def le_wrap(x, y, vx, Lx, Ly, shift, shear_rate):
    """Bring positions back into ``[0, Lx) × [0, Ly)`` in place (Lees-Edwards wrap).

    Crossing y = Ly moves x by ``-shift`` and vx by ``-Ly·γ̇`` (and the reverse
    through y = 0); periods are applied one at a time, as the reference does, for
    a few passes, and in closed form (floor) beyond, so the cost is O(1) in the
    size of a coordinate.  Non-finite coordinates come out NaN.
    Returns True if anything was wrapped.

    Parameters
    ----------
    x, y, vx : ndarray (N,)
        Positions (µm) and x velocities (µm/s) of the spheres, modified in place.
    Lx, Ly : float
        Box lengths (µm, > 0).
    shift : float
        Lees-Edwards offset ``Ly·γ`` (µm).
    shear_rate : float
        Shear rate γ̇ (1/s): a sphere crossing ``y = Ly`` changes vx by ``−Ly·γ̇``.

    Returns
    -------
    bool
        True if any coordinate was wrapped.
    """
    if not len(y):
        return False
    wrapped = False
    if not (y.min() >= 0 and y.max() < Ly):
        y0 = y.copy()
        _wrap_axis(y, Ly, x, shift)
        with np.errstate(invalid="ignore"):
            vx += (y - y0) * shear_rate
        wrapped = True
    if not (x.min() >= 0 and x.max() < Lx):
        _wrap_axis(x, Lx)
        wrapped = True
    return wrapped


def pair_geometry(dx, dy, rng=None):
    """Distance and unit normal of min-image separations; a random normal where d == 0.

    Parameters
    ----------
    dx, dy : ndarray (P,)
        Minimum-image pair vectors ``x_j − x_i`` (µm).
    rng : numpy.random.Generator, optional
        Source of the random directions at ``d = 0`` (the ensemble's generator, so a run
        follows its seed); None uses NumPy's global generator.

    Returns
    -------
    d : ndarray (P,)
        Centre distances (µm).
    nx, ny : ndarray (P,)
        Unit normal from i towards j.
    """
    d = np.sqrt(dx * dx + dy * dy)
    zero = d == 0
    if _nz(zero):
        d_safe = _where(zero, 1.0, d)
        nx = dx / d_safe
        ny = dy / d_safe
        theta = 2 * np.pi * (rng.random(int(zero.sum())) if rng is not None else np.random.random(int(zero.sum())))
        nx[zero] = np.cos(theta)
        ny[zero] = np.sin(theta)
    else:
        nx = dx / d
        ny = dy / d
    return d, nx, ny


# written once in the engine; kept importable here for the canvas classes
from ..engine.tangential import tangential_two_pass  # noqa: E402,F401
