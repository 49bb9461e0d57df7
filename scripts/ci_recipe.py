#!/usr/bin/env python3
"""Run the CI recipe of docs/ci.md as written: its GitHub Actions workflow and GitLab CI job, in a
throw-away team repository, with the omniloc found on PATH (or --omniloc).

usage: scripts/ci_recipe.py [--system github|gitlab|both] [--pr same|degraded] [--docs FILE]
                            [--omniloc BIN] [--workdir DIR] [--print]

What it does, so that every command of the recipe is run by a test (tests/ci_recipe_test.py) and
by the clean-root stage of .ci/run (scripts/clean_root_check.sh) against the installed package:
  1. reads docs/ci.md (default: beside this script's tree, else /usr/share/doc/omniloc/ci.md): the
     team's files (ci/localizer.json, ci/rules.json) and the two YAML blocks;
  2. makes a bare `origin` whose `main` holds the team's files, and a pull-request branch that
     changes nothing (--pr same) or degrades the localizer (--pr degraded: the particle filter's
     sigma_hit 0.01 m, far below the line points' ~5 cm scatter, so its weights collapse onto a
     few particles and its heading error doubles);
  3. clones it as the CI system would (full history) and runs, in order, every `run:` step of the
     workflow (bash -e per step; `if: always()` steps also after a failure) or the job's
     before_script / script (one shell, stops at the first failure) and after_script (always);
  4. checks the outcome: every command but the gate exits 0, the gate exits 0 (same) or 1
     (degraded), and results/junit.xml, results/benchmark.json and results/report/report.html exist.
Lines that install software (apt-get, curl of the .deb) are not run: they need the network and
root; the clean-root stage installs the local .deb the same way. /usr/share/omniloc in the recipe is
replaced by the folder the omniloc under test takes its shipped files from (`omniloc list`).
--print shows the commands and what is skipped, and runs nothing. Exit 0 when the outcome is as
expected, 1 when not, 2 on bad arguments or a recipe that cannot be read.
"""
import argparse
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
INSTALLED_SHARE = "/usr/share/omniloc"
FILES = ("ci/localizer.json", "ci/rules.json", ".github/workflows/localization.yml", ".gitlab-ci.yml")
SKIP = re.compile(r"^\s*(apt-get|curl)\b")
SKIP_WHY = "installs software (network, root): the clean-root stage installs the local .deb instead"


def default_docs():
    for p in (HERE.parent / "docs" / "ci.md", pathlib.Path("/usr/share/doc/omniloc/ci.md")):
        if p.is_file():
            return p
    return HERE.parent / "docs" / "ci.md"


def file_blocks(text):
    """{name: content} of every block written as a line 'NAME:' followed by a fenced code block."""
    out = {}
    for m in re.finditer(r"^(\S+):\n```[a-z]*\n(.*?)^```", text, re.M | re.S):
        out[m.group(1)] = m.group(2)
    return out


def github_steps(yml):
    """[(step name, [command lines], always, shell)] of the workflow's run steps; uses: steps listed apart."""
    import yaml
    doc = yaml.safe_load(yml)
    (job,) = doc["jobs"].values()
    steps, uses = [], []
    for s in job["steps"]:
        if "uses" in s:
            uses.append(s["uses"])
            continue
        always = str(s.get("if", "")).strip() == "always()"
        steps.append((s.get("name", "run"), [ln for ln in s["run"].splitlines() if ln.strip()], always, s.get("shell", "sh")))
    return steps, uses


def gitlab_steps(yml):
    import yaml
    doc = yaml.safe_load(yml)
    (job,) = [v for k, v in doc.items() if isinstance(v, dict) and "script" in v]
    return [("before_script", job.get("before_script", []), False, "bash"), ("script", job["script"], False, "bash"),
            ("after_script", job.get("after_script", []), True, "bash")]


def git(args, cwd, env):
    subprocess.run(["git", "-c", "user.name=ci", "-c", "user.email=ci@example.org", "-c", "init.defaultBranch=main"] + args,
                   cwd=cwd, env=env, check=True, capture_output=True, text=True)


def make_origin(work, files, share, pr, env):
    """A bare origin with main (the team's files) and a branch pr; returns its path."""
    seed = work / "seed"
    seed.mkdir()
    git(["init", "-q"], seed, env)
    for name in ("ci/localizer.json", "ci/rules.json"):
        (seed / name).parent.mkdir(parents=True, exist_ok=True)
        (seed / name).write_text(files[name].replace(INSTALLED_SHARE, share))
    git(["add", "-A"], seed, env)
    git(["commit", "-q", "-m", "team localizer and rules"], seed, env)
    git(["checkout", "-q", "-b", "pr"], seed, env)
    if pr == "degraded":
        loc = json.loads((seed / "ci/localizer.json").read_text())
        loc.setdefault("params", {})["sigma_hit"] = 0.01
        (seed / "ci/localizer.json").write_text(json.dumps(loc, indent=1) + "\n")
        git(["commit", "-q", "-am", "a narrower sensor model"], seed, env)
    else:
        git(["commit", "-q", "--allow-empty", "-m", "a change elsewhere"], seed, env)
    origin = work / "origin.git"
    git(["clone", "-q", "--bare", str(seed), str(origin)], work, env)
    return origin


