"""The constitution on the engine's state (``linkable.builders.constituted_state``) against the builders'.

The state a run's measurement starts from is the hand-over's copy of the constituted ensemble
(``state_from_ensembles``); ``constituted_state`` makes it without any documented ensemble, with
the same algorithms (``linkable.bonds``, ``objects.placement``) and the same random draws, and
must give every array, the pair table and the generator's position bit for bit.
"""
import math

import numpy as np
import pytest

from particleShear.base.engine_adapter import ensembles_of, state_from_ensembles
from particleShear.engine.state import BatchState, PairTable
from particleShear.linkable import bonds
from particleShear.linkable.builders import (ConstitutedState, EnsembleRecipe, constituted_state, constitution,
                                             relax_constitution)
from particleShear.linkable.canvas import CanvasPointsLinkable
from particleShear.linkable.compact import (EnsembleCompactParticles,
                                            EnsembleCompactParticlesAdjustableInterfaceStrength)
from particleShear.objects.ensembles import RandomBimodalSpheres

#: a small gel (the builders' defaults but N)
SMALL = dict(N=30, packing_fraction=1, mu=1, Young_modulus_spheres=10000, density=50, bimodal_factor=1.4,
             cut_lines=5, do_permanent_links=True, relative_viscosity=0.01, central_repulsion_coefficient=0,
             anticipated_amplitude=0.1, relative_transversal_link_strength=1, avoid_horizontal_angle_degree=0,
             avoid_height_spanning_particles=False, doCutByTriangulation=True)

#: (id, legacy, recipe fields over SMALL, seeds): every branch of the constitution
CASES = [
    ("default", False, {}, (1, 2, 3)),
    ("legacy", True, {}, (4, 5)),
    ("no-links", False, dict(do_permanent_links=False), (6,)),
    ("line-cuts", False, dict(doCutByTriangulation=False, avoid_horizontal_angle_degree=30), (7, 8)),
    ("remove-links", False, dict(remove_link_fraction=0.4), (9, 10)),
    ("avoid-spanning", False, dict(avoid_height_spanning_particles=True, cut_lines=8, N=40), (11, 12)),
    ("avoid-spanning-lines", False, dict(avoid_height_spanning_particles=True, doCutByTriangulation=False,
                                         cut_lines=4, avoid_horizontal_angle_degree=45), (13,)),
    ("fuzzy", False, dict(edge_fuzziness=0.7), (14,)),
    ("open-top-bottom", False, dict(cut_top_bottom=False, N=20), (15,)),
    ("unrelaxed", False, dict(do_pre_equilibration=False), (16,)),
    ("spheres-only", True, dict(do_pre_equilibration=False, do_permanent_links=False, N=2), (19,)),
    ("uncut", False, dict(cut_lines=0, packing_fraction=3, relative_transversal_link_strength=6), (20,)),
    ("small-amplitude", False, dict(anticipated_amplitude=0.001, interface_reenforcement_central=2,
                                    interface_reenforcement_tangential=3,
                                    keep_viscosity_coefficients_constant=False), (17,)),
    ("soft", False, dict(mu=0.05, relative_transversal_link_strength=0.05, central_repulsion_coefficient=1), (18,)),
]


def differences(a, b):
    """Names of what differs between two one-replica states (arrays, pair table, generator)."""
    out = [name for name in BatchState.SPHERE_ARRAYS + BatchState.REPLICA_ARRAYS + ("law_params",)
           if not np.array_equal(getattr(a, name), getattr(b, name))]
    pa, pb = a.pairs[0], b.pairs[0]
    out += ["pairs." + f for f in PairTable.ARRAYS if not np.array_equal(getattr(pa, f), getattr(pb, f))]
    out += [name for name in ("birth_count", "n_permanent") if getattr(pa, name) != getattr(pb, name)]
    out += [name for name in ("B", "N", "law", "callback_laws", "applying_shear", "visit")
            if getattr(a, name) is not getattr(b, name) and getattr(a, name) != getattr(b, name)]
    if a.rng[0].bit_generator.state != b.rng[0].bit_generator.state:
        out.append("rng")
    return out


def both(recipe, seed, legacy=False, do_debug=True, law=None):
    """The builders' ensemble with its hand-over state, and the constituted state, of one recipe and seed."""
    ens = relax_constitution(constitution(recipe, legacy=legacy, do_debug=do_debug, rng=seed))
    return ens, state_from_ensembles([ens], backend="numpy", laws=[law]), \
        constituted_state(recipe, legacy=legacy, rng=seed, do_debug=do_debug, law=law)


@pytest.mark.parametrize("legacy, fields, seed",
                         [pytest.param(legacy, fields, seed, id=f"{name}-{seed}")
                          for name, legacy, fields, seeds in CASES for seed in seeds])
