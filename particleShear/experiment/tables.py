"""The typed table of one rheometer test, measured or simulated, in SI units.

A test is one kind of measurement (:data:`KINDS`) with columns of :data:`QUANTITIES`, every
column a float array in the quantity's SI unit (strain absolute, not %), all of one length.
Readers (:mod:`particleShear.experiment.readers`) make them from files; writers
(:mod:`particleShear.experiment.writers`) write them for RepTate and pyRheo.  :class:`Calibration` is
the ranking a calibration (:mod:`particleShear.experiment.calibration`) makes of a campaign against one.
"""
__docformat__ = "numpy"
import dataclasses
import os

import numpy as np

from ..sweep.table import write_table

__all__ = ["ASSUMPTIONS", "KINDS", "QUANTITIES", "RANKING_COLUMNS", "Calibration", "MeasuredTest"]

#: the kinds of test and the columns each must have (others may be present)
KINDS = {
    "amplitude_sweep": ("strain_amplitude", "Gp", "Gpp"),
    "frequency_sweep": ("angular_frequency", "Gp", "Gpp"),
    "flow_curve": ("shear_rate", "stress"),
    "relaxation": ("time", "G"),
    "creep": ("time", "strain"),
    "laos": ("time", "strain", "stress"),
}

#: column name → (SI unit, description)
QUANTITIES = {
    "strain_amplitude": ("1", "strain amplitude γ₀ (absolute: 0.01 = 1 %)"),
    "angular_frequency": ("rad/s", "angular frequency ω = 2πf"),
    "frequency": ("Hz", "frequency f"),
    "Gp": ("Pa", "storage modulus G′"),
    "Gpp": ("Pa", "loss modulus G″"),
    "stress_amplitude": ("Pa", "shear stress amplitude"),
    "shear_rate": ("1/s", "shear rate γ̇"),
    "stress": ("Pa", "shear stress σ"),
    "viscosity": ("Pa·s", "shear viscosity η = σ/γ̇"),
    "N1": ("Pa", "first normal-stress difference"),
    "time": ("s", "time since the start of the test (step, hold or waveform)"),
    "G": ("Pa", "relaxation modulus G(t)"),
    "strain": ("1", "shear strain γ (absolute)"),
    "compliance": ("1/Pa", "creep compliance J(t) = γ(t)/σ₀"),
    "temperature": ("°C", "sample temperature"),
}


@dataclasses.dataclass
class MeasuredTest:
    """One rheometer test as a typed table (SI units; see the module docstring).

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    columns : dict of str → numpy.ndarray
        Quantity name (:data:`QUANTITIES`) → float array, all of one length, SI units.
    meta : dict, optional
        What the source says of the test: ``source`` (file path), ``name`` (test or interval
        name), ``sample``, ``replicate``, the parameters of a creep (``stress``, Pa) or LAOS
        (``omega`` rad/s, ``gamma`` absolute) test, and for simulated data its parameters.
    origin : {"measured", "simulated"}, default "measured"

    Raises
    ------
    ValueError
        An unknown kind or quantity, a missing required column, columns of different lengths.
    """

    kind: str
    columns: dict
    meta: dict = dataclasses.field(default_factory=dict)
    origin: str = "measured"

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} is not allowed: one of {sorted(KINDS)}")
        if self.origin not in ("measured", "simulated"):
            raise ValueError(f"origin={self.origin!r} is not allowed: 'measured' or 'simulated'")
        cols = {}
        for name, v in self.columns.items():
            if name not in QUANTITIES:
                raise ValueError(f"column {name!r} is not a known quantity: one of {sorted(QUANTITIES)}")
            cols[name] = np.asarray(v, dtype=float).reshape(-1)
        missing = [c for c in KINDS[self.kind] if c not in cols]
        if missing:
            raise ValueError(f"a {self.kind} test needs the column(s) {missing}; it has {sorted(cols)}")
        lengths = {len(v) for v in cols.values()}
        if len(lengths) > 1:
            raise ValueError(f"the columns of a test must have one length, got {sorted(lengths)}")
        self.columns = cols

    def __len__(self):
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def __getitem__(self, name):
        return self.columns[name]

    def __contains__(self, name):
        return name in self.columns

    def unit(self, name):
        """The SI unit of a column (:data:`QUANTITIES`).

        Parameters
        ----------
        name : str
            A quantity of :data:`QUANTITIES`.

        Returns
        -------
        str
        """
        return QUANTITIES[name][0]

    def __repr__(self):
        src = self.meta.get("name") or self.meta.get("source") or ""
        head = f"MeasuredTest({self.kind}, {len(self)} points, {self.origin}" + (f", {src!r}" if src else "")
        cols = ", ".join(f"{c} [{QUANTITIES[c][0]}]" for c in self.columns)
        return head + f": {cols})"

    def finite(self):
        """A copy without the rows where a required column is not finite (NaN, inf)."""
        keep = np.ones(len(self), bool)
        for c in KINDS[self.kind]:
            keep &= np.isfinite(self.columns[c])
        return dataclasses.replace(self, columns={k: v[keep] for k, v in self.columns.items()}, meta=dict(self.meta))