def run_system(system, steps, origin, work, share, env, log):
    """Runs one CI system's steps in a fresh clone; returns [(command, exit code)] of the commands run."""
    base = work / system
    base.mkdir()
    repo = base / "repo"
    git(["clone", "-q", str(origin), str(repo)], base, env)
    git(["checkout", "-q", "pr"], repo, env)
    ran, failed = [], False
    for name, lines, always, shell in steps:
        if failed and not always:
            print(f"[{system}] step {name}: not run (an earlier step failed, as the CI system would)", file=log)
            continue
        cmds = []
        for ln in lines:
            if SKIP.match(ln):
                print(f"[{system}] skip: {ln.strip()}  ({SKIP_WHY})", file=log)
                continue
            cmds.append(ln.replace(INSTALLED_SHARE, share))
        for c in cmds:
            t0 = time.monotonic()
            p = subprocess.run(["bash", "-c", c], cwd=repo, env=env, capture_output=True, text=True)
            print(f"[{system}] $ {c}\n[{system}]   exit {p.returncode}, {time.monotonic() - t0:.1f} s", file=log)
            tail = (p.stdout + p.stderr).strip().splitlines()[-12:]
            for t in tail:
                print(f"[{system}]   | {t}", file=log)
            ran.append((c, p.returncode))
            if p.returncode != 0:
                failed = True
                break  # bash -e / GitLab: the step stops at its first failing command
    return ran, repo


def check(system, ran, repo, pr, log):
    ok = True
    gate = [(c, rc) for c, rc in ran if c.lstrip().startswith("omniloc gate")]
    want = 0 if pr == "same" else 1
    if len(gate) != 1 or gate[0][1] != want:
        print(f"[{system}] FAILED: the gate should have run once and exited {want}: {gate}", file=log)
        ok = False
    for c, rc in ran:
        if not c.lstrip().startswith("omniloc gate") and rc != 0:
            print(f"[{system}] FAILED: exit {rc}: {c}", file=log)
            ok = False
    for f in ("results/junit.xml", "results/benchmark.json", "results/report/report.html"):
        if not (repo / f).is_file():
            print(f"[{system}] FAILED: the artefact {f} is missing", file=log)
            ok = False
    return ok


def main(argv=None):
    ap = argparse.ArgumentParser(prog="scripts/ci_recipe.py", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--system", choices=("github", "gitlab", "both"), default="both")
    ap.add_argument("--pr", choices=("same", "degraded"), default="same")
    ap.add_argument("--docs", default=None, help="the recipe (default: docs/ci.md of this tree, else the installed one)")
    ap.add_argument("--omniloc", default=None, help="the omniloc binary (default: the one on PATH)")
    ap.add_argument("--workdir", default=None, help="where the team repository is made (default: a temporary folder, removed)")
    ap.add_argument("--print", action="store_true", help="show the commands and exit")
    try:
        a = ap.parse_args(argv)
    except SystemExit as e:
        return 0 if e.code == 0 else 2
    docs = pathlib.Path(a.docs) if a.docs else default_docs()
    try:
        files = file_blocks(docs.read_text())
        missing = [f for f in FILES if f not in files]
        if missing:
            raise ValueError(f"no block for {', '.join(missing)}")
        systems = {"github": github_steps(files[".github/workflows/localization.yml"])[0], "gitlab": gitlab_steps(files[".gitlab-ci.yml"])}
    except (OSError, ValueError, KeyError) as e:
        print(f"ci_recipe: {docs}: cannot read the recipe: {e}", file=sys.stderr)
        return 2
    chosen = ["github", "gitlab"] if a.system == "both" else [a.system]
    if a.print:
        for s in chosen:
            for name, lines, always, _ in systems[s]:
                for ln in lines:
                    print(f"{s:6} {name:14} {'skip' if SKIP.match(ln) else 'run '} {ln}")
        return 0
    omniloc = pathlib.Path(a.omniloc).resolve() if a.omniloc else (pathlib.Path(shutil.which("omniloc") or ""))
    if not omniloc.is_file():
        print("ci_recipe: no omniloc binary (give --omniloc or put it on PATH)", file=sys.stderr)
        return 2
    lst = subprocess.run([str(omniloc), "list"], capture_output=True, text=True)
    share = next((ln.split(":", 1)[1].strip() for ln in lst.stdout.splitlines() if ln.startswith("shared files:")), INSTALLED_SHARE)
    work = pathlib.Path(a.workdir or tempfile.mkdtemp(prefix="ci_recipe_")).resolve()
    work.mkdir(parents=True, exist_ok=True)
    # The PATH of a debian:12 container (python3 is Debian's, with the packages apt installed),
    # behind the omniloc under test.
    env = dict(os.environ, HOME=str(work / "home"), PATH=f"{omniloc.parent}:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin",
               GIT_CONFIG_NOSYSTEM="1")
    (work / "home").mkdir(exist_ok=True)
    print(f"ci_recipe: {docs}, omniloc {omniloc} (shared files {share}), pull request: {a.pr}, in {work}")
    ok = True
    try:
        origin = make_origin(work, files, share, a.pr, env)
        for s in chosen:
            t0 = time.monotonic()
            ran, repo = run_system(s, systems[s], origin, work, share, env, sys.stdout)
            good = check(s, ran, repo, a.pr, sys.stdout)
            print(f"[{s}] {'as expected' if good else 'NOT as expected'}: {len(ran)} commands in {time.monotonic() - t0:.1f} s")
            ok = ok and good
    finally:
        if not a.workdir:
            shutil.rmtree(work, ignore_errors=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
