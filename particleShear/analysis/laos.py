"""Large-amplitude oscillatory shear (LAOS): Fourier moduli, Chebyshev coefficients and nonlinearity measures.

:func:`laos` turns one recorded strain and stress series of an oscillatory experiment at
frequency ``f`` into the odd Fourier moduli of the stress,

.. math::

    \\sigma(t) = \\gamma_0 \\sum_{n\\ \\mathrm{odd}} \\left(G'_n \\sin n\\theta + G''_n \\cos n\\theta\\right),
    \\qquad \\theta = \\omega t + \\varphi,\\ \\omega = 2\\pi f,

and the measures derived from them (all returned in a :class:`LaosResult`):

* ``G'_n``, ``G''_n`` (Pa): the storage and loss moduli of order ``n``; ``G'_1``, ``G''_1``
  are the first-harmonic moduli (the linear G′, G″ in the linear regime).
* Chebyshev coefficients (Ewoldt, Hosoi & McKinley 2008): ``e_n = G'_n (−1)^((n−1)/2)`` (Pa),
  ``v_n = G''_n / ω`` (Pa·s): the elastic stress is ``σ′ = γ₀ Σ e_n T_n(γ/γ₀)``, the viscous
  stress ``σ″ = γ̇₀ Σ v_n T_n(γ̇/γ̇₀)`` with ``γ̇₀ = γ₀ ω`` and ``T_n`` the Chebyshev
  polynomials of the first kind.
* Minimum-strain and large-strain moduli ``G_M = Σ n G'_n`` and ``G_L = Σ (−1)^((n−1)/2) G'_n``
  (Pa), the slope of σ′(γ) at γ = 0 and its secant at γ = ±γ₀; minimum-rate and large-rate
  dynamic viscosities ``η_M = Σ n (−1)^((n−1)/2) G''_n / ω`` and ``η_L = Σ G''_n / ω`` (Pa·s).
* Strain-stiffening ratio ``S = (G_L − G_M)/G_L`` and shear-thickening ratio
  ``T = (η_L − η_M)/η_L`` (dimensionless; 0 in the linear regime, > 0 for intracycle
  stiffening / thickening).
* Relative third-harmonic intensity ``I₃/I₁ = |G*_3|/|G*_1|`` with ``|G*_n| = hypot(G'_n, G''_n)``
  and the nonlinearity coefficient ``Q = (I₃/I₁)/γ₀²`` (Hyun & Wilhelm 2009), which tends to a
  constant ``Q₀`` as γ₀ → 0 for a material whose first nonlinearity is cubic.

The strain amplitude γ₀ and phase φ are taken from the strain signal itself (a least-squares fit
``γ ≈ c + a sin ωt + b cos ωt``, ``γ₀ = hypot(a, b)``, ``φ = atan2(b, a)``), so ``θ`` is the
phase of the strain, ``γ = c + γ₀ sin θ``, whatever the time origin.  The stress is fitted by
linear least squares on a constant and ``sin kθ``, ``cos kθ`` for *every* order
``k = 1 … n_max``; the even orders and the constant absorb a stress offset, an even harmonic
and the non-orthogonality of the basis on a span that is not a whole number of periods, and only
the odd orders (the ones of a response that is odd in the strain and its rate) are reported.
The fit therefore works on any span of at least one period, any starting phase.

Signs follow the stress as given, as in
:func:`~particleShear.simulation.evaluation.demodulation`: ``G'_1 > 0`` for a stress in phase
with the strain.

References
----------
R. H. Ewoldt, A. E. Hosoi, G. H. McKinley, "New measures for characterizing nonlinear
viscoelasticity in large amplitude oscillatory shear", J. Rheol. 52, 1427–1458 (2008).

K. Hyun, M. Wilhelm, "Establishing a new mechanical nonlinear coefficient Q from FT-rheology:
first investigation of entangled linear and comb polymer model systems", Macromolecules 42,
411–422 (2009).

K. S. Cho, K. Hyun, K. H. Ahn, S. J. Lee, "A geometrical interpretation of large amplitude
oscillatory shear response", J. Rheol. 49, 747–758 (2005) (the elastic/viscous stress
decomposition σ = σ′ + σ″).
"""
__docformat__ = "numpy"
import dataclasses
import math
import numbers

import numpy as np

__all__ = ["LaosResult", "laos"]

#: Relative slack on the one-period minimum span (a period sampled in floating point).
_SPAN_SLACK = 1e-9
#: The fit is refused when its condition number times the machine epsilon exceeds this.
_MAX_RELATIVE_ROUNDING = 1e-6


