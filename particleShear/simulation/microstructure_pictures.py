"""Pictures of the stroboscopic observer (issue 49): force chains and non-affine motion per cycle.

One picture per excitation cycle of a run watched with ``stroboscopic=True``
(``result.microstructure``, :class:`~particleShear.engine.microstructure.Stroboscope`): the packing
at the snapshot that ends the cycle, each sphere filled by its D²_min of the cycle (or its non-affine
displacement), and a line between the centres of every pair in contact whose width is proportional
to the normal force of the contact (force chains); and an animated GIF of the pictures over the
cycles.  Drawn with Pillow only (no display, no matplotlib), with the package's snapshot drawing:
the Lees-Edwards images of :func:`~particleShear.simulation.scene.periodic_offsets`, the caption font
and scale bar of :mod:`~particleShear.simulation.scene` and the GIF writer of
:class:`~particleShear.simulation.drawing.PillowRenderer`.  As in the package's snapshots, y is
drawn downwards.  docs/microstructure.md, "Pictures".
"""
__docformat__ = "numpy"
import math
import numbers
import os

import numpy as np

from ..engine.box import min_image
from .scene import _ascii, _font, periodic_offsets, scale_bar_length
from .drawing import PillowRenderer

__all__ = ["microstructure_pictures", "picture_primitives", "colour_of", "COLOUR_BY", "CHAIN_COLOUR", "NAN_FILL",
           "VIRIDIS"]

#: what the spheres can be coloured by: name → (label, unit of the value shown)
COLOUR_BY = {"d2min": ("D\u00b2_min / r\u0304\u00b2", "per cycle"),
             "non_affine": ("|u_na| / r\u0304", "per cycle")}
#: colour of the force-chain lines
CHAIN_COLOUR = "#d62728"
#: fill of a sphere without a value (D²_min undefined: its neighbours on a line)
NAN_FILL = "#bbbbbb"
#: anchors of the colour scale (matplotlib's viridis at 0, 1/8 … 1), low → high
VIRIDIS = ("#440154", "#472d7b", "#3b528b", "#2c728e", "#21918c", "#28ae80", "#5ec962", "#addc30", "#fde725")
#: height of the caption strip below a picture (pixels)
_CAPTION = 64


def _rgb(hex_colour):
    return tuple(int(hex_colour[k:k + 2], 16) for k in (1, 3, 5))


def colour_of(t):
    """Colour of the scale position ``t`` (0 … 1, clipped) by linear interpolation of :data:`VIRIDIS`.

    Parameters
    ----------
    t : float
        Position on the colour scale; NaN gives :data:`NAN_FILL`.

    Returns
    -------
    str
        ``"#rrggbb"``.
    """
    if not math.isfinite(t):
        return NAN_FILL
    t = min(max(float(t), 0.0), 1.0) * (len(VIRIDIS) - 1)
    k = min(int(t), len(VIRIDIS) - 2)
    a, b = _rgb(VIRIDIS[k]), _rgb(VIRIDIS[k + 1])
    w = t - k
    return "#" + "".join(f"{int(round((1 - w) * x + w * y)):02x}" for x, y in zip(a, b))


def _values(micro, colour_by):
    """The coloured quantity per cycle and sphere (n_c, N), dimensionless."""
    r2 = micro["r_mean"] ** 2
    if colour_by == "d2min":
        return np.asarray(micro["d2min"], float) / r2
    u = np.asarray(micro["non_affine"], float)
    return np.sqrt(u[:, 0] ** 2 + u[:, 1] ** 2) / math.sqrt(r2)


