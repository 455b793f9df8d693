"""Sweep specification: a TOML (or JSON) file with the tables [parameters], [grid], [seeds], [[zip]].

::

    [parameters]        # fixed values: any parameter of doParticleShearSimulation
    N = 150
    saveData = true
    [grid]              # lists: every combination is a point
    theAmplitude = [0.05, 0.1, 0.2, 0.5]
    theMu = [0.01, 0.1]
    [[zip]]             # lists of equal length that vary together (one more grid dimension)
    do_permanent_links = [true, true, false]
    cut_lines = [5, 0, 0]
    [seeds]             # repetitions per point, seeds spawned from one root
    root = 2021
    repetitions = 6

``amplitude`` and ``mu`` are accepted as aliases of ``theAmplitude`` and ``theMu`` (the same
runs, the same run ids); an unknown key is refused with the closest parameter names.
``stroboscopic = true`` (in any table) watches the runs with the stroboscopic observer
(docs/microstructure.md): an output option, so the run ids are those of the same SPEC without it
and it does not split the groups of ``particleShear analyse``.

Run ``k = repetition · n_points + point`` gets ``numpy.random.SeedSequence(root, spawn_key=(k,))``,
i.e. ``SeedSequence(root).spawn(n)[k]``: adding repetitions keeps the ids of the earlier ones.
Points enumerate the grid keys in file order, then each ``[[zip]]`` group, the last varying
fastest.  Every run is validated before any starts (docs/sweeps.md).
"""
__docformat__ = "numpy"
import dataclasses
import functools
import itertools
import json
import math
import numbers
import os

from ..checks import cut_text, show_value
from ..parameters import BY_NAME, PARAMETERS, SPEC_RESERVED, spec_defaults
from ..run.guard import PARAMETER_ALIASES, RUN_PARAMETERS_DOC, UnknownParameterError, close_names
from ..simulation.provenance import run_identity
from ..run.rheometer import LIST_PARAMETERS, normalize_protocol
from ..run.validation import SEED_LIMIT, checked_point

__all__ = ["SweepSpec", "SweepRun", "SweepRuns", "load_spec", "parse_spec", "expand_runs", "spec_runs",
           "sweep_parameter_defaults", "uses_protocols", "SPEC_TABLES", "MAX_POINTS", "MAX_RUNS"]

#: the tables a SPEC may hold
SPEC_TABLES = ("parameters", "grid", "zip", "seeds")
_SEED_KEYS = ("root", "repetitions")
#: arguments a SPEC may not set: the sweep chooses them
_RESERVED = SPEC_RESERVED
#: keyword options of a run that are not parameters of a sweep by default (no table column unless a
#: SPEC sets them) and not part of the run identity, with their defaults: the stroboscopic observer
#: only reads a run (its columns are measure columns, empty where it was off).  A SPEC may set them
#: in [parameters], [grid] or [[zip]]; a SPEC that does gets a column of that name and the run ids
#: of the same SPEC without it.
_NOT_SWEPT = {p.name: p.default for p in PARAMETERS if p.base_role == "observer"}
#: most parameter points of one SPEC: each is validated before any work (≈ 0.1 ms a point)
MAX_POINTS = 10_000
#: most runs of one SPEC (points × repetitions); runs are enumerated lazily, never held all at once
MAX_RUNS = 10 ** 8


@functools.lru_cache(maxsize=2)
def _defaults(protocols):
    return tuple(spec_defaults(protocols).items())


def sweep_parameter_defaults(protocols=False):
    """Every parameter a SPEC may set, with the default of ``doParticleShearSimulation`` (dict, signature order).

    Parameters
    ----------
    protocols : bool, optional
        True: with the parameters of the rheometer's protocols (``protocol``, ``relative_rate``,
        ... :data:`particleShear.run.rheometer.PROTOCOL_DEFAULTS`).  They are parameters (and
        table columns) of a sweep only when its SPEC sets one of them (:func:`uses_protocols`), so
        the tables of oscillatory sweeps keep their columns.  Default False.

    Returns
    -------
    dict
    """
    return dict(_defaults(bool(protocols)))


def uses_protocols(names):
    """True when one of ``names`` (the keys a SPEC or a series sets) is a protocol parameter.

    Parameters
    ----------
    names : iterable of str

    Returns
    -------
    bool
    """
    return any(n in BY_NAME and BY_NAME[n].base_role == "protocol" for n in names)


