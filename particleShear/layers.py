"""The import layers of particleShear, as data, and the import graph that checks them.

Every module of the package belongs to one layer of :data:`LAYERS` (lowest first).  A module
imports only modules of its own layer or of layers below it, and the modules of the package import
one another without a cycle (``particleShearTest/test_layers.py`` checks both from the source
of every module, function-body imports included).  A function-body import (an import inside a
``def``) is allowed only for the standard library and the optional dependencies of
:data:`LAZY_ALLOWED`; every import of the package's own modules and of its required dependencies
(NumPy; Pillow only where it draws) is at the top of its module.

A module's layer is that of the longest entry of :data:`LAYERS` that names it or a package
above it, so a module may be placed above the rest of its package (``analysis.cli`` and
``experiment.calibration`` are command-line modules, ``analysis.figure`` a figure).  The figures
(layer ``plots``) are an optional layer: a result's ``plot()`` method lies below them and reaches
its figure through a named entry point of :mod:`particleShear.hooks` (resolved on call, no import
statement).

This module imports the standard library only; it is read by the tests and drawn in docs/design.md
("Layers"), never at run time.
"""
__docformat__ = "numpy"
import ast
import os
import sys
from collections import defaultdict

__all__ = ["LAYERS", "LAZY_ALLOWED", "PENDING", "layer_of", "import_graph", "cycles", "upward_edges", "summary"]

#: the layers, lowest first: ``(name, modules)``; a module listed is the module or package of
#: that name (with all modules below it unless a longer entry places them elsewhere)
LAYERS = (
    ("core", ("particleShear._version", "particleShear.hooks", "particleShear.checks", "particleShear.messages",
              "particleShear.signals", "particleShear.layers", "particleShear.parameter_entry")),
    ("engine", ("particleShear.engine",)),
    ("protocols", ("particleShear.protocols",)),
    ("parameters", ("particleShear.parameters",)),
    ("base", ("particleShear.base",)),
    ("objects", ("particleShear.objects",)),
    ("linkable", ("particleShear.linkable",)),
    ("simulation", ("particleShear.simulation",)),
    ("analysis", ("particleShear.analysis",)),
    ("run", ("particleShear.run",)),
    ("sweep", ("particleShear.sweep",)),
    ("experiment", ("particleShear.experiment",)),
    ("plots", ("particleShear.plot", "particleShear.plot_tools", "particleShear.sweep_plot", "particleShear.rheometer_plot",
               "particleShear.analysis.figure", "particleShear.experiment.figure")),
    ("command line", ("particleShear.run.cli", "particleShear.sweep.cli", "particleShear.analysis.cli",
                      "particleShear.analysis.outputs", "particleShear.experiment.calibration", "particleShear.experiment.writers",
                      "particleShear.__main__")),
    ("package", ("particleShear",)),
)

#: third-party modules a function body may import: the optional dependencies (loaded on use) and
#: Pillow, a required dependency that a run loads only when it draws (a headless run imports
#: neither PIL nor tkinter: tested)
LAZY_ALLOWED = frozenset(("matplotlib", "mpl_toolkits", "dask", "distributed", "pyarrow", "pandas", "cupy",
                          "cupyx", "numba", "freud", "tqdm", "tomli", "PIL"))

PACKAGE = "particleShear"

#: function-body imports of package modules the test accepts: ``"importer > imported"`` (names
#: without the leading ``particleShear.``).  Empty: every import of a package module is at the top of
#: its module, so the import graph the test draws is the whole one.
_PENDING = ()
PENDING = frozenset(tuple("particleShear." + m for m in e.split(" > ")) for e in _PENDING)


def layer_of(module):
    """The index in :data:`LAYERS` of a module of the package.

    Parameters
    ----------
    module : str
        Dotted module name (a package is named by its ``__init__``'s package name).

    Returns
    -------
    int
        The layer of the longest entry that is the module or a package above it.

    Raises
    ------
    KeyError
        When no entry covers the module.
    """
    best = None
    for i, (_, names) in enumerate(LAYERS):
        for name in names:
            if (module == name or module.startswith(name + ".")) and (best is None or len(name) > best[1]):
                best = (i, len(name))
    if best is None:
        raise KeyError(f"module {module} is in no layer of particleShear.layers.LAYERS")
    return best[0]


def _modules(root):
    """``{module: (path, is_package)}`` of every ``.py`` file under the package folder ``root``."""
    out = {}
    top = os.path.dirname(os.path.abspath(root))
    for folder, _, files in os.walk(root):
        for f in files:
            if f.endswith(".py"):
                path = os.path.join(folder, f)
                name = os.path.relpath(path, top)[:-3].replace(os.sep, ".")
                pkg = name.endswith(".__init__")
                out[name[:-9] if pkg else name] = (path, pkg)
    return out


