"""A particleShear 1.0.2-style script: two bonded spheres, stress tensors step by step.

Builds the scene sphere by sphere (the manual's unit-test scene "general collision with a permanent link"), runs 50
evaluated steps and prints the overall stress tensor, its symmetry error and the conserved
momenta — the checks of the manual's Part 4, on the same API as the old package.

Usage: python examples/two_spheres_with_link.py
"""
from particleShear import EnsembleLinkable, EvaluationHandler, SphereLinkable, StressTensorEvaluation


def main():
    ens = EnsembleLinkable(500, 500, 0, k=1, nu=1, k_t=1, nu_t=1, mu=0.01)
    a = SphereLinkable("grey", 150, 200, 120, 1, 1, force_register=ens)
    b = SphereLinkable("grey", 220, 260, 120, 1, 2, force_register=ens)
    ens.sphereList.append(a)
    ens.sphereList.append(b)
    a.xspeed, b.xspeed, b.omega = 10, -10, 0.25
    a.establish_permanent_link(b)

    ev = StressTensorEvaluation(500, 500)
    handler = EvaluationHandler()
    handler.record(ens, ev)
    L0 = handler.angular_momentum_around_origin
    for _ in range(50):
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ev.evaluate_stress_tensors(ens.force_register, ens.sphereList, 0)
        ens.mechanical_simulation_step_calculate_acceleration(1, 0.01)
        ens.mechanical_simulation_step_calculate_movement(0.01)
    s = ev.overall_stress_tensor
    print("overall stress tensor (Pa):", s)
    print("symmetry error |s01 - s10| / (|s00| + |s11|):", abs(s[0][1] - s[1][0]) / (abs(s[0][0]) + abs(s[1][1])))
    print("Love-Weber tensor (Pa):     ", ev.stress_tensor_LW)
    handler.record(ens, ev)
    print("angular momentum, relative change:", abs(handler.angular_momentum_around_origin - L0) / abs(L0))
    print("relations of sphere 1:", [(r.theSphere.myindex, r.interface_type, r.friction_position)
                                     for r in a.neighbors])


if __name__ == "__main__":
    main()
