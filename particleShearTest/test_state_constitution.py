"""Runs constitute on the engine's state (``linkable.builders.state_constitution``), relaxed in batches.

* The constitution on the state as a generator: its requests run one by one give
  ``constituted_state``; the pending requests of several constitutions run together in one
  engine (``Relaxation.run_together``, ``base.engine_adapter.relax_states``: the states joined,
  relaxed once, each given its replica back) give every target's state bit for bit as alone —
  spheres, clock, strain, μ, the whole pair table with its relation history and creation
  numbers, and the generators' next draws — since the relaxation is per replica and each
  replica has its own generator.
* A run's driver (``simulation.driver``) constitutes that way: after a run ``sim.theEnsemble`` is
  a view of the state ``sim.constituted`` (the measurement worked on a copy), bit for bit the
  ensemble the builders' path makes of the same recipe and seed with the driver's relaxations,
  and the run's results are those of a measurement of that builders' ensemble.
"""
import numpy as np
import pytest

from particleShear.base.engine_adapter import ensembles_of, relax_states, state_from_ensembles, state_of_ensemble
from particleShear.engine.state import BatchState, PairTable
from particleShear.linkable import builders
from particleShear.linkable.builders import EnsembleRecipe, Relaxation, constituted_state, state_constitution
from particleShear.run.measurement import CONCLUSION
from particleShear.run.sessions import build_sessions
from particleShear.run.validation import validated_run
from particleShear.simulation.driver import ENGINE_SKIN_FACTOR, measure_sessions
from particleShearTest.test_batch import QUICK, assert_same_result
from particleShearTest.test_constituted_state import SMALL, differences, driver_style
from particleShearTest.test_ensemble_of_state import MEMORY, PRIVATE, attribute_differences, bits, kept, \
    pair_differences

#: (recipe fields over SMALL at N = 20, seed): gels whose schedules share some blocks and differ in
#: others (frictional spheres only; fewer cuts with links removed; an amplitude below 0.1, whose
#: extra blocks have μ = 0 while a companion's have μ = 1; another friction)
MIXED = [({}, 1), ({}, 2), (dict(do_permanent_links=False), 3), (dict(cut_lines=2, remove_link_fraction=0.3), 4),
         (dict(anticipated_amplitude=0.07), 5), (dict(mu=0.5), 6)]


def recipes():
    return [(EnsembleRecipe(**{**SMALL, "N": 20, **fields}), seed) for fields, seed in MIXED]


def alone(recipe, seed, **settings):
    """Constitute one gel on its state, each request run alone; the constituted state and the target."""
    steps = state_constitution(recipe, rng=seed, do_debug=True, **settings)
    targets = []
    try:
        while True:
            request = next(steps)
            targets.append(request.ensemble)
            request.run()
    except StopIteration as done:
        assert len({id(t) for t in targets}) == 1          # (one target per constitution)
        return done.value, targets[0]


def together(gels, **settings):
    """Constitute several gels as the driver does: the pending requests of equal batch key in one engine.

    Returns the constituted states, the targets and the largest group run together."""
    steps = [state_constitution(recipe, rng=seed, do_debug=True, **settings) for recipe, seed in gels]
    pending, done, targets, largest = {}, {}, {}, 0

    def advance(b):
        try:
            pending[b] = next(steps[b])
            targets[b] = pending[b].ensemble
        except StopIteration as stop:
            pending.pop(b, None)
            done[b] = stop.value

    for b in range(len(steps)):
        advance(b)
    while pending:
        key = pending[min(pending)].batch_key
        group = [b for b in sorted(pending) if pending[b].batch_key == key]
        largest = max(largest, len(group))
        Relaxation.run_together([pending[b] for b in group])
        for b in group:
            advance(b)
    return [done[b] for b in range(len(steps))], [targets[b] for b in range(len(steps))], largest


