"""Adapters of the Lees-Edwards box and the pair normals for the documented classes (docs/design.md).

The box is written once, in :mod:`particleShear.engine.box` (minimum image, wrap) and the
normals in :func:`particleShear.engine.forces.normals`; the functions here keep the
signatures and return conventions of the canvas classes and of scripts written against
earlier versions (scalar box, an image velocity correction that is None when nothing wrapped,
int period counts) and call the engine.  Every function takes and returns NumPy arrays (or
scalars) and never touches an ensemble.  Lengths in µm, velocities in µm/s.
"""
__docformat__ = "numpy"

import numpy as np

from ..engine import box as _box
from ..engine.forces import normals as _normals
# NumPy-only speed shims live in the namespace module (no private NumPy import here)
from .namespace import count_nonzero as _nz

__all__ = ["min_image", "le_wrap", "pair_geometry", "tangential_two_pass", "MAX_LOOP_PASSES"]


#: one-period passes per axis before the closed form takes over (the engine's
#: :data:`particleShear.engine.box.MAX_PASSES`): ordinary coordinates (within a couple of periods
#: of the cell) never reach it, so their results stay bit-identical to the reference loop, while
#: a huge coordinate costs O(1) instead of O(|x| / L) passes
MAX_LOOP_PASSES = _box.MAX_PASSES


def min_image(dx, dy, Lx, Ly, shift, shear_rate=0.0, passes=None, counts=False):
    """Lees-Edwards minimum image of raw differences with the relative-speed correction of the image.

    The y image is chosen first and moves x by ``shift = Ly·γ``; intervals are
    half-open (``[-L/2, L/2)``) and periods are subtracted one at a time, as the
    reference does, so the result is bit-identical to it; beyond
    :data:`MAX_LOOP_PASSES` passes the rest is folded in closed form, so the cost never
    depends on the size of a coordinate.  The arithmetic is that of
    :func:`particleShear.engine.box.min_image`, which this function calls.

    Returns ``(dx, dy, dvx)`` where ``dvx`` is the x velocity correction of the
    image (``−Ly·γ̇`` per image above) — an array, or None when nothing wrapped in y.
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
        Accepted and ignored.  It once fixed the number of one-period passes for
        differences of positions inside the cell (see :func:`in_cell_passes`); the passes
        now stop as soon as one moves nothing, which gives the same numbers (a pass that
        moves nothing changes no value) at a cost that differs by less than the noise of
        a step (docs/performance.md).
    counts : bool
        Also return the period counts.

    Returns
    -------
    dx, dy : ndarray (P,)
        Minimum-image separation (µm), each in ``[−L/2, L/2)``.
    dvx : ndarray (P,) or None
        x velocity of j's image relative to j, ``−Ly·γ̇·ky`` (µm/s); None when no pair
        wrapped in y or γ̇ = 0.
    ky, kx : ndarray of int8 (P,) or None
        Only with ``counts``: y and x periods subtracted per pair; both None when some pair
        needed more than one period (a count could not reproduce the result bit for bit)
        or a difference was not finite.
    """
    Ly = float(Ly)
    dx, dy, ky, kx = _box.min_image(np.asarray(dx, dtype=float), np.asarray(dy, dtype=float),
                                    float(Lx), Ly, float(shift))
    rate_shift = Ly * float(shear_rate)
    dvx = -rate_shift * ky if rate_shift != 0 and _nz(ky) else None
    if not counts:
        return dx, dy, dvx
    # per pair −1, 0 or +1; a count of several periods (or NaN) cannot reproduce the repeated
    # subtraction bit for bit, so callers then recompute the images
    if (np.abs(ky) <= 1).all() and (np.abs(kx) <= 1).all():
        return dx, dy, dvx, ky.astype(np.int8), kx.astype(np.int8)
    return dx, dy, dvx, None, None


def in_cell_passes(Lx, shift, margin=0.01):
    """(ny, nx) one-period passes that suffice for differences of positions inside the cell.

    With both positions in ``[0, Lx) × [0, Ly)`` one y pass suffices; the y image moves x by
    up to ``|shift|``, so x needs ``|shift|/Lx`` more passes (rounded, plus one).  Kept for
    scripts that pass it as :func:`min_image`'s ``passes``, which that function now ignores.

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
        ``(ny, nx)``.
    """
    return 1, int(0.5 + abs(shift) / Lx + margin) + 1


def le_wrap(x, y, vx, Lx, Ly, shift, shear_rate):
    """Bring positions back into ``[0, Lx) × [0, Ly)`` in place (Lees-Edwards wrap).

    Crossing y = Ly moves x by ``−shift`` and vx by ``−Ly·γ̇`` (and the reverse
    through y = 0; ``vx += (y' − y)·γ̇`` as in the reference); periods are applied one
    at a time, as the reference does, for a few passes, and in closed form beyond, so
    the cost is O(1) in the size of a coordinate.  An infinite coordinate comes out
    NaN; a NaN stays NaN.  The arithmetic is that of
    :func:`particleShear.engine.box.wrap`, which this function calls.

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
        True if any coordinate was moved by a period.
    """
    return bool(_box.wrap(x, y, vx, float(Lx), float(Ly), float(shift), float(shear_rate)))


def pair_geometry(dx, dy, rng=None):
    """Distance and unit normal of min-image separations; a random normal where d == 0.

    The normals are those of :func:`particleShear.engine.forces.normals`, which this
    function calls with the one generator.

    Parameters
    ----------
    dx, dy : ndarray (P,)
        Minimum-image pair vectors ``x_j − x_i`` (µm).
    rng : numpy.random.Generator, optional
        Source of the random directions at ``d = 0`` (the ensemble's generator, so a run
        follows its seed): one uniform number ``u`` per pair at ``d = 0``, in pair order,
        and the normal ``(cos 2πu, sin 2πu)``.  None uses NumPy's global generator.

    Returns
    -------
    d : ndarray (P,)
        Centre distances (µm).
    nx, ny : ndarray (P,)
        Unit normal from i towards j.
    """
    d = np.sqrt(dx * dx + dy * dy)
    gen = np.random if rng is None else rng
    if np.ndim(d) == 1:
        nx, ny = _normals(dx, dy, d, None, (gen,))
    else:   # the engine's normals are over a flat pair axis: draw in row-major order, as a mask did
        shape = np.shape(d)
        flat = [np.ravel(np.broadcast_to(a, shape)).astype(float) for a in (dx, dy, d)]
        nx, ny = (a.reshape(shape) for a in _normals(*flat, None, (gen,)))
    return d, nx, ny


# written once in the engine; kept importable here for the canvas classes
from ..engine.tangential import tangential_two_pass  # noqa: E402,F401
