"""The reference text output (spec §9.1, §9.3): header blocks, summary, 42-column table, atomic files.

Values are formatted with ``str()`` exactly as the reference does.  Files are
written to a temporary file in the target folder and renamed into place with
``os.replace`` when complete, so an interrupted run never leaves a truncated file.
"""
import math
import os

from ..base.stress import TENSOR_NAMES

__all__ = ["TABLE_COLUMNS", "AtomicOutputFile", "reserve_numbered_path", "experiment_description_text",
           "output_summary_text", "table_text", "NO_TENSOR_DATA_TEXT"]

#: output-table column name stems of the nine tensors, in the order of TENSOR_NAMES
_TENSOR_COLUMN_STEMS = (
    "stress_tensor_Love_Weber",
    "stress_tensor_peculiar_acceleration_otsuki",
    "stress_tensor_from_external_forces",
    "stress_tensor_linear_acceleration",
    "stress_tensor_unbalanced_linear_forces",
    "stress_tensor_tangential_torque",
    "stress_tensor_internal_tangential_torque",
    "stress_tensor_centrifugal",
    "stress_tensor_overall",
)
assert len(_TENSOR_COLUMN_STEMS) == len(TENSOR_NAMES)

#: the 42 column names of the detailed stress tensor table (§9.1)
TABLE_COLUMNS = (["index", "t", "strain", "strain_rate", "stress_measured_at_surface",
                  "shear_stress_internal_stress-tensor"]
                 + [stem + "_" + ab for stem in _TENSOR_COLUMN_STEMS for ab in ("00", "01", "10", "11")])

NO_TENSOR_DATA_TEXT = ("\tNot saving detailed stress tensor data. If you wish to save this data, pass \n"
                       "\t  saveStressTensorData=True")


class AtomicOutputFile:
    """Text file written under a temporary name and moved to ``path`` by :meth:`commit`.

    ``abort()`` (or leaving a ``with`` block by an exception) removes the temporary file.
    The temporary name ``.<name>.part`` in the same folder is created exclusively, which
    also reserves ``path`` against concurrent runs choosing the same number (§9.3).
    """

    def __init__(self, path, exclusive=True):
        self.path = path
        folder, name = os.path.split(path)
        self.tmp_path = os.path.join(folder, "." + name + ".part")
        flags = os.O_WRONLY | os.O_CREAT | (os.O_EXCL if exclusive else os.O_TRUNC)
        fd = os.open(self.tmp_path, flags, 0o644)
        self._f = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.committed = False

    def write(self, text):
        return self._f.write(text)

    def flush(self):
        self._f.flush()

    def commit(self):
        """Close and move the complete file into place (``os.replace``)."""
        if self.committed:
            return self.path
        self._f.close()
        os.replace(self.tmp_path, self.path)
        self.committed = True
        return self.path

    def abort(self):
        """Close and delete the temporary file (nothing appears under ``path``)."""
        if not self._f.closed:
            self._f.close()
        if not self.committed and os.path.exists(self.tmp_path):
            os.remove(self.tmp_path)

    @property
    def closed(self):
        return self._f.closed

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.abort()
        return False


def reserve_numbered_path(stem, suffix=".txt"):
    """Open an :class:`AtomicOutputFile` at ``stem + str(k) + suffix`` for the smallest k ≥ 1 free.

    A number is free when neither the file nor its temporary twin exists; the temporary file
    is created exclusively, so concurrent processes never pick the same number.
    """
    k = 1
    while True:
        path = stem + str(k) + suffix
        if not os.path.exists(path):
            try:
                return AtomicOutputFile(path, exclusive=True)
            except FileExistsError:
                pass
        k += 1


def _s(v):
    return str(v)


def _particle_info(ens, reference):
    """The ensemble's description; the 1.0.2 text (with its §12 #23 defects) when ``reference``."""
    try:
        return ens.particle_info(reference=reference)
    except TypeError:
        return ens.particle_info()


