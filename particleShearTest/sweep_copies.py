"""A finished sweep made once per test class, and fresh copies of its folder for each damage test."""
import os
import shutil
import tempfile

from particleShear.sweep import run_sweep


class CopiesOfOneSweep:
    """Mixin of a ``unittest.TestCase``: ``SPEC`` swept once into ``ref``; :meth:`_copy` gives a copy to damage.

    Attributes
    ----------
    SPEC : dict
        The sweep (set by the test class).
    tmp, ref : str
        The class's scratch folder and the finished sweep's folder in it.
    rows : list of dict
        The rows ``run_sweep`` returned.
    """
    SPEC = None

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="ps_sweep_")
        cls.ref = os.path.join(cls.tmp, "ref")
        cls.rows = run_sweep(cls.SPEC, cls.ref, workers=2, progress=False)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def _copy(self, name):
        out = os.path.join(self.tmp, name)
        shutil.copytree(self.ref, out)
        return out
