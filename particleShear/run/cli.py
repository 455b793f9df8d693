"""Command line: ``python -m particleShear`` / ``particleShear`` (console script).

``particleShear [run] [FLAGS]`` runs one :func:`~particleShear.doParticleShearSimulation`,
headless by default (no windows unless ``--draw``), with a progress line on stderr, and prints G′
and G″ from both estimators (internal and surface) on stdout, or with
``--json`` the result row (:meth:`~particleShear.SimulationResult.to_dict`) as JSON and nothing
else.  ``particleShear sweep SPEC --out DIR`` runs a sweep (docs/sweeps.md), ``particleShear plot
DIR`` plots one.

The flags of ``run`` are generated from the signature of ``doParticleShearSimulation``: every
parameter has the flag of its name in kebab case (``time_step_factor`` → ``--time-step-factor``,
``saveOutputImages`` → ``--save-output-images``; booleans as ``--flag``/``--no-flag``), with the
help text, type, unit and allowed range taken from its numpydoc docstring; the short names of
earlier versions (``--amplitude``, ``--mu``, ``--young-modulus``, ``--no-permanent-links``,
``--line-cuts``, ``--no-tensor-data``, ``--save DIR``, ``--images [TYPE]``, ``--draw``, ``--movie``,
``--quiet``) stay as aliases.  Exit status: 0 ok, 1 output not written or run unstable, 2 invalid
parameters, 130 interrupted.
"""
__docformat__ = "numpy"
import argparse
import contextlib
import inspect
import json
import math
import os
import re
import sys
import time

from .._version import __version__
from .guard import SuggestingParser, shorten_values
from ..signals import sigterm_raises
from .validation import IMAGE_FILE_TYPES, validate_run
from ..parameters import BY_NAME, PARAMETERS
from ..analysis.cli import main as analyse_main
from ..analysis.verdicts import CHECKS, verdict_lines
from ..base.stability import SimulationInstabilityError
from ..experiment.calibration import main as calibrate_main
from ..experiment.writers import main as export_main
from ..plot import check_figure_path, cli_main
from ..sweep.cli import main as sweep_main
from ..sweep.progress import RemainingTime
from ..sweep.schema import column_spec
from .api import doParticleShearSimulation

__all__ = ["main", "console_main", "build_parser", "ProgressLine", "PARAMETER_FLAGS", "cli_message", "parameter_docs",
           "flag_name", "api_kwargs", "NOT_FLAGS"]

#: today's (short) flag names of the parameters, kept as the first option string of each
_ALIASES = {"theAmplitude": "--amplitude", "theMu": "--mu", "Young_modulus_spheres": "--young-modulus",
            "saveOutputMovie": "--movie"}
#: earlier flags that switch a boolean parameter off
_NEGATIVE_ALIASES = {"do_permanent_links": "--no-permanent-links", "doCutByTriangulation": "--line-cuts",
                     "saveStressTensorData": "--no-tensor-data"}
#: parameters without a flag, and why
NOT_FLAGS = {"return_result": "the command line always takes the whole result; --json prints it"}
#: parameters whose command-line default differs from the API's (headless, quiet, progress line)
_CLI_DEFAULTS = {
    "doDrawing": "off unless --draw or --images",
    "plotStress": "off unless --draw",
    "renderer": '"none"; "auto" with --draw, "pillow" with --images',
    "verbose": "off",
    "progress": "on (--quiet: off)",
    "saveData": "off; on with --save DIR",
    "root_folder": '""; DIR of --save DIR',
    "saveOutputImages": "off; on with --images",
}
#: help of parameters whose command-line meaning differs from the API's
_CLI_HELP = {"progress": "Show a progress line on stderr (phase, step, elapsed, estimated remaining time), "
                         "the progress callback of the API."}
#: the command-line type of parameters whose Python type is wider
def float_list(text):
    """A comma-separated list of numbers (``--sweep-amplitudes 0.01,0.1,1``) as a list of float.

    Parameters
    ----------
    text : str
        The flag's text.

    Returns
    -------
    list of float
    """
    return [float(x) for x in text.split(",") if x.strip()]