def test_bit_identical_to_the_builders(legacy, fields, seed):
    recipe = EnsembleRecipe(**{**SMALL, **fields})
    ens, ref, got = both(recipe, seed, legacy=legacy)
    assert isinstance(got, ConstitutedState)
    assert differences(ref, got.state) == []
    assert (got.dt, got.dt_max, got.removed_fraction, got.r_max) == (ens.dt, ens.dt_max, ens.removed_fraction,
                                                                      ens.r_max)
    assert vars(got.model) == vars(ens.model)
    if recipe.do_permanent_links and recipe.doCutByTriangulation:
        assert np.array_equal(got.triangulation_points, ens.triangulation_points)
    else:
        assert got.triangulation_points is None
    if recipe.do_permanent_links:
        assert got.state.pairs[0].n_permanent > 0          # a gel, not spheres only: the comparison has bonds


def test_default_size_and_a_law():
    """The documented size (N = 150, full relaxations), with a registered central law handed over."""
    recipe = EnsembleRecipe(**{**SMALL, "N": 150})
    law = ("plateau", (0.3, 0.8, 0.1))
    ens, ref, got = both(recipe, 2024, do_debug=False, law=law)
    assert differences(ref, got.state) == []
    assert got.state.law == "plateau"


def test_a_generator_is_used_not_copied():
    recipe = EnsembleRecipe(**SMALL)
    g1, g2 = np.random.default_rng(99), np.random.default_rng(99)
    ens = relax_constitution(constitution(recipe, do_debug=True, rng=g1))
    got = constituted_state(recipe, rng=g2, do_debug=True)
    assert got.state.rng[0] is g2
    assert differences(state_from_ensembles([ens], backend="numpy"), got.state) == []
    assert g1.bit_generator.state == g2.bit_generator.state


def test_no_documented_ensemble_is_made(monkeypatch):
    """The state path constitutes without a documented ensemble (their constructors raise here)."""
    recipe = EnsembleRecipe(**{**SMALL, "remove_link_fraction": 0.2, "avoid_height_spanning_particles": True})
    ens, ref, _ = both(recipe, 31)

    def forbidden(self, *args, **kwargs):
        raise AssertionError(f"a {type(self).__name__} was made")

    for cls in (EnsembleCompactParticles, EnsembleCompactParticlesAdjustableInterfaceStrength, CanvasPointsLinkable):
        monkeypatch.setattr(cls, "__init__", forbidden)
    monkeypatch.setattr(RandomBimodalSpheres, "_create_spheres", forbidden)
    for legacy in (False, True):
        with pytest.raises(AssertionError):
            relax_constitution(constitution(recipe, legacy=legacy, do_debug=True, rng=31))
    got = constituted_state(recipe, rng=31, do_debug=True)
    assert ensembles_of(got.state) is None
    assert differences(ref, got.state) == []


def test_an_unusable_backend_raises_before_any_work():
    g = np.random.default_rng(5)
    before = g.bit_generator.state
    with pytest.raises(ValueError):
        constituted_state(EnsembleRecipe(**SMALL), rng=g, backend="no such backend", do_debug=True)
    assert g.bit_generator.state == before


def test_angles_and_a_bounded_redraw():
    assert bonds.angle_ok(0.0, 30) and not bonds.angle_ok(math.pi / 2, 30) and bonds.angle_ok(math.pi / 2, 0)
    g = np.random.default_rng(3)
    for _ in range(50):
        (px, py), angle = bonds.random_line(g, 100, 50, 80)
        assert 0 <= px <= 100 and 0 <= py <= 50 and bonds.angle_ok(angle, 80)
    with pytest.raises(RuntimeError):
        bonds.random_line(g, 100, 50, 90.0001)          # (the recipe forbids it: every angle rejected)


def driver_style(recipe, seed, law, backend, do_debug=True):
    """The builders' ensemble with each relaxation as a run's driver relaxes it: the run's law and
    backend and the driver's skin (``relax_ensembles``, a batch of one)."""
    from particleShear.base.engine_adapter import relax_ensembles
    from particleShear.simulation.driver import ENGINE_SKIN_FACTOR
    steps = constitution(recipe, do_debug=do_debug, rng=seed)
    try:
        while True:
            request = next(steps)
            relax_ensembles([request.ensemble], request.N, skin_factor=ENGINE_SKIN_FACTOR, laws=[law], backend=backend)
    except StopIteration as done:
        return done.value


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_relaxations_with_the_runs_law_and_backend(backend):
    """With the relaxations' law and backend of a run's driver, the state is the driver's hand-over state."""
    if backend == "numba":
        pytest.importorskip("numba")
    from particleShear.simulation.driver import ENGINE_SKIN_FACTOR
    recipe = EnsembleRecipe(**{**SMALL, "N": 20})
    law = ("plateau", (0.3, 0.8, 0.1))
    ens = driver_style(recipe, 41, law, backend)
    got = constituted_state(recipe, rng=41, do_debug=True, law=law, relaxation_law=law, relaxation_backend=backend,
                            skin_factor=ENGINE_SKIN_FACTOR)
    assert differences(state_from_ensembles([ens], backend="numpy", laws=[law]), got.state) == []
    plain = constituted_state(recipe, rng=41, do_debug=True, law=law)      # (the builders' relaxations: callbacks)
    assert differences(plain.state, got.state) != []
