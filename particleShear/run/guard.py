"""Guard-rails for misspelled names: keyword arguments, dict keys, SPEC keys and command-line flags.

A name that is not a parameter is refused with the closest allowed names (``theAmplitud`` →
"did you mean theAmplitude?", :func:`close_names`) and where the allowed names are documented.

* :func:`checked_keywords` wraps a public function (``doParticleShearSimulation``,
  ``doParticleShearSimulationSeries``, ``run_batch``): before the body runs it checks the keyword
  names against the signature and raises :class:`UnknownParameterError` — a subclass of both
  ``TypeError`` (what Python itself raises for an unexpected keyword) and ``ValueError`` (what the
  package raises for a bad parameter) — instead of Python's bare TypeError.  It can also accept
  documented aliases (:data:`PARAMETER_ALIASES`: ``amplitude`` for ``theAmplitude``, ``mu`` for
  ``theMu``).  ``inspect.signature`` of the wrapped function is that of the original
  (``functools.wraps``): the command line and the docs are generated from it.
* :func:`resolve_names` does the same for a dict of parameters (a batch's keyword dicts, the
  tables of a sweep SPEC).
* :class:`SuggestingParser` is the ``argparse.ArgumentParser`` of every command: no prefix
  abbreviations (``allow_abbrev=False``: ``--amplitud`` is not ``--amplitude``) and an unknown
  flag is refused with the closest flags.
"""
__docformat__ = "numpy"
import argparse
import difflib
import functools
import inspect
import re

from ..checks import MESSAGE_VALUE_LIMIT, cut_text

__all__ = ["shorten_values", "command_line_names", "UnknownParameterError", "PARAMETER_ALIASES", "PARAMETER_HINTS", "close_names", "unknown_name_message", "resolve_names",
           "checked_keywords", "SuggestingParser"]

#: documented aliases of parameters of ``doParticleShearSimulation`` (alias → parameter); the
#: command line has the same short names (``--amplitude``, ``--mu``)
PARAMETER_ALIASES = {"amplitude": "theAmplitude", "mu": "theMu"}

#: names people use for parameters of a run that are no spelling of them (name → parameter, suggested)
PARAMETER_HINTS = {"law": "contact_law", "force_law": "contact_law", "elastic_force_law": "contact_law",
                   "plateau_start": "plateau_begin", "plateau_stop": "plateau_end"}

#: where the parameters of a run are documented (named in every unknown-name message)
RUN_PARAMETERS_DOC = "help(particleShear.doParticleShearSimulation) and docs/parameters.md"


class UnknownParameterError(TypeError, ValueError):
    """A name that is not a parameter (or a parameter given twice under two spellings).

    Subclass of ``TypeError`` (so code written for Python's own "unexpected keyword argument"
    still catches it) and of ``ValueError`` (the package's error for a bad parameter).

    Parameters
    ----------
    message : str
        The message: the unknown name, where it was given, the closest allowed names and where
        the allowed names are documented.
    name : str, optional
        The unknown name.
    suggestions : tuple of str, optional
        The closest allowed names (best first; empty when none is close).

    Attributes
    ----------
    name : str
        As given.
    suggestions : tuple of str
        As given.
    """

    def __init__(self, message, name="", suggestions=()):
        super().__init__(message)
        self.name = name
        self.suggestions = tuple(suggestions)


def _norm(name):
    return name.lower().replace("_", "").replace("-", "")


# a name= then a quoted literal as repr writes it or a list (of numbers or of lists), or a run of non-blanks
_LONG_VALUE = re.compile(r"""[^\s'"\[]*(?:'(?:[^'\\\n]|\\.)*'|"(?:[^"\\\n]|\\.)*"|\[(?:[^\[\]\n]|\[[^\[\]\n]*\])*\])|\S+""")


