"""The value checks of every layer (``particleShear.checks``).

* each check accepts exactly the real numbers (a 0-d array counts as its value; a bool, a string,
  ``None`` are not numbers: TypeError) inside its range, compared exactly (an integer beyond the
  float range included), and returns the value as a float;
* the fast paths of ``finite``, ``positive`` and ``non_negative`` (Python and NumPy floats, Python
  ints) decide as the general range check ``in_range`` does, value by value, errors included;
* the message names the parameter, the value and the allowed range.
"""
import math
import unittest

import numpy as np

from particleShear import checks

VALUES = [0.0, -0.0, 1.5, -2.5, 1e308, -1e308, math.inf, -math.inf, math.nan, 0, 3, -4, 10 ** 308, 10 ** 400,
          -10 ** 400, np.float64(2.0), np.float64(-1.0), np.float64(np.nan), np.int64(7), np.int64(0), np.float32(0.5),
          np.array(5.0), np.array(-5.0), np.array(np.inf), True, False, np.True_, "1", None, [1.0], np.zeros(2)]


def outcome(fn, *args, **kw):
    try:
        return fn(*args, **kw)
    except (TypeError, ValueError) as exc:
        return type(exc)


class TestChecks(unittest.TestCase):

    def test_fast_paths_decide_as_the_range_check(self):
        for v in VALUES:
            with self.subTest(value=repr(v)):
                self.assertEqual(repr(outcome(checks.finite, "v", v)), repr(outcome(checks.in_range, "v", v)))
                self.assertEqual(repr(outcome(checks.positive, "v", v)),
                                 repr(outcome(checks.in_range, "v", v, lo=0, lo_open=True)))
                self.assertEqual(repr(outcome(checks.non_negative, "v", v)),
                                 repr(outcome(checks.in_range, "v", v, lo=0)))

    def test_the_definition(self):
        for v in VALUES:
            with self.subTest(value=repr(v)):
                x = v.item() if isinstance(v, np.ndarray) and v.ndim == 0 else v
                if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
                    self.assertIs(outcome(checks.finite, "v", v), TypeError)
                    continue
                ok = math.isfinite(x) if isinstance(x, (float, np.floating)) else abs(int(x)) <= 1.7976931348623157e308
                got = outcome(checks.finite, "v", v)
                self.assertEqual(got if got is ValueError else "ok", "ok" if ok else ValueError)
                if ok:
                    self.assertEqual(got, float(x))
                    self.assertIsInstance(got, float)
                    self.assertEqual(outcome(checks.positive, "v", v) is ValueError, not x > 0)
                    self.assertEqual(outcome(checks.non_negative, "v", v) is ValueError, not x >= 0)

    def test_integer_and_messages(self):
        self.assertEqual(checks.integer("N", 5, 2), 5)
        self.assertEqual(checks.integer("N", 5.0, 2), 5)
        self.assertEqual(checks.integer("N", np.array(5), 2), 5)
        for bad, exc in ((5.5, ValueError), (1, ValueError), (True, TypeError), ("5", TypeError)):
            with self.subTest(value=bad):
                self.assertIs(outcome(checks.integer, "N", bad, 2), exc)
        with self.assertRaisesRegex(ValueError, r"^k=-1 is out of range: allowed 0 <= value$"):
            checks.non_negative("k", -1)
        with self.assertRaisesRegex(ValueError, r"^angle=90 is out of range: allowed 0 <= value < 90$"):
            checks.in_range("angle", 90, 0, 90, hi_open=True)
        with self.assertRaisesRegex(ValueError, r"^N=10\*\*400 is out of range: allowed integers 2 <= value <= 1,000$"):
            checks.integer("N", 10 ** 400, 2, 1000)
        with self.assertRaisesRegex(TypeError, r"^x=True is invalid: allowed a real number$"):
            checks.finite("x", True)


if __name__ == "__main__":
    unittest.main()
