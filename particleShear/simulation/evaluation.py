"""Per-step recording of the oscillatory experiment and the demodulation of G′, G″.

The reference keeps Python lists that grow by one entry per step and recomputes
running estimates over the whole history at every step (O(n²) per run; reference defect
#43 in docs/output.md).
Here every series lives in a preallocated NumPy buffer (grown by doubling when
the number of steps is not known in advance); the reference list attributes
(``t``, ``strain``, ``stress_tensor_LW`` …) are built lazily when read, and the
running estimates ``Gprime`` / ``viscosity`` are computed on demand.
"""
__docformat__ = "numpy"
import math
import warnings

import numpy as np

from ..base.stress import StressTensorEvaluation, TENSOR_NAMES

__all__ = ["EvaluationHandler", "EvaluationHandlerPlotter", "demodulation"]

# scalar columns of the buffer
_T, _STRAIN, _RATE, _FORCE, _SHEAR = range(5)


def demodulation(t, shear_stress, f, amplitude, baseline_pre_periods=0, periods=2, baseline_post_periods=0,
                 correct_drift_sign=False):
    """Project a shear-stress series on the strain (sine) and strain-rate (cosine) signals.

    G′ is the least-squares amplitude of the component in phase with the strain
    ``A·sin(2π(f t − pre))``, G″ that of the component in phase with the strain rate (cosine),
    both divided by A, after a linear drift estimate from the baselines.

    Parameters
    ----------
    t : array_like
        Sample times since the start of the protocol (s).
    shear_stress : array_like
        Shear stress samples (Pa), same length as ``t``.
    f : float
        Excitation frequency (Hz).
    amplitude : float
        Strain amplitude A (absolute).
    baseline_pre_periods, periods, baseline_post_periods : float
        Protocol: ``pre`` baseline periods, ``periods`` excitation periods, ``post`` recovery periods.
    correct_drift_sign : bool, optional
        False (default) reproduces the reference quirk (defect #1 in docs/output.md): the drift estimate
        ``D = (S2 − S1)/(T1 − T2)`` is *minus* the baseline slope and is subtracted,
        so a linear drift is doubled instead of removed.  True uses
        ``D = (S2 − S1)/(T2 − T1)``, which removes a linear drift exactly.

    Returns
    -------
    list of float
        ``[in_phase_stress, out_of_phase_stress, G_prime, G_double_prime]`` in Pa; the moduli are the
        stresses divided by ``amplitude``.  The projection window is ``[(pre+e)/f, (pre+P)/f]`` with
        ``e = 1`` if ``P >= 2`` (first excitation period skipped as transient), else 0.

    Notes
    -----
    The baseline levels are the means over ``2·pre/(3f) <= t < pre/f`` and
    ``(pre+P)/f < t <= (pre+P+post/3)/f``; without a baseline (``pre`` or ``post`` = 0)
    the first or last sample is used.  Where the reference would divide by zero (a
    baseline window without samples) the first/last sample is used as well.
    """
    t = np.asarray(t, dtype=float)
    s = np.asarray(shear_stress, dtype=float)
    if t.shape != s.shape or t.ndim != 1:
        raise ValueError(f"t and shear_stress must be 1-D arrays of equal length, got shapes {t.shape} and {s.shape}")
    if len(t) == 0:
        return [math.nan, math.nan, math.nan, math.nan]
    pre = baseline_pre_periods
    P = periods
    post = baseline_post_periods
    e = 1 if P >= 2 else 0
    S1, T1 = float(s[0]), float(t[0])
    if pre > 0:
        w = (t >= 2 * pre / (3 * f)) & (t < pre / f)
        if w.any():
            S1, T1 = float(np.mean(s[w])), float(np.mean(t[w]))
    S2, T2 = float(s[-1]), float(t[-1])
    if post > 0:
        w = (t > (pre + P) / f) & (t <= (pre + P + post / 3) / f)
        if w.any():
            S2, T2 = float(np.mean(s[w])), float(np.mean(t[w]))
    if T1 == T2:
        D = 0.0
    elif correct_drift_sign:
        D = (S2 - S1) / (T2 - T1)
    else:
        D = (S2 - S1) / (T1 - T2)
    win = (t >= (pre + e) / f) & (t <= (pre + P) / f)
    tw = t[win]
    phase = 2 * math.pi * (f * tw - pre)
    a = np.sin(phase)
    b = np.cos(phase)
    sc = s[win] - (tw - pre / f) * D
    saa = float(a @ a)
    sbb = float(b @ b)
    SA = float(sc @ a) / saa if saa else math.nan
    SB = float(sc @ b) / sbb if sbb else math.nan
    return [SA, SB, SA / amplitude, SB / amplitude]


