"""Every script answers --help with its usage and does nothing else (no install, build, run or file).

Each scripts/*.sh, .ci/run, scripts/*.py and each command module of the results package
(python/omniloc/commands/X.py, run as `python3 -m omniloc.commands.X` with PYTHONPATH=python, as
`omniloc report|gate|compare|paper-table` run them) is run with --help (and -h) from the repository
root with a 20 s limit; it must exit 0, print text, and leave the tree as it was (git status and the
mtime of build/ and results/ unchanged). Run by ctest as help_py.
"""
import os
import pathlib
import subprocess
import unittest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PY = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else "python3"


def commands():
    out = [[str(p)] for p in sorted((ROOT / "scripts").glob("*.sh"))] + [[str(ROOT / ".ci" / "run")]]
    out += [[PY, str(p)] for p in sorted((ROOT / "scripts").glob("*.py"))]
    out += [[PY, "-m", f"omniloc.commands.{p.stem}"] for p in sorted((ROOT / "python" / "omniloc" / "commands").glob("*.py"))
            if p.name != "__init__.py"]
    return out


def state():
    st = subprocess.run(["git", "status", "--porcelain", "--ignored"], cwd=ROOT, capture_output=True, text=True).stdout
    times = {d: (ROOT / d).stat().st_mtime_ns for d in ("build", "results") if (ROOT / d).exists()}
    return st, times


class Help(unittest.TestCase):
    def test_every_script_answers_help_and_does_nothing_else(self):
        before = state()
        for cmd in commands():
            for flag in ("--help", "-h"):
                with self.subTest(script=cmd[-1] if cmd[-2:-1] == ["-m"] else pathlib.Path(cmd[-1]).name, flag=flag):
                    r = subprocess.run(cmd + [flag], cwd=ROOT, capture_output=True, text=True, timeout=20,
                                       env={**os.environ, "PATH": "/usr/bin:/bin", "SUDO_ASKPASS": "/bin/false",
                                            "PYTHONPATH": str(ROOT / "python"), "PYTHONDONTWRITEBYTECODE": "1"})
                    self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
                    self.assertTrue(r.stdout.strip(), "no usage printed")
                    self.assertNotIn("install-deps:", r.stdout + r.stderr, "ran the installer")
        self.assertEqual(state(), before, "a --help changed the tree")


if __name__ == "__main__":
    unittest.main()