def _odd_signs(n):
    """``(−1)^((n−1)/2)`` for odd orders ``n``."""
    return np.where(((n - 1) // 2) % 2 == 0, 1.0, -1.0)


def _ratio(num, den):
    return float(num / den) if den != 0 else math.nan


def _frozen(a):
    a = np.array(a, dtype=float)
    a.setflags(write=False)
    return a


@dataclasses.dataclass(frozen=True, eq=False)
class LaosResult:
    """The LAOS measures of one strain/stress series (made by :func:`laos`; frozen).

    The arrays are read-only and indexed like :attr:`n`, the odd orders ``1, 3, …, ≤ n_max``.
    See the module docstring for the definitions and references.

    Parameters
    ----------
    n : numpy.ndarray of int
        The odd harmonic orders ``1, 3, 5, …`` up to ``n_max``.
    Gp : numpy.ndarray
        Storage moduli ``G'_n`` (Pa), the coefficients of ``γ₀ sin nθ`` in the stress.
    Gpp : numpy.ndarray
        Loss moduli ``G''_n`` (Pa), the coefficients of ``γ₀ cos nθ`` in the stress.
    e : numpy.ndarray
        Elastic Chebyshev coefficients ``e_n = G'_n (−1)^((n−1)/2)`` (Pa).
    v : numpy.ndarray
        Viscous Chebyshev coefficients ``v_n = G''_n / ω`` (Pa·s).
    G_M : float
        Minimum-strain modulus ``Σ n G'_n`` (Pa): slope of the elastic stress at γ = 0.
    G_L : float
        Large-strain modulus ``Σ (−1)^((n−1)/2) G'_n`` (Pa): secant of the elastic stress at γ = γ₀.
    eta_M : float
        Minimum-rate dynamic viscosity ``Σ n (−1)^((n−1)/2) G''_n / ω`` (Pa·s).
    eta_L : float
        Large-rate dynamic viscosity ``Σ G''_n / ω`` (Pa·s).
    S : float
        Strain-stiffening ratio ``(G_L − G_M)/G_L`` (dimensionless); NaN when ``G_L = 0``.
        Meaningless where the elastic stress is at rounding level (a purely viscous response).
    T : float
        Shear-thickening ratio ``(η_L − η_M)/η_L`` (dimensionless); NaN when ``η_L = 0``.
        Meaningless where the viscous stress is at rounding level (a purely elastic response).
    I3_I1 : float
        Relative third-harmonic intensity ``|G*_3|/|G*_1|``, ``|G*_n| = hypot(G'_n, G''_n)``
        (dimensionless); NaN when ``n_max < 3`` or ``|G*_1| = 0``.
    Q : float
        Nonlinearity coefficient ``(I₃/I₁)/γ₀²`` of Hyun & Wilhelm (dimensionless, strain is
        absolute); NaN where ``I3_I1`` is.
    strain_amplitude : float
        γ₀, the amplitude of the strain's first harmonic (absolute strain).
    phase : float
        φ (rad): the strain is ``c + γ₀ sin(ωt + φ)``.
    frequency : float
        f (Hz).
    omega : float
        ω = 2πf (rad/s).
    residual_rms : float
        Root mean square of the stress minus the fitted constant and all orders ``1 … n_max``
        (even ones included), in Pa: noise and harmonics above ``n_max``.
    """

    n: np.ndarray
    Gp: np.ndarray
    Gpp: np.ndarray
    e: np.ndarray
    v: np.ndarray
    G_M: float
    G_L: float
    eta_M: float
    eta_L: float
    S: float
    T: float
    I3_I1: float
    Q: float
    strain_amplitude: float
    phase: float
    frequency: float
    omega: float
    residual_rms: float

    def elastic_stress(self, theta):
        """The elastic stress ``σ′ = γ₀ Σ G'_n sin nθ`` (odd orders only).

        Plotted against the strain ``γ₀ sin θ`` it is the elastic Lissajous–Bowditch curve
        (single-valued, since odd ``sin nθ`` are polynomials of ``sin θ``).

        Parameters
        ----------
        theta : float or array_like
            Phase θ = ωt + φ of the strain (rad).

        Returns
        -------
        float or numpy.ndarray
            σ′ (Pa), of the shape of ``theta``.
        """
        return self._odd_series(np.sin, theta, self.Gp)

    def viscous_stress(self, theta):
        """The viscous stress ``σ″ = γ₀ Σ G''_n cos nθ`` (odd orders only).

        Plotted against the strain rate ``γ₀ ω cos θ`` it is the viscous Lissajous–Bowditch curve.

        Parameters
        ----------
        theta : float or array_like
            Phase θ = ωt + φ of the strain (rad).

        Returns
        -------
        float or numpy.ndarray
            σ″ (Pa), of the shape of ``theta``.
        """
        return self._odd_series(np.cos, theta, self.Gpp)

    def _odd_series(self, trig, theta, coefficients):
        """γ₀ Σ_n c_n trig(nθ) over the odd orders, of the shape of ``theta``."""
        theta = np.asarray(theta, dtype=float)
        out = self.strain_amplitude * (trig(np.multiply.outer(theta, self.n)) @ coefficients)
        return out if out.ndim else float(out)

    def lissajous(self, n_points=200):
        """The elastic and viscous Lissajous–Bowditch curves over one closed cycle, for plotting.

        Parameters
        ----------
        n_points : int, optional
            Points on the cycle θ ∈ [0, 2π], both ends included so the curves close (default 200, ≥ 2).

        Returns
        -------
        dict of numpy.ndarray
            ``theta`` (rad), ``strain`` ``γ₀ sin θ`` (without the strain's offset), ``strain_rate``
            ``γ₀ ω cos θ`` (1/s), ``elastic_stress`` σ′ and ``viscous_stress`` σ″ (Pa), and
            ``stress`` σ′ + σ″ (Pa, the odd part of the measured stress): plot ``elastic_stress``
            against ``strain``, ``viscous_stress`` against ``strain_rate``, ``stress`` against either.
        """
        if isinstance(n_points, bool) or not isinstance(n_points, numbers.Integral) or n_points < 2:
            raise ValueError(f"n_points must be an integer >= 2, got {n_points!r}")
        theta = np.linspace(0.0, 2 * np.pi, int(n_points))
        el = self.elastic_stress(theta)
        vi = self.viscous_stress(theta)
        return {"theta": theta, "strain": self.strain_amplitude * np.sin(theta),
                "strain_rate": self.strain_amplitude * self.omega * np.cos(theta),
                "elastic_stress": el, "viscous_stress": vi, "stress": el + vi}


def _series(name, x):
    a = np.asarray(x, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D array, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        bad = int(np.flatnonzero(~np.isfinite(a))[0])
        raise ValueError(f"{name} must be finite everywhere, got {a[bad]!r} at index {bad}")
    return a


def _check_frequency(f):
    if isinstance(f, bool) or not isinstance(f, numbers.Real) or not math.isfinite(f) or f <= 0:
        raise ValueError(f"f must be a finite frequency > 0 (Hz), got {f!r}")
    return float(f)


def laos(t, strain, stress, f, n_max=15):
    """Odd Fourier moduli, Chebyshev coefficients and nonlinearity measures of an oscillatory series.

    Fits the strain by ``c + a sin ωt + b cos ωt`` (γ₀ = hypot(a, b), φ = atan2(b, a)), then the
    stress by least squares (:func:`numpy.linalg.lstsq`) on a constant and ``sin kθ``, ``cos kθ``,
    ``θ = ωt + φ``, for all ``k = 1 … n_max``, and reports the odd orders as
    ``G'_k = A_k/γ₀``, ``G''_k = B_k/γ₀`` with the derived measures of the module docstring.

    Parameters
    ----------
    t : array_like
        Sample times (s), 1-D, strictly increasing; any origin, any span of at least one period.
    strain : array_like
        Shear strain γ (absolute, not %), same shape as ``t``: a sinusoid at ``f`` (an offset is allowed).
    stress : array_like
        Shear stress σ (Pa), same shape as ``t``, signed so that it is in phase with the strain
        for an elastic solid.
    f : float
        Excitation frequency (Hz), > 0.
    n_max : int, optional
        Highest harmonic order fitted (default 15, ≥ 1); the odd orders ``1, 3, … ≤ n_max`` are reported.

    Returns
    -------
    LaosResult
        The moduli ``Gp``, ``Gpp`` per odd order and every derived measure.

    Raises
    ------
    ValueError
        Naming the parameter, its value and what is allowed: ``t``, ``strain``, ``stress`` not 1-D,
        of different shapes, not finite, ``t`` not strictly increasing; ``f`` not a finite number
        > 0; ``n_max`` not an integer ≥ 1; fewer than ``4·n_max + 2`` samples (twice the
        ``2·n_max + 1`` unknowns); a sampling rate not above ``2·n_max·f`` (order ``n_max``
        would alias); a span shorter than one period ``1/f`` (each sample standing for the mean
        spacing; a shorter span leaves ``sin θ`` and its neighbours nearly collinear, so the
        low orders are ill-conditioned); a strain without a first harmonic (γ₀ = 0); a
        rank-deficient or ill-conditioned design (irregular sampling).

    Notes
    -----
    The design matrix holds ``len(t) × (2·n_max + 1)`` numbers (31 per sample by default).
    Harmonics above ``n_max`` in the stress are not fitted; on a span that is not a whole number
    of periods they leak into the fitted orders, so choose ``n_max`` above the last significant
    harmonic (``residual_rms`` shows what is left).  A drift of the stress is not removed.
    """
    t = _series("t", t)
    strain = _series("strain", strain)
    stress = _series("stress", stress)
    if strain.shape != t.shape:
        raise ValueError(f"strain must have the shape of t {t.shape}, got {strain.shape}")
    if stress.shape != t.shape:
        raise ValueError(f"stress must have the shape of t {t.shape}, got {stress.shape}")
    f = _check_frequency(f)
    if isinstance(n_max, bool) or not isinstance(n_max, numbers.Integral) or n_max < 1:
        raise ValueError(f"n_max must be an integer >= 1, got {n_max!r}")
    n_max = int(n_max)
    n_samples = len(t)
    needed = 4 * n_max + 2
    if n_samples < needed:
        raise ValueError(f"t, strain, stress: {n_samples} samples given, at least 4*n_max + 2 = {needed} are "
                         f"needed for n_max = {n_max} (twice the {2 * n_max + 1} fitted unknowns)")
    if not np.all(np.diff(t) > 0):
        bad = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"t must be strictly increasing, got t[{bad}] = {t[bad]!r} >= t[{bad + 1}] = {t[bad + 1]!r}")
    span = float(t[-1] - t[0]) * n_samples / (n_samples - 1)   # each sample stands for the mean spacing
    if span < (1 - _SPAN_SLACK) / f:
        raise ValueError(f"t spans {span!r} s (the {n_samples} samples at their mean spacing); at least one "
                         f"period 1/f = {1 / f!r} s is needed: a shorter span makes the low orders ill-conditioned")
    rate = n_samples / span
    if rate <= 2 * n_max * f:
        raise ValueError(f"t: mean sampling rate {rate!r} Hz, more than 2*n_max*f = {2 * n_max * f!r} Hz is needed "
                         f"to resolve order n_max = {n_max} at f = {f!r} Hz (fewer samples alias it)")

    omega = 2 * math.pi * f
    wt = omega * t
    design = np.column_stack((np.ones(n_samples), np.sin(wt), np.cos(wt)))
    (_, a, b), *_ = np.linalg.lstsq(design, strain, rcond=None)
    gamma0 = math.hypot(a, b)
    if not gamma0 > 1e-12 * float(np.max(np.abs(strain))):
        raise ValueError(f"strain has no first harmonic at f = {f!r} Hz (amplitude gamma0 = {gamma0!r}); "
                         f"a strain oscillating at f with an amplitude > 0 is needed")
    phase = math.atan2(b, a)

    theta = wt + phase
    k = np.arange(1, n_max + 1)
    ktheta = np.multiply.outer(theta, k)
    design = np.empty((n_samples, 2 * n_max + 1))
    design[:, 0] = 1.0
    design[:, 1::2] = np.sin(ktheta)
    design[:, 2::2] = np.cos(ktheta)
    del ktheta
    coef, _, rank, singular = np.linalg.lstsq(design, stress, rcond=None)
    if rank < design.shape[1] or singular[0] / singular[-1] * np.finfo(float).eps > _MAX_RELATIVE_ROUNDING:
        cond = singular[0] / singular[-1] if singular[-1] > 0 else math.inf
        raise ValueError(f"t: the sampling does not resolve the orders 1 ... n_max = {n_max} (design rank {rank} "
                         f"of {design.shape[1]}, condition number {cond:.3g}); sample more evenly or lower n_max")
    residual = stress - design @ coef
    residual_rms = float(np.sqrt(np.mean(residual ** 2)))

    n = np.arange(1, n_max + 1, 2)
    Gp = coef[2 * n - 1] / gamma0
    Gpp = coef[2 * n] / gamma0
    signs = _odd_signs(n)
    e = Gp * signs
    v = Gpp / omega
    G_M = float(np.sum(n * Gp))
    G_L = float(np.sum(signs * Gp))
    eta_M = float(np.sum(n * signs * Gpp)) / omega
    eta_L = float(np.sum(Gpp)) / omega
    if n_max >= 3:
        I3_I1 = _ratio(math.hypot(Gp[1], Gpp[1]), math.hypot(Gp[0], Gpp[0]))
    else:
        I3_I1 = math.nan
    n.setflags(write=False)
    return LaosResult(n=n, Gp=_frozen(Gp), Gpp=_frozen(Gpp), e=_frozen(e), v=_frozen(v),
                      G_M=G_M, G_L=G_L, eta_M=eta_M, eta_L=eta_L,
                      S=_ratio(G_L - G_M, G_L), T=_ratio(eta_L - eta_M, eta_L),
                      I3_I1=I3_I1, Q=I3_I1 / gamma0 ** 2, strain_amplitude=gamma0, phase=phase,
                      frequency=f, omega=omega, residual_rms=residual_rms)
