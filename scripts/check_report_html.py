#!/usr/bin/env python3
"""Reads a report.html as a reader would: opens it in headless Chromium and checks what the browser
rendered (its DOM after loading), not only the file.

usage: check_report_html.py [REPORT.html] [--max-mb 3] [--self-test]

Checks, each printed with its result:
  - the page renders: Chromium loads it, and the rendered DOM has the title, the scorecard and
    every embedded picture of the file;
  - the file is under --max-mb megabytes (default 3: the report embeds its pictures);
  - no raw markdown in the rendered text (**, backticks, "](" of a link): markdown is rendered;
  - no absolute paths (/home/..., /work/..., /tmp/..., the repository's own folder) in the text;
  - the scorecard is the first section (the first <h2> after the title).
--self-test builds a report of a small synthetic sweep (the fixtures of tests/report_test.py, with
an outlying seed) with scripts/report.py in a temporary folder and checks that one; ctest runs it
(report_html). Exit 0: all pass; 1: a check failed; 77: Chromium is missing (the check skips with a
message; scripts/install-deps.sh --report-check installs Debian's chromium).
"""
import argparse
import html
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SKIP = 77
# Folders a path on this machine or a CI runner starts with; the report must show none of them.
ABSOLUTE = re.compile(r"(?<![\w.~-])/(home|work|tmp|root|usr|var|mnt|opt|srv|scratch|builds|Users)/[\w.-]+")


def find_chromium():
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        p = shutil.which(name)
        if p:
            return p
    return None


def rendered_dom(browser, page):
    """The DOM Chromium built from the page (scripts off: the report has none)."""
    with tempfile.TemporaryDirectory() as profile:
        out = subprocess.run([browser, "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                              f"--user-data-dir={profile}", "--virtual-time-budget=5000", "--dump-dom", page.resolve().as_uri()],
                             capture_output=True, text=True, timeout=180)
    if out.returncode != 0 or "<body" not in out.stdout:
        raise RuntimeError(f"chromium did not render {page.name} (exit {out.returncode}): {out.stderr.strip()[-500:]}")
    return out.stdout


def visible_text(dom):
    """The text a reader sees: tags, styles and embedded picture data removed, entities decoded."""
    dom = re.sub(r"<style.*?</style>", " ", dom, flags=re.S)
    dom = re.sub(r"data:image/[a-z]+;base64,[A-Za-z0-9+/=]+", "", dom)
    return html.unescape(re.sub(r"<[^>]+>", " ", dom))


def check(page, max_mb, browser):
    """[(name, ok, detail)] for one report."""
    results = []
    size = page.stat().st_size
    results.append(("size", size <= max_mb * 1e6, f"{size / 1e6:.2f} MB (limit {max_mb} MB)"))
    source = page.read_text()
    dom = rendered_dom(browser, page)
    pictures = len(re.findall(r"<img [^>]*src=\"data:image/(?:png|jpeg);base64,", source))
    rendered = len(re.findall(r"<img [^>]*src=\"data:image/(?:png|jpeg);base64,", dom))
    results.append(("renders", "id=\"scorecard\"" in dom and rendered == pictures,
                    f"rendered DOM has the scorecard and {rendered} of the file's {pictures} pictures"))
    text = visible_text(dom)
    raw = [m for m in ("**", "`", "](") if m in text]
    where = [text[max(0, text.find(m) - 40):text.find(m) + 40].replace("\n", " ") for m in raw]
    results.append(("markdown rendered", not raw, "no raw markdown" if not raw else f"raw {raw} e.g. ...{where[0]}..."))
    paths = sorted({m.group(0) for m in ABSOLUTE.finditer(text)} | ({str(ROOT)} if str(ROOT) in text else set()))
    results.append(("no absolute paths", not paths, "none" if not paths else ", ".join(paths[:5])))
    first = re.search(r"<h2\b[^>]*>", dom)
    first_id = re.search(r"id=\"([^\"]*)\"", first.group(0)).group(1) if first and "id=" in first.group(0) else None
    results.append(("scorecard first", first_id == "scorecard", f"first section: {first_id or 'none'}"))
    return results


def self_test_report(tmp):
    """A report of a synthetic occlusion sweep with one outlying seed, made by scripts/report.py."""
    sys.path.insert(0, str(ROOT / "tests"))
    import report_test as T
    T.write_occlusion_sweep(tmp / "results" / "sweep", [0.0, 0.5])
    T.write_run(tmp / "results" / "mcl" / "s1", "tracking", "mcl", 1, {}, T.robot(3.0))
    T.write_run(tmp / "results" / "mcl" / "s2", "tracking", "mcl", 2, {}, T.robot(806.0))
    T.write_run(tmp / "results" / "mcl" / "s3", "tracking", "mcl", 3, {}, T.robot(3.1))
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "report.py"), str(tmp / "results"), "-o", str(tmp / "report"),
                          "--history", "none"], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError("report.py failed: " + out.stderr[-2000:])
    return tmp / "report" / "report.html"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("report", nargs="?", default="results/report/report.html")
    ap.add_argument("--max-mb", type=float, default=3.0)
    ap.add_argument("--self-test", action="store_true", help="check a report made here from synthetic results")
    a = ap.parse_args()
    browser = find_chromium()
    if browser is None:
        print("check_report_html: SKIPPED: no Chromium here (Debian: scripts/install-deps.sh --report-check installs it)")
        return SKIP
    with tempfile.TemporaryDirectory() as tmp:
        try:
            page = self_test_report(pathlib.Path(tmp)) if a.self_test else pathlib.Path(a.report)
            if not page.exists():
                print(f"check_report_html: no {page} (run scripts/run.sh or scripts/report.py first)", file=sys.stderr)
                return 2
            results = check(page, a.max_mb, browser)
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            print(f"check_report_html: FAILED: {e}", file=sys.stderr)
            return 1
    for name, ok, detail in results:
        print(f"check_report_html: {'ok  ' if ok else 'FAIL'} {name}: {detail}")
    return 0 if all(ok for _, ok, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main())
