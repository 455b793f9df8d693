"""The typed table of one rheometer test, measured or simulated, in SI units.

A test is one kind of measurement (:data:`KINDS`) with columns of :data:`QUANTITIES`, every
column a float array in the quantity's SI unit (strain absolute, not %), all of one length.
Readers (:mod:`particleShear.experiment.readers`) make them from files; writers
(:mod:`particleShear.experiment.writers`) write them for RepTate and pyRheo.
"""
__docformat__ = "numpy"
import dataclasses

import numpy as np

__all__ = ["KINDS", "QUANTITIES", "MeasuredTest"]

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
            A quantity name.

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