def _check(micro, colour_by, decades):
    if not isinstance(micro, dict) or "d2min" not in micro:
        raise ValueError("result.microstructure is None: the run was not watched; allowed a result of a run with "
                         "stroboscopic=True (CLI --stroboscopic)")
    if colour_by not in COLOUR_BY:
        raise ValueError(f"colour_by={colour_by!r} is invalid: allowed {', '.join(map(repr, COLOUR_BY))}")
    if isinstance(decades, bool) or not isinstance(decades, numbers.Real) or not (0 < decades <= 12):
        raise ValueError(f"decades={decades!r} is out of range: allowed a number 0 < decades <= 12")
    if len(micro["msd"]) < 1:
        raise ValueError("result.microstructure has no complete cycle: allowed a run of periods >= 1 "
                         "(a picture is drawn per cycle)")


def picture_primitives(micro, cycle, colour_by="d2min", decades=3.0, vmax=None, fmax=None, max_width=None):
    """What the picture of one cycle shows, in cell coordinates (µm).

    The packing at snapshot ``cycle + 1`` (the end of the cycle); the fill of sphere i is
    :func:`colour_of` ``((log10 q_i − log10 vmax)/decades + 1)`` with q_i its D²_min / r̄² (or
    |u_na|/r̄) of the cycle — a logarithmic scale over ``decades`` decades up to ``vmax``, q ≤ 0 at
    its bottom; a contact (i, j) of that snapshot is the segment from the centre of i to the
    centre of j's nearest image (Lees-Edwards minimum image) of width ``max_width·f_n/fmax``,
    proportional to its normal force f_n (compressive contacts only).  Discs and segments are
    repeated at the periodic images that reach into the cell.

    Parameters
    ----------
    micro : dict
        ``result.microstructure`` (:meth:`~particleShear.engine.microstructure.Stroboscope.replica`).
    cycle : int
        The cycle, 0 … n_c − 1.
    colour_by : {"d2min", "non_affine"}, default "d2min"
        D²_min per sphere / r̄² (:func:`~particleShear.engine.microstructure.d2min`), or the length of
        the non-affine displacement / r̄.
    decades : float, default 3
        Decades of the colour scale (0 < decades ≤ 12).
    vmax : float, optional
        Top of the colour scale (dimensionless, > 0); default the largest value over all cycles
        (the pictures of a run share the scale; 1 when no value is positive).
    fmax : float, optional
        Normal force drawn ``max_width`` wide (the engine's force unit); default the largest over
        all snapshots drawn (snapshots 1 … n_c).
    max_width : float, optional
        Width of the line of ``fmax`` (µm); default 0.25 r̄.

    Returns
    -------
    discs : list of tuple
        ``(x, y, r, fill)`` (µm, µm, µm, "#rrggbb").
    segments : list of tuple
        ``(x1, y1, x2, y2, width, k)``: µm, width in µm, ``k`` the index of the contact in
        ``micro["contact_i"][cycle + 1]``.

    Raises
    ------
    ValueError
        Without observer data or complete cycle, an unknown ``colour_by``, ``decades`` out of
        range, ``cycle`` outside 0 … n_c − 1, ``vmax``/``fmax``/``max_width`` not > 0.
    """
    _check(micro, colour_by, decades)
    n_c = len(micro["msd"])
    if isinstance(cycle, bool) or not isinstance(cycle, numbers.Integral) or not 0 <= cycle < n_c:
        raise ValueError(f"cycle={cycle!r} is out of range: allowed an integer 0 <= cycle <= {n_c - 1}")
    vmax, fmax, max_width = _scales(micro, colour_by, vmax, fmax, max_width)
    q = _values(micro, colour_by)[cycle]
    s = cycle + 1
    pos, r = np.asarray(micro["positions"][s], float), np.asarray(micro["radius"], float)
    Lx, Ly = float(micro["Lx"]), float(micro["Ly"])
    shift = float(micro["shift"][s]) if "shift" in micro else Ly * float(micro["gamma"][s])
    offsets = periodic_offsets(Lx, Ly, shift)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (np.log10(np.where(q > 0, q, np.nan)) - math.log10(vmax)) / decades + 1.0
    t = np.where(np.isfinite(q) & (q <= 0), 0.0, t)
    discs = []
    for x, y, rr, tt in zip(pos[0].tolist(), pos[1].tolist(), r.tolist(), t.tolist()):
        fill = colour_of(tt)
        for ox, oy in offsets:
            X, Y = x + ox, y + oy
            if X + rr >= 0 and X - rr <= Lx and Y + rr >= 0 and Y - rr <= Ly:
                discs.append((X, Y, rr, fill))
    ci, cj = np.asarray(micro["contact_i"][s], np.intp), np.asarray(micro["contact_j"][s], np.intp)
    fn = np.asarray(micro["normal_force"][s], float)
    dx, dy = min_image(pos[0][cj] - pos[0][ci], pos[1][cj] - pos[1][ci], Lx, Ly, shift)[:2]
    segments = []
    for k in np.flatnonzero(fn > 0).tolist():
        x1, y1 = float(pos[0][ci[k]]), float(pos[1][ci[k]])
        x2, y2 = x1 + float(dx[k]), y1 + float(dy[k])
        w = max_width * float(fn[k]) / fmax
        for ox, oy in offsets:
            a, b, c, d = x1 + ox, y1 + oy, x2 + ox, y2 + oy
            if max(a, c) >= 0 and min(a, c) <= Lx and max(b, d) >= 0 and min(b, d) <= Ly:
                segments.append((a, b, c, d, w, k))
    return discs, segments


