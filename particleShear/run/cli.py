"""Command line: ``python -m particleShear`` / ``particleShear`` (console script).

Runs one ``doParticleShearSimulation`` headless by default (no windows), shows a
progress line on stderr (phase, step, elapsed, estimated remaining) and prints G′ and
G″ from both estimators (overall stress tensor and surface forces) on stdout.
"""
import argparse
import re
import sys
import time

__all__ = ["main", "build_parser", "ProgressLine", "PARAMETER_FLAGS", "cli_message"]

#: the ``doParticleShearSimulation`` parameter behind each flag, so that errors name what the user typed
PARAMETER_FLAGS = {
    "theAmplitude": "--amplitude", "theMu": "--mu", "N": "--N", "cut_lines": "--cut-lines",
    "Young_modulus_spheres": "--young-modulus", "packing_fraction": "--packing-fraction", "density": "--density",
    "bimodal_factor": "--bimodal-factor", "relative_viscosity": "--relative-viscosity",
    "relative_transversal_link_strength": "--relative-transversal-link-strength",
    "relative_frequency": "--relative-frequency", "remove_link_fraction": "--remove-link-fraction",
    "edge_fuzziness": "--edge-fuzziness", "pre_periods": "--pre-periods", "periods": "--periods",
    "post_periods": "--post-periods", "cool_factor": "--cool-factor", "seed": "--seed", "root_folder": "--save",
    "imageFileType": "--images",
}
#: parameter settings that a flag switches
_SETTING_FLAGS = {"saveStressTensorData=False": "--no-tensor-data", "doCutByTriangulation=False": "--line-cuts",
                  "do_permanent_links=False": "--no-permanent-links", "saveData=True": "--save DIR",
                  "saveOutputImages=True": "--images"}


def cli_message(text):
    """``text`` of an API error on one line, with parameter names replaced by the CLI flags.

    A name is replaced where it is unambiguous: followed by ``=`` or a comparison, or spelled
    like an identifier (an underscore or a capital letter inside it).
    """
    text = " ".join(str(text).split())
    for setting, flag in _SETTING_FLAGS.items():
        text = text.replace(setting, flag)
    for name, flag in sorted(PARAMETER_FLAGS.items(), key=lambda kv: -len(kv[0])):
        identifier = "_" in name or any(c.isupper() for c in name[1:])
        pattern = rf"(?<![\w-])({re.escape(name)})(?![\w-])" if identifier else \
            rf"(?<![\w-])({re.escape(name)})(?=\s*(?:=|<=|>=|<|>))"
        text = re.sub(pattern, flag, text)
    return text


class _Parser(argparse.ArgumentParser):
    """Argument parser whose usage errors are one line on stderr (exit status 2), no usage block."""

    def error(self, message):
        self.exit(2, f"{self.prog}: invalid parameter: {' '.join(message.split())}\n")