def _spec_keys(spec):
    keys = list(spec.parameters) + list(spec.grid)
    for group in spec.zips:
        keys += list(group)
    return keys


@dataclasses.dataclass(frozen=True)
class SweepRun:
    """One run of a sweep (made by :func:`expand_runs`; frozen).

    Parameters
    ----------
    index : int
        Position in the sweep (``repetition · n_points + point``); also the spawn key.
    point : int
        Index of the parameter point (the combination of [grid] and [[zip]] values), 0-based.
    repetition : int
        Index of the repetition of that point (0 … ``repetitions`` − 1).
    parameters : dict
        The complete parameter set (every SPEC-settable argument, defaults filled in).
    seed_entropy : int
        The SPEC's ``[seeds] root``: entropy of the run's ``numpy.random.SeedSequence``.
    spawn_key : tuple of int
        ``(index,)``: the run's child of the root seed sequence, so every run has its own,
        reproducible random stream.
    run_id : str
        :func:`particleShear.simulation.provenance.run_identity` of the above.
    checked : CheckedPoint or None, optional
        The checked arguments of its point (:func:`particleShear.run.validation.checked_point`,
        shared by the point's runs), from which a worker makes the run's
        :class:`~particleShear.run.validation.RunParameters` without validating it again; None
        (default) for a run without one (a series' run: validated where it runs).
    """

    index: int
    point: int
    repetition: int
    parameters: dict
    seed_entropy: int
    spawn_key: tuple
    run_id: str
    checked: object = dataclasses.field(default=None, compare=False, repr=False)


@dataclasses.dataclass
class SweepSpec:
    """A parsed, checked SPEC (see the module docstring and docs/sweeps.md).

    Parameters
    ----------
    parameters : dict
        The [parameters] table: values fixed for every run.
    grid : dict
        The [grid] table: ``{name: [values]}``, every combination is run.
    zips : list of dict
        The [[zip]] tables: each ``{name: [values]}`` with lists of equal length, varied together.
    root : int
        ``[seeds] root``: the root entropy of every run's seed.
    repetitions : int
        ``[seeds] repetitions``: runs per parameter point (≥ 1).
    source : str, optional
        Where the SPEC came from (file path), for messages.
    """
    parameters: dict
    grid: dict
    zips: list
    root: int
    repetitions: int
    source: str = ""

    @property
    def n_points(self):
        """Number of parameter points: product of the [grid] list lengths and the [[zip]] lengths."""
        n = 1
        for values in self.grid.values():
            n *= len(values)
        for group in self.zips:
            n *= len(next(iter(group.values())))
        return n