def experiment_description_text(exp, reference_header=False):
    """Block 2 of §9.1 for an :class:`OscillatoryShearExperiment` ``exp`` (ends with a newline).

    ``reference_header=True`` reproduces the reference's bookkeeping defects: "Simulated
    time" = excitation time only (§12 #22) and "Post-measurement periods" printing the
    pre value (§12 #21).  By default both are correct (whole protocol time; post value).
    """
    ens = exp.theEnsemble
    L = ["Oscillatory shear experiment", ""]
    model = getattr(ens, "model", False)
    if model:
        L += ["Model parameters",
              "Width of simulation area size_x =" + _s(model.size_x) + "micrometers",
              "Height of simulation area size_y =" + _s(model.size_y) + "micrometers",
              "Nominal packing fraction = " + _s(model.packing_fraction),
              "Young modulus spheres = " + _s(model.Young_modulus_spheres) + "Pa",
              "Relative density spheres = " + _s(model.density) + "kg/m^3",
              "Characteristic time constant = " + _s(model.time_constant) + "s",
              "Characteristic spring constant = " + _s(model.k) + "mg/s^2",
              "Characteristic viscosity  = " + _s(model.k * model.time_constant) + "mg/s",
              ""]
    L += ["Ensemble parameters"]
    if model:
        L += ["Particle mass m = " + _s(model.m) + "mg"]
    L += ["Central spring constant k = " + _s(ens.k) + "mg*s^(-2)",
          "Central viscosity constant nu = " + _s(ens.nu) + "mg*s^(-1)",
          "Lateral spring constant k_t = " + _s(ens.k_t) + "mg*s^(-2)",
          "Lateral viscosity constant nu_t = " + _s(ens.nu_t) + "mg*s^(-1)",
          "Friction coefficient mu = " + _s(ens.mu),
          "Sample width = " + _s(ens.size_x) + "micrometers",
          "Sample height = Gap height = " + _s(ens.size_y) + "micrometers",
          "Particle number = " + _s(ens.N if hasattr(ens, "N") else len(ens.sphereList)),
          "Particle information",
          "\t" + _particle_info(ens, reference_header)]
    if hasattr(ens, "central_repulsion_coefficient"):
        L.append("Nonlinear enhancement for repulsion near sphere center = " + _s(ens.central_repulsion_coefficient)
                 + "[-], 0=no enhancement, 1=maximum enhancement; see CircleBasicElasticity.get_elastic_force")
    if hasattr(ens, "permanent_ratio_central"):
        prc = ens.permanent_ratio_central
        L += ["Adjustment coefficient for central force in permanent links = " + _s(prc)
              + "[-], 0=no central force, 1=as in free interfaces; >1 re-enforcement of permanent over "
                "transient links",
              "\tk_permanent=" + _s(ens.k * prc) + "mg*s^(-2)"]
    if hasattr(ens, "permanent_ratio_tangential"):
        prt = ens.permanent_ratio_tangential
        L += ["Adjustment coefficient for tangential force in permanent links = " + _s(prt)
              + "[-], 0=no tangential force, 1=as in free interfaces; >1 re-enforcement of permanent over "
                "transient links",
              "\tk_t_permanent=" + _s(ens.k_t * prt) + "mg*s^(-2)"]
    if hasattr(ens, "keep_viscosity_coefficients_constant") and hasattr(ens, "permanent_ratio_central"):
        L.append("Viscosity adjustment for permanent links:")
        if ens.keep_viscosity_coefficients_constant:
            L += ["\tNo adjustment: Impose constant viscosity regardless of the permanent link adjustment ",
                  "\tnu_permanent=" + _s(ens.nu), "\tnu_t_permanent=" + _s(ens.nu_t)]
        else:
            L += ["\tAdjustment: Adjust viscosity (central and tangential) by same factor as the respective "
                  "spring constant (k and k_t)",
                  "\tnu_permanent=" + _s(ens.nu * ens.permanent_ratio_central),
                  "\tnu_t_permanent=" + _s(ens.nu_t * ens.permanent_ratio_tangential)]
    if hasattr(ens, "avoid_height_spanning_particles"):
        if ens.avoid_height_spanning_particles:
            L.append("avoid_height_spanning_particles: Ensembles with full height spanning particles discarded")
        else:
            L.append("avoid_height_spanning_particles: Full height spanning particles allowed")
    if hasattr(ens, "removed_fraction"):
        L += ["Actual fraction of randomly removed non-essential permanent bonds = " + _s(ens.removed_fraction)
              + "[-]", ""]
    if hasattr(ens, "edge_fuzziness"):
        L += ["Edge fuzziness for creating interlocking = " + _s(ens.edge_fuzziness) + "[-]", ""]
    pre, P, post, f = exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods, exp.f
    simulated = P / f if reference_header else (pre + P + post) / f
    L += ["",
          "Rheology experiment information",
          "Simulated time = " + _s(simulated) + "s",
          "Time step = " + _s(exp.dt) + "s",
          "Frequency = " + _s(f) + "Hz",
          "Strain amplitude = " + _s(100 * exp.amplitude) + "%",
          "Damping factor = " + _s(exp.cool_factor) + " [1 = no damping]",
          "Pre-measurement periods = " + _s(pre) + " [-]",
          "Oscillatory shear periods = " + _s(P) + " [-]",
          "Post-measurement periods = " + _s(pre if reference_header else post) + " [-]"]
    return "\n".join(L) + "\n"


def output_summary_text(G_internal, G_surface):
    """Block 3 up to and including the line "Detailed stress tensor data" (no newline at the end).

    ``G_internal`` / ``G_surface`` are the demodulation results ``[SA, SB, G', G'']``.
    """
    SA, SB, Gp, Gpp = G_internal
    L = ["", "", "Output data", "Summary data",
         "In phase stress = " + _s(SA) + "Pa",
         "Out of phase stress = " + _s(SB) + "Pa",
         "Stress = " + _s(math.sqrt(SA ** 2 + SB ** 2)) + "Pa",
         "G'=" + _s(Gp) + "Pa",
         "G''=" + _s(Gpp) + "Pa",
         "G'(by surface force)=" + _s(G_surface[2]) + "Pa",
         "G''(by surface force)=" + _s(G_surface[3]) + "Pa",
         "", "",
         "Detailed stress tensor data"]
    return "\n".join(L)


def table_text(scalars, tensors):
    """The header line and the data lines of the 42-column table, each data line preceded by "\\n".

    ``scalars`` (n, 5) = t, strain, strain_rate, τ_surface, τ_internal; ``tensors`` (n, 9, 2, 2).
    Returns the text starting with a newline (after "Detailed stress tensor data") and without a
    trailing newline.
    """
    n = len(scalars)
    parts = ["\n", "\t".join(TABLE_COLUMNS)]
    sc = scalars.tolist()
    tt = tensors.reshape(n, 36).tolist()
    for k in range(n):
        parts.append("\n" + str(k) + "\t" + "\t".join(map(str, sc[k])) + "\t" + "\t".join(map(str, tt[k])))
    return "".join(parts)
