"""Concrete non-crosslinkable ensembles of random bimodal spheres (lengths µm, masses mg per m depth)."""
__docformat__ = "numpy"

from ..base.canvas import (CanvasPointsBasicElasticity, CanvasPointsBasicElasticityLeesEdwards,
                           CanvasPointsFrictionElasticityLeesEdwards, NonNegative, ReplicaValue,
                           check_non_negative)
from ..checks import integer, positive as _check_positive
from .placement import bimodal_factors, bimodal_placement
from .spheres import SphereFriction, SphereFrictionLeesEdwards, SphereLeesEdwards

__all__ = ["Ensemble", "EnsembleFriction", "EnsembleLeesEdwards", "EnsembleFrictionLeesEdwards",
           "RandomBimodalSpheres"]


class RandomBimodalSpheres:
    """Mixin: N spheres of radius ``r_b/√bf`` or ``r_b·√bf`` (probability 1/2) at random integer positions.

    ``r_b``: :func:`~particleShear.objects.model.r_estimate`; masses ``adjust_m(m, r, r_b)``; no overlap
    check.  Every draw comes from the ensemble's ``numpy.random.Generator`` (one seed fixes the ensemble).
    """

    def _init_bimodal(self, N, packing_fraction, bimodal_factor):
        integer("N", N, 0)
        _check_positive("packing_fraction", packing_fraction)
        _check_positive("bimodal_factor", bimodal_factor)
        self.bimodal_lower, self.bimodal_upper = bimodal_factors(bimodal_factor)
        self.N, self.packing_fraction, self.r_max = N, packing_fraction, 0

    def random_radius_bimodal(self, r):
        """Return ``r/√bf`` or ``r·√bf`` (µm) with equal probability (one draw of the ensemble's generator).

        Parameters
        ----------
        r : float
        """
        return r * (self.bimodal_lower + (self.bimodal_upper - self.bimodal_lower) * int(self._rng.integers(0, 2)))

    def _create_spheres(self, N, m):
        """Draw and append N spheres; one block of draws per quantity, in index order."""
        self._append_spheres(*bimodal_placement(self._rng, N, self.size_x, self.size_y, self.packing_fraction,
                                                self.bimodal_lower, self.bimodal_upper, m))

    def _append_spheres(self, x, y, r, mass):
        """Append a sphere of the class (``_new_sphere``) per element of the given placement, in index order,
        growing ``r_max``; no draw (a placement made elsewhere: ``linkable.builders.ensemble_of_state``).

        Parameters
        ----------
        x, y, r, mass : array_like of float (n,)
            Positions and radii (µm), masses (mg per m depth).
        """
        first = len(self.sphereList)
        for p in range(len(r)):
            self.r_max = max(self.r_max, float(r[p]))
            self.sphereList.append(self._new_sphere(float(x[p]), float(y[p]), float(r[p]), float(mass[p]),
                                                    first + p))

    def particle_info(self):
        """Description of the spheres (radii ``r1``, ``r2`` in µm) for the header of the output file."""
        return ("Spheres with, bimodal distribution, equal probability, \n\tr1="
                + str(self.r_max / self.bimodal_upper * self.bimodal_lower) + "r2=" + str(self.r_max))


class Ensemble(RandomBimodalSpheres, CanvasPointsBasicElasticity):
    """Legacy ensemble: periodic cell (minimum image) without shear offset, frictional spheres, central forces.

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor
        As for :class:`EnsembleFrictionLeesEdwards` (ValueError when out of range).
    """

    use_lees_edwards = False

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1,
                 nu=0.01, m=1, bimodal_factor=1.4):
        CanvasPointsBasicElasticity.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self.record_type, self.spheres_boundary = "internal", []
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereFriction(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                              self.theCanvas, self.doDrawing, self)

    def periodic_boundary_extension(self):
        """No replicas are needed: the minimum image makes the cell periodic."""
        self.spheres_boundary = []


class EnsembleFriction(Ensemble):
    """Legacy periodic ensemble with tangential forces (no shear offset).

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor, k_t, nu_t, mu
        As for :class:`EnsembleFrictionLeesEdwards` (ValueError when out of range).
    """

    k_t = NonNegative()
    nu_t = NonNegative()
    mu = ReplicaValue(check_non_negative)

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1,
                 nu=0.01, m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1):
        Ensemble.__init__(self, size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m,
                          bimodal_factor)
        self.k_t, self.nu_t, self.mu = k_t, nu_t, mu


# EnsembleFriction takes the friction canvas's tangential machinery; its strain advances as in its base class
for _name, _value in vars(CanvasPointsFrictionElasticityLeesEdwards).items():
    if not _name.startswith("__") and _name not in ("_strain_only_while_shearing", "k_t", "nu_t", "mu"):
        setattr(EnsembleFriction, _name, _value)
del _name, _value


class EnsembleLeesEdwards(RandomBimodalSpheres, CanvasPointsBasicElasticityLeesEdwards):
    """Frictionless Lees-Edwards ensemble (constructible, unlike in 1.0.2 for N > 0).

    Parameters
    ----------
    size_x, size_y, N, packing_fraction, theCanvas, doDrawing, k, nu, m, bimodal_factor
        As for :class:`EnsembleFrictionLeesEdwards` (ValueError when out of range).
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1,
                 nu=0.01, m=1, bimodal_factor=1.4):
        CanvasPointsBasicElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereLeesEdwards(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r, m, index,
                                 self.theCanvas, self.doDrawing, self, self.size_x, self.size_y)


class EnsembleFrictionLeesEdwards(RandomBimodalSpheres, CanvasPointsFrictionElasticityLeesEdwards):
    """Frictional spheres under Lees-Edwards boundary conditions (ValueError when a parameter is out of range).

    Parameters
    ----------
    size_x, size_y : float
        Periodic cell (µm), > 0.
    N : int
        Number of spheres, >= 0 (0 for hand-built scenes).
    packing_fraction, bimodal_factor : float, optional
        Nominal area fraction φ (eq. S1-14) and large/small radius ratio bf, > 0.
    theCanvas, doDrawing : optional
        Tk canvas of the live drawing (False: none) and whether the spheres are drawn on it.
    k, nu, k_t, nu_t : float, optional
        Central and tangential spring (mg·s⁻²) and viscosity (mg·s⁻¹) constants per m depth, >= 0
        (eq. S1-8, S1-9).
    m : float, optional
        Mass of a sphere of the mean radius (mg per m depth); masses scale with the area.
    mu : float, optional
        Coulomb friction coefficient μ of transient contacts, >= 0.
    """

    def __init__(self, size_x, size_y, N, packing_fraction=0.8, theCanvas=False, doDrawing=False, k=1,
                 nu=0.01, m=1, bimodal_factor=1.4, k_t=1, nu_t=0.01, mu=0.1):
        CanvasPointsFrictionElasticityLeesEdwards.__init__(self, size_x, size_y, theCanvas, doDrawing, k, nu, m,
                                                           k_t, nu_t, mu)
        self._init_bimodal(N, packing_fraction, bimodal_factor)
        self._create_spheres(N, m)

    def _new_sphere(self, x, y, r, m, index):
        return SphereFrictionLeesEdwards(self.graphical_output_configuration.color_spheres_volume, x, y, 2 * r,
                                         m, index, self.theCanvas, self.doDrawing, self, self.size_x,
                                         self.size_y)

    def particle_info(self):
        return "Frictional spheres under Lees-Edwards boundary conditions\n\t" + \
            RandomBimodalSpheres.particle_info(self)