def _read_toml(path):
    """The tables of the TOML file ``path``: the one reader of TOML in the package (``tomllib``, or
    ``tomli`` on Python < 3.11)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python < 3.11
        try:
            import tomli as tomllib
        except ModuleNotFoundError:
            raise ValueError(f"SPEC={path!r}: reading TOML needs Python >= 3.11 or the package 'tomli' (a "
                             "dependency of particleShear on Python < 3.11: pip install 'tomli>=1.1'); "
                             "or write the SPEC as JSON (same tables)") from None
    with open(path, "rb") as fh:
        try:
            return tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(toml_error_message(path, exc)) from None


#: the usual fixes of a SPEC that is not valid TOML (named in every TOML error)
TOML_FIXES = ("TOML booleans are lowercase true/false; strings need quotes (\"png\"); lists use square brackets "
              "[0.1, 0.2]; a number needs a digit on both sides of its point (0.5, 5.0); there is no None (leave "
              "a key out for its default); each key once per table, and every [[zip]] group in double brackets")


def _toml_hint(line):
    """The fix of the usual mistake on ``line`` of a TOML file (empty when none is recognised)."""
    import re
    m = re.match(r"\s*([\w.\"'-]+)\s*=\s*(.*?)\s*(#.*)?$", line)
    if not m:
        return ""
    key, value = m.group(1), m.group(2)
    words = r"(?<![\w\"'])(True|False|TRUE|FALSE)(?![\w\"'])"
    if re.search(words, value):
        fixed = re.sub(words, lambda b: b.group(1).lower(), value)
        return f"TOML booleans are lowercase: write {key} = {fixed}"
    if re.fullmatch(r"(?i)none|null|nil", value):
        return f"TOML has no None: leave {key} out to keep its default"
    if value.startswith("("):
        return f"lists use square brackets: {key} = [{value[1:-1] if value.endswith(')') else value[1:]}]"
    if re.fullmatch(r"[+-]?\.\d.*", value) or re.fullmatch(r"[+-]?\d+\.", value):
        fixed = re.sub(r"^([+-]?)\.", r"\g<1>0.", value)
        fixed = fixed + "0" if fixed.endswith(".") else fixed
        return f"a number needs a digit on both sides of its point: write {key} = {fixed}"
    if re.fullmatch(r"[A-Za-z_][\w./-]*", value) and value not in ("inf", "nan"):
        return f'strings need quotes: write {key} = "{value}"'
    return ""


def toml_error_message(path, exc):
    """The message for a SPEC that is not valid TOML: the file, the line, its likely fix and the usual fixes.

    Parameters
    ----------
    path : str
        The SPEC file.
    exc : Exception
        The ``TOMLDecodeError`` of ``tomllib`` (or ``tomli``), whose text ends with
        "(at line L, column C)" or "(at end of document)".

    Returns
    -------
    str
        ``SPEC 'path' is not valid TOML: <error>``, then the offending line with a caret under the
        column, the fix of a recognised mistake (``doDrawing = False`` → "TOML booleans are
        lowercase: write doDrawing = false") and :data:`TOML_FIXES`.
    """
    import re
    text = str(exc)
    lineno, colno = getattr(exc, "lineno", None), getattr(exc, "colno", None)
    m = re.search(r"at line (\d+), column (\d+)", text)
    if lineno is None and m:
        lineno, colno = int(m.group(1)), int(m.group(2))
    msg = getattr(exc, "msg", None) or re.sub(r"\s*\(at (line \d+, column \d+|end of document)\)\s*$", "", text)
    where = f"line {lineno}, column {colno}" if lineno else "end of document" if "end of document" in text else ""
    out = [f"SPEC {path!r} is not valid TOML: {msg}" + (f" (at {where})" if where else "")]
    hint = ""
    if lineno:
        try:
            with open(path, encoding="utf-8", errors="replace") as fh:
                lines = fh.read().splitlines()
        except OSError:
            lines = []
        if 0 < lineno <= len(lines):
            line = lines[lineno - 1]
            label = f"  line {lineno}: "
            out.append(label + line)
            if colno:
                out.append(" " * (len(label) + colno - 1) + "^")
            hint = _toml_hint(line)
    if "Cannot overwrite" in msg or "Cannot declare" in msg:
        hint = hint or "a key or a table is set twice (repeated [[zip]] groups need double brackets)"
    if hint:
        out.append(hint + ".")
    out.append("Usual fixes: " + TOML_FIXES + ".")
    return "\n".join(out)


def load_spec(path):
    """Read and check a SPEC file (``.toml`` or ``.json``); return a :class:`SweepSpec`.

    Parameters
    ----------
    path : str or os.PathLike
        The SPEC file: ``.toml`` (``tomllib``; ``tomli`` on Python < 3.11, a dependency there) or ``.json``, same tables.


    Returns
    -------
    SweepSpec

    Raises
    ------
    ValueError
        Unknown table or key, a value out of range (the message names the key), or an unreadable file.
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"SPEC={path!r} is invalid: no such file")
    if path.endswith(".toml"):
        try:
            doc = _read_toml(path)
        except RecursionError:
            raise ValueError(_too_deep(path)) from None
    elif path.endswith(".json"):
        with open(path, encoding="utf-8") as fh:
            try:
                doc = json.load(fh)
            except RecursionError:
                raise ValueError(_too_deep(path)) from None
            except json.JSONDecodeError as exc:
                raise ValueError(f"SPEC={path!r} is not valid JSON: {exc}; JSON booleans are lowercase true/false, "
                                 "strings need double quotes, no trailing commas, null is not a value a "
                                 "parameter takes (leave the key out)") from None
    else:
        raise ValueError(f"SPEC={path!r} is invalid: allowed a .toml or .json file")
    return parse_spec(doc, source=path)


#: the most levels of tables and lists in a SPEC: the document, [[zip]], a table, a list of steps'
#: lists and a list of steps reach 5
MAX_SPEC_DEPTH = 8

#: the longest string a SPEC value may be (a path's limit, PATH_MAX on Linux; every other string
#: parameter is a short name)
MAX_SPEC_STRING = 4096