def whole_table_differences(pa, pb):
    """What differs between two whole pair tables: every row with its history, the counter of creation numbers."""
    return ([f for f in PairTable.ARRAYS if not np.array_equal(bits(getattr(pa, f)), bits(getattr(pb, f)))]
            + [f for f in ("birth_count", "n_permanent") if getattr(pa, f) != getattr(pb, f)])


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_batched_relaxations_equal_one_by_one(backend):
    if backend == "numba":
        pytest.importorskip("numba")
    law = ("plateau", (0.3, 0.8, 0.1))       # the run's law and backend, as the driver relaxes
    settings = dict(law=law, relaxation_law=law, relaxation_backend=backend, skin_factor=ENGINE_SKIN_FACTOR)
    gels = recipes()
    batched, batched_targets, largest = together(gels, **settings)
    assert largest >= 4                      # relaxations really ran together
    for (recipe, seed), got, target in zip(gels, batched, batched_targets, strict=True):
        ref, ref_target = alone(recipe, seed, **settings)
        assert differences(ref.state, got.state) == [], seed
        assert (got.steps, got.dt, got.dt_max, got.removed_fraction) == \
            (ref.steps, ref.dt, ref.dt_max, ref.removed_fraction)
        assert got.steps > 0
        w, v = target.state, ref_target.state
        for name in BatchState.SPHERE_ARRAYS + BatchState.REPLICA_ARRAYS:
            assert np.array_equal(bits(getattr(w, name)), bits(getattr(v, name))), (seed, name)
        assert whole_table_differences(w.pairs[0], v.pairs[0]) == [], seed
        if recipe.do_permanent_links:
            assert w.pairs[0].n_permanent > 0
        assert np.array_equal(w.rng[0].random(4), v.rng[0].random(4))      # the generators' next draws
    # (and the one-by-one path is constituted_state)
    recipe, seed = gels[0]
    assert differences(constituted_state(recipe, rng=seed, do_debug=True, **settings).state,
                       alone(recipe, seed, **settings)[0].state) == []


def test_relax_states_gives_each_state_its_replica():
    """Two states of other histories relaxed together: each as relaxed alone, its own table object back."""
    gels = recipes()[:2]
    firsts = []
    for _ in range(2):                       # two copies of the states at their first relaxation
        pair = []
        for recipe, seed in gels:
            request = next(state_constitution(recipe, rng=seed, do_debug=True))
            request.ensemble.state.mu[0] = 0.25 * seed        # (another μ per replica)
            pair.append(request)
        firsts.append(pair)
    joint, single = firsts
    n, dt, dt_max = joint[0].key
    steps = relax_states([r.ensemble.state for r in joint], n, dt, dt_max)
    for r in single:
        assert relax_states([r.ensemble.state], n, dt, dt_max) == steps > 0
    for a, b in zip(joint, single):
        s, t = a.ensemble.state, b.ensemble.state
        assert differences(s, t) == []
        assert whole_table_differences(s.pairs[0], t.pairs[0]) == []
        assert s.mu[0] == t.mu[0] != 0 and s.t[0] == t.t[0] > 0
    with pytest.raises(ValueError, match="given twice"):
        relax_states([joint[0].ensemble.state] * 2, n, dt, dt_max)


def test_requests_of_other_batch_keys_are_refused_before_any_step():
    gels = recipes()
    a = next(state_constitution(gels[0][0], rng=1, do_debug=True))
    b = next(state_constitution(gels[0][0], rng=1, do_debug=True, skin_factor=0.5))     # (another skin)
    assert a.key == b.key and a.batch_key != b.batch_key
    before = a.ensemble.state.x.copy()
    with pytest.raises(ValueError, match="batch keys"):
        Relaxation.run_together([a, b])
    assert np.array_equal(a.ensemble.state.x, before) and a.ensemble.steps == 0