def shorten_values(text, limit=MESSAGE_VALUE_LIMIT):
    """``text`` with every value longer than ``limit`` characters cut (:func:`particleShear.checks.cut_text`).

    A value is a quoted literal (as ``repr`` writes it) or a bracketed list (lists in it included),
    with the name and ``=`` written before it, or else a run of non-blank characters.  Applied by
    the commands to every message they print: a 50 MB string in a SPEC is named, not echoed.

    Parameters
    ----------
    text : str or Exception
        The message.
    limit : int, default :data:`particleShear.checks.MESSAGE_VALUE_LIMIT`
        The most characters shown of one value.

    Returns
    -------
    str
    """
    text = str(text)
    if len(text) <= limit:
        return text
    return _LONG_VALUE.sub(lambda m: cut_text(m.group(0), limit), text)


def command_line_names(text, parser, aliases=None):
    """``text`` with every ``name=value`` of a Python argument written as the command line names it.

    A command's message comes from the function it calls, whose arguments have Python names
    (``folder_or_csv='x' is invalid``); the command shows the names its user typed: an option as
    ``--x=value``, a positional argument as its metavar (``DIR 'x' is invalid``).

    Parameters
    ----------
    text : str or Exception
        The message.
    parser : argparse.ArgumentParser
        The command's parser: each argument's ``dest`` is replaced by its last option string
        (``--no-split`` for ``split``) or, positional, by its metavar.
    aliases : dict of str to str, optional
        Python argument name → the parser's ``dest`` where they differ
        (``{"folder_or_csv": "folder", "path": "output"}``).

    Returns
    -------
    str
    """
    shown = {}
    for action in parser._actions:
        if action.dest in ("help", argparse.SUPPRESS):
            continue
        shown[action.dest] = (action.option_strings[-1] + "=") if action.option_strings else \
            f"{action.metavar or action.dest.upper()} "
    for name, dest in (aliases or {}).items():
        if dest in shown:
            shown[name] = shown[dest]
    text = str(text)
    for name in sorted(shown, key=len, reverse=True):
        text = re.sub(rf"(?<![\w.-]){re.escape(name)}=", lambda m, s=shown[name]: s, text)
    return text


def close_names(name, allowed, n=3, hints=None):
    """The allowed names closest to ``name``, best first.

    First an explicit hint (``hints[name]``), then the names equal to ``name`` but for case,
    underscores and hyphens (``save_data`` → ``saveData``), then :func:`difflib.get_close_matches`
    on those normalised spellings: ratio at least 0.6 and within 0.1 of the best one.

    Parameters
    ----------
    name : str
        The name that was given.
    allowed : iterable of str
        The names that would be accepted.
    n : int, default 3
        Most names returned.
    hints : dict, optional
        ``{name: suggestion}`` for known confusions that are not spelling mistakes
        (e.g. ``theAmplitude`` → ``amplitudes`` in a series).

    Returns
    -------
    list of str
        At most ``n`` distinct names of ``allowed`` (or hints), best first; empty when none is close.
    """
    allowed = list(dict.fromkeys(allowed))
    out = []
    if hints and name in hints:
        out.append(hints[name])
    key = _norm(str(name))
    by_norm = {}
    for a in allowed:
        by_norm.setdefault(_norm(a), []).append(a)
    out += by_norm.get(key, [])
    # a ratio >= 0.6 needs len(key) <= 7/3 of the other's length: longer names cannot be close
    # (and difflib's time grows with the product of the lengths: a 5 MB key would take hours)
    if len(key) > 7 * max((len(k) for k in by_norm), default=0) // 3 + 1:
        return list(dict.fromkeys(out))[:n]
    scored = [(difflib.SequenceMatcher(None, key, k).ratio(), k) for k in by_norm]
    best = max((r for r, _ in scored), default=0.0)
    # the close spellings: ratio >= 0.6, and within 0.1 of the best (a clear winner stands alone)
    for r, match in sorted(scored, key=lambda rk: -rk[0]):
        if r >= max(0.6, best - 0.1):
            out += by_norm[match]
    return list(dict.fromkeys(out))[:n]


def _or(names):
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


