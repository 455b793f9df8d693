"""The import layers of particleShear (issue 45): no import cycle, no upward import, lazy imports
only of the standard library and the optional dependencies — from the source of every module,
function-body imports included (:mod:`particleShear.layers`)."""
import os
import re
import unittest

import particleShear
from particleShear import layers

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class TestLayers(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.graph = layers.import_graph(os.path.dirname(particleShear.__file__))
        cls.counts = layers.summary(cls.graph)

    def _say(self, what, items):
        return f"{what}: {items}\nimport graph: {self.counts}"

    def test_every_module_has_a_layer(self):
        for m in self.graph["modules"]:
            layers.layer_of(m)          # raises KeyError for a module of no layer

    def test_no_cycle(self):
        edges = set(self.graph["edges"]) - set(layers.PENDING)
        found = layers.cycles(edges)
        self.assertEqual(found, [], self._say("import cycles", found))

    def test_no_upward_edge(self):
        found = [e for e in layers.upward_edges(self.graph["edges"]) if e not in layers.PENDING]
        self.assertEqual(found, [], self._say("upward imports", found))

    def test_pending_edges_still_exist(self):
        """An edge of the pending list that is gone must leave the list (it only shrinks)."""
        gone = [e for e in layers.PENDING if e not in self.graph["edges"]]
        self.assertEqual(gone, [], self._say("pending edges that no longer exist", gone))

    def test_lazy_imports_only_optional_or_standard(self):
        found = self.counts["lazy_not_allowed"]
        self.assertEqual(found, [], self._say("function-body imports of required or unknown modules", found))

    def test_no_lazy_import_of_the_package(self):
        """Every import of the package's own modules is at the top of its module."""
        lazy = sorted(e for e, kinds in self.graph["edges"].items() if "function" in kinds and e not in layers.PENDING)
        self.assertEqual(lazy, [], self._say("function-body imports of the package's modules", lazy))

    def test_every_entry_is_a_module(self):
        """Every module named in LAYERS exists (a layer lists no module that is gone)."""
        modules = set(self.graph["modules"])
        gone = [m for _, names in layers.LAYERS for m in names if m not in modules]
        self.assertEqual(gone, [], self._say("entries of LAYERS that are no module", gone))

    def test_design_draws_the_layers(self):
        """docs/design.md's layer diagram lists the layers of particleShear.layers, in order, with their modules."""
        expected = [(i, name, sorted(names)) for i, (name, names) in enumerate(layers.LAYERS)]
        self.assertEqual(design_layers(), expected[::-1], "the diagram draws every layer, highest first")


#: a row of the layer diagram: its number, its name (words separated by one space), its modules
#: (separated by single spaces) and, after two spaces or more, what they hold
_ROW = re.compile(r"^\s*(\d+) (\S+(?: \S+)*?)\s{2,}(\S+(?: \S+)*?)(?:\s{2,}.*)?$")


def design_layers():
    """``(number, name, sorted module names)`` of every row of docs/design.md's layer diagram, in its order.

    The diagram is the ```text block of the section "Layers"; its modules are named relative to the
    package (``particleShear`` itself as ``particleShear``).
    """
    with open(os.path.join(ROOT, "docs", "design.md"), encoding="utf-8") as fh:
        text = fh.read()
    section = text.split("\n## Layers\n", 1)[1].split("\n## ", 1)[0]
    block = section.split("```text\n", 1)[1].split("```", 1)[0]
    rows = []
    for line in block.splitlines():
        m = _ROW.match(line)
        if m:
            names = [n if n == "particleShear" else "particleShear." + n for n in m.group(3).split(" ")]
            rows.append((int(m.group(1)), m.group(2), sorted(names)))
    return rows

if __name__ == "__main__":
    unittest.main()