def _list_property(col, doc):
    def fget(self):
        return self._scal[: self._n, col].tolist()

    return property(fget, doc=doc + " (list built on demand from the NumPy buffer).")


def _tensor_history_property(k, name):
    def fget(self):
        if self._tens is None:
            return []
        return self._tens[: self._n, k].tolist()

    return property(fget, doc=f"History of ``{name}`` (2×2 nested lists per recorded step; "
                              "empty unless ``keep_tensor_history``).")


class EvaluationHandler:
    """Records time, strain, strain rate, both shear stresses and (optionally) the nine tensors per step.

    Reference attributes (read-only views built on demand): ``t`` (s), ``strain``,
    ``strain_rate`` (1/s), ``force`` (τ_surface, Pa), ``shear_stress`` (τ_internal, Pa),
    the tensor histories named as in :data:`particleShear.base.stress.TENSOR_NAMES`,
    ``overall_stress_tensor2`` (never filled, as in the reference), and the running
    estimates ``Gprime`` (−Σγτ/Σγ², Pa) and ``viscosity`` (−Σγ̇τ/Σγ̇², Pa·s).  After each
    :meth:`record`: ``total_mass`` (mg/m), ``xg`` (mass-weighted centre, µm), ``v_mean``
    (µm/s) and ``angular_momentum_around_origin`` (mg·µm²/s per m, spin included) — on
    every fully evaluated step (every step unless a protocol runs without tensor history,
    where only its first and last steps are fully evaluated).

    Storage: call :meth:`allocate` with the number of steps to preallocate; otherwise
    buffers grow by doubling.  ``keep_tensor_history`` (default True) controls whether the
    36 tensor numbers are stored per step; the first and last tensors are always kept
    (``first_tensors``, ``last_tensors``).
    """

    #: print a warning when the internal pair forces do not sum to zero to this relative level
    force_balance_tolerance = 1e-14
    #: the force-balance diagnostic runs on every k-th recorded step (1 = every step, as the reference)
    force_balance_check_interval = 25

    def __init__(self):
        self.theEvaluator = None
        self.keep_tensor_history = True
        self.check_force_balance = True
        self.n_force_balance_warnings = 0
        self._momenta = None
        self._momenta_values = {"total_mass": 0.0, "xg": [0.0, 0.0], "v_mean": [0.0, 0.0],
                                "angular_momentum_around_origin": 0.0}
        self.overall_stress_tensor2 = []
        self.first_tensors = None
        self.last_tensors = None
        self.reset()

    # -- storage ---------------------------------------------------------------------------------
    def reset(self):
        """Forget every recorded sample (buffers are released)."""
        self._n = 0
        self._planned = 0  # samples announced by allocate(); the last one gets all tensors
        self._scal = np.zeros((0, 5))
        self._tens = None
        self.first_tensors = None
        self.last_tensors = None

    def allocate(self, n_steps, keep_tensor_history=None):
        """Preallocate room for ``n_steps`` further samples (and the tensor history if kept).

        Parameters
        ----------
        n_steps : int
            Samples still to come (the last of them is always fully evaluated).
        keep_tensor_history : bool, optional
            Store the 36 tensor numbers of every step (True) or only the first and last
            tensors (False); None (default) keeps the current setting.
        """
        if keep_tensor_history is not None:
            self.keep_tensor_history = bool(keep_tensor_history)
        self._planned = self._n + int(n_steps)
        self._grow(self._n + int(n_steps))

    def _grow(self, cap):
        if cap <= len(self._scal) and (not self.keep_tensor_history or
                                       (self._tens is not None and len(self._tens) >= cap)):
            return
        cap = max(cap, 16)
        scal = np.zeros((cap, 5))
        scal[: self._n] = self._scal[: self._n]
        self._scal = scal
        if self.keep_tensor_history:
            tens = np.zeros((cap, 9, 2, 2))
            if self._tens is not None:
                tens[: self._n] = self._tens[: self._n]
            self._tens = tens

    def __len__(self):
        return self._n

    # reference list views
    t = _list_property(_T, "Sample times (s)")
    strain = _list_property(_STRAIN, "Strain γ before the step's update")
    strain_rate = _list_property(_RATE, "Applied shear rate γ̇ (1/s)")
    force = _list_property(_FORCE, "Shear stress from the external forces τ_surface (Pa)")
    shear_stress = _list_property(_SHEAR, "Shear stress from the overall tensor τ_internal (Pa)")

    for _k, _name in enumerate(TENSOR_NAMES):
        locals()[_name] = _tensor_history_property(_k, _name)
    del _k, _name

    # NumPy accessors
    def arrays(self):
        """Dict of the recorded series as NumPy arrays (copies): t, strain, strain_rate,
        stress_surface, stress_internal and, when kept, tensors (n, 9, 2, 2)."""
        n = self._n
        out = {"t": self._scal[:n, _T].copy(), "strain": self._scal[:n, _STRAIN].copy(),
               "strain_rate": self._scal[:n, _RATE].copy(), "stress_surface": self._scal[:n, _FORCE].copy(),
               "stress_internal": self._scal[:n, _SHEAR].copy()}
        if self._tens is not None:
            out["tensors"] = self._tens[:n].copy()
        return out

    @property
    def t_array(self):
        """Sample times t (s), a view of the buffer."""
        return self._scal[: self._n, _T]

    @property
    def strain_array(self):
        """Strain γ samples (–), a view of the buffer."""
        return self._scal[: self._n, _STRAIN]

    @property
    def strain_rate_array(self):
        """Strain-rate γ̇ samples (1/s), a view of the buffer."""
        return self._scal[: self._n, _RATE]

    @property
    def force_array(self):
        """τ_surface samples (Pa), a view of the buffer."""
        return self._scal[: self._n, _FORCE]

    @property
    def shear_stress_array(self):
        """τ_internal samples (Pa), a view of the buffer."""
        return self._scal[: self._n, _SHEAR]

    @property
    def tensor_history(self):
        """Array (n, 9, 2, 2) of the recorded tensors in output-column order, or None if not kept."""
        return None if self._tens is None else self._tens[: self._n]

    # running estimates (computed on demand; reference defect #43 in docs/output.md)
    @property
    def Gprime(self):
        """Running elastic estimate ``−Σ γ·τ_int / Σ γ²`` over all samples (Pa); 0 without strain."""
        g = self.strain_array
        den = float(g @ g)
        return -float(g @ self.shear_stress_array) / den if den else 0.0

    @property
    def viscosity(self):
        """Running viscous estimate ``−Σ γ̇·τ_int / Σ γ̇²`` over all samples (Pa·s); 0 without rate."""
        g = self.strain_rate_array
        den = float(g @ g)
        return -float(g @ self.shear_stress_array) / den if den else 0.0

    # -- recording -------------------------------------------------------------------------------
    def _check_balance(self, register):
        blocks = getattr(register, "_blocks", None)
        if not blocks:
            return
        sx = sy = den = 0.0
        for p in blocks:
            m = p["internal"]
            if not m.any():
                continue
            fix, fiy, fjx, fjy = p["fix"][m], p["fiy"][m], p["fjx"][m], p["fjy"][m]
            sx += float(fix.sum() + fjx.sum())
            sy += float(fiy.sum() + fjy.sum())
            den += float(np.abs(fix + fiy).sum() + np.abs(fjx + fjy).sum())
        if den and (abs(sx) / den >= self.force_balance_tolerance or abs(sy) / den >= self.force_balance_tolerance):
            self.n_force_balance_warnings += 1
            if self.n_force_balance_warnings == 1:
                warnings.warn(f"EvaluationHandler: internal pair forces do not balance: |ΣFx|/Σ|F| = {abs(sx) / den}, "
                      f"|ΣFy|/Σ|F| = {abs(sy) / den} (further warnings are counted in "
                      "n_force_balance_warnings)", RuntimeWarning, stacklevel=2)

    def _record_momenta(self, ens):
        """Keep what the momenta of this step are made of; they are summed when first read."""
        a = ens._a
        self._momenta = (ens.__dict__.get("_m_given"),
                         np.array((a["m"], a["x"], a["y"], a["xspeed"], a["yspeed"], a["omega"], a["inertia"])))
        self._momenta_values = None

    def _momentum_values(self):
        """``total_mass``, ``xg``, ``v_mean``, ``angular_momentum_around_origin`` of the last fully evaluated
        step as the reference computes them (docs/classes.md): plain Python numbers, summed sphere by sphere
        in list order, with the masses as given (``int`` masses give an ``int`` total mass)."""
        v = self._momenta_values
        if v is None:
            given, rows = self._momenta
            m, x, y, vx, vy, w, inertia = rows.tolist()
            if given is not None and len(given) == len(m) and np.array_equal(np.asarray(given, dtype=float),
                                                                               rows[0]):
                m = list(given)   # unchanged since they were given: use them as given
            M = 0
            sx = sy = su = sv = ang = 0.0
            for mk, xk, yk, uk, vk, wk, ik in zip(m, x, y, vx, vy, w, inertia):
                M += mk
                sx += mk * xk
                sy += mk * yk
                su += mk * uk
                sv += mk * vk
                ang += mk * xk * vk - mk * yk * uk + wk * ik
            v = {"total_mass": M, "xg": [sx / M, sy / M] if M else [0.0, 0.0],
                 "v_mean": [su / M, sv / M] if M else [0.0, 0.0], "angular_momentum_around_origin": ang}
            self._momenta_values = v
        return v

    def _momentum_property(name, doc):
        def fget(self):
            return self._momentum_values()[name]

        def fset(self, value):
            self._momentum_values()[name] = value

        return property(fget, fset, doc=doc)

    total_mass = _momentum_property("total_mass",
                                    "Σ m over all spheres (mg/m); an int if the masses were given as ints.")
    xg = _momentum_property("xg", "Mass-weighted centre ``[Σ m x / Σ m, Σ m y / Σ m]`` (µm), raw coordinates.")
    v_mean = _momentum_property("v_mean", "Mass-weighted mean velocity ``[Σ m v_x / Σ m, Σ m v_y / Σ m]`` (µm/s).")
    angular_momentum_around_origin = _momentum_property(
        "angular_momentum_around_origin",
        "``Σ (m x v_y − m y v_x + ω I)`` about the cell corner (mg·µm²/s per m depth), spin included.")
    del _momentum_property

    def record(self, theEnsemble, theEvaluator=False):
        """Evaluate the stress tensors of the current step and append one sample.

        Parameters
        ----------
        theEnsemble : ensemble
            After its force phase and ``record_total_particle_forces()``.
        theEvaluator : StressTensorEvaluation, optional
            Evaluator to use; by default the handler's ``theEvaluator`` (created on first use —
            the reference crashed without one, defect #34 in docs/output.md).

        Returns
        -------
        StressTensorEvaluation
            The evaluator used (its ``tensors`` hold this step's tensors when fully evaluated).
        """
        ev = theEvaluator or self.theEvaluator
        if not ev:
            ev = StressTensorEvaluation(theEnsemble.size_x, theEnsemble.size_y)
        self.theEvaluator = ev
        n = self._n
        if n >= len(self._scal) or (self.keep_tensor_history and (self._tens is None or n >= len(self._tens))):
            self._grow(max(2 * n, 16))
        if self.check_force_balance and n % self.force_balance_check_interval == 0:
            self._check_balance(theEnsemble.force_register)
        row = self._scal[n]
        row[_T] = theEnsemble.t
        row[_STRAIN] = theEnsemble.shear
        row[_RATE] = theEnsemble.shear_rate
        full = self.keep_tensor_history or n == 0 or n + 1 >= self._planned
        if not full and hasattr(ev, "evaluate_shear_stresses"):
            # tensors nobody keeps are not evaluated: only the two shear stresses G needs
            row[_SHEAR], row[_FORCE] = ev.evaluate_shear_stresses(
                theEnsemble.force_register, theEnsemble._mobile_selection())
            self._n = n + 1
            return ev
        self._record_momenta(theEnsemble)
        theEnsemble.evaluate_stress_tensors(ev)
        tens = ev.tensors
        row[_FORCE] = ev.evaluate_externally_applied_shear_stress()
        row[_SHEAR] = ev.evaluate_quasistatic_shear_stress()
        if self.keep_tensor_history:
            self._tens[n] = tens
            self.last_tensors = self._tens[n]
        else:
            self.last_tensors = tens.copy()
        if n == 0:
            self.first_tensors = tens.copy()
        self._n = n + 1
        return ev


