"""What pyproject.toml declares matches what the code needs: the TOML reader and the extras that
error messages name."""
import os
import pathlib
import re
import sys
import tempfile
import unittest
from unittest import mock

ROOT = pathlib.Path(__file__).resolve().parent.parent
PYPROJECT = ROOT / "pyproject.toml"


def _pyproject():
    from particleShear.sweep.spec import _read_toml
    return _read_toml(str(PYPROJECT))


@unittest.skipUnless(PYPROJECT.exists(), "pyproject.toml not shipped with this installation")
class TestDeclaredDependencies(unittest.TestCase):
    def test_tomli_below_python_311(self):
        project = _pyproject()["project"]
        floor = re.fullmatch(r">=\s*3\.(\d+)", project["requires-python"].strip())
        self.assertIsNotNone(floor, project["requires-python"])
        if int(floor.group(1)) < 11:          # tomllib is in the standard library from 3.11 only
            tomli = [d for d in project["dependencies"] if d.replace(" ", "").startswith("tomli")]
            self.assertEqual(len(tomli), 1, project["dependencies"])
            self.assertIn('python_version<"3.11"', tomli[0].replace(" ", "").replace("'", '"'))

    def test_runtime_dependencies(self):
        names = sorted(re.split(r"[<>=;\[ ]", d, 1)[0] for d in _pyproject()["project"]["dependencies"])
        self.assertEqual(names, ["numpy", "pillow", "tomli"])

    def test_extras_named_by_messages_exist(self):
        extras = _pyproject()["project"]["optional-dependencies"]
        self.assertIn("pandas", " ".join(extras["tables"]))
        self.assertIn("matplotlib", " ".join(extras["plot"]))
        self.assertIn("dask", " ".join(extras["dask"]))
        # every "particleShear[extra]" an error message or document names is declared
        named = set()
        for path in list((ROOT / "particleShear").rglob("*.py")) + [ROOT / "README.md"] + list((ROOT / "docs").glob("*.md")):
            named |= set(re.findall(r"particleShear\[([a-z,]+)\]", path.read_text(encoding="utf-8")))
        for group in named:
            for extra in group.split(","):
                self.assertIn(extra, extras, f"particleShear[{group}] is named but [{extra}] is not an extra")

    def test_one_toml_reader(self):
        # every use of tomllib/tomli goes through particleShear.sweep.spec._read_toml
        users = [p.relative_to(ROOT).as_posix() for p in (ROOT / "particleShear").rglob("*.py")
                 if re.search(r"\bimport toml(lib|i)\b", p.read_text(encoding="utf-8"))]
        self.assertEqual(users, ["particleShear/sweep/spec.py"])


@unittest.skipUnless((ROOT / ".ci" / "run").exists() and (ROOT / "README.md").exists(),
                     "CI script and README not shipped with this installation")
class TestReadmeTestCommand(unittest.TestCase):
    """CI runs the README's test command, and the [test] extra installs what that command uses."""

    def test_ci_runs_the_readme_test_command(self):
        readme = (ROOT / "README.md").read_text(encoding="utf-8")
        commands = re.findall(r'pip install "\.\[test\]" && (python -m pytest [^\n]*)', readme)
        self.assertEqual(len(commands), 1, "README.md: one test command after pip install \".[test]\"")
        ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
              if line.strip() and not line.lstrip().startswith("#")]
        self.assertIn('pip install ".[test]"', ci)
        self.assertIn(commands[0].strip(), ci)       # the README's command, after the install it needs
        self.assertGreater(ci.index(commands[0].strip()), ci.index('pip install ".[test]"'))

    def test_test_extra_has_the_plugins_of_the_command(self):
        readme = (ROOT / "README.md").read_text(encoding="utf-8")
        (command,) = re.findall(r'pip install "\.\[test\]" && (python -m pytest [^\n]*)', readme)
        test_extra = " ".join(_pyproject()["project"]["optional-dependencies"]["test"])
        self.assertIn("pytest", test_extra)
        if re.search(r"(^| )(-n|--dist)( |=)", command):      # pytest-xdist's options
            self.assertIn("pytest-xdist", test_extra)


class TestTomlWithoutReader(unittest.TestCase):
    def test_clear_error_without_tomllib_and_tomli(self):
        from particleShear.sweep.spec import _read_toml
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "s.toml")
            with open(path, "w") as fh:
                fh.write("[parameters]\nN = 30\n")
            with mock.patch.dict(sys.modules, {"tomllib": None, "tomli": None}):
                with self.assertRaisesRegex(ValueError, r"needs Python >= 3\.11 or the package 'tomli'.*JSON"):
                    _read_toml(path)
            self.assertEqual(_read_toml(path), {"parameters": {"N": 30}})


if __name__ == "__main__":
    unittest.main()