def run_sessions(kws, constituted=None):
    """The runs' sessions measured by the driver; with ``constituted`` (one ensemble per run) instead of
    their own constitution.  Returns the results and the simulations."""
    sims, _, sessions = build_sessions([validated_run(dict(kw, return_result=True)) for kw in kws])
    if constituted is not None:
        for sim, ens in zip(sims, constituted):
            sim.theEnsemble, sim.model, sim.dt, sim.dt_max = ens, ens.model, ens.dt, ens.dt_max
    return measure_sessions(sessions, constituted=constituted is not None, conclusion=CONCLUSION), sims


def test_a_runs_ensemble_is_a_view_of_the_builders_gel_and_gives_its_results(monkeypatch):
    # (a law other than the callbacks': the relaxations' law shows in the gel)
    kws = [dict(QUICK, seed=s, contact_law="plateau", **more) for s, more in
           ((1, dict(theMu=0.05, cut_lines=2)), (2, dict(theMu=0.05, cut_lines=2)),
            (3, dict(theMu=0.0, do_permanent_links=False)))]
    sizes = []

    def counted(states, *args, **kwargs):
        sizes.append(len(states))
        return relax_states(states, *args, **kwargs)
    monkeypatch.setattr(builders, "relax_states", counted)
    results, sims = run_sessions(kws)
    monkeypatch.undo()
    assert max(sizes) == len(kws)           # the driver relaxed the sessions' states together
    assert sims[0].contact_law[0] == "plateau"
    theirs = []
    for kw, sim in zip(kws, sims):
        recipe = sim.ensemble_recipe()
        generator = validated_run(dict(kw, return_result=True)).generator      # the run's seed, afresh
        ens = driver_style(recipe, generator, sim.contact_law, sim.parameters["backend"], do_debug=False)
        theirs.append(ens)
        view, s = sim.theEnsemble, sim.constituted.state
        assert ensembles_of(s) == [view] and state_of_ensemble(view).pairs[0] is s.pairs[0] and view._rng is s.rng[0]
        assert np.shares_memory(view._block, s.x)
        # the constituted gel, untouched by the measurement (which ran on a copy): the builders' bit for bit
        assert np.array_equal(bits(view._st), bits(ens._st))
        assert [view.t, view.shear, view.shear_rate, view.mu] == [ens.t, ens.shear, ens.shear_rate, ens.mu] \
            and view.t > 0
        assert pair_differences(kept(ens.pair_table), view.pair_table) == []
        # (the run's experiment set its guard on the ensemble)
        assert attribute_differences(ens, view, PRIVATE + MEMORY + ("stability_guard",)) == []
        assert differences(*(state_from_ensembles([e], backend="numpy") for e in (ens, view))) == []
    # the builders' gels measured by the same driver: the same results bit for bit
    again, _ = run_sessions(kws, constituted=theirs)
    for a, b in zip(results, again, strict=True):
        assert_same_result(_Asserter(), a, b)


class _Asserter:
    """The unittest-style assertions ``assert_same_result`` calls, as plain asserts."""

    def assertEqual(self, a, b, msg=None):
        assert a == b, msg

    def assertTrue(self, x, msg=None):
        assert x, msg


def _legacy_factory(sim, **kw):
    """The legacy builder called with the simulation's parameters (not its recipe)."""
    from particleShear.linkable.builders import EnsembleCompactParticlesFromModelParameters
    return EnsembleCompactParticlesFromModelParameters(
        size_x=500, size_y=500, N=sim.N, packing_fraction=sim.packing_fraction, mu=sim.mu,
        Young_modulus_spheres=sim.Young_modulus_spheres, cut_lines=sim.cut_lines,
        do_permanent_links=sim.do_permanent_links, anticipated_amplitude=sim.amplitude, doDrawing=False, **kw)


def _interlocking(sim):
    from particleShear.linkable.builders import constitution, relax_constitution
    return relax_constitution(constitution(sim.ensemble_recipe(), do_debug=True, rng=7))


