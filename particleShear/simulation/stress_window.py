"""The live stress/strain window (Tk) of a drawn run (docs/output.md, "Live windows").

:class:`StressPlotWindow` draws the time axis (s), the shear stress (Pa) and the strain of a run
as it goes; :func:`nice_ticks` chooses its round tick values.  Opened through
:func:`~particleShear.simulation.drawing.open_stress_plot`, fed by the
:class:`~particleShear.simulation.observers.StressWindow` observer.
"""
__docformat__ = "numpy"
import math
import time


__all__ = ["nice_ticks", "StressPlotWindow"]


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
        for k, (col, label) in enumerate((("red", "internal (stress tensor)"),
                                          ("blue", "surface (plate forces)"), ("green", "strain \u03b3"))):
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