float_list.__name__ = "comma-separated float list"   # argparse names the type in its message
_CLI_TYPES = {"seed": int, "progress": bool}


def flag_name(name):
    """The flag of a parameter: its name in kebab case (``theMu`` → ``--the-mu``; ``N`` stays ``--N``).

    Parameters
    ----------
    name : str
        Parameter name of :func:`~particleShear.doParticleShearSimulation`.

    Returns
    -------
    str
    """
    if len(name) == 1:
        return "--" + name
    kebab = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "-", name).replace("_", "-").lower()
    return "--" + kebab


def parameter_docs(func=None):
    """``{name: (type text, description)}`` of the numpydoc Parameters section of ``func``.

    The description is one line (whitespace joined); a leading "Keyword-only." is dropped.

    Parameters
    ----------
    func : callable, optional
        Function with a numpydoc docstring (default :func:`~particleShear.doParticleShearSimulation`).

    Returns
    -------
    dict
    """
    if func is None:
        func = doParticleShearSimulation
    lines = inspect.cleandoc(func.__doc__ or "").splitlines()
    try:
        i = next(k for k in range(len(lines) - 1) if lines[k].strip() == "Parameters"
                 and set(lines[k + 1].strip()) == {"-"}) + 2
    except StopIteration:
        return {}
    docs, current = {}, None
    for k in range(i, len(lines)):
        line = lines[k]
        if k + 1 < len(lines) and line.strip() and set(lines[k + 1].strip()) == {"-"} and not line.startswith(" "):
            break  # the next section
        if line and not line.startswith(" "):
            names, _, type_text = line.partition(" : ")
            current = [n.strip() for n in names.split(",")]
            for n in current:
                docs[n] = [type_text.strip(), ""]
        elif current and line.strip():
            for n in current:
                docs[n][1] = (docs[n][1] + " " + line.strip()).strip()
    out = {}
    for n, (t, d) in docs.items():
        d = re.sub(r"^Keyword-only\.\s*", "", d)
        out[n] = (t, d)
    return out


def _cli_type(par):
    """The argparse type of a parameter of the table: its kind's, or the command line's own."""
    if par.name in _CLI_TYPES:
        return _CLI_TYPES[par.name]
    return {"bool": bool, "int": int, "float": float, "str": str, "float_list": float_list}.get(par.kind, str)


def _float(text):
    """``float(text)``; an integer literal beyond the float range stays an ``int``, so that the
    validation refuses it as the API does (naming its range), not as ``inf``."""
    x = float(text)
    if not math.isfinite(x):
        try:
            return int(text)
        except ValueError:
            pass
    return x


_float.__name__ = "float"   # argparse names the type in its message: "invalid float value: 'x'"


def _default_text(value):
    if isinstance(value, float):
        return f"{value:g}"
    return '""' if value == "" else (json.dumps(value) if isinstance(value, str) else str(value))


def _help(text):
    """Help text for argparse: plain reST markup dropped, ``%`` escaped."""
    text = re.sub(r":\w+:`~?([^`]*)`", r"\1", text).replace("``", "")
    return text.replace("%", "%%")


def _record(namespace, dest, option_string):
    typed = getattr(namespace, "_typed", None)
    if typed is None:
        typed = {}
        setattr(namespace, "_typed", typed)
    typed[dest] = option_string


class _Store(argparse._StoreAction):
    """``store``, remembering the option string the user typed (for error messages)."""

    def __call__(self, parser, namespace, values, option_string=None):
        _record(namespace, self.dest, option_string)
        super().__call__(parser, namespace, values, option_string)


class _StoreConst(argparse._StoreConstAction):
    def __call__(self, parser, namespace, values, option_string=None):
        _record(namespace, self.dest, option_string)
        super().__call__(parser, namespace, values, option_string)


class _Bool(argparse.BooleanOptionalAction):
    """``--flag``/``--no-flag``, remembering which was typed."""

    def __call__(self, parser, namespace, values, option_string=None):
        _record(namespace, self.dest, option_string)
        super().__call__(parser, namespace, values, option_string)


