"""Small pure functions over arrays: Lees-Edwards geometry and pair terms (spec §2, §3).

Every function takes and returns NumPy arrays (or scalars) and never touches an
ensemble; they are the hot path of a step and reusable by other back-ends.
Lengths in µm, velocities in µm/s, forces in mg·µm·s⁻² per m depth.
"""
import numpy as np

try:  # the C function behind np.count_nonzero, without its Python wrapper (a third of the call cost)
    from numpy._core.multiarray import count_nonzero as _nz
except ImportError:  # pragma: no cover - NumPy 1.x
    _nz = np.count_nonzero
# _nz(a): number of nonzero (True) entries; cheaper than ndarray.any() on small arrays

try:  # the C functions behind np.dot, np.where, …, without their __array_function__ dispatch (~0.3 µs a call);
    # the engine passes only ndarrays, for which dispatch changes nothing
    from numpy._core import _multiarray_umath as _mu
    _dot, _where, _copyto = _mu.dot, _mu.where, _mu.copyto
    _bincount, _concat = _mu.bincount, _mu.concatenate
except (ImportError, AttributeError):  # pragma: no cover - other NumPy layouts
    _dot, _where, _copyto, _bincount, _concat = np.dot, np.where, np.copyto, np.bincount, np.concatenate

__all__ = ["min_image", "le_wrap", "pair_geometry", "tangential_two_pass"]


def _wrap_count(v, half):
    """−1, 0 or +1 per element: one period to subtract (``v ≥ half``) or add (``v < −half``)."""
    return (v >= half).view(np.int8) - (v < -half).view(np.int8)


def min_image(dx, dy, Lx, Ly, shift, shear_rate=0.0, passes=None, counts=False):
    """Lees-Edwards minimum image of raw differences (§3.1) with the relative-speed correction (§3.2).

    The y image is chosen first and moves x by ``shift = Ly·γ``; intervals are
    half-open (``[-L/2, L/2)``) and periods are subtracted one at a time, as the
    reference does, so the result is bit-identical to it.  ``passes`` = (ny, nx)
    fixes the number of one-period passes when the caller knows the range of the
    differences (positions inside the cell); by default passes repeat until done.

    Returns ``(dx, dy, dvx)`` where ``dvx`` is the x velocity correction of the
    image (``-Ly·γ̇`` per image above) — an array, or None when nothing wrapped in y.
    With ``counts`` also the numbers of y and x periods subtracted (int arrays or None).
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
    while True if n_y is None else p < n_y:
        ky = _wrap_count(dy, hy)
        if n_y is None and not _nz(ky):
            break
        dy = dy - Ly * ky
        dx = dx - shift * ky
        ky_total = ky if ky_total is None else ky_total + ky
        p += 1
    if ky_total is not None and rate_shift != 0:
        dvx = -rate_shift * ky_total
    n_x = passes[1] if passes is not None else None
    p = 0
    kx_total = None
    while True if n_x is None else p < n_x:
        kx = _wrap_count(dx, hx)
        if n_x is None and not _nz(kx):
            break
        dx = dx - Lx * kx
        kx_total = kx if kx_total is None else kx_total + kx
        p += 1
    if counts:
        # period counts per pair (zeros where nothing wrapped); None when some pair needed
        # several periods, whose repeated subtraction a count cannot reproduce bit for bit
        if ky_total is None:
            ky_total = np.zeros(dx.shape, np.int8)
        if kx_total is None:
            kx_total = np.zeros(dx.shape, np.int8)
        if np.abs(ky_total).max(initial=0) > 1 or np.abs(kx_total).max(initial=0) > 1:
            ky_total = kx_total = None
        return dx, dy, dvx, ky_total, kx_total
    return dx, dy, dvx


def in_cell_passes(Lx, shift, margin=0.01):
    """(ny, nx) one-period passes that suffice for differences of positions inside the cell."""
    return 1, int(0.5 + abs(shift) / Lx + margin) + 1


def le_wrap(x, y, vx, Lx, Ly, shift, shear_rate):
    """Bring positions back into ``[0, Lx) × [0, Ly)`` in place (§3.3).

    Crossing y = Ly moves x by ``-shift`` and vx by ``-Ly·γ̇`` (and the reverse
    through y = 0); periods are applied one at a time, as the reference does.
    Returns True if anything was wrapped.
    """
    if not len(y):
        return False
    wrapped = False
    if y.min() < 0 or y.max() >= Ly:
        y0 = y.copy()
        m = y >= Ly
        while _nz(m):
            y[m] -= Ly
            x[m] -= shift
            m = y >= Ly
        m = y < 0
        while _nz(m):
            y[m] += Ly
            x[m] += shift
            m = y < 0
        vx += (y - y0) * shear_rate
        wrapped = True
    if x.min() < 0 or x.max() >= Lx:
        m = x >= Lx
        while _nz(m):
            x[m] -= Lx
            m = x >= Lx
        m = x < 0
        while _nz(m):
            x[m] += Lx
            m = x < 0
        wrapped = True
    return wrapped


def pair_geometry(dx, dy, rng=None):
    """Distance and unit normal of min-image separations; a random normal where d == 0 (§2.1)."""
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
