"""Every command of docs/ci.md's CI recipe runs here: scripts/ci_recipe.py takes the
GitHub Actions workflow and the GitLab CI job from the page and runs their commands in a throw-away
team repository with the built omniloc (only the install lines are not run: network and root; the
clean-root stage of .ci/run installs the .deb instead). GitHub's steps run on a pull request that
degrades the localizer (the gate must exit 1 and the report still be written), GitLab's on one that
changes nothing (the gate must exit 0).
Run with OMNILOC_BIN=build/omniloc /usr/bin/python3 -m unittest ci_recipe_test (ctest ci_recipe_py).
"""
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parents[1]
BIN = os.path.abspath(os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc")))
RECIPE = [sys.executable, str(ROOT / "scripts" / "ci_recipe.py"), "--omniloc", BIN]


class CiRecipe(unittest.TestCase):
    def run_recipe(self, system, pr):
        with tempfile.TemporaryDirectory(prefix="ci_recipe_test_") as work:
            p = subprocess.run(RECIPE + ["--system", system, "--pr", pr, "--workdir", work], capture_output=True, text=True, timeout=600)
            self.assertEqual(p.returncode, 0, p.stdout[-6000:] + p.stderr)
            repo = pathlib.Path(work) / system / "repo"
            root = ET.parse(repo / "results" / "junit.xml").getroot()
            return p.stdout, root

    def test_github_workflow_on_a_degraded_pull_request(self):
        out, junit = self.run_recipe("github", "degraded")
        self.assertIn("[github] as expected", out)
        self.assertIn("omniloc gate results/candidate", out)
        self.assertGreater(int(junit.get("failures")), 0)
        self.assertTrue(any("regression" in f.get("message") for f in junit.iter("failure")))
        # Every run: line of the workflow either ran or is an install line, said so.
        printed = subprocess.run(RECIPE + ["--system", "github", "--print"], capture_output=True, text=True).stdout.splitlines()
        for ln in printed:
            cmd = ln.split(None, 1)[1].split(" run  ", 1)[-1] if " run  " in ln else None
            if cmd is None:
                self.assertRegex(ln, r"skip (apt-get|curl) ")
            else:
                self.assertIn(f"$ {cmd.strip()}", out)

    def test_gitlab_job_on_an_unchanged_pull_request(self):
        out, junit = self.run_recipe("gitlab", "same")
        self.assertIn("[gitlab] as expected", out)
        self.assertEqual(junit.get("failures"), "0")
        self.assertEqual(int(junit.get("tests")), 8)  # 4 rules x 2 scenarios of ci/rules.json

    def test_recipe_unreadable_is_exit_2(self):
        with tempfile.NamedTemporaryFile("w", suffix=".md") as f:
            f.write("# no recipe here\n")
            f.flush()
            p = subprocess.run(RECIPE + ["--docs", f.name, "--print"], capture_output=True, text=True)
            self.assertEqual(p.returncode, 2)
            self.assertIn("cannot read the recipe", p.stderr)


if __name__ == "__main__":
    unittest.main()
