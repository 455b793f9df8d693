"""What a picture of an ensemble shows, as arrays and primitives (docs/output.md, "Snapshots").

Pure NumPy, shared by the drawing backends of :mod:`.drawing`: the geometry of the spheres and
relations (:func:`scene_geometry`), the particle colours (:func:`particle_labels`,
:func:`sphere_fills`), the Lees-Edwards images of discs crossing an edge
(:func:`periodic_offsets`), the drawing primitives of a scene (:func:`scene_primitives`) and the
caption strip under a snapshot (:func:`caption_items`).  Lengths in µm, drawing units in pixels.
"""
__docformat__ = "numpy"
import math
import os

import numpy as np

from ..engine.box import min_image
from ..engine.graph import component_labels
from ..base.neighbours import PERMANENT, SLIP

__all__ = ["scene_geometry", "PARTICLE_COLOURS", "particle_labels", "sphere_fills", "CAPTION_HEIGHT", "periodic_offsets",
           "scene_primitives", "snapshot_caption", "scale_bar_length", "caption_items"]


# ---------------------------------------------------------------------------------------------
# scene geometry (pure NumPy; shared by both backends)
# ---------------------------------------------------------------------------------------------
def scene_geometry(ens):
    """Arrays describing what to draw for the current state of ``ens``.

    Parameters
    ----------
    ens : ensemble
        An ensemble of this package (its state arrays and pair table are read, not changed).

    Returns
    -------
    dict
        ``x, y, r, phi`` (per sphere; µm, rad), ``chords`` (k, 4) = x1, y1, x2, y2 and
        ``chord_state`` (k,) for touching transient contacts (state codes of
        :mod:`particleShear.base.neighbours`), ``links`` (m, 4) centre-to-centre segments of
        permanent links (through the periodic image), and ``perm_chords`` (m', 4).
    """
    a = ens._a
    x, y, r = a["x"].copy(), a["y"].copy(), a["r"].copy()
    out = {"x": x, "y": y, "r": r, "phi": a["phi"].copy(), "chords": np.zeros((0, 4)),
           "chord_state": np.zeros(0, np.int8), "links": np.zeros((0, 4)), "perm_chords": np.zeros((0, 4))}
    pt = getattr(ens, "_pairs", None)
    if pt is None or not len(pt.i):
        return out
    act = np.flatnonzero(pt.active)
    if not len(act):
        return out
    i, j, st = pt.i[act], pt.j[act], pt.state[act]
    shift = ens._le_shift() if hasattr(ens, "_le_shift") else 0.0
    dx, dy = min_image(x[j] - x[i], y[j] - y[i], ens.size_x, ens.size_y, shift)[:2]
    d = np.sqrt(dx * dx + dy * dy)
    ok = d > 0
    nx = np.where(ok, dx / np.where(ok, d, 1), 1.0)
    ny = np.where(ok, dy / np.where(ok, d, 1), 0.0)
    ri, rj = r[i], r[j]
    touching = d < ri + rj
    with np.errstate(divide="ignore", invalid="ignore"):
        l = (d + (ri ** 2 - rj ** 2) / np.where(ok, d, 1)) / 2
        h = np.sqrt(np.maximum(ri ** 2 - l ** 2, 0.0))
    cx = x[i] + l * nx
    cy = y[i] + l * ny
    chords = np.stack([cx + h * ny, cy - h * nx, cx - h * ny, cy + h * nx], axis=1)
    perm = st == PERMANENT
    tr = touching & ~perm & ok
    out["chords"] = chords[tr]
    out["chord_state"] = st[tr]
    out["links"] = np.stack([x[i][perm], y[i][perm], x[i][perm] + dx[perm], y[i][perm] + dy[perm]], axis=1)
    out["perm_chords"] = chords[perm & touching & ok]
    return out


#: fills of the crosslinked particles: ColorBrewer "Set3" without its grey — light colours, so the red,
#: green and blue contact and bond lines drawn over the discs stay visible, and none is grey
PARTICLE_COLOURS = ("#8dd3c7", "#ffffb3", "#bebada", "#fb8072", "#80b1d3", "#fdb462", "#b3de69", "#fccde5",
                    "#bc80bd", "#ccebc5", "#ffed6f")


