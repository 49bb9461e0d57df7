#!/usr/bin/env python3
"""Words that stand alone: no reference to the project's private tracker ("issue" and a number,
"issue #N", "issues N and M", "Issue N's", a bare "#N") where a user of a clone reads.

Scanned: (a) README.md and every file under docs/; (b) the CLI's own words: `omniloc --help`,
`omniloc list` and `omniloc CMD --help` for every command `omniloc --help` lists; (c) the report of
a short run (scenarios/quickstart.json, then `omniloc report ... --history none`): report.md and
report.html; (d) every git-tracked text file (`git ls-files`; without a git checkout, every file of
the tree), binary files and this file aside. A reference is replaced by what it refers to: the
capability in words, the doc section (docs/camera.md "The mirror centre") or the commit where a
figure was measured (short hash).

Run: `OMNILOC_BIN=build/omniloc /usr/bin/python3 tests/standalone_words_test.py`, or from tests/
`OMNILOC_BIN=../build/omniloc python3 -m unittest standalone_words_test` (ctest standalone_words_py).
Without a binary (OMNILOC_BIN unset and no build/omniloc) the CLI and report checks are skipped.
"""
import os
import re
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve()
ROOT = HERE.parents[1]
BIN = os.path.abspath(os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc")))

# The patterns are spelled in pieces so that this file does not contain what it looks for.
_WORD = "iss" + "ue"
_HASH = "#"
# Between the word and the number: blanks, at most one line break followed by a comment leader
# (a reference wrapped across two comment lines), then an optional hyphen, hash or colon and an
# optional hash before the digits. \b keeps "tissue 12 cm" out; a number must follow, so
# "issues.md" is not one.
_SEP = r"(?:[ \t]*\r?\n[ \t]*(?:/{2,3}|#|\*|>|--)?)?[ \t]*[-#:]?[ \t]*#?"
TRACKER = re.compile(r"\b" + _WORD + r"s?" + _SEP + r"\d+", re.IGNORECASE)
# An identifier in camel case that carries the number (a test named AsBefore, the capitalised word
# and a number).
CAMEL = re.compile(r"(?<=[a-z])I" + _WORD[1:] + r"s?\d+")
# A bare hash and number ("#" then "17"): after a blank or an opening bracket, one or two digits
# and no more word characters. (Three digits are as often a CSS colour, "#222", as a tracker
# number; "#include", "&#39;" and "color:#222" do not follow a blank.)
HASH_REF = re.compile(r"(?<![^\s(\[])#\d{1,2}(?![\w#])")
PATTERNS = (TRACKER, CAMEL, HASH_REF)
# Pictures inlined in HTML (base64) are no text a reader reads.
DATA_URI = re.compile(r"data:[\w/+.-]+;base64,[A-Za-z0-9+/=\s]*")


def find_references(text):
    """[(line number, matched text, the line)] for every tracker reference in text."""
    hits = []
    for pattern in PATTERNS:
        for m in pattern.finditer(text):
            line_no = text.count("\n", 0, m.start()) + 1
            start = text.rfind("\n", 0, m.start()) + 1
            end = text.find("\n", m.end())
            line = text[start:end if end >= 0 else len(text)]
            hits.append((line_no, " ".join(m.group(0).split()), line.strip()))
    return sorted(set(hits))


def read_text(path):
    """The file's text, or None for a binary file (a NUL byte, or not UTF-8)."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
    if b"\0" in data[:65536]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def scan_file(path, label=None):
    """['LABEL:LINE: "match" in: line'] for path."""
    text = read_text(path)
    if text is None:
        return []
    if path.suffix in (".html", ".htm"):
        text = DATA_URI.sub("", text)
    return describe(label or rel(path), text)


def describe(label, text):
    return [f"{label}:{n}: \"{m}\" in: {line[:160]}" for n, m, line in find_references(text)]


def rel(path):
    try:
        return str(Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def tracked_files():
    """The repository's files: git ls-files in a git checkout, else every file under ROOT (build
    trees, results and caches aside)."""
    try:
        r = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True, timeout=60)
        if r.returncode == 0 and r.stdout:
            return [ROOT / p for p in r.stdout.decode("utf-8", "surrogateescape").split("\0") if p], "git ls-files"
    except (OSError, subprocess.TimeoutExpired):
        pass
    skip_dirs = {".git", "__pycache__", ".cache", "results", "node_modules"}
    files = []
    for dirpath, dirnames, filenames in os.walk(ROOT):
        dirnames[:] = [d for d in dirnames if d not in skip_dirs and not d.startswith("build")]
        files.extend(Path(dirpath) / f for f in filenames)
    return files, "a walk of the source tree"


def report(failures, what):
    shown = failures[:300]
    more = f"\n... and {len(failures) - len(shown)} more" if len(failures) > len(shown) else ""
    return (f"{len(failures)} tracker reference(s) in {what}; say what is meant instead (the capability, "
            f"the doc section, or the commit of a measured figure):\n" + "\n".join(shown) + more)


def have_binary():
    return os.path.isfile(BIN) and os.access(BIN, os.X_OK)


def omniloc(args, cwd, timeout=120):
    r = subprocess.run([BIN] + args, cwd=cwd, capture_output=True, text=True, errors="replace", timeout=timeout)
    return r.returncode, r.stdout + r.stderr


def listed_commands(help_text):
    """The command names of `omniloc --help`: under "commands:", a line indented by two blanks that
    starts with a lower-case word begins a command's entry ("COMMAND --help" and "--version" are no
    commands), deeper-indented lines continue it. {name: the text of its entries}, each name once;
    the text tells the commands that forward to Python."""
    commands, current, in_commands = {}, None, False
    for line in help_text.splitlines():
        if line.strip().lower().startswith("commands"):
            in_commands = True
            continue
        if not in_commands or not line.strip():
            continue
        if not line.startswith(" "):
            in_commands, current = False, None  # a section after the command list
            continue
        m = re.match(r"^  ([a-z][a-z0-9-]*)(?=\s|$)", line)
        if m:
            current = m.group(1)
            commands.setdefault(current, "")
        elif re.match(r"^  \S", line):
            current = None
        if current:
            commands[current] += line + "\n"
    return commands


# What a command that forwards to Python prints when it cannot start (its script or package is not
# where the binary looks, or a module is missing).
NOT_STARTED = re.compile(r"No such file|not found|ModuleNotFoundError|ImportError|can't open file|No module named")


def forwards_to_python(entry):
    return bool(re.search(r"\bruns (scripts/|python)|\.py\b|python3? -m", entry))


class SelfTest(unittest.TestCase):
    """The scanner catches what it must and nothing else."""

    def test_a_reference_in_a_file_is_caught_and_lookalikes_are_not(self):
        lines = ["clean line",
                 "see " + _WORD + " 12",
                 "a t" + _WORD + " 12 cm thick",
                 "docs/" + _WORD + "s.md and " + _WORD + "s.md",
                 "color:#222; &#39; #include <x>"]
        with tempfile.TemporaryDirectory() as tmp:
            f = Path(tmp) / "sample.md"
            f.write_text("\n".join(lines) + "\n")
            hits = scan_file(f, "sample.md")
        self.assertEqual(len(hits), 1, hits)
        self.assertTrue(hits[0].startswith("sample.md:2: "), hits)

    def test_every_variant_is_caught(self):
        for text in (_WORD + " " + _HASH + "17", _WORD.capitalize() + " 5's", _WORD + "s 20 and 36", "(" + _WORD + " 29, item 4)",
                     "anchor-" + _WORD + "-29", "see " + _HASH + "17", "(" + _HASH + "17)", "the " + _WORD + "\n// 29 fix",
                     "AsBefore" + _WORD.capitalize() + "38", _WORD.upper() + " 3"):
            self.assertTrue(find_references(text), text)

    def test_lookalikes_are_not_caught(self):
        for text in ("t" + _WORD + " 12 cm", _WORD + "s.md", "an " + _WORD + " with the map", "#include <x>",
                     "color:#222", "color: #222;", "&#39;", "$#", "x#1", "#123456", "open " + _WORD + "s: none"):
            self.assertFalse(find_references(text), text)

    def test_commands_are_parsed_from_the_help(self):
        text = ("usage: omniloc <command> [options]\n\ncommands:\n"
                "  run FILE [--seed N]\n                         run a scenario\n"
                "  gl-devices             the EGL devices\n"
                "  sweep SWEEP.json [-j N]\n        [--localizer JSON|FILE]... [-o DIR]\n"
                "  sweep SWEEP.json --status\n"
                "  report RESULTS... -o DIR\n                         report.md; runs scripts/report.py\n"
                "  COMMAND --help         that command's options\n  --version              the build\n")
        commands = listed_commands(text)
        self.assertEqual(list(commands), ["run", "gl-devices", "sweep", "report"])
        self.assertTrue(forwards_to_python(commands["report"]))
        self.assertFalse(forwards_to_python(commands["run"]))


class Documentation(unittest.TestCase):
    def test_readme_and_docs(self):
        files = [ROOT / "README.md"] + sorted(p for p in (ROOT / "docs").rglob("*") if p.is_file())
        self.assertTrue(files[0].is_file(), "README.md missing")
        failures = [h for f in files for h in scan_file(f)]
        if failures:
            self.fail(report(failures, "README.md and docs/"))


class RepositoryFiles(unittest.TestCase):
    def test_every_tracked_text_file(self):
        files, how = tracked_files()
        failures, scanned = [], 0
        for f in files:
            if f.resolve() == HERE or not f.is_file() or f.is_symlink():
                continue
            scanned += 1
            failures.extend(scan_file(f))
        print(f"\nstandalone_words: {scanned} files from {how} scanned", file=sys.stderr)
        self.assertGreater(scanned, 50, how)
        if failures:
            self.fail(report(failures, f"the repository's files ({how})"))


@unittest.skipUnless(have_binary(), f"no omniloc binary at {BIN} (set OMNILOC_BIN)")
class CommandLine(unittest.TestCase):
    def test_help_list_and_every_commands_help(self):
        with tempfile.TemporaryDirectory() as tmp:
            rc, text = omniloc(["--help"], tmp)
            self.assertEqual(rc, 0, text)
            failures = describe("omniloc --help", text)
            rc, text = omniloc(["list"], tmp)
            self.assertEqual(rc, 0, text)
            failures += describe("omniloc list", text)
            commands = listed_commands(omniloc(["--help"], tmp)[1])
            self.assertIn("run", commands, "no commands parsed from omniloc --help")
            skipped = []
            for cmd, entry in commands.items():
                rc, text = omniloc([cmd, "--help"], tmp)
                if rc != 0 and forwards_to_python(entry) and (rc == 127 or NOT_STARTED.search(text)):
                    first = (text.strip().splitlines() or ["no output"])[-1][:160]
                    skipped.append(f"omniloc {cmd} --help (forwards to Python; exit {rc}: {first})")
                failures += describe(f"omniloc {cmd} --help", text)
            for s in skipped:
                print(f"\nSKIPPED, did not start: {s}", file=sys.stderr)
        if failures:
            self.fail(report(failures, "the CLI's output"))

    def test_report_of_a_short_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            run_dir, rep_dir = Path(tmp) / "run", Path(tmp) / "rep"
            rc, text = omniloc(["run", str(ROOT / "scenarios" / "quickstart.json"), "-o", str(run_dir), "--quiet"], tmp)
            self.assertEqual(rc, 0, text)
            failures = describe("omniloc run scenarios/quickstart.json", text)
            rc, text = omniloc(["report", str(run_dir), "-o", str(rep_dir), "--history", "none"], tmp, timeout=300)
            if rc != 0 and (rc == 127 or NOT_STARTED.search(text)):
                self.skipTest(f"omniloc report did not start here (exit {rc}): {text.strip()[-300:]}")
            self.assertEqual(rc, 0, text)
            failures += describe("omniloc report", text)
            for name in ("report.md", "report.html"):
                self.assertTrue((rep_dir / name).is_file(), name)
                failures += scan_file(rep_dir / name, f"report/{name}")
        if failures:
            self.fail(report(failures, "the report"))


if __name__ == "__main__":
    unittest.main(verbosity=2)