def _too_deep(source, where=""):
    return (f"SPEC {source!r} is invalid: {where or 'its values'} nest tables or lists deeper than "
            f"{MAX_SPEC_DEPTH} levels: allowed tables of values, lists and lists of lists")


def _check_depth(doc, source):
    """Refuse a SPEC nested deeper than :data:`MAX_SPEC_DEPTH` (iteratively: no recursion to overflow)."""
    todo = [(doc, 1, "SPEC")]
    while todo:
        v, depth, where = todo.pop()
        if depth > MAX_SPEC_DEPTH:
            raise ValueError(_too_deep(source, cut_text(where)))
        if isinstance(v, dict):
            todo.extend((x, depth + 1, f"{where}.{k}" if where != "SPEC" else str(k)) for k, x in v.items())
        elif isinstance(v, (list, tuple)):
            todo.extend((x, depth + 1, f"{where}[{i}]") for i, x in enumerate(v) if isinstance(x, (dict, list, tuple)))


def _name_source(exc, source):
    """``exc`` with its message starting ``SPEC 'source':`` unless it names the SPEC already; in place."""
    msg = str(exc)
    if source and f"SPEC {source!r}" not in msg and f"SPEC={source!r}" not in msg and exc.args:
        exc.args = (f"SPEC {source!r}: {msg}",) + tuple(exc.args[1:])
    return exc


def _scalar(where, v, name=None):
    if name in LIST_PARAMETERS:   # a list is one value of these (the steps of a one-packing sweep)
        if not isinstance(v, list) or not v:
            raise ValueError(f"{where}={show_value(v)} is invalid: allowed a non-empty list of numbers (one value of {name})")
        return [_scalar(f"{where}[{i}]", x) for i, x in enumerate(v)]
    if isinstance(v, str) and len(v) > MAX_SPEC_STRING:
        raise ValueError(f"{where}={show_value(v)} is invalid: allowed a string of at most {MAX_SPEC_STRING:,} "
                         f"characters (got {len(v):,})")
    ok = isinstance(v, (bool, str, numbers.Integral)) or (isinstance(v, numbers.Real) and math.isfinite(v))
    if not ok:
        raise ValueError(f"{where}={show_value(v)} is invalid: allowed a bool, a finite number or a string")
    return v


def _known(where, name, known):
    if name not in known:
        if name in _RESERVED:
            raise UnknownParameterError(f"{where}.{name} is not a parameter a SPEC may set: the sweep sets it "
                                        "itself", name=name)
        near = close_names(name, list(known) + list(PARAMETER_ALIASES))
        guess = f"did you mean {' or '.join(near)}?" if near else "no parameter name is close"
        raise UnknownParameterError(f"{where}.{cut_text(str(name))} is not a parameter of doParticleShearSimulation: {guess} "
                                    f"(the parameters: {RUN_PARAMETERS_DOC}; aliases: "
                                    f"{', '.join(f'{a} = {t}' for a, t in PARAMETER_ALIASES.items())})",
                                    name=name, suggestions=near)


def _values(where, v, name=None):
    if not isinstance(v, list) or not v:
        raise ValueError(f"{where}={show_value(v)} is invalid: allowed a non-empty list of values")
    return [_scalar(f"{where}[{i}]", x, name) for i, x in enumerate(v)]


def parse_spec(doc, source=""):
    """Check a SPEC given as a dict (parsed TOML/JSON) and return a :class:`SweepSpec`.

    Parameters
    ----------
    doc : dict
        The parsed SPEC: tables ``parameters``, ``grid``, ``zip`` (list) and ``seeds``
        (``root`` required, ``repetitions`` default 1).
    source : str, optional
        Where the SPEC came from, kept in :attr:`SweepSpec.source` for messages.

    Returns
    -------
    SweepSpec

    Raises
    ------
    ValueError
        Unknown table or parameter (an unknown parameter:
        :class:`~particleShear.run.guard.UnknownParameterError`, naming the closest parameters), a
        parameter set twice (also under its alias), zip lists of unequal length, a missing or
        invalid seed (the message names the key).

    Notes
    -----
    ``amplitude`` and ``mu`` are accepted as aliases of ``theAmplitude`` and ``theMu`` in
    [parameters], [grid] and [[zip]] (:data:`particleShear.run.guard.PARAMETER_ALIASES`); the
    parsed SPEC holds the parameter names, so the runs and their ids are those of the same SPEC
    written with ``theAmplitude`` and ``theMu``.
    """
    try:
        _check_depth(doc, source)
        return _parse_spec(doc, source)
    except (ValueError, TypeError) as exc:
        raise _name_source(exc, source) from None


