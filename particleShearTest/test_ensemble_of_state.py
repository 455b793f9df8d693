"""The documented ensemble of a constituted state (``linkable.builders.ensemble_of_state``), a view of it.

* It is the ensemble the builders make of the same recipe and seed (``constitution`` +
  ``relax_constitution``), field by field and bit for bit: class, attributes, spheres and their
  state block, the pair table's rows that the hand-over keeps, clock, strain, μ, the cut's facts,
  the step counts, ``particle_info`` and the generator's next draws; and it is made without a
  draw or a relaxation.
* It is a view: its state block, replica cells, pair table, predictor and generator are the
  state's memory, a write on either side is read on the other, and ``state_of_ensemble`` of it
  gives arrays of that memory.
* The documented step of the view gives the bits of the documented step of the builders' ensemble.
"""
import numpy as np
import pytest

from particleShear.base.engine_adapter import ensembles_of, state_of_ensemble
from particleShear.engine.state import PERMANENT, BatchState, PairTable
from particleShear.linkable.builders import (EnsembleRecipe, constituted_state, constitution, ensemble_of_state,
                                             relax_constitution)
from particleShearTest.test_constituted_state import SMALL      # the small gel of the constitution's tests


#: (id, legacy, recipe fields over SMALL, seeds): crosslinked and cut, legacy, frictional spheres only, ...
CASES = [
    ("default", False, {}, (1, 2)),
    ("legacy", True, {}, (4,)),
    ("no-links", False, dict(do_permanent_links=False), (6,)),
    ("avoid-spanning", False, dict(avoid_height_spanning_particles=True, cut_lines=8, N=40), (11,)),
    ("remove-links", False, dict(remove_link_fraction=0.4, central_repulsion_coefficient=1), (9,)),
    ("line-cuts-unrelaxed", False, dict(doCutByTriangulation=False, do_pre_equilibration=False), (16,)),
]
PARAMS = [pytest.param(legacy, fields, seed, id=f"{name}-{seed}") for name, legacy, fields, seeds in CASES
          for seed in seeds]

#: what differs by construction, not by content: the private counters of what depends on the block and
#: the step's engine's caches (the builders' ensemble made one for its neighbour update)
PRIVATE = ("_block_version", "_pos_version", "_params_version", "_engine_mu", "_engine_strain", "_kept_terms")
#: the state's memory, compared separately (shared objects or their own checks below)
MEMORY = ("_block", "_st", "_a", "_pos", "_vel", "_frc", "_replica", "_pairs", "_predictor", "_rng", "_sphereList",
          "particles", "model", "graphical_output_configuration", "force_register", "_memo")
SCALARS = (bool, int, float, str, type(None), np.floating, np.integer)


def both(recipe, seed, legacy=False):
    """The builders' ensemble, and the view of the constituted state, of one recipe and seed (with the state)."""
    ens = relax_constitution(constitution(recipe, legacy=legacy, do_debug=True, rng=seed))
    got = constituted_state(recipe, legacy=legacy, rng=seed, do_debug=True)
    before = got.state.rng[0].bit_generator.state
    view = ensemble_of_state(got, recipe, legacy=legacy)
    assert got.state.rng[0].bit_generator.state == before          # nothing drawn
    return ens, view, got.state


def bits(a):
    return np.ascontiguousarray(a, dtype=float).view(np.uint64)


def kept(pt):
    """The rows of a pair table that the hand-over keeps (active relations and bonds)."""
    return pt.copy(pt.active | (pt.state == PERMANENT))


def attribute_differences(a, b, skip=()):
    """Names of the attributes (scalars, arrays, lists of scalars) in which two objects differ or that one lacks."""
    da, db = vars(a), vars(b)
    out = []
    for name in sorted(set(da) | set(db)):
        if name in skip:
            continue
        if name not in da or name not in db:
            out.append(name)
            continue
        x, y = da[name], db[name]
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            same = np.shape(x) == np.shape(y) and np.array_equal(bits(x), bits(y))
        elif isinstance(x, SCALARS) or isinstance(x, list) and all(isinstance(v, SCALARS) for v in x):
            same = x == y and type(x) is type(y)      # (a file writes 0 and 0.0 differently)
        else:
            same = type(x) is type(y)
        if not same:
            out.append(name)
    return out


def pair_differences(pa, pb):
    return ([f for f in PairTable.ARRAYS if not np.array_equal(getattr(pa, f), getattr(pb, f))]
            + [f for f in ("birth_count", "n_permanent") if getattr(pa, f) != getattr(pb, f)])