def _flags():
    """``{parameter: (option strings, CLI type, choices, default)}`` in signature order, from the
    parameter table (:mod:`particleShear.parameters`)."""
    out = {}
    for par in PARAMETERS:
        if par.name in NOT_FLAGS:
            continue
        derived = flag_name(par.name)
        strings = [_ALIASES[par.name], derived] if par.name in _ALIASES and _ALIASES[par.name] != derived else [derived]
        out[par.name] = (strings, _cli_type(par), par.choices, par.default)
    return out


def _primary(name):
    return _ALIASES.get(name) or flag_name(name)


def _negative(name):
    return "--no-" + _primary(name)[2:]


#: the flag named in messages for each ``doParticleShearSimulation`` parameter
PARAMETER_FLAGS = {}


def cli_message(text, typed=None):
    """``text`` of an API error on one line, with parameter names replaced by the CLI flags.

    ``typed`` maps parameters to the flag the user typed (preferred over the documented one).
    A name is replaced where it is unambiguous: followed by ``=`` or a comparison, or spelled
    like an identifier (an underscore or a capital letter inside it); ``name=True`` and
    ``name=False`` of a boolean become its flag and its ``--no-`` flag.

    Parameters
    ----------
    text : str or Exception
        The message.
    typed : dict, optional
        ``{parameter: flag the user typed}``.

    Returns
    -------
    str
    """
    if not PARAMETER_FLAGS:
        _flags_for_messages()
    typed = typed or {}
    text = " ".join(shorten_values(text).split())
    for name in sorted(PARAMETER_FLAGS, key=len, reverse=True):
        for value in ("True", "False"):
            setting = f"{name}={value}"
            if not re.search(rf"(?<![\w-]){re.escape(setting)}(?!\w)", text):
                continue
            t = typed.get(name)
            if value == "True":
                flag = t if t and not t.startswith("--no-") and t not in _NEGATIVE_ALIASES.values() else \
                    ("--save DIR" if name == "saveData" else _primary(name))
            else:
                flag = t if t and (t.startswith("--no-") or t in _NEGATIVE_ALIASES.values()) else \
                    _NEGATIVE_ALIASES.get(name, _negative(name))
            text = re.sub(rf"(?<![\w-]){re.escape(setting)}(?!\w)", flag, text)
    for name in sorted(PARAMETER_FLAGS, key=len, reverse=True):
        flag = typed.get(name) or PARAMETER_FLAGS[name]
        identifier = "_" in name or any(c.isupper() for c in name[1:])
        pattern = rf"(?<![\w-])({re.escape(name)})(?![\w-])" if identifier else \
            rf"(?<![\w-])({re.escape(name)})(?=\s*(?:=|<=|>=|<|>))"
        text = re.sub(pattern, flag.replace("\\", "\\\\"), text)
    return text


def _flags_for_messages():
    for name in _flags():
        PARAMETER_FLAGS[name] = _primary(name)
    PARAMETER_FLAGS["root_folder"] = "--save"


_flags_for_messages()