def _parse_spec(doc, source):
    if not isinstance(doc, dict):
        raise ValueError(f"SPEC {source!r} is invalid: allowed a table of the tables {SPEC_TABLES}")
    for table in doc:
        if table not in SPEC_TABLES:
            raise ValueError(f"SPEC table [{cut_text(str(table))}] is unknown: allowed {', '.join(SPEC_TABLES)}")
    known = dict(sweep_parameter_defaults(protocols=True), **_NOT_SWEPT)
    seen = {}

    def claim(name, where):
        """The parameter ``name`` stands for (an alias resolved), checked and claimed once."""
        target = PARAMETER_ALIASES.get(name, name) if name not in known else name
        _known(where, target, known)
        if target in seen:
            first, spelled = seen[target]
            alias = name if name != target else spelled
            also = "" if spelled == name else f" (as {spelled}; {alias} is an alias of {target}: keep one)"
            raise ValueError(f"{where}.{name} is set twice: also in {first}{also}")
        seen[target] = (where, name)
        return target

    parameters = doc.get("parameters", {})
    if not isinstance(parameters, dict):
        raise ValueError("[parameters] is invalid: allowed a table of fixed values")
    fixed = {}
    for name, v in parameters.items():
        target = claim(name, "parameters")
        fixed[target] = _scalar(f"parameters.{name}", v, target)
    parameters = fixed

    grid = doc.get("grid", {})
    if not isinstance(grid, dict):
        raise ValueError("[grid] is invalid: allowed a table of lists")
    grid = {target: _values(f"grid.{name}", v, target) for name, v, target in
            [(name, v, claim(name, "grid")) for name, v in grid.items()]}

    zips = doc.get("zip", [])
    if isinstance(zips, dict):
        zips = [zips]
    if not isinstance(zips, list):
        raise ValueError("[[zip]] is invalid: allowed an array of tables of equal-length lists")
    checked = []
    for i, group in enumerate(zips):
        where = f"zip[{i}]"
        if not isinstance(group, dict) or not group:
            raise ValueError(f"{where} is invalid: allowed a non-empty table of equal-length lists")
        lengths = {name: len(v) if isinstance(v, list) else 0 for name, v in group.items()}
        group = {target: _values(f"{where}.{name}", v, target) for name, v, target in
                 [(name, v, claim(name, where)) for name, v in group.items()]}
        if len(set(lengths.values())) != 1:
            raise ValueError(f"{where} is invalid: its lists must have equal lengths, got {lengths}")
        checked.append(group)

    if "seeds" not in doc:
        raise ValueError("[seeds] is missing: allowed root = <integer >= 0> and repetitions = <integer >= 1>")
    seeds = doc["seeds"]
    if not isinstance(seeds, dict):
        raise ValueError("[seeds] is invalid: allowed a table with root and repetitions")
    for key in seeds:
        if key not in _SEED_KEYS:
            raise ValueError(f"seeds.{key} is unknown: allowed {', '.join(_SEED_KEYS)}")
    root = seeds.get("root")
    if isinstance(root, bool) or not isinstance(root, numbers.Integral) or not 0 <= root < SEED_LIMIT:
        raise ValueError(f"seeds.root={show_value(root)} is invalid: allowed an integer 0 <= value < 2**128")
    reps = seeds.get("repetitions", 1)
    if isinstance(reps, bool) or not isinstance(reps, numbers.Integral) or not 1 <= reps <= MAX_RUNS:
        raise ValueError(f"seeds.repetitions={show_value(reps)} is invalid: allowed an integer 1 <= value <= "
                         f"{MAX_RUNS:,}")
    n_points = 1
    for values in list(grid.values()) + [next(iter(g.values())) for g in checked]:
        n_points *= len(values)
        if n_points > MAX_POINTS:
            sizes = [len(v) for v in grid.values()] + [len(next(iter(g.values()))) for g in checked]
            raise ValueError(f"the SPEC has {' x '.join(map(str, sizes))} parameter points: allowed at most "
                             f"{MAX_POINTS:,} points (every point is checked before any work)")
    if n_points * reps > MAX_RUNS:
        raise ValueError(f"seeds.repetitions={reps} with {n_points:,} points is {n_points * reps:,} runs: allowed "
                         f"at most {MAX_RUNS:,} runs (repetitions <= {MAX_RUNS // n_points:,})")
    return SweepSpec(parameters=dict(parameters), grid=grid, zips=checked, root=int(root), repetitions=int(reps),
                     source=str(source))


