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

    def test_design_states_the_table(self):
        """docs/design.md's layer table lists the layers of particleShear.layers, in order."""
        with open(os.path.join(ROOT, "docs", "design.md"), encoding="utf-8") as fh:
            text = fh.read()
        section = text.split("## Layers", 1)[1].split("\n## ", 1)[0]
        rows = re.findall(r"^\| (\d+) \| ([^|]+?) \|", section, re.M)
        self.assertEqual([(int(i), n.strip()) for i, n in rows], [(i, n) for i, (n, _) in enumerate(layers.LAYERS)])


if __name__ == "__main__":
    unittest.main()
