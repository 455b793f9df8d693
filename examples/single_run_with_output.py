"""One default simulation with a reproducible seed, the text output file and the full result.

Usage: python examples/single_run_with_output.py [OUTPUT_FOLDER]
"""
import os
import sys

from particleShear import doParticleShearSimulation


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "particleShear_output"
    os.makedirs(folder, exist_ok=True)
    result = doParticleShearSimulation(root_folder=folder, doDrawing=False, plotStress=False, saveData=True,
                                       seed=1, verbose=False, return_result=True)
    print("G', G'' of the internal estimator (Pa):", result.G_internal)
    print("G', G'' from the surface forces (Pa):      ", result.G_surface)
    print("output file:", result.output_path)
    print("wall time per phase (s):", {k: round(v, 2) for k, v in result.timings.items()})


if __name__ == "__main__":
    main()