def _points(spec):
    dims = [[{name: v} for v in values] for name, values in spec.grid.items()]
    for group in spec.zips:
        n = len(next(iter(group.values())))
        dims.append([{name: values[i] for name, values in group.items()} for i in range(n)])
    for combo in itertools.product(*dims):
        point = {}
        for part in combo:
            point.update(part)
        yield point


class SweepRuns:
    """The runs of one SPEC as a lazy sequence: ``runs[k]`` is made when asked (its id hashed then).

    Run ``k`` is repetition ``k // n_points`` of point ``k % n_points``; only the validated
    points are held, so a SPEC of :data:`MAX_RUNS` runs costs the memory of its points.

    Parameters
    ----------
    points : list of dict
        The complete parameter set of each point (validated).
    root : int
        ``[seeds] root``.
    repetitions : int
        ``[seeds] repetitions``.
    checked : list of CheckedPoint, optional
        Each point's checked arguments (:func:`particleShear.run.validation.checked_point`), given
        to its runs (``SweepRun.checked``); default None: runs without them.
    """

    def __init__(self, points, root, repetitions, checked=None):
        self.points, self.root, self.repetitions = list(points), root, int(repetitions)
        self.checked = None if checked is None else list(checked)

    def __len__(self):
        return len(self.points) * self.repetitions

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        n = len(self)
        if isinstance(k, bool) or not isinstance(k, numbers.Integral):
            raise TypeError(f"run index {k!r} is invalid: allowed an integer")
        if k < 0:
            k += n
        if not 0 <= k < n:
            raise IndexError(f"run index {k} is out of range: the sweep has {n} runs")
        rep, p = divmod(int(k), len(self.points))
        params = self.points[p]
        return SweepRun(index=int(k), point=p, repetition=rep, parameters=params, seed_entropy=self.root,
                        spawn_key=(int(k),), run_id=run_identity(params, self.root, (int(k),)),
                        checked=None if self.checked is None else self.checked[p])

    def __iter__(self):
        return (self[k] for k in range(len(self)))


def spec_runs(spec):
    """The runs of ``spec`` as a lazy :class:`SweepRuns`, every point validated first.

    Parameters
    ----------
    spec : SweepSpec

    Returns
    -------
    SweepRuns

    Raises
    ------
    ValueError, TypeError
        The first invalid point, naming the parameter (and the point) — before any work.
    """
    points, checked = _validated_points(spec)
    return SweepRuns(points, spec.root, spec.repetitions, checked)


def expand_runs(spec):
    """Every run of ``spec`` in sweep order (a list), each validated before any is returned.

    Parameters
    ----------
    spec : SweepSpec
        A parsed SPEC (:func:`load_spec`, :func:`parse_spec`).

    Returns
    -------
    list of SweepRun

    Raises
    ------
    ValueError, TypeError
        The first invalid run, naming the parameter (and the run's point) — before any work.
    """
    return list(spec_runs(spec))


def _validated_points(spec):
    """``(points, checked)``: the complete parameter set of every point of ``spec`` (point order) and its
    checked arguments (:func:`~particleShear.run.validation.checked_point`, each point validated once)."""
    defaults = sweep_parameter_defaults(protocols=uses_protocols(_spec_keys(spec)))
    points, checked = [], []
    for p_index, point in enumerate(_points(spec)):
        params = dict(defaults, **spec.parameters, **point)
        where = f"point {p_index} ({', '.join(f'{k}={show_value(v)}' for k, v in point.items()) or 'fixed parameters'})"
        try:
            # the sweep makes DIR (not required yet); each run sets its folder and seed (CheckedPoint.run)
            checked.append(checked_point(dict(params, root_folder=os.curdir)))
        except (ValueError, TypeError) as exc:
            msg = f"{where}: {exc}" if not str(exc).startswith("point ") else str(exc)
            raise _name_source(type(exc)(msg), spec.source) from None
        # a one-packing sweep is constituted for its first value: its row says so (and its id is the
        # id of the same call to doParticleShearSimulation)
        points.append(normalize_protocol(params) if "protocol" in params else params)
    return points, checked