def _dermal(sim):
    return _legacy_factory(sim, density=sim.density, bimodal_factor=sim.bimodal_factor,
                           relative_viscosity=sim.relative_viscosity,
                           relative_transversal_link_strength=sim.relative_transversal_link_strength,
                           central_repulsion_coefficient=sim.central_repulsion_coefficient,
                           avoid_horizontal_angle_degree=sim.avoid_horizontal_angle_degree,
                           avoid_height_spanning_particles=sim.avoid_height_spanning_particles,
                           doCutByTriangulation=sim.doCutByTriangulation, do_debug=True, rng=7)


@pytest.mark.parametrize("cls, builder", [("Simulation_interlocking_rheology", _interlocking),
                                          ("Simulation_dermal_filler_rheology", _dermal),
                                          ("OscillatorySimulationFragmentation",
                                           lambda sim: _legacy_factory(sim, do_debug=True, rng=7))])
def test_init_ensemble_is_the_builders_ensemble_as_a_view(cls, builder):
    """``initEnsemble`` (not a generator) runs the same constitution's requests itself: each class's
    builder's gel (the legacy classes': the legacy builder called with the class's parameters)."""
    from particleShear.simulation import fragmentation
    sim = getattr(fragmentation, cls)("", N=20, cut_lines=2, do_permanent_links=True, mu=0.05, amplitude=0.2,
                                      doDrawing=False)
    sim.rng = 7
    got = sim.initEnsemble(do_debug=True)
    ens = builder(sim)
    assert type(got) is type(ens)
    assert got is sim.theEnsemble and ensembles_of(sim.constituted.state) == [got]
    assert np.array_equal(bits(got._st), bits(ens._st)) and got.t == ens.t > 0
    assert pair_differences(kept(ens.pair_table), got.pair_table) == [] and got.pair_table.n_permanent > 0
    assert attribute_differences(ens, got, PRIVATE + MEMORY) == []
    assert (sim.dt, sim.dt_max, vars(sim.model)) == (ens.dt, ens.dt_max, vars(ens.model))
    assert np.array_equal(got._rng.random(4), ens._rng.random(4))


def test_a_fractional_mu_constitutes():
    # a μ given as any real number (validated as such) is stored as a float: its view is accepted
    from fractions import Fraction
    recipe = EnsembleRecipe(**{**SMALL, "mu": Fraction(1, 3)})
    got = constituted_state(recipe, rng=2, do_debug=True)
    view = builders.ensemble_of_state(got, recipe)
    assert view.mu == float(Fraction(1, 3)) == got.state.mu[0]


@pytest.mark.parametrize("cls, named, builder", [
    ("Simulation_dermal_filler_rheology", "OscillatorySimulationFragmentation", "fragmentation"),
    ("Simulation_interlocking_rheology", "Simulation_dermal_filler_rheology", "dermal")])
def test_a_classes_init_ensemble_named_from_a_subclass_builds_that_classes_gel(cls, named, builder):
    # as in 1.0.2: `Base.initEnsemble(self)` in a subclass's own initEnsemble builds Base's builder's gel
    from particleShear.simulation import fragmentation
    parent = getattr(fragmentation, named)
    sub = type("Sub", (getattr(fragmentation, cls),), {"initEnsemble": lambda self: parent.initEnsemble(self, True)})
    sim = sub("", N=20, cut_lines=2, do_permanent_links=True, mu=0.05, amplitude=0.2, doDrawing=False)
    sim.rng = 7
    assert fragmentation.builder_of(sub) is None                  # (its own initEnsemble: called as it is)
    got = sim.initEnsemble()
    ens = {"fragmentation": lambda: _legacy_factory(sim, do_debug=True, rng=7), "dermal": lambda: _dermal(sim)}[builder]()
    assert type(got) is type(ens)
    assert np.array_equal(bits(got._st), bits(ens._st))
    assert pair_differences(kept(ens.pair_table), got.pair_table) == []
