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
  - the scorecard is the first section (the first <h2> after the title);
  - no negative bound of an interval of a non-negative quantity (an error, a count) in the report,
    nor in an aggregate.csv beside it (negative_bounds(); `--aggregate CSV` checks a sweep's alone);
  - a headline (id "headline") is the first thing after the title;
  - reader's language: no tracker numbers (the word "issue" and a number) and no raw identifiers with underscores
    (JSON keys, claim ids, metric names) in the text a reader reads; <code>, <pre> and an
    experiment's own notes (class "quoted") are quoted material and exempt, and so are file names,
    paths and the names a reader types (scenarios, sweeps, experiments, localizers, noise profiles,
    fields: read from the repository) and the abbreviations E_k, N_th, N_eff;
  - no section heading (an <h2> or <h3> of the report's own) twice;
  - a bibliography ("References", the last section) lists the papers, each with a year, and every
    citation [n] in the text names one of its entries;
  - links (check_links()): the page is self-contained except for its relative links (no href to an
    absolute path or file: URL); every link into viewers/ (the runs' viewer pages, in report.html
    and in report.md beside it) resolves to a file inside viewers/ that exists and is a viewer page
    (its data element), with no absolute path in it.
--self-test builds a report of a small synthetic sweep (the fixtures of python/tests/helpers.py, with
an outlying seed, and a run the viewer can draw, whose link it then requires) with
`python3 -m omniloc.commands.report` in a temporary folder and checks that one; ctest runs it
(report_html). Exit 0: all pass; 1: a check failed; 77: Chromium is missing (the check skips with a
message; scripts/install-deps.sh --report-check installs Debian's chromium).
"""
import argparse
import html
import html.parser
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
# A developer's tool, run from a checkout: its self-test writes synthetic results with the fixtures of
# the results package's tests (python/tests/helpers.py) and reports them with the package (python/).
sys.path[:0] = [str(ROOT / "python"), str(ROOT / "python" / "tests")]
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


# An error, a count or a fraction cannot be negative, so neither can a bound of its interval
# (omniloc.core.stats.interval clips the t interval at 0; the seeds' range of non-negative values is too).
# The report prints intervals of such quantities only; aggregate.csv also holds signed ones, told by name.
REPORT_INTERVAL = re.compile(r"(-?\d+(?:\.\d+)?) (?:\[(-?\d+(?:\.\d+)?), -?\d+(?:\.\d+)?\]|\(seeds' range (-?\d+(?:\.\d+)?) to )")
NON_NEGATIVE_METRIC = re.compile(r"(^|/)(x_cm|y_cm|theta_rad|position_m|line_points|recovery|after_recovery|recall)(/|$)|"
                                 r"(^|/)(frames|valid_fraction|coasting_frames|relocalisations|wrong_frames|mirrored_frames|excluded_s)$")


def negative_bounds(text, aggregate_csv=None):
    """The intervals with a negative lower bound for a non-negative quantity: in the report's text
    ("m [lo, hi]" and "m (seeds' range lo to hi"), and in an aggregate.csv's rows of non-negative
    metrics (by name: errors, counts, fractions). [] when there are none."""
    import csv
    bad = [m.group(0) for m in REPORT_INTERVAL.finditer(text) if float(m.group(2) or m.group(3)) < 0]
    if aggregate_csv is not None:
        with pathlib.Path(aggregate_csv).open(newline="") as fh:
            for row in csv.DictReader(fh):
                try:
                    low = float(row.get("ci95_low") or "nan")
                except ValueError:
                    continue
                if low < 0 and NON_NEGATIVE_METRIC.search(row.get("metric", "")):
                    bad.append(f"aggregate.csv {row.get('scenario')} / {row.get('localizer')} / {row['metric']}: {row.get('mean')} [{low}, {row.get('ci95_high')}]")
    return bad


class ReaderText(html.parser.HTMLParser):
    """The text a reader reads as prose: what visible_text keeps, less <code>, <pre>, <style>,
    <script> and elements of class "quoted" (an experiment's own output, quoted as written)."""
    EXEMPT = {"code", "pre", "style", "script"}
    VOID = {"img", "br", "hr", "meta", "link", "input", "source", "wbr"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.parts, self.stack = [], []  # (tag, exempt) of the open elements

    def handle_starttag(self, tag, attrs):
        if tag in self.VOID:
            return
        cls = dict(attrs).get("class") or ""
        exempt = tag in self.EXEMPT or "quoted" in cls.split() or bool(self.stack and self.stack[-1][1])
        self.stack.append((tag, exempt))

    def handle_endtag(self, tag):
        for k in range(len(self.stack) - 1, -1, -1):  # tolerant of unclosed tags
            if self.stack[k][0] == tag:
                del self.stack[k:]
                break

    def handle_data(self, data):
        if not (self.stack and self.stack[-1][1]):
            self.parts.append(data)


def reader_text(dom):
    p = ReaderText()
    p.feed(re.sub(r"data:image/[a-z]+;base64,[A-Za-z0-9+/=]+", "", dom))
    return " ".join(p.parts)


ISSUE = re.compile(r"\b[Ii]ssues? #?\d+\b")
# An identifier with underscores that is not part of a path or a file name (docs/error_budget.md,
# paper_suite.json, frames.csv stay: a reader opens them).
SNAKE = re.compile(r"(?<![\w/.#=-])([A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+)(?![\w/-]|\.[A-Za-z])")
ABBREVIATIONS_WITH_UNDERSCORE = {"E_k", "N_th", "N_eff"}


def reader_names():
    """Names a reader types or picks (scenario, sweep, experiment, localizer, noise profile and
    field names), read from the repository: allowed in the text."""
    import json
    names = set(ABBREVIATIONS_WITH_UNDERSCORE) | {"field_robot", "x86_64"}  # x86_64: the machine's architecture
    for pattern in ("scenarios/**/*.json", "experiments/*.hpp", "localization/*.hpp", "data/fields/*.json"):
        names |= {p.stem for p in ROOT.glob(pattern)}

    def values(j):  # the string values a user writes in a scenario or experiment file (presets: "nubot_tan")
        if isinstance(j, dict):
            for v in j.values():
                yield from values(v)
        elif isinstance(j, list):
            for v in j:
                yield from values(v)
        elif isinstance(j, str) and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", j):
            yield j
    for p in ROOT.glob("scenarios/**/*.json"):
        try:
            names |= set(values(json.loads(p.read_text())))
        except (OSError, ValueError):
            pass
    for p in ROOT.glob("data/**/recording.json"):  # stored recordings' names (nubot_robot1): a sweep's scenario names
        try:
            name = json.loads(p.read_text()).get("name")
            if isinstance(name, str):
                names.add(name)
        except (OSError, ValueError, AttributeError):
            pass
    try:
        names |= {p["name"] for p in json.loads((ROOT / "data" / "noise_profiles.json").read_text()).get("profiles", [])}
    except (OSError, ValueError, AttributeError, KeyError, TypeError):
        pass
    return names


def check_no_issue_numbers(dom):
    """(ok, detail): no tracker reference (the word and a number) in the text a reader reads (the tracker is the developers')."""
    text = reader_text(dom)
    hits = sorted({m.group(0) for m in ISSUE.finditer(text)})
    where = [text[max(0, text.find(h) - 40):text.find(h) + 40].replace("\n", " ") for h in hits[:1]]
    return not hits, "none" if not hits else f"{', '.join(hits)} e.g. ...{where[0]}..."


def check_no_raw_keys(dom, allowed=None):
    """(ok, detail): no identifier with underscores (a JSON key, claim id or metric name) in the
    text a reader reads, outside code and quoted output, other than reader_names()."""
    allowed = reader_names() if allowed is None else allowed
    text = reader_text(dom)
    hits = {}
    for m in SNAKE.finditer(text):
        if m.group(1) not in allowed:
            hits.setdefault(m.group(1), text[max(0, m.start() - 40):m.end() + 40].replace("\n", " "))
    return not hits, "none" if not hits else f"{len(hits)}: {', '.join(sorted(hits)[:8])}; e.g. ...{next(iter(hits.values()))}..."


def check_headline(dom):
    """(ok, detail): the element right after the title is the headline (id "headline"), with text."""
    m = re.search(r"</h1>\s*<([a-z0-9]+)\b([^>]*)>(.*?)</\1>", dom, re.S)
    ok = bool(m) and re.search(r"\bid=[\"']headline[\"']", m.group(2)) is not None
    text = html.unescape(re.sub(r"<[^>]+>", "", m.group(3))).strip() if ok else ""
    return ok and len(text) >= 60, (f"{len(text)} characters: {text[:90]}..." if ok else "no element with id \"headline\" right after the title")


def check_unique_headings(dom):
    """(ok, detail): no section heading of the report (<h2>/<h3> with an id) twice."""
    seen, twice = set(), []
    for m in re.finditer(r"<h([23])\b[^>]*\bid=[\"'][^\"']*[\"'][^>]*>(.*?)</h\1>", dom, re.S):
        t = " ".join(html.unescape(re.sub(r"<[^>]+>", "", m.group(2))).split())
        (twice.append(t) if t in seen else seen.add(t))
    return not twice, "every heading once" if not twice else "twice: " + "; ".join(sorted(set(twice))[:5])


def check_bibliography(dom):
    """(ok, detail): a "References" section last, listing entries with a year, and every citation
    'Author 2013 [n]' of the text naming one of them."""
    h2 = re.findall(r"<h2\b[^>]*\bid=[\"']([^\"']*)[\"']", dom)
    m = re.search(r"<ol\b[^>]*\bid=[\"']bibliography[\"'][^>]*>(.*?)</ol>", dom, re.S)
    if not h2 or h2[-1] != "references" or not m:
        return False, "no bibliography (ol id=bibliography)" if not m else f"References is not the last section (last: {h2[-1] if h2 else 'none'})"
    entries = re.findall(r"<li\b[^>]*>(.*?)</li>", m.group(1), re.S)
    no_year = [k + 1 for k, e in enumerate(entries) if not re.search(r"\b(19|20)\d\d\b", e)]
    cited = {int(n) for n in re.findall(r"(?<=\d{4} \[)(\d+)(?=\])", reader_text(dom))}
    dangling = sorted(n for n in cited if not 1 <= n <= len(entries))
    ok = len(entries) >= 5 and not no_year and not dangling
    return ok, (f"{len(entries)} entries, citations {sorted(cited) or 'none'}" + (f"; without a year: {no_year}" if no_year else "")
                + (f"; citations without an entry: {dangling}" if dangling else ""))


HREF = re.compile(r"""\bhref=(?:"([^"]*)"|'([^']*)')""")
MD_LINK = re.compile(r"\]\((viewers/[^)\s]*)\)")
VIEWER_MARK = 'id="omniloc-data"'  # the viewer page's data element (omniloc/view/viewer.html)


def check_links(page, require_viewer=False):
    """(ok, detail): every href of report.html relative (no absolute path, no file: URL), and every link
    into viewers/ (report.html's and report.md's) a viewer page that exists inside viewers/, with no
    absolute path in it. require_viewer: at least one such link (the self-test's report has one)."""
    source = page.read_text()
    hrefs = [html.unescape(a or b) for a, b in HREF.findall(source)]
    md = page.with_suffix(".md")
    md_links = MD_LINK.findall(md.read_text()) if md.exists() else []
    bad = [h for h in hrefs if h.startswith(("/", "file:", "\\")) or re.match(r"^[A-Za-z]:[\\/]", h)]
    folder = (page.parent / "viewers").resolve()
    viewer_links = sorted({h.split("#", 1)[0].split("?", 1)[0] for h in hrefs + md_links if h.startswith("viewers/")})
    broken, not_viewer, absolute = [], [], []
    for link in viewer_links:
        target = (page.parent / link).resolve()
        if not target.is_relative_to(folder) or not target.is_file():
            broken.append(link)
            continue
        text = target.read_text(errors="replace")
        if VIEWER_MARK not in text:
            not_viewer.append(link)
        elif ABSOLUTE.search(text) or str(ROOT) in text:
            absolute.append(link)
    in_html = {h for h in hrefs if h.startswith("viewers/")}
    missing_in_md = sorted(h for h in in_html if h not in set(md_links)) if md.exists() else []
    ok = not (bad or broken or not_viewer or absolute or missing_in_md) and (viewer_links or not require_viewer)
    detail = f"{len(hrefs)} links, {len(viewer_links)} viewer pages, each found" if ok else "; ".join(filter(None, (
        f"absolute: {', '.join(bad[:3])}" if bad else "",
        f"no such file in viewers/: {', '.join(broken[:3])}" if broken else "",
        f"not a viewer page: {', '.join(not_viewer[:3])}" if not_viewer else "",
        f"an absolute path inside: {', '.join(absolute[:3])}" if absolute else "",
        f"linked from report.html, not report.md: {', '.join(missing_in_md[:3])}" if missing_in_md else "",
        "no link to a viewer page (the self-test's report has a run the viewer draws)" if require_viewer and not viewer_links else "")))
    return ok, detail


def check(page, max_mb, browser, require_viewer=False):
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
    neg = negative_bounds(text, next((p for p in (page.parent / "aggregate.csv",) if p.exists()), None))
    results.append(("no negative bound", not neg, "no interval of a non-negative quantity below 0" if not neg else "; ".join(neg[:3])))
    results.append(("headline", *check_headline(dom)))
    results.append(("no issue numbers", *check_no_issue_numbers(dom)))
    results.append(("no raw keys", *check_no_raw_keys(dom)))
    results.append(("headings once", *check_unique_headings(dom)))
    results.append(("bibliography", *check_bibliography(dom)))
    results.append(("links", *check_links(page, require_viewer)))
    return results


def self_test_report(tmp):
    """A report of a synthetic occlusion sweep with one outlying seed, made by omniloc.commands.report."""
    import helpers as T
    T.write_occlusion_sweep(tmp / "results" / "sweep", [0.0, 0.5])
    T.write_run(tmp / "results" / "mcl" / "s1", "tracking", "mcl", 1, {}, T.robot(3.0))
    T.write_run(tmp / "results" / "mcl" / "s2", "tracking", "mcl", 2, {}, T.robot(806.0))
    T.write_run(tmp / "results" / "mcl" / "s3", "tracking", "mcl", 3, {}, T.robot(3.1))
    T.write_viewable_run(tmp / "results" / "quickstart")  # its viewer page: the links check requires one
    out = subprocess.run([sys.executable, "-m", "omniloc.commands.report", str(tmp / "results"), "-o", str(tmp / "report"),
                          "--history", "none"], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, (str(ROOT / "python"), os.environ.get("PYTHONPATH"))))})
    if out.returncode != 0:
        raise RuntimeError("omniloc.commands.report failed: " + out.stderr[-2000:])
    return tmp / "report" / "report.html"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("report", nargs="?", default="results/report/report.html")
    ap.add_argument("--max-mb", type=float, default=3.0)
    ap.add_argument("--self-test", action="store_true", help="check a report made here from synthetic results")
    ap.add_argument("--aggregate", metavar="CSV", help="check only an aggregate.csv for negative bounds of non-negative metrics (no browser)")
    a = ap.parse_args()
    if a.aggregate:
        neg = negative_bounds("", a.aggregate)
        print(f"check_report_html: {'ok  ' if not neg else 'FAIL'} no negative bound: " + ("; ".join(neg[:5]) if neg else a.aggregate))
        return 1 if neg else 0
    browser = find_chromium()
    if browser is None:
        print("check_report_html: SKIPPED: no Chromium here (Debian: scripts/install-deps.sh --report-check installs it)")
        return SKIP
    with tempfile.TemporaryDirectory() as tmp:
        try:
            page = self_test_report(pathlib.Path(tmp)) if a.self_test else pathlib.Path(a.report)
            if not page.exists():
                print(f"check_report_html: no {page} (run scripts/run.sh or omniloc report first)", file=sys.stderr)
                return 2
            results = check(page, a.max_mb, browser, require_viewer=a.self_test)
        except (RuntimeError, subprocess.TimeoutExpired) as e:
            print(f"check_report_html: FAILED: {e}", file=sys.stderr)
            return 1
    for name, ok, detail in results:
        print(f"check_report_html: {'ok  ' if ok else 'FAIL'} {name}: {detail}")
    return 0 if all(ok for _, ok, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main())
