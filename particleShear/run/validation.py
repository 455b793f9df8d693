"""Validation of every ``doParticleShearSimulation`` parameter before any work (spec §10.1).

Each failure raises ``ValueError`` (``TypeError`` for a wrong type) naming the
parameter, its value and the allowed range.
"""
import math
import numbers
import os

import numpy as np

__all__ = ["validate_simulation_parameters", "IMAGE_FILE_TYPES"]

#: accepted ``imageFileType`` values (the reference silently wrote PostScript for anything else)
IMAGE_FILE_TYPES = ("jpg", "png", "ps")


def _real(name, v):
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError(f"{name}={v!r} is invalid: allowed a real number")
    if not math.isfinite(v):
        raise ValueError(f"{name}={v!r} is out of range: allowed a finite number")
    return float(v)


def _range(name, v, lo=None, hi=None, lo_open=False, hi_open=False):
    x = _real(name, v)
    bad = ((lo is not None and (x <= lo if lo_open else x < lo))
           or (hi is not None and (x >= hi if hi_open else x > hi)))
    if bad:
        left = "" if lo is None else (f"{lo} < " if lo_open else f"{lo} <= ")
        right = "" if hi is None else (f" < {hi}" if hi_open else f" <= {hi}")
        raise ValueError(f"{name}={v!r} is out of range: allowed {left}value{right}")


def _int(name, v, lo):
    x = _real(name, v)
    if int(x) != x or x < lo:
        raise ValueError(f"{name}={v!r} is out of range: allowed integers >= {lo}")


def _bool(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{name}={v!r} is invalid: allowed True or False")


def validate_simulation_parameters(p):
    """Check the dict ``p`` of ``doParticleShearSimulation`` arguments; raise on the first bad value."""
    for name in ("do_permanent_links", "keep_viscosity_coefficients_constant", "avoid_height_spanning_particles",
                 "cut_top_bottom", "saveOutputImages", "doCutByTriangulation", "doDrawing", "saveData",
                 "saveStressTensorData", "plotStress"):
        _bool(name, p[name])
    _range("theAmplitude", p["theAmplitude"], 0, lo_open=True)
    _range("theMu", p["theMu"], 0)
    _int("cut_lines", p["cut_lines"], 0)
    _range("Young_modulus_spheres", p["Young_modulus_spheres"], 0, lo_open=True)
    _int("N", p["N"], 2)
    _range("packing_fraction", p["packing_fraction"], 0, lo_open=True)
    _range("density", p["density"], 0, lo_open=True)
    _range("bimodal_factor", p["bimodal_factor"], 0, lo_open=True)
    _range("relative_viscosity", p["relative_viscosity"], 0)
    _range("relative_transversal_link_strength", p["relative_transversal_link_strength"], 0)
    _range("relative_frequency", p["relative_frequency"], 0, lo_open=True)
    _range("avoid_horizontal_angle_degree", p["avoid_horizontal_angle_degree"], 0, 90, hi_open=True)
    _range("interface_reenforcement_central", p["interface_reenforcement_central"], 0, lo_open=True)
    _range("interface_reenforcement_tangential", p["interface_reenforcement_tangential"], 0, lo_open=True)
    if p["imageFileType"] not in IMAGE_FILE_TYPES:
        raise ValueError(f"imageFileType={p['imageFileType']!r} is invalid: allowed one of {IMAGE_FILE_TYPES}")
    _range("remove_link_fraction", p["remove_link_fraction"], 0, 1)
    _range("edge_fuzziness", p["edge_fuzziness"], 0)
    _range("central_repulsion_coefficient", p["central_repulsion_coefficient"], 0, 1)
    _real("relative_y_scale_force", p.get("relative_y_scale_force", 1e8))
    _range("pre_periods", p["pre_periods"], 0)
    _range("periods", p["periods"], 0, lo_open=True)
    _range("post_periods", p["post_periods"], 0)
    _range("cool_factor", p["cool_factor"], 0, 1, lo_open=True)
    root = p["root_folder"]
    if not isinstance(root, (str, os.PathLike)):
        raise TypeError(f"root_folder={root!r} is invalid: allowed a path string")
    wants = [n + "=True" for n in ("saveData", "saveOutputImages") if p[n]]
    if wants and not root:
        raise ValueError(f"root_folder={root!r} is invalid: {' and '.join(wants)} needs an existing output folder")
    if wants and not os.path.isdir(root):
        raise ValueError(f"root_folder={root!r} is invalid: {' and '.join(wants)} needs an existing output folder "
                         "(no such directory)")
    seed = p.get("seed")
    if seed is not None and not isinstance(seed, (np.random.SeedSequence, np.random.Generator,
                                                  np.random.BitGenerator)):
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed={seed!r} is invalid: allowed None, an integer >= 0, a numpy SeedSequence "
                             "or Generator")
