"""The experiment's loops stepped by the documented classes, written out as the tests' reference.

``OscillatoryShearExperiment.pre_equilibrate`` and ``run_protocol`` run in the engine.  The tests that
compare the engine with the documented classes' own step use these loops instead: the same
schedules (MODEL_SPEC section 6: coarse levels from ``dt_max``, 2N steps at dt with damping 0.98, N
steps with γ̇ reset to 0; then per protocol step setShearRate → forces → totals → record →
acceleration → movement → reset_force), stepped by the ensemble's documented step methods.
"""
import math


def classes_pre_equilibrate(exp, N=25, cool_factor=0.99):
    """The fixed-boundary pre-equilibration of ``exp.theEnsemble`` by ``mechanical_simulation_step``."""
    ens = exp.theEnsemble
    ens.applyingShear = True
    ens.phase = "pre-equilibration"
    level_dt, cf = exp.dt_max, 0.5
    while level_dt > exp.dt:
        for _ in range(int(N / 2)):
            ens.mechanical_simulation_step(cf, level_dt)
        level_dt = level_dt / 2
        cf = (1 + cf) / 2
    for _ in range(2 * int(N)):
        ens.mechanical_simulation_step(0.98, exp.dt)
    for _ in range(int(N)):
        ens.shear_rate = 0
        ens.mechanical_simulation_step(cool_factor, exp.dt)
        ens.reset_force()


def classes_run_protocol(exp, cool_factor, n_steps=None):
    """The protocol of ``exp`` stepped by the documented step methods, recorded by its plotter
    (:meth:`~particleShear.simulation.experiment.OscillatoryShearExperiment.prepare_recording` first
    when there is none); the shear rate follows the ensemble's clock ``ens.t``.  Returns the steps run."""
    ens = exp.theEnsemble
    dt, f, A = exp.dt, exp.f, exp.amplitude
    pre, P, post = exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods
    N_steps = int((P + pre + post) / f / dt)
    lo, hi = pre / (f * dt), (P + pre) / (f * dt)
    if exp.plotter is None:
        exp.prepare_recording()
    n_run = N_steps if n_steps is None else min(int(n_steps), N_steps)
    ens.phase = "protocol"
    ens.step_count = 0
    for i in range(n_run):
        rate = A * math.cos(2 * math.pi * (ens.t * f - pre)) * 2 * math.pi * f if lo <= i <= hi else 0
        ens.setShearRate(rate)
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        exp.plotter.record(ens, exp.theEvaluator)
        ens.mechanical_simulation_step_calculate_acceleration(cool_factor, dt)
        ens.mechanical_simulation_step_calculate_movement(dt)
        ens.reset_force()
    exp.N_steps = n_run
    return n_run


REGISTER_LISTS = ("pair_register", "external_force_register", "internal_moment_register", "external_moment_register",
                  "total_particle_force_register", "unbalanced_moment_register")


def assert_same_register(test, a, b, rtol=1e-12):
    """The six force-register lists of ensembles ``a`` and ``b`` hold the same entries in the same
    order (targets and sources by their index in ``sphereList``) with values equal to ``rtol`` of
    each list's largest value (the two ensembles' states agree to rounding)."""
    def index(sphere):
        return sphere.__dict__["_idx"]

    for name in REGISTER_LISTS:
        la, lb = getattr(a.force_register, name), getattr(b.force_register, name)
        test.assertEqual(len(la), len(lb), name)
        test.assertEqual([tuple(index(v) for v in row[:-1]) for row in la],
                         [tuple(index(v) for v in row[:-1]) for row in lb], name)
        va = [[float(x) for x in (row[-1] if isinstance(row[-1], list) else [row[-1]])] for row in la]
        vb = [[float(x) for x in (row[-1] if isinstance(row[-1], list) else [row[-1]])] for row in lb]
        scale = max((abs(x) for row in vb for x in row), default=0.0)
        worst = max((abs(x - y) for ra, rb in zip(va, vb) for x, y in zip(ra, rb)), default=0.0)
        test.assertLessEqual(worst, rtol * scale, name)