class _Parser(SuggestingParser):
    """Argument parser whose usage errors are one line on stderr (exit status 2), no usage block; no prefix
    abbreviations, an unknown flag named with the closest flags (:class:`~particleShear.run.guard.SuggestingParser`)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: invalid parameter: {' '.join(message.split())}\n")


class ProgressLine:
    """Progress callback writing one self-overwriting line to a stream (default stderr).

    The remaining time of a phase is estimated from the steps after its first report
    (:class:`~particleShear.sweep.progress.RemainingTime`: the first step's start-up is not a
    rate); the first report of a phase shows none.

    Parameters
    ----------
    stream : file-like, optional
        Where the line goes (default ``sys.stderr``); without a terminal, one line per phase
        boundary, one with the phase's first estimate, and at most one every ``log_interval`` s,
        without carriage returns.
    clock : callable, optional
        Seconds (default ``time.perf_counter``; tests pass a fake clock).
    """

    def __init__(self, stream=None, clock=time.perf_counter):
        self.stream = stream if stream is not None else sys.stderr
        self.clock = clock
        self.t0 = clock()
        self._remaining = RemainingTime()
        self._width = 0
        self._tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self._last_phase = None
        self._estimated = False   # a line with an estimate was written in this phase (no terminal)
        self._last_line = 0.0
        #: without a terminal, a line is written at phase boundaries and at most every ``log_interval`` s
        self.log_interval = 5.0

    def __call__(self, phase, step, total, elapsed):
        if phase != self._last_phase:
            self._remaining.reset()
            self._estimated = False
        remaining = self._remaining.update(step, total, elapsed) if total else None
        now = self.clock()
        if total and step:
            left = "remaining ~   –  " if remaining is None else f"remaining ~{remaining:6.1f} s"
            text = (f"[{phase}] step {step}/{total}  elapsed {elapsed:6.1f} s  {left}  "
                    f"(total {now - self.t0:6.1f} s)")
        elif total:
            text = f"[{phase}] done in {elapsed:.1f} s"
        else:
            text = f"[{phase}] running (total {now - self.t0:6.1f} s)"
        if self._tty:
            pad = max(0, self._width - len(text))
            self.stream.write("\r" + text + " " * pad)
            self._width = len(text)
        elif (phase != self._last_phase or step == total or now - self._last_line >= self.log_interval
              or (remaining is not None and not self._estimated)):
            self.stream.write(text + "\n")  # no carriage returns in logs; the first estimate gets its line
            self._last_line = now
            self._estimated = self._estimated or remaining is not None
        self._last_phase = phase
        self.stream.flush()

    def finish(self):
        """End the self-overwriting line (a newline on a terminal)."""
        if self._tty and self._width:
            self.stream.write("\n")
            self.stream.flush()


def build_parser():
    """The parser of ``particleShear [run]``: one flag per parameter of ``doParticleShearSimulation``."""
    p = _Parser(prog="particleShear",
                description="2D soft-particle oscillatory shear rheology: G' and G'' of one run. Commands: "
                            "run (default; the flags below), sweep SPEC --out DIR (particleShear sweep --help), "
                            "analyse DIR (particleShear analyse --help), plot DIR (particleShear plot --help), "
                            "export DIR --format reptate|pyrheo (particleShear export --help), calibrate MEASURED "
                            "DIR (particleShear calibrate --help). "
                            "Flags follow the parameters of "
                            "doParticleShearSimulation (its docstring and docs/parameters.md); headless by default.")
    p.add_argument("--version", action="version", version=f"particleShear {__version__}")
    groups = {True: p.add_argument_group("parameters of doParticleShearSimulation (reference order)"),
              False: p.add_argument_group("keyword-only options of doParticleShearSimulation")}
    for name, (strings, cli_type, choices, default) in _flags().items():
        par = BY_NAME[name]
        group = groups[not par.keyword_only]
        desc = _CLI_HELP.get(name) or par.doc
        if par.extra and par.unit:       # a law's own parameter (its file's declaration): its unit
            desc += "; unit: " + ("dimensionless" if par.unit == "1" else par.unit)
        if par.has_range:
            desc += f"; allowed {par.range_text()}"
        shown = _CLI_DEFAULTS.get(name, _default_text(default))
        help_text = _help(cli_message(desc)) + f" [default: {shown}]"
        if cli_type is bool:
            group.add_argument(*strings, dest=name, action=_Bool, default=None, help=help_text)
            if name in _NEGATIVE_ALIASES:
                group.add_argument(_NEGATIVE_ALIASES[name], dest=name, action=_StoreConst, const=False,
                                   default=None, help=f"same as {_negative(name)}")
        else:
            # choices are shown, and refused by the API's validation (validate_run) with its message
            metavar = ("{" + ",".join(choices) + "}" if choices else "DIR" if name == "root_folder" else
                       {int: "INT", float: "FLOAT", float_list: "X,Y,..."}.get(cli_type, "STR"))
            group.add_argument(*strings, dest=name, action=_Store, type=_float if cli_type is float else cli_type,
                               default=None, metavar=metavar, help=help_text)
    c = p.add_argument_group("command line")
    c.add_argument("--save", metavar="DIR", default=None, action=_Store,
                   help="write the output file into DIR (made with its parents if missing): --root-folder DIR "
                        "--save-data")
    c.add_argument("--images", nargs="?", const="jpg", default=None, choices=IMAGE_FILE_TYPES, action=_Store,
                   help="with --save: save ~200 snapshots of type jpg (default), png, ps or svg: "
                        "--save-output-images --image-file-type TYPE")
    c.add_argument("--draw", action="store_true",
                   help="show the live particle and stress windows (needs a display): "
                        "--do-drawing --plot-stress --renderer auto")
    c.add_argument("--plot", metavar="FILE", default=None,
                   help="write the strain/stress trace and Lissajous loop to FILE (.png/.pdf/.svg/.eps; "
                        "needs particleShear[plot])")
    c.add_argument("--stroboscopic-pictures", metavar="DIR", default=None, action=_Store,
                   help="watch the run with the stroboscopic observer (--stroboscopic) and write one picture per "
                        "excitation cycle into DIR (force chains, spheres coloured by D2_min; Pillow) and "
                        "DIR/cycles.gif (docs/microstructure.md)")
    c.add_argument("--json", action="store_true",
                   help="print the result row (SimulationResult.to_dict(), the row of a sweep's results.csv) "
                        "as one JSON object on stdout, and nothing else there; an amplitude or frequency "
                        "sweep: one object {protocol, run_id, rows: [one row per step]}")
    c.add_argument("--quiet", dest="progress", action=_StoreConst, const=False, default=None,
                   help="no progress line (same as --no-progress)")
    return p


def api_kwargs(args):
    """The keyword arguments of ``doParticleShearSimulation`` for parsed ``args`` (command-line defaults applied).

    Parameters
    ----------
    args : argparse.Namespace
        Parsed by :func:`build_parser`.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        Naming the flags, for combinations the API cannot express.
    """
    kw = {}
    for par in PARAMETERS:
        if par.name in NOT_FLAGS:
            continue
        value = getattr(args, par.name, None)
        kw[par.name] = par.default if value is None else value
    given = {n for n in kw if getattr(args, n, None) is not None}
    images = getattr(args, "images", None)
    save = getattr(args, "save", None)
    draw = bool(getattr(args, "draw", False))
    if "root_folder" not in given:
        kw["root_folder"] = save or ""
    if "saveData" not in given:
        kw["saveData"] = bool(save)
    if "saveOutputImages" not in given:
        kw["saveOutputImages"] = bool(images)
    if "imageFileType" not in given and images:
        kw["imageFileType"] = images
    if "doDrawing" not in given:
        kw["doDrawing"] = bool(draw or images)
    if "plotStress" not in given:
        kw["plotStress"] = draw
    if "renderer" not in given:
        kw["renderer"] = "auto" if draw else ("pillow" if kw["saveOutputImages"] else "none")
    if "verbose" not in given:
        kw["verbose"] = False
    kw["progress"] = ProgressLine() if getattr(args, "progress", None) in (None, True) else None
    if images and not kw["root_folder"]:
        raise ValueError("--images needs --save DIR")
    pictures = getattr(args, "stroboscopic_pictures", None)
    if pictures is not None:
        if not str(pictures).strip():
            raise ValueError("--stroboscopic-pictures='' is invalid: allowed a folder name")
        if "stroboscopic" in given and not kw["stroboscopic"]:
            raise ValueError("--stroboscopic-pictures needs the stroboscopic observer: drop --no-stroboscopic")
        if kw.get("protocol", "oscillatory") != "oscillatory":
            raise ValueError(f"--stroboscopic-pictures with --protocol {kw['protocol']} is invalid: allowed only "
                             "the oscillatory protocol (the observer watches its periods)")
        periods = kw.get("periods")
        if isinstance(periods, (int, float)) and not isinstance(periods, bool) and periods < 1:
            raise ValueError(f"--stroboscopic-pictures with --periods {periods:g} is invalid: allowed --periods >= 1 "
                             "(one picture per complete period)")
        kw["stroboscopic"] = True
    return kw


def _json_row(res):
    """The result row with non-finite numbers as null (strict JSON)."""
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v
    rows = [{k: clean(v) for k, v in row.items()} for row in res.rows()]   # one, or a sweep's steps
    if len(rows) == 1:
        return json.dumps(rows[0], default=str)
    return json.dumps({"protocol": res.protocol, "run_id": rows[0].get("run_id"), "rows": rows}, default=str)


class RunTerminated(KeyboardInterrupt):
    """SIGTERM during a single run of the CLI: handled as Ctrl-C (temporary files removed), exit 143."""


def main(argv=None):
    """Entry point; returns the process exit status (0 ok, 1 output not written or run unstable,
    2 invalid parameters, 130 interrupted, 143 terminated by SIGTERM).

    ``particleShear run ...`` (or flags only) runs one simulation, ``particleShear plot DIR ...``
    dispatches to :func:`particleShear.plot.cli_main`, ``particleShear sweep SPEC --out DIR ...`` to
    :func:`particleShear.sweep.cli.main`.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["plot"]:
        return cli_main(argv[1:])
    if argv[:1] == ["sweep"]:  # python -m particleShear sweep SPEC --out DIR (particleShear.sweep.cli)
        return sweep_main(argv[1:])
    if argv[:1] in (["analyse"], ["analyze"]):  # python -m particleShear analyse DIR (particleShear.analysis.cli)
        return analyse_main(argv[1:])
    if argv[:1] == ["export"]:  # particleShear export DIR --format reptate|pyrheo (particleShear.experiment.writers)
        return export_main(argv[1:])
    if argv[:1] == ["calibrate"]:  # particleShear calibrate MEASURED DIR (particleShear.experiment.calibration)
        return calibrate_main(argv[1:])
    if argv[:1] == ["run"]:
        argv = argv[1:]
    elif argv and not argv[0].startswith("-"):
        print(f"particleShear: invalid parameter: unknown command {argv[0]!r}: allowed run (default), sweep, plot, "
              "analyse, export, calibrate",
              file=sys.stderr)
        return 2
    args = build_parser().parse_args(argv)
    typed = getattr(args, "_typed", {})
    if "save" in typed:
        typed.setdefault("root_folder", "--save")
        typed.setdefault("saveData", "--save")
    if "images" in typed:
        typed.setdefault("saveOutputImages", "--images")
    try:
        kw = api_kwargs(args)
    except ValueError as exc:
        print(f"particleShear: {exc}", file=sys.stderr)
        return 2
    # before any work: the run's parameters (the API's validation, its messages with the flags),
    # then the --plot target
    # --save DIR is made (with its parents) as `sweep --out` makes its folder: after every other
    # parameter is valid, so a refused run leaves nothing behind
    make_save = bool(args.save) and not os.path.exists(args.save)
    try:
        validate_run(dict(kw, root_folder=os.curdir) if make_save else kw)
    except ImportError as exc:  # an optional extra (e.g. --output-format parquet without pyarrow)
        print(f"particleShear: {exc}", file=sys.stderr)
        return 2
    except (ValueError, TypeError) as exc:
        print(f"particleShear: invalid parameter: {cli_message(exc, typed)}", file=sys.stderr)
        return 2
    if make_save:
        try:
            os.makedirs(args.save, exist_ok=True)
        except OSError as exc:
            print(f"particleShear: invalid parameter: --save={args.save!r}: the folder cannot be made: "
                  f"{exc.strerror or exc}", file=sys.stderr)
            return 2
    if args.plot:
        try:
            check_figure_path(args.plot, name="--plot")
        except (ValueError, ImportError) as exc:
            print(f"particleShear: invalid parameter: {exc}", file=sys.stderr)
            return 2
    progress = kw["progress"]
    # with --json, stdout holds the JSON only: the run's console messages go to stderr
    quiet_stdout = contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext()
    try:
        with quiet_stdout, sigterm_raises(RunTerminated):
            res = doParticleShearSimulation(**kw, return_result=True)
    except KeyboardInterrupt as exc:  # one line, no traceback; the run removed its temporary files
        if progress is not None:
            progress.finish()
        phase, step, total = getattr(exc, "position", ("set-up", 0, 0))
        where = f"at step {step} of {total} ({phase})" if total else f"during {phase}"
        terminated = isinstance(exc, RunTerminated)
        print(f"particleShear: {'terminated (SIGTERM)' if terminated else 'interrupted'} {where}; no file written",
              file=sys.stderr)
        return 143 if terminated else 130
    except ImportError as exc:  # an optional extra (e.g. --output-format parquet without pyarrow)
        print(f"particleShear: {exc}", file=sys.stderr)
        return 2
    except (ValueError, TypeError) as exc:
        if progress is not None:
            progress.finish()
        print(f"particleShear: invalid parameter: {cli_message(exc, typed)}", file=sys.stderr)
        return 2
    except SimulationInstabilityError as exc:
        if progress is not None:
            progress.finish()
        print(f"particleShear: {cli_message(exc, typed)}", file=sys.stderr)
        return 1
    if progress is not None:
        progress.finish()
    info = sys.stderr if args.json else sys.stdout
    if args.json:
        print(_json_row(res))
    elif res.protocol != "oscillatory":     # a summary or a sweep's steps (docs/protocols.md)

        def unit(name):   # the unit of the results.csv column of the same name (docs/protocols.md)
            u = column_spec(name).get("unit") or ""
            return "" if u in ("", "1") else " " + u

        def shown(items):
            return "  ".join(f"{k} = {v:.6g}{unit(k)}" if isinstance(v, float) else f"{k} = {v}" for k, v in items)
        for st in res.steps:
            print(shown((k, st[k]) for k in ("position", "amplitude", "relative_frequency", "Gp_surface",
                                             "Gp_surface_se", "Gpp_surface", "Gpp_surface_se", "Gp_internal",
                                             "Gpp_internal", "verdict")))
        if res.summary:
            print(shown((k, v) for k, v in res.summary.items() if k not in CHECKS and k != "verdict"))
            print("\n".join(verdict_lines(res.summary, res.protocol)))
        print(f"protocol = {res.protocol}; seed entropy = {res.seed}; tau = {res.tau:.6g} s; wall time "
              + ", ".join(f"{k} {v:.2f} s" for k, v in res.timings.items()))
        if res.output_path:
            print("output file: " + res.output_path)
    else:
        print(f"G'  = {res.G_internal[0]} Pa   G'' = {res.G_internal[1]} Pa   (internal estimator)")
        print(f"G'  = {res.G_surface[0]} Pa   G'' = {res.G_surface[1]} Pa   (surface estimator)")
        print("\n".join(verdict_lines(res.measures)))
        t = res.timings
        print("seed entropy = " + str(res.seed) + "; wall time " + ", ".join(
            f"{k} {t[k]:.2f} s" for k in ("constitution", "pre_equilibration", "protocol", "output", "total")
            if k in t))
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
        print("plot: " + args.plot, file=info)
    if args.stroboscopic_pictures is not None:
        try:
            made = res.microstructure_pictures(args.stroboscopic_pictures)
        except (OSError, ValueError) as exc:
            print(f"particleShear: --stroboscopic-pictures: {exc}", file=sys.stderr)
            return 1
        print(f"pictures: {len(made['pictures'])} cycles and {os.path.basename(made['gif'])} in "
              f"{args.stroboscopic_pictures}", file=info)
    return 0


if __name__ == "__main__":
    sys.exit(main())


def console_main():
    """Console-script entry (``particleShear`` / ``python -m particleShear``): :func:`main` with a closed pipe ended quietly.

    A reader that stops early (``particleShear --json | head -c 100``) closes stdout; that ends
    the command with status 141 (as a shell pipeline reports SIGPIPE) instead of a traceback.

    Returns
    -------
    int
    """
    import os
    try:
        return main()
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # no second error when Python flushes stdout at exit
        return 141