class EvaluationHandlerPlotter(EvaluationHandler):
    """:class:`EvaluationHandler` that also plots each sample into a stress window (docs/output.md).

    ``theCanvas`` is a Tk canvas (or any object with ``create_oval``); with ``False``/None or
    ``plotStress=False`` nothing is drawn.  Three dots per sample at ``x = t·x_scale + offset_x``:
    red τ_internal − τ_internal(0), blue τ_surface − τ_surface(0) (scaled by ``y_scale_force``),
    green strain (scaled by ``y_scale_strain``), at ``y = offset_y − value·scale``.

    Parameters
    ----------
    theTk : tkinter.Tk or None
        The window's Tk root (kept for the reference API; not used for drawing).
    theCanvas : tkinter.Canvas or None
        Where the dots are drawn; False/None draws nothing.
    x_scale : float, optional
        Pixels per second of simulated time (default 1).
    y_scale_strain : float, optional
        Pixels per unit strain (default 1).
    y_scale_force : float, optional
        Pixels per Pa of both shear stresses (default 1).
    r : float, optional
        Dot radius in pixels (default 10).
    offset_x, offset_y : float, optional
        Pixel position of t = 0 and of the zero line (default 0).
    plotStress : bool, optional
        False: record only, draw nothing (default True).
    """

    def __init__(self, theTk, theCanvas, x_scale=1, y_scale_strain=1, y_scale_force=1, r=10, offset_x=0,
                 offset_y=0, plotStress=True):
        EvaluationHandler.__init__(self)
        self.theTk = theTk
        self.theCanvas = theCanvas
        self.x_scale = x_scale
        self.y_scale_strain = y_scale_strain
        self.y_scale_force = y_scale_force
        self.r = r
        self.offset_x = offset_x
        self.offset_y = offset_y
        self.plotStress = plotStress

    def plot(self, t, strain, force, shear_stress):
        """Draw one sample (stresses already relative to the first sample).

        Parameters
        ----------
        t : float
            Time of the sample (s).
        strain : float
            Strain γ (–).
        force : float
            τ_surface − τ_surface(0) (Pa).
        shear_stress : float
            τ_internal − τ_internal(0) (Pa).
        """
        c = self.theCanvas
        if not (self.plotStress and c):
            return
        x = t * self.x_scale + self.offset_x
        r = self.r
        for value, scale, colour in ((shear_stress, self.y_scale_force, "red"),
                                     (force, self.y_scale_force, "blue"),
                                     (strain, self.y_scale_strain, "green")):
            y = self.offset_y - value * scale
            c.create_oval(x - r, y - r, x + r, y + r, fill=colour, outline=colour)

    def record(self, theEnsemble, theEvaluator=False):
        ev = EvaluationHandler.record(self, theEnsemble, theEvaluator)
        if self.plotStress and self.theCanvas:
            s = self._scal
            n = self._n - 1
            self.plot(s[n, _T], s[n, _STRAIN], s[n, _FORCE] - s[0, _FORCE], s[n, _SHEAR] - s[0, _SHEAR])
        return ev