def _imports(tree):
    """Every import node of a module with whether it is inside a function body."""
    found = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                found.append((child, in_function))
            visit(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))
    visit(tree, False)
    return found


def import_graph(root=None):
    """The import graph of the package from the source of its modules.

    Parameters
    ----------
    root : str, optional
        The package folder (default: this package's).

    Returns
    -------
    dict
        ``modules`` (sorted names), ``edges`` (``{(importer, imported): {"top", "function"}}``
        between the package's modules: ``from a import b`` is an edge to the module ``a.b`` when
        it is one, else to ``a``), ``lazy`` (``{(module, top-level name of an outside module)}``
        of the function-body imports of other packages, with their count).
    """
    root = root or os.path.dirname(os.path.abspath(__file__))
    mods = _modules(root)
    edges = defaultdict(set)
    lazy = defaultdict(int)
    for mod, (path, is_pkg) in mods.items():
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
        here = mod if is_pkg else mod.rpartition(".")[0]
        for node, in_function in _imports(tree):
            if isinstance(node, ast.Import):
                targets = [(a.name, None) for a in node.names]
            else:
                if node.level:
                    parts = here.split(".")
                    parts = parts[:len(parts) - node.level + 1]
                    src = ".".join(parts + ([node.module] if node.module else []))
                else:
                    src = node.module
                targets = [(src, a.name) for a in node.names]
            for src, name in targets:
                if src.split(".")[0] != PACKAGE:
                    if in_function:
                        lazy[(mod, src.split(".")[0])] += 1
                    continue
                target = f"{src}.{name}" if name and f"{src}.{name}" in mods else src
                while target not in mods:
                    target = target.rpartition(".")[0]
                if target != mod:
                    edges[(mod, target)].add("function" if in_function else "top")
    return {"modules": sorted(mods), "edges": dict(edges), "lazy": dict(lazy)}


def cycles(edges):
    """The strongly connected components of more than one module (each a sorted list).

    Parameters
    ----------
    edges : iterable of tuple
        ``(importer, imported)`` pairs.

    Returns
    -------
    list of list of str
        The import cycles' components, largest first.
    """
    graph = defaultdict(list)
    for a, b in edges:
        graph[a].append(b)
    index, low, stack, on, out = {}, {}, [], set(), []
    for start in list(graph):
        if start in index:
            continue
        work = [(start, iter(graph[start]))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(graph[w])))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return sorted(out, key=len, reverse=True)


def upward_edges(edges):
    """The edges from a module to a module of a higher layer, sorted.

    Parameters
    ----------
    edges : iterable of tuple
        ``(importer, imported)`` pairs.

    Returns
    -------
    list of tuple
        ``(importer, imported)`` with ``layer_of(imported) > layer_of(importer)``.
    """
    return sorted((a, b) for a, b in edges if layer_of(b) > layer_of(a))


def summary(graph):
    """The counts of an :func:`import_graph`: modules, edges, cycles, upward edges, lazy imports.

    Parameters
    ----------
    graph : dict
        An :func:`import_graph`.

    Returns
    -------
    dict
        ``modules``, ``edges``, ``function_edges`` (edges made by a function-body import),
        ``cycles`` (components), ``largest_cycle`` (modules of the largest), ``upward``,
        ``lazy_by_module`` (function-body imports of outside modules by top-level name) and
        ``lazy_not_allowed`` (those neither standard library nor :data:`LAZY_ALLOWED`).
    """
    comps = cycles(graph["edges"])
    by = defaultdict(int)
    for (_, name), n in graph["lazy"].items():
        by[name] += n
    return {"modules": len(graph["modules"]), "edges": len(graph["edges"]),
            "function_edges": sum(1 for k in graph["edges"].values() if "function" in k),
            "cycles": len(comps), "largest_cycle": max((len(c) for c in comps), default=0),
            "upward": len(upward_edges(graph["edges"])), "lazy_by_module": dict(sorted(by.items())),
            "lazy_not_allowed": sorted(k for k in graph["lazy"] if not _lazy_ok(k[1]))}


def _lazy_ok(name):
    """Whether a function body may import the top-level module ``name``."""
    return name in LAZY_ALLOWED or name in _stdlib()


def _stdlib():
    names = getattr(sys, "stdlib_module_names", None)
    if names is None:       # Python < 3.10
        import sysconfig
        lib = sysconfig.get_paths()["stdlib"]
        names = {f[:-3] if f.endswith(".py") else f for f in os.listdir(lib)} | set(sys.builtin_module_names)
    return names


if __name__ == "__main__":      # python -m particleShear.layers: the counts and the offending edges
    g = import_graph()
    print(summary(g))
    for comp in cycles(g["edges"]):
        print("cycle:", " ".join(m.replace("particleShear.", "") for m in comp))
    for a, b in upward_edges(g["edges"]):
        print("upward:", a, "->", b, sorted(g["edges"][(a, b)]))