#: the assumptions of a calibration, stated with every ranking (:mod:`particleShear.experiment.calibration`)
ASSUMPTIONS = (
    "rates: the simulation's frequency is dimensionless (f·τ = relative_frequency); the measured sweep is compared "
    "with a campaign run at the f·τ the material's τ gives for the rheometer's f (Hz); amplitudes are matched, the "
    "frequency is not",
    "moduli: G ∝ E at fixed dimensionless parameters, so the E to use is scale × Young_modulus_spheres",
    "2D vs 3D: the simulated stress is force per length per metre of depth (Pa), compared with the 3D moduli as is; "
    "a 2D→3D geometric factor would be absorbed into the scale (into E)",
    "shape: curves are normalised by their own G′ at the smallest amplitude both cover, interpolated linearly in "
    "log γ₀ on the overlap of the amplitude ranges",
)

#: columns of the ranking table: name → (unit, description)
RANKING_COLUMNS = {
    "rank": ("1", "1 = best match (smallest mismatch)"),
    "label": ("", "the grid point: its parameters that vary across the campaign"),
    "mismatch": ("1", "rms difference of G′/G′_p and G″/G′_p over the comparison points"),
    "p_best": ("1", "fraction of bootstrap replicates in which this grid point ranks first"),
    "scale": ("1", "modulus scale s = measured G′_p / simulated G′_p"),
    "scale_ci_low": ("1", "lower end of the bootstrap interval of scale"),
    "scale_ci_high": ("1", "upper end of the bootstrap interval of scale"),
    "Young_modulus_spheres": ("Pa", "the E the grid point was simulated with"),
    "E_to_use": ("Pa", "scale × Young_modulus_spheres: the E that matches the measured plateau"),
    "E_ci_low": ("Pa", "lower end of the bootstrap interval of E_to_use"),
    "E_ci_high": ("Pa", "upper end of the bootstrap interval of E_to_use"),
    "overlap_min": ("1", "smallest strain amplitude compared"),
    "overlap_max": ("1", "largest strain amplitude compared"),
    "n_points": ("1", "comparison points"),
    "n_runs": ("1", "simulated runs of the grid point"),
}


@dataclasses.dataclass
class Calibration:
    """The ranking of a campaign's grid points against a measured amplitude sweep (:func:`~particleShear.experiment.calibration.calibrate`).

    Parameters
    ----------
    rows : list of dict
        One per grid point, best first; columns :data:`RANKING_COLUMNS` plus the varying parameters.
    varying : list of str
        The parameters that vary across the grid (they label the grid points).
    measured : dict
        ``"A"`` (1), ``"Gp"``, ``"Gpp"`` (Pa): the mean measured curve; ``"replicates"``.
    simulated : dict
        label → ``{"A", "Gp", "Gpp", "parameters"}``: each grid point's mean curve (Pa, unscaled).
    settings : dict
        ``estimator``, ``n_boot``, ``confidence``, ``seed``, ``sweep_dir``.
    assumptions : tuple of str
        :data:`ASSUMPTIONS`.
    notes : list of str
        Grid points left out (fewer than 2 amplitudes, no overlap) and other remarks.
    """

    rows: list
    varying: list
    measured: dict
    simulated: dict
    settings: dict
    assumptions: tuple = ASSUMPTIONS
    notes: list = dataclasses.field(default_factory=list)

    @property
    def best(self):
        """The first row (the best grid point), or None."""
        return self.rows[0] if self.rows else None

    def columns(self):
        """The ranking table's columns, in order."""
        return ["rank", "label"] + list(self.varying) + [c for c in RANKING_COLUMNS if c not in ("rank", "label")]

    def write_csv(self, path):
        """Write the ranking table (atomically).

        Parameters
        ----------
        path : str or os.PathLike

        Returns
        -------
        str
        """
        path = os.fspath(path)
        write_table(path, self.rows, self.columns())
        return path

    def table_text(self, limit=20):
        """The ranking as printed text: one line per grid point (best first), the notes, the assumptions.

        Parameters
        ----------
        limit : int, optional
            Most grid points shown (default 20).

        Returns
        -------
        str
        """
        conf = int(round(100 * self.settings["confidence"]))
        lines = [f"calibration against {self.measured['replicates']} measured replicate(s), "
                 f"{self.settings['estimator']} estimator, {conf} % bootstrap intervals ({self.settings['n_boot']})"]
        for r in self.rows[:limit]:
            lines.append(f"{r['rank']:3d}. {r['label']}: mismatch {r['mismatch']:.4g}, p_best {r['p_best']:.2f}, "
                         f"scale {r['scale']:.4g} [{r['scale_ci_low']:.4g}, {r['scale_ci_high']:.4g}] "
                         f"-> E = {r['E_to_use']:.4g} Pa [{r['E_ci_low']:.4g}, {r['E_ci_high']:.4g}]")
        if len(self.rows) > limit:
            lines.append(f"     … {len(self.rows) - limit} more in the table")
        lines += [f"note: {n}" for n in self.notes]
        lines += [f"assumption: {a}" for a in self.assumptions]
        return "\n".join(lines)