def particle_labels(ens):
    """Per sphere, the id of its crosslinked particle; −1 for a sphere without a bond.

    A particle is a connected component of the permanent links (bonds through the periodic
    boundary included: a particle crossing an edge is one particle); its id is the smallest
    sphere index in it.  Bonds are made before the protocol and never removed, and spheres are
    never reordered, so the id of a sphere is the same in every snapshot of a run.

    Parameters
    ----------
    ens : ensemble
        An ensemble of this package (its pair table is read, not changed); one without a pair
        table has no particles.

    Returns
    -------
    numpy.ndarray of int
        Shape (n,): the particle id of each sphere, or −1.
    """
    n = len(ens._a["x"])
    pt = getattr(ens, "_pairs", None)
    if pt is None or not len(pt.i):
        return np.full(n, -1, dtype=np.intp)
    perm = np.asarray(pt.state) == PERMANENT
    i, j = np.asarray(pt.i)[perm], np.asarray(pt.j)[perm]
    lab = component_labels(n, i, j)
    bonded = np.zeros(n, dtype=bool)
    bonded[i] = True
    bonded[j] = True
    return np.where(bonded, lab, -1)


def sphere_fills(ens, unlinked="grey"):
    """Fill colour of each sphere: its particle's colour, ``unlinked`` for a sphere without a bond.

    Particle ``k`` in the order of the ids of :func:`particle_labels` (the smallest sphere index)
    gets ``PARTICLE_COLOURS[k % 11]``: distinct colours for up to 11 particles, the same colour of a
    particle in every snapshot of a run.

    Parameters
    ----------
    ens : ensemble
        The ensemble drawn.
    unlinked : str, default "grey"
        Colour of spheres without a bond (``color_spheres_volume`` of the drawing configuration).

    Returns
    -------
    list of str
        One colour per sphere.
    """
    lab = particle_labels(ens)
    ids = np.unique(lab[lab >= 0])
    rank = np.searchsorted(ids, lab)
    return [PARTICLE_COLOURS[k % len(PARTICLE_COLOURS)] if l >= 0 else unlinked
            for l, k in zip(lab.tolist(), rank.tolist())]


CAPTION_HEIGHT = 44

#: colours of the drawn interfaces (legend entries), defaults of Graphical_output_configuration
_LEGEND = (("color_interface_locked", "red", "sticking contact"), ("color_interface_slip", "green", "slipping"),
           (None, "blue", "bond"))


def periodic_offsets(size_x, size_y, shift):
    """(dx, dy) of the 3 × 4 Lees-Edwards images of the cell that can overlap it (µm).

    The image above (``y + Ly``) is moved by ``+shift = Ly·γ`` in x, the one below by ``−shift``
    (the convention of :func:`particleShear.engine.box.min_image`).  Drawing every disc and
    segment at these offsets (clipped to the cell) shows a disc crossing an edge on both sides.

    Parameters
    ----------
    size_x, size_y : float
        Cell width L_x and height L_y (µm).
    shift : float
        Lees-Edwards offset ``L_y·γ`` (µm).

    Returns
    -------
    list of tuple
        The (dx, dy) offsets (µm), (0, 0) included.
    """
    out = []
    for ky in (-1, 0, 1):
        base = math.fmod(ky * shift, size_x)
        if base < 0:
            base += size_x
        for kx in (-2, -1, 0, 1):
            out.append((base + kx * size_x, ky * size_y))
    return out


def scene_primitives(ens, cfg=None):
    """What a snapshot shows, in cell coordinates (µm, y downwards as on the Tk canvas).

    Parameters
    ----------
    ens : ensemble
        The ensemble to draw.
    cfg : Graphical_output_configuration, optional
        Colours and drawing options (default: the built-in colours).

    Returns
    -------
    tuple of list
        ``(discs, segments)``: ``discs`` = list of (x, y, r, fill) and ``segments`` = list of
        (x1, y1, x2, y2, colour, width_µm), periodic images included (only those that reach into
        the cell ``[0, Lx] × [0, Ly]``).
    """
    opt = (lambda name, d: getattr(cfg, name, d)) if cfg is not None else (lambda name, d: d)
    g = scene_geometry(ens)
    Lx, Ly = float(ens.size_x), float(ens.size_y)
    offsets = periodic_offsets(Lx, Ly, ens._le_shift() if hasattr(ens, "_le_shift") else 0.0)
    discs, segs = [], []
    how = opt("draw_spheres_as", "spheres")
    if how != "none":
        fills = sphere_fills(ens, opt("color_spheres_volume", "grey"))
        for xx, yy, rr, fill in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist(), fills):
            rad = rr if how == "spheres" else 2.0
            for ox, oy in offsets:
                X, Y = xx + ox, yy + oy
                if X + rad >= 0 and X - rad <= Lx and Y + rad >= 0 and Y - rad <= Ly:
                    discs.append((X, Y, rad, fill))
    plain = []
    if opt("draw_rotation_line", False):
        col = opt("color_rotation_line", "black")
        for xx, yy, rr, ph in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist(), g["phi"].tolist()):
            plain.append((xx, yy, xx + rr * math.cos(ph), yy + rr * math.sin(ph), col, 1.0))
    if opt("draw_active_interface", True):
        locked = opt("color_interface_locked", "red")
        slip = opt("color_interface_slip", "green")
        for seg, st in zip(g["chords"].tolist(), g["chord_state"].tolist()):
            plain.append((*seg, slip if st == SLIP else locked, 3.0))
    if opt("draw_permanent_interfaces", False):
        for seg in g["perm_chords"].tolist():
            plain.append((*seg, "darkorange", 3.0))
    for seg in g["links"].tolist():
        plain.append((*seg, "blue", 3.0))
    for x1, y1, x2, y2, col, w in plain:
        for ox, oy in offsets:
            a, b, c, d = x1 + ox, y1 + oy, x2 + ox, y2 + oy
            if max(a, c) >= 0 and min(a, c) <= Lx and max(b, d) >= 0 and min(b, d) <= Ly:
                segs.append((a, b, c, d, col, w))
    return discs, segs