@pytest.mark.parametrize("legacy, fields, seed", PARAMS)
def test_the_builders_ensemble_bit_for_bit(legacy, fields, seed):
    recipe = EnsembleRecipe(**{**SMALL, **fields})
    ens, view, _ = both(recipe, seed, legacy)
    assert type(view) is type(ens)
    assert attribute_differences(ens, view, PRIVATE + MEMORY) == []
    assert np.array_equal(bits(view._st), bits(ens._st))
    assert [view.t, view.shear, view.shear_rate, view.mu] == [ens.t, ens.shear, ens.shear_rate, ens.mu]
    assert pair_differences(kept(ens.pair_table), view.pair_table) == []
    if recipe.do_permanent_links:
        assert view.pair_table.n_permanent > 0               # a gel: the comparison has bonds
    assert ens.step_count > 0 or not recipe.do_pre_equilibration
    assert vars(view.model) == vars(ens.model)
    assert vars(view.graphical_output_configuration) == vars(ens.graphical_output_configuration)
    for s, t in zip(ens.sphereList, view.sphereList, strict=True):
        assert type(t) is type(s)
        assert attribute_differences(s, t, ("_ens", "force_register", "graphical_output_configuration")) == []
        assert (t.x, t.y, t.r, t.m, t.color) == (s.x, s.y, s.r, s.m, s.color)
    assert [[s._idx for s in p] for p in view.particles] == [[s._idx for s in p] for p in ens.particles]
    assert (not recipe.avoid_height_spanning_particles) or len(view.particles) > 1
    assert view.particle_info() == ens.particle_info()
    assert view.particle_info(reference=True) == ens.particle_info(reference=True)
    assert view._rng.bit_generator.state == ens._rng.bit_generator.state
    assert np.array_equal(view._rng.random(4), ens._rng.random(4))


def test_it_is_a_view_of_the_state():
    recipe = EnsembleRecipe(**SMALL)
    _, view, s = both(recipe, 3)
    block = view._block
    for name in BatchState.SPHERE_ARRAYS:
        assert np.shares_memory(block, getattr(s, name)), name
    for name in ("t", "gamma", "rate", "mu"):
        assert np.shares_memory(view._replica, getattr(s, name)), name
    assert view._predictor is s.predictor and view._rng is s.rng[0]
    assert ensembles_of(s) == [view]
    sphere = view.sphereList[7]
    sphere.x = 123.5                                   # the ensemble's writes, the state's values
    view.shear, view.mu = 0.25, 0.5
    assert (s.x[7], s.gamma[0], s.mu[0]) == (123.5, 0.25, 0.5)
    s.vy[4], s.t[0], s.rate[0] = -7.0, 2.0, 3.0        # the state's writes, the ensemble's values
    assert (view.sphereList[4].yspeed, view.t, view.shear_rate) == (-7.0, 2.0, 3.0)
    again = state_of_ensemble(view)
    for name in BatchState.SPHERE_ARRAYS + ("t", "gamma", "rate", "mu"):
        assert np.shares_memory(getattr(again, name), getattr(s, name)), name
    assert again.pairs[0] is s.pairs[0] and again.predictor is s.predictor


def test_the_recipe_must_be_the_states():
    recipe = EnsembleRecipe(**SMALL)
    got = constituted_state(recipe, rng=5, do_debug=True)
    for other in (dict(N=31), dict(Young_modulus_spheres=20000), dict(size_x=400), dict(mu=SMALL["mu"] + 0.25)):
        with pytest.raises(ValueError, match="not a constitution of the recipe"):
            ensemble_of_state(got, EnsembleRecipe(**{**SMALL, **other}))
    with pytest.raises(ValueError, match="legacy=True, but the state is a constitution with legacy=False"):
        ensemble_of_state(got, recipe, legacy=True)      # (the legacy builder's class on another constitution)
    ensemble_of_state(got, recipe)
    with pytest.raises(ValueError, match="already the memory of an ensemble"):    # one view per state
        ensemble_of_state(got, recipe)


@pytest.mark.parametrize("legacy, fields, seed, integrator",
                         [(False, {}, 1, "euler"), (True, {}, 4, "verlet"),
                          (False, dict(do_permanent_links=False), 6, "euler")])
def test_the_documented_steps_of_the_view_are_the_builders(legacy, fields, seed, integrator):
    recipe = EnsembleRecipe(**{**SMALL, **fields})
    ens, view, s = both(recipe, seed, legacy)
    for e in (ens, view):
        e.set_integrator(integrator)
        e.applyingShear = True
        e.shear_rate = 40.0
        for _ in range(120):
            e.mechanical_simulation_step(0.9, e.dt)
    assert np.array_equal(bits(view._st), bits(ens._st))
    assert not np.array_equal(view._st, relax_constitution(constitution(recipe, legacy=legacy, do_debug=True,
                                                                        rng=seed))._st)     # (they moved)
    assert (view.t, view.shear, view.step_count) == (ens.t, ens.shear, ens.step_count)
    assert pair_differences(kept(ens.pair_table), kept(view.pair_table)) == []
    assert np.array_equal(bits(s.vel), bits(ens._vel)) and s.t[0] == ens.t          # the state holds the steps


def test_a_state_whose_ensemble_is_gone_is_free_again():
    # the adapter's record of whose memory a state is holds the ensembles weakly
    import gc
    recipe = EnsembleRecipe(**SMALL)
    got = constituted_state(recipe, rng=5, do_debug=True)
    view = ensemble_of_state(got, recipe)
    assert ensembles_of(got.state) == [view]
    del view
    gc.collect()
    assert ensembles_of(got.state) is None
    again = ensemble_of_state(got, recipe)
    assert ensembles_of(got.state) == [again]
