"""Drawing: one renderer interface, a Pillow backend (files) and a Tk backend (live windows) (docs/output.md).

Drawing never influences the physics.  Neither Pillow nor tkinter is imported
unless something is actually drawn or saved: a headless run that saves no
images leaves ``PIL`` and ``tkinter`` out of ``sys.modules``.

Backends
--------
``PillowRenderer``
    Renders the particle picture of the current state into an image and saves
    PNG, JPG or (E)PS snapshots.  No window; works without a display.
``TkRenderer``
    Live particle window (and, through :func:`open_stress_plot`, the stress/strain
    window).  Snapshots are rendered by a :class:`PillowRenderer` so JPG/PNG need
    no Ghostscript (the reference rasterised the Tk PostScript instead).

:func:`make_renderer` picks a backend at run time: ``backend="auto"`` (default, or the
environment variable ``PARTICLESHEAR_RENDERER``) uses Tk when a display is available
and falls back to Pillow (only if snapshots are requested) otherwise, printing one
message per process.
"""
__docformat__ = "numpy"
import math
import os
import sys
import time
import warnings

import numpy as np

from ..base.kernels import min_image
from ..base.neighbours import PERMANENT, SLIP

__all__ = ["Renderer", "PillowRenderer", "TkRenderer", "StressPlotWindow", "display_available",
           "make_renderer", "open_stress_plot", "nice_ticks", "scene_geometry", "scene_primitives", "periodic_offsets",
           "particle_labels", "sphere_fills", "IMAGE_EXTENSIONS", "CAPTION_HEIGHT", "PARTICLE_COLOURS"]

#: imageFileType → (file extension, Pillow format)
IMAGE_EXTENSIONS = {"jpg": (".jpg", "JPEG"), "png": (".png", "PNG"), "ps": (".ps", "EPS"), "eps": (".eps", "EPS"),
                    "svg": (".svg", "SVG")}

_headless_message_printed = False


def _headless_message(reason, files):
    global _headless_message_printed
    if _headless_message_printed:
        return
    _headless_message_printed = True
    extra = " Snapshots are rendered off-screen with Pillow." if files else ""
    message = f"particleShear: no display available ({reason}); running headless without live windows.{extra}"
    warnings.warn(message, UserWarning, stacklevel=3)


def display_available():
    """``(True, "")`` if a GUI display can be expected, else ``(False, reason)``; never imports tkinter."""
    if sys.platform.startswith("linux") or "bsd" in sys.platform:
        if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            return False, "DISPLAY is not set"
    return True, ""


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
    dx, dy, _ = min_image(x[j] - x[i], y[j] - y[i], ens.size_x, ens.size_y, shift)
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
    from ..linkable.compact import component_labels
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


class Renderer:
    """Interface of a drawing backend.

    ``draw(ens)`` draws the initial picture, ``update(ens)`` is called by the ensemble after
    every movement (only for live backends, which set ``live = True``), ``save(ens, path,
    file_type)`` writes a snapshot and ``close()`` releases windows.
    """

    live = False

    def draw(self, ens):
        """Draw the initial picture of ``ens`` (nothing in this base class).

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        """
        pass

    def update(self, ens):
        """Redraw after a movement of ``ens`` (live backends; nothing in this base class).

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        """
        pass

    def save(self, ens, path, file_type="jpg", step=None):
        """Write a snapshot of ``ens`` to ``path``.

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        path : str
            Destination file.
        file_type : str, optional
            "jpg" (default), "png" (raster), "ps"/"eps" (vector EPS) or "svg" (vector SVG).
        step : int, optional
            Protocol step shown in the caption.

        Raises
        ------
        NotImplementedError
            In this base class.
        """
        raise NotImplementedError

    def close(self):
        """Release windows and resources (nothing in this base class)."""
        pass


#: height (pixels) of the caption strip under the particle picture of a snapshot
CAPTION_HEIGHT = 44

#: colours of the drawn interfaces (legend entries), defaults of Graphical_output_configuration
_LEGEND = (("color_interface_locked", "red", "sticking contact"), ("color_interface_slip", "green", "slipping"),
           (None, "blue", "bond"))