class ProgressLine:
    """Progress callback writing one self-overwriting line to a stream (default stderr).

    The estimate of the remaining time of a phase is ``elapsed · (total − step)/step``.
    """

    def __init__(self, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self._width = 0
        self._tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self._last_phase = None
        self._last_line = 0.0
        #: without a terminal, a line is written at phase boundaries and at most every ``log_interval`` s
        self.log_interval = 5.0

    def __call__(self, phase, step, total, elapsed):
        if total and step:
            remaining = elapsed * (total - step) / step
            text = (f"[{phase}] step {step}/{total}  elapsed {elapsed:6.1f} s  remaining ~{remaining:6.1f} s  "
                    f"(total {time.perf_counter() - self.t0:6.1f} s)")
        elif total:
            text = f"[{phase}] done in {elapsed:.1f} s"
        else:
            text = f"[{phase}] running (total {time.perf_counter() - self.t0:6.1f} s)"
        if self._tty:
            pad = max(0, self._width - len(text))
            self.stream.write("\r" + text + " " * pad)
            self._width = len(text)
        elif (phase != self._last_phase or step == total
              or time.perf_counter() - self._last_line >= self.log_interval):
            self.stream.write(text + "\n")  # no carriage returns in logs
            self._last_line = time.perf_counter()
        self._last_phase = phase
        self.stream.flush()

    def finish(self):
        if self._tty and self._width:
            self.stream.write("\n")
            self.stream.flush()


def build_parser():
    p = _Parser(prog="particleShear",
                                description="2D soft-particle oscillatory shear rheology: G' and G'' of one run "
                                            "(defaults = doParticleShearSimulation defaults).")
    a = p.add_argument
    a("--amplitude", type=float, default=0.2, help="strain amplitude A (0.2 = 20%%)")
    a("--mu", type=float, default=0.01, help="friction coefficient of transient contacts")
    a("--N", type=int, default=150, help="number of spheres")
    a("--cut-lines", type=int, default=5, help="number of particles (triangulation) / cut lines; 0 = bulk gel")
    a("--no-permanent-links", action="store_true", help="frictional spheres only (no crosslinks)")
    a("--young-modulus", type=float, default=8000, help="Young modulus of the sphere material (Pa)")
    a("--packing-fraction", type=float, default=1.5, help="nominal packing fraction")
    a("--density", type=float, default=50, help="density (kg/m^3)")
    a("--bimodal-factor", type=float, default=1.4, help="large/small radius ratio")
    a("--relative-viscosity", type=float, default=0.1, help="rv in nu = rv*sqrt(m k)")
    a("--relative-transversal-link-strength", type=float, default=1, help="k_t/k")
    a("--relative-frequency", type=float, default=0.025, help="f * tau")
    a("--remove-link-fraction", type=float, default=0, help="fraction of non-essential bonds to remove")
    a("--edge-fuzziness", type=float, default=0, help="roughening of particle borders (units of r_max)")
    a("--line-cuts", action="store_true", help="cut with random straight lines instead of triangulation")
    a("--pre-periods", type=float, default=2, help="baseline periods before the excitation")
    a("--periods", type=float, default=3, help="excitation periods")
    a("--post-periods", type=float, default=1, help="recovery periods after the excitation")
    a("--cool-factor", type=float, default=0.5, help="peculiar velocity left after one period")
    a("--seed", type=int, default=None, help="random seed (same seed = identical run)")
    a("--save", metavar="DIR", default=None, help="write the text output file into DIR (must exist)")
    a("--no-tensor-data", action="store_true", help="with --save: omit the 42-column per-step table")
    a("--output-format", default="text", choices=("text", "text.gz", "npz", "parquet"),
      help="with --save: file format (default text, the reference format; see docs/output.md)")
    a("--images", nargs="?", const="jpg", default=None, choices=("jpg", "png", "ps"),
      help="with --save: save ~200 snapshots (default type jpg)")
    a("--draw", action="store_true", help="show the live particle and stress windows (needs a display)")
    a("--correct-drift-sign", action="store_true", help="use the correct drift sign in the demodulation")
    a("--reference-header", action="store_true", help="reproduce the reference header defects #21-22")
    a("--movie", action="store_true", help="with --images: also write the snapshots as movie.gif")
    a("--plot", metavar="FILE", default=None,
      help="write the strain/stress trace and Lissajous loop to FILE (.png/.pdf/.svg; needs particleShear[plot])")
    a("--quiet", action="store_true", help="no progress line")
    a("--verbose", action="store_true", help="print the reference console messages")
    return p


def main(argv=None):
    """Entry point; returns the process exit status (0 ok, 1 output not written or run unstable,
    2 invalid parameters, 130 interrupted).

    ``particleShear plot DIR ...`` dispatches to :func:`particleShear.plot.cli_main`,
    ``particleShear sweep SPEC --out DIR ...`` to :func:`particleShear.sweep.cli.main`.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] == "plot":
        from ..plot import cli_main
        return cli_main(argv[1:])
    if argv[:1] == ["sweep"]:  # python -m particleShear sweep SPEC --out DIR (particleShear.sweep.cli)
        from ..sweep.cli import main as sweep_main
        return sweep_main(argv[1:])
    args = build_parser().parse_args(argv)
    from .api import doParticleShearSimulation
    from ..base.stability import SimulationInstabilityError
    progress = None if args.quiet else ProgressLine()
    if args.images and not args.save:
        print("particleShear: --images needs --save DIR", file=sys.stderr)
        return 2
    try:
        res = doParticleShearSimulation(
            root_folder=args.save or "", theAmplitude=args.amplitude, theMu=args.mu,
            do_permanent_links=not args.no_permanent_links, cut_lines=args.cut_lines,
            Young_modulus_spheres=args.young_modulus, N=args.N, packing_fraction=args.packing_fraction,
            density=args.density, bimodal_factor=args.bimodal_factor, relative_viscosity=args.relative_viscosity,
            relative_transversal_link_strength=args.relative_transversal_link_strength,
            relative_frequency=args.relative_frequency, saveOutputImages=bool(args.images),
            imageFileType=args.images or "jpg", remove_link_fraction=args.remove_link_fraction,
            edge_fuzziness=args.edge_fuzziness, doCutByTriangulation=not args.line_cuts,
            doDrawing=bool(args.draw or args.images), saveData=bool(args.save),
            saveStressTensorData=not args.no_tensor_data, plotStress=bool(args.draw), pre_periods=args.pre_periods,
            periods=args.periods, post_periods=args.post_periods, cool_factor=args.cool_factor, seed=args.seed,
            return_result=True, verbose=args.verbose, progress=progress,
            correct_drift_sign=args.correct_drift_sign, reference_header=args.reference_header,
            renderer="auto" if args.draw else ("pillow" if args.images else "none"),
            saveOutputMovie=bool(args.movie and args.images),
            output_format=args.output_format)

    except KeyboardInterrupt as exc:  # one line, no traceback; the run removed its temporary files
        if progress is not None:
            progress.finish()
        phase, step, total = getattr(exc, "position", ("set-up", 0, 0))
        where = f"at step {step} of {total} ({phase})" if total else f"during {phase}"
        print(f"particleShear: interrupted {where}; no file written", file=sys.stderr)
        return 130
    except ImportError as exc:  # an optional extra (e.g. --output-format parquet without pyarrow)
        print(f"particleShear: {exc}", file=sys.stderr)
        return 2
    except (ValueError, TypeError) as exc:
        if progress is not None:
            progress.finish()
        print(f"particleShear: invalid parameter: {cli_message(exc)}", file=sys.stderr)
        return 2
    except SimulationInstabilityError as exc:
        if progress is not None:
            progress.finish()
        print(f"particleShear: {cli_message(exc)}", file=sys.stderr)
        return 1
    if progress is not None:
        progress.finish()
    print(f"G'  = {res.G_internal[0]} Pa   G'' = {res.G_internal[1]} Pa   (overall stress tensor)")
    print(f"G'  = {res.G_surface[0]} Pa   G'' = {res.G_surface[1]} Pa   (surface forces)")
    t = res.timings
    print("seed entropy = " + str(res.seed) + "; wall time " + ", ".join(
        f"{k} {t[k]:.2f} s" for k in ("constitution", "pre_equilibration", "protocol", "output", "total") if k in t))
    if res.output_path:
        print("output file: " + res.output_path)
    if res.image_folder:
        print(f"images: {res.n_images} in {res.image_folder}")
    if res.write_error is not None:
        print(f"particleShear: writing the output failed, nothing was saved: {res.write_error}", file=sys.stderr)
        return 1
    if args.plot:
        try:
            res.plot(args.plot)
        except (ImportError, ValueError) as exc:
            print(f"particleShear: --plot: {exc}", file=sys.stderr)
            return 1
        print("plot: " + args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