def unknown_name_message(name, allowed, where, documented, hints=None, kind="parameter", drop=None):
    """The message for a name that is not allowed, with the closest allowed names.

    Parameters
    ----------
    name : str
        The unknown name.
    allowed : iterable of str
        The names that would be accepted.
    where : str
        What the name was given to (``"doParticleShearSimulation"``, ``"list_of_kwargs[2]"``,
        ``"SPEC grid"``).
    documented : str
        Where the allowed names are documented.
    hints : dict, optional
        Known confusions (see :func:`close_names`).
    kind : str, default "parameter"
        What a name is ("parameter", "keyword", "flag").
    drop : dict, optional
        ``{alias: parameter}``: an alias is not suggested beside its parameter.

    Returns
    -------
    tuple
        ``(message, suggestions)``: the message and the list of suggested names.
    """
    suggestions = close_names(name, allowed, hints=hints)
    if drop:
        suggestions = [s for s in suggestions if drop.get(s) not in suggestions]
    guess = f"did you mean {_or(suggestions)}?" if suggestions else "no allowed name is close"
    return (f"{name!r} is not a {kind} of {where}: {guess} (the allowed names: {documented})", suggestions)


def resolve_names(params, allowed, where, documented=RUN_PARAMETERS_DOC, aliases=None, hints=None, bound=()):
    """``params`` with documented aliases replaced by their parameter; unknown names refused.

    Parameters
    ----------
    params : dict
        ``{name: value}`` as given.
    allowed : iterable of str
        The parameter names.
    where : str
        What the names were given to (for the message).
    documented : str, default: the docs of doParticleShearSimulation
        Where the allowed names are documented (for the message).
    aliases : dict, optional
        ``{alias: parameter}`` accepted in place of the parameter (:data:`PARAMETER_ALIASES`).
    hints : dict, optional
        Known confusions suggested for a name (see :func:`close_names`).
    bound : iterable of str, optional
        Parameters given otherwise (e.g. positionally): an alias of one of them is a second spelling.

    Returns
    -------
    dict
        A new dict with every name a parameter (aliases resolved), in the given order.

    Raises
    ------
    UnknownParameterError
        For a name that is neither a parameter nor an alias (naming the closest parameters), and
        for a parameter given under two spellings (``amplitude`` and ``theAmplitude``).
    """
    allowed = list(allowed)
    known = set(allowed)
    aliases = aliases or {}
    bound = set(bound)
    out = {}
    for name, value in params.items():
        target = aliases.get(name) if name not in known else None
        if target is not None:
            if target in params or target in bound:
                raise UnknownParameterError(
                    f"{name!r} and {target!r} are given to {where}: {name} is an alias of {target}, give only one",
                    name=name, suggestions=(target,))
            out[target] = value
            continue
        if name not in known:
            # an alias is suggested only where its parameter is not (``mu`` for ``Mu``; not beside ``theMu``)
            message, suggestions = unknown_name_message(name, allowed + list(aliases), where, documented, hints=hints,
                                                        drop=aliases)
            raise UnknownParameterError(message, name=name, suggestions=suggestions)
        out[name] = value
    return out


