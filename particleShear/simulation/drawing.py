"""Drawing: one renderer interface, a Pillow backend (files) and a Tk backend (live windows) (spec §9.4, §9.5).

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
import math
import os
import sys
import time

import numpy as np

from ..base.kernels import min_image
from ..base.neighbours import PERMANENT, SLIP

__all__ = ["Renderer", "PillowRenderer", "TkRenderer", "StressPlotWindow", "display_available",
           "make_renderer", "open_stress_plot", "scene_geometry", "IMAGE_EXTENSIONS"]

#: imageFileType → (file extension, Pillow format)
IMAGE_EXTENSIONS = {"jpg": (".jpg", "JPEG"), "png": (".png", "PNG"), "ps": (".ps", "EPS"), "eps": (".eps", "EPS")}

_headless_message_printed = False


def _headless_message(reason, files):
    global _headless_message_printed
    if _headless_message_printed:
        return
    _headless_message_printed = True
    extra = " Snapshots are rendered off-screen with Pillow." if files else ""
    print(f"particleShear: no display available ({reason}); running headless without live windows.{extra}",
          file=sys.stderr)


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

    Returns a dict with ``x, y, r, phi`` (per sphere), ``chords`` (k, 4) = x1, y1, x2, y2 and
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


class Renderer:
    """Interface of a drawing backend.

    ``draw(ens)`` draws the initial picture, ``update(ens)`` is called by the ensemble after
    every movement (only for live backends, which set ``live = True``), ``save(ens, path,
    file_type)`` writes a snapshot and ``close()`` releases windows.
    """

    live = False

    def draw(self, ens):
        pass

    def update(self, ens):
        pass

    def save(self, ens, path, file_type="jpg"):
        raise NotImplementedError

    def close(self):
        pass


class PillowRenderer(Renderer):
    """Off-screen rendering of the particle picture with Pillow (imported on first use)."""

    def __init__(self, graphical_output_configuration=None, scale=1.0, background="white"):
        self.cfg = graphical_output_configuration
        self.scale = float(scale)
        self.background = background

    def _opt(self, name, default):
        return getattr(self.cfg, name, default) if self.cfg is not None else default

    def render(self, ens):
        """Return a ``PIL.Image`` of the current state (y drawn downwards, as on the Tk canvas)."""
        from PIL import Image, ImageDraw
        cfg = self.cfg if self.cfg is not None else getattr(ens, "graphical_output_configuration", None)
        self.cfg = cfg
        s = self.scale
        W, H = int(round(ens.size_x * s)), int(round(ens.size_y * s))
        img = Image.new("RGB", (max(W, 1), max(H, 1)), self.background)
        dr = ImageDraw.Draw(img)
        g = scene_geometry(ens)
        how = self._opt("draw_spheres_as", "spheres")
        fill = self._opt("color_spheres_volume", "grey")
        if how != "none":
            for xx, yy, rr in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist()):
                rad = rr if how == "spheres" else 2.0 / s
                dr.ellipse([(xx - rad) * s, (yy - rad) * s, (xx + rad) * s, (yy + rad) * s], fill=fill,
                           outline="black")
        if self._opt("draw_rotation_line", False):
            col = self._opt("color_rotation_line", "black")
            for xx, yy, rr, ph in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist(), g["phi"].tolist()):
                dr.line([xx * s, yy * s, (xx + rr * math.cos(ph)) * s, (yy + rr * math.sin(ph)) * s], fill=col)
        w = max(1, int(round(3 * s)))
        if self._opt("draw_active_interface", True):
            locked = self._opt("color_interface_locked", "red")
            slip = self._opt("color_interface_slip", "green")
            for seg, st in zip(g["chords"].tolist(), g["chord_state"].tolist()):
                dr.line([v * s for v in seg], fill=slip if st == SLIP else locked, width=w)
        if self._opt("draw_permanent_interfaces", False):
            for seg in g["perm_chords"].tolist():
                dr.line([v * s for v in seg], fill="darkorange", width=w)
        for seg in g["links"].tolist():
            dr.line([v * s for v in seg], fill="blue", width=w)
        return img

    def save(self, ens, path, file_type="jpg"):
        """Write a snapshot atomically (temporary file in the same folder, then ``os.replace``)."""
        ext, fmt = IMAGE_EXTENSIONS.get(file_type, IMAGE_EXTENSIONS["ps"])
        img = self.render(ens)
        tmp = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".part")
        try:
            options = {"PNG": {"compress_level": 1}, "JPEG": {"quality": 90}}.get(fmt, {})
            img.save(tmp, format=fmt, **options)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)


class TkRenderer(Renderer):
    """Live particle window (``size_x × size_y`` pixels).  Redraws at most every ``min_interval`` s."""

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
        fill = getattr(cfg, "color_spheres_volume", "grey")
        how = getattr(cfg, "draw_spheres_as", "spheres")
        if how != "none":
            for xx, yy, rr in zip(g["x"].tolist(), g["y"].tolist(), g["r"].tolist()):
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

    def save(self, ens, path, file_type="jpg"):
        self._pillow.cfg = self.cfg if self.cfg is not None else getattr(ens, "graphical_output_configuration", None)
        self._pillow.save(ens, path, file_type)

    def close(self):
        if not self.closed:
            self.closed = True
            try:
                self.root.destroy()
            except Exception:
                pass


class StressPlotWindow:
    """Tk window with a ``width × height`` canvas for the stress/strain plot (§9.5)."""

    def __init__(self, width=1000, height=500, title="Stress and strain", master=None):
        import tkinter
        self._tkinter = tkinter
        self.tk = tkinter.Toplevel(master) if master is not None else tkinter.Tk()
        self.tk.title(title)
        self.canvas = tkinter.Canvas(self.tk, width=width, height=height, bg="white")
        self.canvas.pack()
        self._last = 0.0

    def update(self, min_interval=0.03):
        if time.monotonic() - self._last >= min_interval:
            try:
                self.tk.update()
            except self._tkinter.TclError:
                pass
            self._last = time.monotonic()

    def close(self):
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
        Draw at all (live window when possible).  False → None (and no snapshots, as in the reference).
    save_images : bool
        Snapshots will be saved (needs a renderer even without a display).
    backend : {"auto", "tk", "pillow", "none"}
        "auto" = Tk if a display is available, else Pillow for snapshots or nothing.

    Returns
    -------
    Renderer or None
    """
    backend = _backend_choice(backend)
    if not doDrawing or backend == "none":
        return None
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
    """Open the live stress/strain window, or return None (headless, or backend not Tk)."""
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
