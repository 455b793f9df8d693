"""The engine reads no private member of the documented classes (docs/classes.md, "The documented classes").

The engine (``particleShear/engine``) works on a :class:`~particleShear.engine.state.BatchState`
of plain arrays; the documented classes (``base``, ``objects``, ``linkable``) reach it through
their adapter, :mod:`particleShear.base.engine_adapter`.  Checked from the source: every private
name (``_x``, not ``__x__``) that a class of those packages defines (a method, an attribute it
assigns on ``self``, a class attribute) is read or written in engine/ only on ``self``/``cls``,
i.e. by an engine class on itself.  An engine class's own private member of the same name used on
another object counts too (the check cannot tell the types apart), so such names stay distinct.
"""
import ast
import os
import unittest

import particleShear

PACKAGE = os.path.dirname(particleShear.__file__)
DOCUMENTED = ("base", "objects", "linkable")


def _sources(folder):
    for top, _, files in os.walk(os.path.join(PACKAGE, folder)):
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(top, name)
                with open(path, encoding="utf-8") as f:
                    yield os.path.relpath(path, os.path.dirname(PACKAGE)), ast.parse(f.read(), path)


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def private_members(folder):
    """The private names the classes of ``folder`` define: methods, ``self._x = …`` targets, class attributes."""
    names = set()
    for _, tree in _sources(folder):
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                for item in node.body:
                    if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)) and _private(item.name):
                        names.add(item.name)
                    targets = item.targets if isinstance(item, ast.Assign) else (
                        [item.target] if isinstance(item, ast.AnnAssign) else [])
                    names.update(t.id for t in targets if isinstance(t, ast.Name) and _private(t.id))
            elif (isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) and _private(node.attr)
                  and isinstance(node.value, ast.Name) and node.value.id == "self"):
                names.add(node.attr)
    return names


class TestEngineBoundary(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.documented = set().union(*(private_members(folder) for folder in DOCUMENTED))

    def test_the_scan_sees_the_classes_private_members(self):
        # the scan must see what the adapter uses, else the next test could not fail
        self.assertLessEqual({"_a", "_pairs", "_rng", "_block", "_st", "_invalidate_neighbours", "_links_changed",
                              "_relations_edited", "_predictor", "_last_dt"}, self.documented)

    def test_engine_reads_no_private_member_of_the_documented_classes(self):
        found = []
        for path, tree in _sources("engine"):
            for node in ast.walk(tree):
                if (isinstance(node, ast.Attribute) and node.attr in self.documented
                        and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
                    found.append(f"{path}:{node.lineno} .{node.attr}")
        self.assertEqual(found, [], "engine/ reaches into the documented classes; go through "
                                    "particleShear.base.engine_adapter or a public method of the class")


if __name__ == "__main__":
    unittest.main()