def periodic_offsets(size_x, size_y, shift):
    """(dx, dy) of the 3 × 4 Lees-Edwards images of the cell that can overlap it (µm).

    The image above (``y + Ly``) is moved by ``+shift = Ly·γ`` in x, the one below by ``−shift``
    (the convention of :func:`particleShear.base.kernels.min_image`).  Drawing every disc and
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


class PillowRenderer(Renderer):
    """Off-screen snapshots with Pillow (imported on first use): particle picture plus a caption.

    The picture is the cell at ``scale`` pixels per µm (1 canvas pixel = 1 µm at scale 1),
    discs crossing a periodic edge drawn on both sides (Lees-Edwards images); below it a
    strip of :data:`CAPTION_HEIGHT` pixels with time, strain and step, a scale bar in µm and
    the legend of the interface colours.  ``"ps"``/``"eps"`` snapshots are vector EPS and
    ``"svg"`` vector SVG (same content); ``"jpg"``/``"png"`` are raster.

    Parameters
    ----------
    graphical_output_configuration : Graphical_output_configuration, optional
        Colours and drawing options (default: the ensemble's, else the built-in colours).
    scale : float, optional
        Pixels per µm (default 1).
    background : str, optional
        Background colour of the cell (default "white").

    Attributes
    ----------
    collect_movie : bool
        Keep a reduced copy (at most ``movie_width`` pixels wide) of every saved frame for
        :meth:`write_movie`.  At most ``movie_max_frames`` are kept: when full, every second
        frame is dropped and only every second later frame is kept (bounded memory).
    """

    def __init__(self, graphical_output_configuration=None, scale=1.0, background="white"):
        self.cfg = graphical_output_configuration
        self.scale = float(scale)
        self.background = background
        self.collect_movie = False
        self.movie_width = 320
        self.movie_max_frames = 400
        self.movie_frames = []
        self._movie_stride = 1
        self._movie_seen = 0

    def _opt(self, name, default):
        return getattr(self.cfg, name, default) if self.cfg is not None else default

    def _config(self, ens):
        if self.cfg is None:
            self.cfg = getattr(ens, "graphical_output_configuration", None)
        return self.cfg

    def render(self, ens, step=None, caption=True):
        """Return a ``PIL.Image`` of the current state (y drawn downwards, as on the Tk canvas).

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        step : int, optional
            Protocol step shown in the caption.
        caption : bool, optional
            Add the caption strip below the picture (default True).

        Returns
        -------
        PIL.Image.Image
        """
        from PIL import Image, ImageDraw
        cfg = self._config(ens)
        s = self.scale
        W, H = max(int(round(ens.size_x * s)), 1), max(int(round(ens.size_y * s)), 1)
        img = Image.new("RGB", (W, H + (CAPTION_HEIGHT if caption else 0)), self.background)
        dr = ImageDraw.Draw(img)
        discs, segs = scene_primitives(ens, cfg)
        for x, y, r, fill in discs:
            dr.ellipse([(x - r) * s, (y - r) * s, (x + r) * s, (y + r) * s], fill=fill, outline="black")
        for x1, y1, x2, y2, col, w in segs:
            dr.line([x1 * s, y1 * s, x2 * s, y2 * s], fill=col, width=max(1, int(round(w * s))))
        if caption:
            dr.rectangle([0, H, W, H + CAPTION_HEIGHT], fill="white")
            dr.line([0, H, W, H], fill="black")
            for item in caption_items(ens, cfg, W, s, step):
                if item[0] == "text":
                    _, x, y, text, size = item
                    font, unicode_ok = _font(size)
                    if not unicode_ok:
                        text = _ascii(text)
                    dr.text((x, H + y), text, fill="black", font=font)
                else:
                    _, x1, y1, x2, y2, col, w = item
                    dr.line([x1, H + y1, x2, H + y2], fill=col, width=w)
        return img

    # -- vector output ------------------------------------------------------------------------
    def vector(self, ens, fmt, step=None):
        """EPS (``fmt="eps"``) or SVG (``"svg"``) text of the snapshot: same content as :meth:`render`.

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        fmt : {"eps", "svg"}
            The vector format.
        step : int, optional
            Protocol step shown in the caption.

        Returns
        -------
        str
        """
        from PIL import ImageColor
        cfg = self._config(ens)
        s = self.scale
        W, H = ens.size_x * s, ens.size_y * s
        Ht = H + CAPTION_HEIGHT
        discs, segs = scene_primitives(ens, cfg)
        items = caption_items(ens, cfg, W, s, step)
        rgb = {}

        def colour(c):
            if c not in rgb:
                rgb[c] = ImageColor.getrgb(c)[:3]
            return rgb[c]

        if fmt == "svg":
            out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W:g}" height="{Ht:g}" '
                   f'viewBox="0 0 {W:g} {Ht:g}">',
                   f'<rect width="{W:g}" height="{Ht:g}" fill="white"/>',
                   f'<clipPath id="cell"><rect width="{W:g}" height="{H:g}"/></clipPath><g clip-path="url(#cell)">']
            for x, y, r, fill in discs:
                out.append(f'<circle cx="{x * s:.2f}" cy="{y * s:.2f}" r="{r * s:.2f}" fill="rgb{colour(fill)}" '
                           'stroke="black" stroke-width="0.5"/>')
            for x1, y1, x2, y2, col, w in segs:
                out.append(f'<line x1="{x1 * s:.2f}" y1="{y1 * s:.2f}" x2="{x2 * s:.2f}" y2="{y2 * s:.2f}" '
                           f'stroke="rgb{colour(col)}" stroke-width="{w * s:.2f}"/>')
            out.append(f'</g><line x1="0" y1="{H:g}" x2="{W:g}" y2="{H:g}" stroke="black"/>')
            for item in items:
                if item[0] == "text":
                    _, x, y, text, size = item
                    text = text.replace("&", "&amp;").replace("<", "&lt;")
                    out.append(f'<text x="{x:g}" y="{H + y + size:g}" font-family="Helvetica, Arial, sans-serif" '
                               f'font-size="{size}">{text}</text>')
                else:
                    _, x1, y1, x2, y2, col, w = item
                    out.append(f'<line x1="{x1:g}" y1="{H + y1:g}" x2="{x2:g}" y2="{H + y2:g}" '
                               f'stroke="rgb{colour(col)}" stroke-width="{w}"/>')
            out.append("</svg>\n")
            return "\n".join(out)

        def ps_col(c):
            r, g, b = colour(c)
            return f"{r / 255:.3f} {g / 255:.3f} {b / 255:.3f} setrgbcolor"

        def ps_text(text):
            text = _ascii(text)  # the standard PostScript fonts: ASCII here
            return "(" + text.replace("\\", "\\\\").replace("(", "\\(").replace(")", "\\)") + ")"

        # PostScript has y upwards: flip once, so all coordinates stay those of the picture
        out = ["%!PS-Adobe-3.0 EPSF-3.0", f"%%BoundingBox: 0 0 {math.ceil(W)} {math.ceil(Ht)}",
               "%%Creator: particleShear", "%%EndComments",
               "/D { 0 360 arc closepath gsave fill grestore 0 setgray stroke } bind def",
               "/L { moveto lineto stroke } bind def", "1 1 1 setrgbcolor "
               f"0 0 {W:g} {Ht:g} rectfill", f"0 {Ht:g} translate 1 -1 scale",
               f"gsave 0 0 {W:g} {H:g} rectclip 0.5 setlinewidth"]
        last = None
        for x, y, r, fill in discs:
            if fill != last:
                out.append(f"/F {{ {ps_col(fill)} }} def")
                last = fill
            out.append(f"newpath F {x * s:.2f} {y * s:.2f} {r * s:.2f} D")
        for x1, y1, x2, y2, col, w in segs:
            out.append(f"{ps_col(col)} {w * s:.2f} setlinewidth {x2 * s:.2f} {y2 * s:.2f} {x1 * s:.2f} {y1 * s:.2f} L")
        out.append("grestore")
        out.append(f"0 setgray 1 setlinewidth 0 {H:g} {W:g} {H:g} L")
        for item in items:
            if item[0] == "text":
                _, x, y, text, size = item
                out.append(f"gsave /Helvetica findfont {size} scalefont setfont {x:g} {H + y + size:g} moveto "
                           f"1 -1 scale {ps_text(text)} show grestore")
            else:
                _, x1, y1, x2, y2, col, w = item
                out.append(f"{ps_col(col)} {w} setlinewidth {x2:g} {H + y2:g} {x1:g} {H + y1:g} L")
        out.append("showpage\n%%EOF\n")
        return "\n".join(out)

    # -- files ---------------------------------------------------------------------------------
    def save(self, ens, path, file_type="jpg", step=None):
        """Write a snapshot atomically (temporary file in the same folder, then ``os.replace``).

        Parameters
        ----------
        ens : ensemble
            The ensemble to draw.
        path : str
            Destination file.
        file_type : str, optional
            "jpg" (default), "png" (raster), "ps"/"eps" (vector EPS) or "svg" (vector SVG).
        step : int, optional
            Protocol step shown in the caption.
        """
        ext, fmt = IMAGE_EXTENSIONS.get(file_type, IMAGE_EXTENSIONS["ps"])
        img = None
        if fmt in ("EPS", "SVG"):
            data = self.vector(ens, fmt.lower(), step).encode("utf-8")
        else:
            img = self.render(ens, step)
            data = None
        tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".part")
        try:
            if data is not None:
                with open(tmp, "wb") as fh:
                    fh.write(data)
            else:
                options = {"PNG": {"compress_level": 1}, "JPEG": {"quality": 90}}.get(fmt, {})
                img.save(tmp, format=fmt, **options)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        if self.collect_movie:
            self._keep_movie_frame(img if img is not None else self.render(ens, step))

    # -- movie ---------------------------------------------------------------------------------
    def _keep_movie_frame(self, img):
        self._movie_seen += 1
        if (self._movie_seen - 1) % self._movie_stride:
            return
        if img.width > self.movie_width:
            h = max(1, round(img.height * self.movie_width / img.width))
            img = img.resize((self.movie_width, h))
        self.movie_frames.append(img.convert("P", palette=1, colors=64))  # 1 = Image.Palette.ADAPTIVE
        if len(self.movie_frames) >= self.movie_max_frames:
            self.movie_frames = self.movie_frames[::2]
            self._movie_stride *= 2

    def write_movie(self, path, frame_duration_ms=80):
        """Write the kept frames as an animated GIF (Pillow ``save_all``), atomically; return the count.

        Writes nothing and returns 0 when no frame was kept.

        Parameters
        ----------
        path : str
            The GIF file.
        frame_duration_ms : int, optional
            Display time of each frame (ms, default 80).

        Returns
        -------
        int
            Frames written.
        """
        frames = self.movie_frames
        if not frames:
            return 0
        tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".part")
        try:
            frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:],
                           duration=int(frame_duration_ms), loop=0, optimize=False, disposal=1)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        return len(frames)


class TkRenderer(Renderer):
    """Live particle window (``size_x × size_y`` pixels).  Redraws at most every ``min_interval`` s.

    Snapshots are written by an internal :class:`PillowRenderer` (same picture as headless).

    Parameters
    ----------
    size_x, size_y : float
        Canvas size (pixels; 1 pixel = 1 µm).
    title : str, optional
        Window title.
    graphical_output_configuration : Graphical_output_configuration, optional
        Colours and drawing options (default: the ensemble's).
    min_interval : float, optional
        Shortest time between two redraws (s, default 0.03: about 30 per second).
    root : tkinter.Tk, optional
        An existing Tk root to draw into (default: a new one).
    """

    live = True

    def __init__(self, size_x, size_y, title="particleShear", graphical_output_configuration=None,
                 min_interval=0.03, root=None):
        import tkinter
        self._tkinter = tkinter
        self.root = root if root is not None else tkinter.Tk()
        self.root.title(title)
        self.canvas = tkinter.Canvas(self.root, width=int(size_x), height=int(size_y), bg="white")
        self.canvas.pack()
        self.cfg = graphical_output_configuration
        self.min_interval = min_interval
        self._last = 0.0
        self._pillow = PillowRenderer(graphical_output_configuration)
        self.closed = False

    def _redraw(self, ens):
        c = self.canvas
        c.delete("all")
        cfg = self.cfg if self.cfg is not None else getattr(ens, "graphical_output_configuration", None)
        g = scene_geometry(ens)
        how = getattr(cfg, "draw_spheres_as", "spheres")
        if how != "none":
            fills = sphere_fills(ens, getattr(cfg, "color_spheres_volume", "grey"))
            for xx, yy, rr, fill in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist(), fills):
                rad = rr if how == "spheres" else 2.0
                c.create_oval(xx - rad, yy - rad, xx + rad, yy + rad, fill=fill)
        if getattr(cfg, "draw_active_interface", True):
            locked = getattr(cfg, "color_interface_locked", "red")
            slip = getattr(cfg, "color_interface_slip", "green")
            for seg, st in zip(g["chords"].tolist(), g["chord_state"].tolist()):
                c.create_line(*seg, fill=slip if st == SLIP else locked, width=3)
        if getattr(cfg, "draw_permanent_interfaces", False):
            for seg in g["perm_chords"].tolist():
                c.create_line(*seg, fill="darkorange", width=3)
        for seg in g["links"].tolist():
            c.create_line(*seg, fill="blue", width=3)

    def draw(self, ens):
        if self.closed:
            return
        try:
            self._redraw(ens)
            self.root.update()
            self._last = time.monotonic()
        except self._tkinter.TclError:  # window closed by the user: keep simulating
            self.closed = True

    def update(self, ens):
        if self.closed or time.monotonic() - self._last < self.min_interval:
            return
        self.draw(ens)

    def save(self, ens, path, file_type="jpg", step=None):
        self._pillow.cfg = self.cfg if self.cfg is not None else getattr(ens, "graphical_output_configuration", None)
        self._pillow.save(ens, path, file_type, step)

    @property
    def collect_movie(self):
        """Keep reduced frames for :meth:`write_movie` (see :class:`PillowRenderer`)."""
        return self._pillow.collect_movie

    @collect_movie.setter
    def collect_movie(self, value):
        self._pillow.collect_movie = value

    def write_movie(self, path, frame_duration_ms=80):
        """Write the kept frames as an animated GIF; see :meth:`PillowRenderer.write_movie`.

        Parameters
        ----------
        path : str
            The GIF file.
        frame_duration_ms : int, optional
            Display time of each frame (ms, default 80).

        Returns
        -------
        int
            Frames written.
        """
        return self._pillow.write_movie(path, frame_duration_ms)

    def close(self):
        if not self.closed:
            self.closed = True
            try:
                self.root.destroy()
            except Exception:
                pass


def nice_ticks(lo, hi, n=5):
    """Round tick values (1, 2 or 5 × 10^k steps) covering [lo, hi] with about ``n`` ticks.

    Parameters
    ----------
    lo, hi : float
        The range.
    n : int, optional
        About how many ticks (default 5).

    Returns
    -------
    list of float
    """
    span = float(hi) - float(lo)
    if not math.isfinite(span) or span <= 0:
        return []
    raw = span / max(int(n), 1)
    k = math.floor(math.log10(raw))
    step = next(m * 10 ** k for m in (1, 2, 5, 10) if m * 10 ** k >= raw)
    first = math.ceil(lo / step)
    return [i * step for i in range(first, int(math.floor(hi / step)) + 1)][:50]


class StressPlotWindow:
    """Tk window with a ``width × height`` canvas for the live stress/strain plot.

    :meth:`draw_axes` adds the time axis (s), the stress axis (Pa, left), strain marks (right),
    the excitation window and a legend; the dots are drawn by
    :class:`~particleShear.simulation.evaluation.EvaluationHandlerPlotter`.  At the end of a run
    :meth:`finish` keeps the window open until the user closes it (only in the main process and
    when :attr:`keep_open` is True; set ``StressPlotWindow.keep_open = False`` for scripted loops).

    Parameters
    ----------
    width, height : int, optional
        Canvas size (pixels, default 1000 × 500).
    title : str, optional
        Window title.
    master : tkinter widget, optional
        Open as a ``Toplevel`` of this window (e.g. the particle window's root); default a new Tk.
    """

    #: wait for the user to close the window at the end of a run
    keep_open = True

    def __init__(self, width=1000, height=500, title="Stress and strain", master=None):
        import tkinter
        self._tkinter = tkinter
        self.tk = tkinter.Toplevel(master) if master is not None else tkinter.Tk()
        self.tk.title(title)
        self.width, self.height = width, height
        self.canvas = tkinter.Canvas(self.tk, width=width, height=height, bg="white")
        self.canvas.pack()
        self._last = 0.0

    def draw_axes(self, T_total, x_scale, y_scale_force, y_scale_strain, amplitude, t_on=None, t_off=None):
        """Axes, ticks, units and legend matching the plotter's mapping ``y = height/2 − value·scale``.

        Parameters
        ----------
        T_total : float
            Duration of the protocol (s): range of the time axis.
        x_scale : float
            Pixels per second.
        y_scale_force : float
            Pixels per Pa of the stresses (0: no stress ticks).
        y_scale_strain : float
            Pixels per unit strain.
        amplitude : float
            Strain amplitude A (marks at ±A).
        t_on, t_off : float, optional
            Start and end of the excitation (s), drawn as dashed lines.
        """
        c = self.canvas
        if not hasattr(c, "create_text"):  # minimal canvases (tests) draw dots only
            return
        W, H, y0 = self.width, self.height, self.height / 2
        c.create_line(0, y0, W, y0, fill="black")
        for t in nice_ticks(0, T_total, 8):
            x = t * x_scale
            c.create_line(x, y0 - 4, x, y0 + 4, fill="black")
            c.create_text(x + 2, y0 + 6, text=f"{t:.3g}", anchor="nw", font=("TkDefaultFont", 8))
        c.create_text(W - 4, y0 + 20, text="time t (s)", anchor="ne")
        if y_scale_force:
            half = y0 / abs(y_scale_force)
            for v in nice_ticks(-half, half, 8):
                y = y0 - v * y_scale_force
                c.create_line(0, y, 6, y, fill="black")
                c.create_text(8, y, text=f"{v:.3g}", anchor="w", font=("TkDefaultFont", 8))
            c.create_text(8, 4, text="stress − stress(0) (Pa)", anchor="nw")
        for v in (-amplitude, amplitude):
            y = y0 - v * y_scale_strain
            c.create_line(W - 6, y, W, y, fill="green")
            c.create_text(W - 8, y, text=f"\u03b3 = {v:+.3g}", anchor="e", fill="green", font=("TkDefaultFont", 8))
        for t in (t_on, t_off):
            if t is not None:
                c.create_line(t * x_scale, 0, t * x_scale, H, fill="grey", dash=(2, 4))
        for k, (col, label) in enumerate((("red", "\u03c4 internal (stress tensor)"),
                                          ("blue", "\u03c4 surface (plate forces)"), ("green", "strain \u03b3"))):
            y = 24 + 16 * k
            c.create_line(200, y, 220, y, fill=col, width=3)
            c.create_text(226, y, text=label, anchor="w")

    def update(self, min_interval=0.03):
        """Process window events, at most every ``min_interval`` s.

        Parameters
        ----------
        min_interval : float, optional
            Shortest time between two updates (s, default 0.03).
        """
        if time.monotonic() - self._last >= min_interval:
            try:
                self.tk.update()
            except self._tkinter.TclError:
                pass
            self._last = time.monotonic()

    def finish(self, wait=True):
        """End of the run: with ``wait``, wait until the user closes the window (see :attr:`keep_open`), then close.

        Parameters
        ----------
        wait : bool, optional
            Wait for the user (default True; only in the main process and with ``keep_open``).
        """
        import multiprocessing
        loop = getattr(self.tk, "mainloop", None)
        if wait and self.keep_open and loop is not None and multiprocessing.parent_process() is None:
            try:
                self.tk.title("Stress and strain (run finished: close this window to continue)")
                self.tk.protocol("WM_DELETE_WINDOW", self.tk.quit)  # closing ends the wait
                loop()
            except self._tkinter.TclError:
                pass
        self.close()

    def close(self):
        """Destroy the window (errors of an already closed window are ignored)."""
        try:
            self.tk.destroy()
        except Exception:
            pass


def _backend_choice(backend):
    if backend in (None, "auto"):
        backend = os.environ.get("PARTICLESHEAR_RENDERER", "auto") or "auto"
    backend = str(backend).lower()
    if backend not in ("auto", "tk", "pillow", "none"):
        raise ValueError(f"renderer backend must be 'auto', 'tk', 'pillow' or 'none', got {backend!r}")
    return backend


def make_renderer(doDrawing, save_images, size_x=500, size_y=500, title="particleShear",
                  graphical_output_configuration=None, backend="auto"):
    """Choose a renderer at run time (see the module docstring).

    Parameters
    ----------
    doDrawing : bool
        Show the live window when possible.  False: no window; a Pillow renderer is still
        returned when ``save_images`` (snapshots do not need a display).
    save_images : bool
        Snapshots will be saved (needs a renderer even without a display).
    backend : {"auto", "tk", "pillow", "none"}
        "auto" = Tk if a display is available, else Pillow for snapshots or nothing.
    size_x, size_y : float, optional
        Size of the live window (pixels = µm, default 500 × 500).
    title : str, optional
        Title of the live window.
    graphical_output_configuration : Graphical_output_configuration, optional
        Colours and drawing options.

    Returns
    -------
    Renderer or None

    Raises
    ------
    ValueError
        For an unknown ``backend``.
    RuntimeError
        For ``backend="tk"`` without a display.
    """
    backend = _backend_choice(backend)
    if backend == "none":
        return None
    if not doDrawing:
        return PillowRenderer(graphical_output_configuration) if save_images else None
    if backend == "pillow":
        return PillowRenderer(graphical_output_configuration) if save_images else None
    ok, reason = display_available()
    if ok:
        try:
            return TkRenderer(size_x, size_y, title, graphical_output_configuration)
        except Exception as exc:  # no usable Tk (TclError, ImportError, ...)
            if backend == "tk":
                raise
            ok, reason = False, f"Tk failed: {exc}"
    elif backend == "tk":
        raise RuntimeError(f"Tk renderer requested but no display is available ({reason})")
    _headless_message(reason, save_images)
    return PillowRenderer(graphical_output_configuration) if save_images else None


def open_stress_plot(width=1000, height=500, title="Stress and strain", renderer=None, backend="auto"):
    """Open the live stress/strain window, or return None (headless, or backend not Tk).

    Parameters
    ----------
    width, height : int, optional
        Canvas size (pixels, default 1000 × 500).
    title : str, optional
        Window title.
    renderer : Renderer, optional
        A live :class:`TkRenderer`: the window opens as its ``Toplevel``.
    backend : {"auto", "tk", "pillow", "none"}, optional
        "none"/"pillow" return None.

    Returns
    -------
    StressPlotWindow or None

    Raises
    ------
    ValueError
        For an unknown ``backend``.
    """
    backend = _backend_choice(backend)
    if backend in ("none", "pillow"):
        return None
    master = renderer.root if isinstance(renderer, TkRenderer) and not renderer.closed else None
    if master is None:
        ok, reason = display_available()
        if not ok:
            _headless_message(reason, False)
            return None
    try:
        return StressPlotWindow(width, height, title, master)
    except Exception as exc:
        _headless_message(f"Tk failed: {exc}", False)
        return None