def snapshot_caption(ens, step=None):
    """Text of the caption: time (s), strain γ and protocol step.

    Parameters
    ----------
    ens : ensemble
        Its clock ``t`` (s) and strain ``shear`` are shown.
    step : int, optional
        Protocol step (omitted when None).

    Returns
    -------
    str
    """
    t = float(getattr(ens, "t", 0.0))
    gamma = float(getattr(ens, "shear", 0.0))
    text = f"t = {t:.4g} s   strain \u03b3 = {gamma:+.4f}"
    if step is not None:
        text += f"   step {int(step)}"
    return text


def scale_bar_length(size_x):
    """A round scale-bar length (µm): 1, 2 or 5 × 10^k, about a fifth of the cell width.

    Parameters
    ----------
    size_x : float
        Cell width (µm), > 0.

    Returns
    -------
    float
    """
    target = size_x / 5.0
    k = math.floor(math.log10(target))
    for m in (5, 2, 1):
        if m * 10 ** k <= target:
            return m * 10 ** k
    return 10 ** k


_FONTS = {}


def _font(size):
    """``(font, unicode_ok)``: DejaVu Sans (system, or matplotlib's copy, found without importing it),
    else Pillow's default font (ASCII only on old Pillow, no µ/γ glyphs in Pillow's own font)."""
    if size in _FONTS:
        return _FONTS[size]
    from PIL import ImageFont
    import importlib.util
    candidates = ["DejaVuSans.ttf"]
    spec = importlib.util.find_spec("matplotlib")
    if spec is not None and spec.submodule_search_locations:
        for loc in spec.submodule_search_locations:
            candidates.append(os.path.join(loc, "mpl-data", "fonts", "ttf", "DejaVuSans.ttf"))
    found = None
    for c in candidates:
        try:
            found = (ImageFont.truetype(c, size), True)
            break
        except OSError:
            continue
    if found is None:
        try:
            found = (ImageFont.load_default(size=size), False)
        except TypeError:  # Pillow < 10.1: bitmap font
            found = (ImageFont.load_default(), False)
    _FONTS[size] = found
    return found


def _ascii(text):
    return text.replace("\u03b3", "gamma").replace("\u00b5", "u")


def _text_width(text, size):
    """Width in pixels of ``text`` in the caption font (estimate 0.6·size per character without one)."""
    try:
        font, ok = _font(size)
        return font.getlength(text if ok else _ascii(text))
    except Exception:
        return 0.6 * size * len(text)


def _legend_entries(cfg):
    out = []
    for name, default, label in _LEGEND:
        out.append((getattr(cfg, name, default) if (cfg is not None and name) else default, label))
    return out


def caption_items(ens, cfg, width_px, scale, step=None):
    """Caption layout in pixels below the picture (origin at the top left of the strip).

    Time/strain/step on the first row; scale bar and colour legend on the second.

    Parameters
    ----------
    ens : ensemble
        The ensemble shown (clock, strain, cell width).
    cfg : Graphical_output_configuration or None
        Colours of the legend (None: the built-in colours).
    width_px : float
        Width of the picture (pixels).
    scale : float
        Pixels per µm.
    step : int, optional
        Protocol step shown (omitted when None).

    Returns
    -------
    list of tuple
        ("text", x, y, string, size) / ("line", x1, y1, x2, y2, colour, width) items shared by
        the raster and the vector writers.
    """
    items = [("text", 6, 4, snapshot_caption(ens, step), 13)]
    L = scale_bar_length(ens.size_x)
    y = 30
    items.append(("line", 6, y, 6 + L * scale, y, "black", 4))
    items.append(("text", 12 + L * scale, y - 8, f"{L:g} \u00b5m", 12))
    x = 24 + L * scale + _text_width(f"{L:g} \u00b5m", 12)
    for col, label in _legend_entries(cfg):
        items.append(("line", x, y, x + 16, y, col, 4))
        items.append(("text", x + 20, y - 8, label, 12))
        x += 32 + _text_width(label, 12)
    return items