def _scales(micro, colour_by, vmax, fmax, max_width):
    """The shared scales of a run's pictures: (vmax, fmax, max_width)."""
    for name, v in (("vmax", vmax), ("fmax", fmax), ("max_width", max_width)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v)
                              or v <= 0):
            raise ValueError(f"{name}={v!r} is out of range: allowed a finite number > 0")
    if vmax is None:
        q = _values(micro, colour_by)
        q = q[np.isfinite(q) & (q > 0)]
        vmax = float(q.max()) if len(q) else 1.0
    if fmax is None:
        f = [np.asarray(a, float) for a in micro["normal_force"][1:]]
        f = np.concatenate(f) if f else np.zeros(0)
        f = f[np.isfinite(f) & (f > 0)]
        fmax = float(f.max()) if len(f) else 1.0
    if max_width is None:
        max_width = 0.25 * float(micro["r_mean"])
    return float(vmax), float(fmax), float(max_width)


def _render(micro, cycle, discs, segments, scale, colour_by, decades, vmax):
    """The PIL image of one cycle: the cell at ``scale`` pixels per µm and a caption strip."""
    from PIL import Image, ImageDraw
    Lx, Ly = float(micro["Lx"]), float(micro["Ly"])
    W, H = max(int(round(Lx * scale)), 1), max(int(round(Ly * scale)), 1)
    img = Image.new("RGB", (W, H + _CAPTION), "white")
    dr = ImageDraw.Draw(img)
    for x, y, r, fill in discs:
        dr.ellipse([(x - r) * scale, (y - r) * scale, (x + r) * scale, (y + r) * scale], fill=fill, outline="black")
    for x1, y1, x2, y2, w, _ in sorted(segments, key=lambda sg: sg[4]):      # thickest on top
        dr.line([x1 * scale, y1 * scale, x2 * scale, y2 * scale], fill=CHAIN_COLOUR,
                width=max(1, int(round(w * scale))))
    dr.rectangle([0, H, W, H + _CAPTION], fill="white")
    dr.line([0, H, W, H], fill="black")

    def text(x, y, s, size):
        font, ok = _font(size)
        dr.text((x, H + y), s if ok else _ascii(s), fill="black", font=font)
    n_c = len(micro["msd"])
    gamma = float(micro["gamma"][cycle + 1])
    text(6, 4, f"cycle {cycle + 1}/{n_c}   strain \u03b3 = {gamma:+.4f}   line width \u221d normal force", 12)
    label = COLOUR_BY[colour_by][0]
    lo = math.log10(vmax) - decades
    text(6, 22, f"{label}: 10^{lo:.1f} \u2026 10^{math.log10(vmax):.1f} (log)", 11)
    x0, bar = 6, min(160, W // 2)
    for px in range(bar):
        dr.line([x0 + px, H + 40, x0 + px, H + 50], fill=colour_of(px / max(bar - 1, 1)))
    L = scale_bar_length(Lx)
    xs = x0 + bar + 16
    dr.line([xs, H + 45, xs + L * scale, H + 45], fill="black", width=4)
    text(xs + L * scale + 6, 38, f"{L:g} \u00b5m", 11)
    return img


def microstructure_pictures(result, folder, colour_by="d2min", gif=True, scale=None, decades=3.0,
                            frame_duration_ms=500):
    """Write one picture per excitation cycle (PNG) and a GIF over the cycles.

    ``folder/cycle_001.png`` … ``cycle_{n_c}.png`` (:func:`picture_primitives`: spheres coloured
    by D²_min or non-affine displacement on one logarithmic scale for the run, force chains with
    line width ∝ normal force on one force scale for the run) and ``folder/cycles.gif`` (one frame
    per cycle).  Pillow only; no display needed.

    Parameters
    ----------
    result : SimulationResult or dict
        A result of a run with ``stroboscopic=True``, or its ``microstructure`` dict.
    folder : str or os.PathLike
        Output folder (made with its parents when missing).
    colour_by : {"d2min", "non_affine"}, default "d2min"
        What fills the spheres (:func:`picture_primitives`).
    gif : bool, default True
        Also write ``cycles.gif``.
    scale : float, optional
        Pixels per µm (> 0, at most 20); default such that the picture is 480 pixels wide.
    decades : float, default 3
        Decades of the colour scale.
    frame_duration_ms : int, default 500
        Display time of a GIF frame (ms, 20 … 60,000).

    Returns
    -------
    dict
        ``"pictures"``: the PNG paths in cycle order; ``"gif"``: the GIF's path (None without).

    Raises
    ------
    ValueError
        A result without observer data or complete cycle, ``colour_by``, ``decades``, ``scale``
        or ``frame_duration_ms`` out of range (naming the parameter and the allowed values).
    """
    micro = result if isinstance(result, dict) else getattr(result, "microstructure", None)
    _check(micro, colour_by, decades)
    if scale is not None and (isinstance(scale, bool) or not isinstance(scale, numbers.Real)
                              or not (0 < scale <= 20)):
        raise ValueError(f"scale={scale!r} is out of range: allowed a number 0 < scale <= 20 (pixels per \u00b5m)")
    if (isinstance(frame_duration_ms, bool) or not isinstance(frame_duration_ms, numbers.Integral)
            or not 20 <= frame_duration_ms <= 60_000):
        raise ValueError(f"frame_duration_ms={frame_duration_ms!r} is out of range: allowed an integer 20 ... 60000")
    if scale is None:
        scale = 480.0 / float(micro["Lx"])
    vmax, fmax, max_width = _scales(micro, colour_by, None, None, None)
    os.makedirs(folder, exist_ok=True)
    movie = PillowRenderer()
    n_c = len(micro["msd"])
    movie.movie_max_frames = n_c + 1
    paths = []
    for c in range(n_c):
        discs, segs = picture_primitives(micro, c, colour_by, decades, vmax, fmax, max_width)
        img = _render(micro, c, discs, segs, float(scale), colour_by, decades, vmax)
        path = os.path.join(os.fspath(folder), f"cycle_{c + 1:03d}.png")
        img.save(path, format="PNG")
        paths.append(path)
        if gif:
            movie.movie_width = img.width
            movie._keep_movie_frame(img)
    gif_path = None
    if gif:
        gif_path = os.path.join(os.fspath(folder), "cycles.gif")
        movie.write_movie(gif_path, frame_duration_ms=frame_duration_ms)
    return {"pictures": paths, "gif": gif_path}
