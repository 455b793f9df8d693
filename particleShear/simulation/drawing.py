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

from ..base.neighbours import SLIP
from .scene import (CAPTION_HEIGHT, PARTICLE_COLOURS, _ascii, _font, caption_items, particle_labels,  # noqa: F401 (re-exported)
                    periodic_offsets, scale_bar_length, scene_geometry, scene_primitives, snapshot_caption,
                    sphere_fills)
from .stress_window import StressPlotWindow, nice_ticks  # noqa: F401 (re-exported)

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