def checked_keywords(where=None, documented=RUN_PARAMETERS_DOC, aliases=None, hints=None, extra=()):
    """Decorator: check the keyword names of every call against the signature before the body runs.

    An unknown keyword raises :class:`UnknownParameterError` naming it, the closest parameters and
    ``documented``; an alias of ``aliases`` is passed on as its parameter (given together with
    that parameter, by keyword or by position, it is refused).  The wrapper keeps the name, the
    docstring and ``inspect.signature`` of the function (``functools.wraps``).

    Parameters
    ----------
    where : str, optional
        The function's name in messages (default its ``__name__``).
    documented : str, default: the docs of doParticleShearSimulation
        Where the allowed names are documented.
    aliases : dict, optional
        ``{alias: parameter}`` accepted in place of a parameter.
    hints : dict, optional
        Known confusions suggested for a name (see :func:`close_names`).
    extra : iterable of str or callable, optional
        Further names a ``**kwargs`` of the function takes (a callable is called once, at the
        first call, and returns them); without ``**kwargs`` and without ``extra`` only the
        signature's names are allowed; with ``**kwargs`` and no ``extra`` any name passes.

    Returns
    -------
    callable
        The decorator.
    """
    def decorate(func):
        sig = inspect.signature(func)
        params = sig.parameters
        names = [n for n, p in params.items() if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
        positional = [n for n, p in params.items() if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
        open_kwargs = any(p.kind is p.VAR_KEYWORD for p in params.values())
        label = where or func.__name__
        known = frozenset(names)
        allowed_cache = []

        def allowed():
            if not allowed_cache:
                more = extra() if callable(extra) else extra
                allowed_cache.append(names + [n for n in more if n not in names])
            return allowed_cache[0]

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if known.issuperset(kwargs):
                return func(*args, **kwargs)
            if open_kwargs and not extra:   # any name passes: only the aliases are resolved
                kwargs = {(aliases or {}).get(k, k) if k not in known else k: v for k, v in kwargs.items()}
                return func(*args, **kwargs)
            kwargs = resolve_names(kwargs, allowed(), label, documented, aliases=aliases, hints=hints,
                                   bound=positional[:len(args)])
            return func(*args, **kwargs)
        return wrapper
    return decorate


class SuggestingParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` without prefix abbreviations, suggesting the closest flags.

    ``allow_abbrev`` defaults to False (a prefix such as ``--amplitud`` is not taken for
    ``--amplitude``); an unrecognized flag is reported through :meth:`error` (exit status 2) with
    the closest flags of the parser ("--amplitud: did you mean --amplitude?"), on every Python
    version.

    Parameters
    ----------
    *args, **kwargs
        As ``argparse.ArgumentParser``.
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def flag_suggestions(self, token):
        """The closest flags of this parser to ``token`` (one per option; best first).

        Flags equal to ``token`` but for case, underscores and hyphens come first (``--n`` → ``--N``),
        then flags that ``token`` abbreviates (shortest first), then the close spellings
        (:func:`close_names`).

        Parameters
        ----------
        token : str
            An unrecognized argument such as ``--amplitud`` or ``--amplitud=0.1``.

        Returns
        -------
        list of str
        """
        flag = token.split("=", 1)[0]
        strings = self._option_string_actions
        out, seen = [], set()
        same = [s for s in strings if _norm(s) == _norm(flag)]      # --n → --N, --save_data → --save-data
        prefixed = sorted((s for s in strings if len(flag) > 2 and s.startswith(flag)), key=len)
        for match in same + prefixed + close_names(flag, list(strings), n=6):
            action = strings[match]
            if id(action) not in seen:
                seen.add(id(action))
                out.append(match)
        return out[:3]

    def parse_args(self, args=None, namespace=None):
        """Parse like ``argparse.ArgumentParser.parse_args``; an unknown flag names the closest flags.

        Parameters
        ----------
        args : list of str, optional
            The arguments (default ``sys.argv[1:]``).
        namespace : argparse.Namespace, optional
            Where the values go.

        Returns
        -------
        argparse.Namespace
        """
        ns, extras = self.parse_known_args(args, namespace)
        if extras:
            notes = []
            for token in extras:
                if token.startswith("-") and len(token) > 1 and not _is_number(token):
                    near = self.flag_suggestions(token)
                    flag = token.split("=", 1)[0]
                    notes.append(f"{flag} is not a flag: did you mean {_or(near)}?" if near else
                                 f"{flag} is not a flag")
            help_flag = f"{self.prog} --help lists the flags"
            detail = f" ({'; '.join(notes)}; {help_flag})" if notes else ""
            self.error(f"unrecognized arguments: {' '.join(extras)}{detail}")
        return ns


def _is_number(token):
    try:
        float(token)
    except ValueError:
        return False
    return True
