"""Each run the report shows on its own links to its viewer page (omniloc.view, docs/viewer.md):
DIR/viewers/<name>.html, written with the viewer's Python API (load_run, render) and its defaults,
without camera images; particles only where the run has view.jsonl (the viewer draws them from
there alone). <name> is the run folder's path from the results folder given to the report, that
folder's own name first, made file-safe ("paper_suite--runs--tracking__mcl__default__s1"): the same
results give the same names.

A report that shows more than LIMIT runs links only the runs it shows on their own (plotted, an
outlying seed, a real-robot run), at most LIMIT pages, and says how to make the others (`omniloc
view RUN_DIR`). A run whose page cannot be made (a missing or malformed file) gets no link and one
line saying why; the report goes on.

The links are written where the report lists or plots a run: in tables through a token that
ViewerReport.write replaces by the link (a markdown link in report.md, <a> in report.html), after a
run's heading or figure as a line of its own.
"""
from __future__ import annotations

import hashlib
import html
import os
import pathlib
import re
import tempfile
from typing import Optional, Sequence, Union

from omniloc.core.files import InputFileError
from omniloc.core.rundir import Run
from omniloc.tools.markup import Report, Writer
from omniloc.view.load import load_run
from omniloc.view.page import render

# At most this many pages; a report showing more runs than this links only the runs shown on their own.
LIMIT = 200
FOLDER = "viewers"
# Stands for a link in a cell or line until ViewerReport.write: survives escaping, path cleaning,
# citations and abbreviations (no slash, no letters those touch).
TOKEN = "\u27e6viewer {}\u27e7"
TOKEN_RE = re.compile("\u27e6viewer (\\d+)\u27e7")
MAX_NAME = 150


def safe_part(text: str) -> str:
    """A path component as file-safe text: letters, digits, '.', '_' and '-' kept, the rest '_'."""
    out = re.sub(r"[^A-Za-z0-9._-]", "_", text).strip(".")
    return out or "_"


def shown_path(folder: pathlib.Path, roots: Sequence[pathlib.Path]) -> list[str]:
    """The run folder's path from the innermost results folder given that holds it, that folder's
    own name first (['paper_suite', 'runs', 'tracking__mcl__default__s1']); its name alone when none."""
    folder = folder.resolve()
    for root in sorted(roots, key=lambda r: len(r.parts), reverse=True):
        if folder == root or folder.is_relative_to(root):
            return [root.name] + list(folder.relative_to(root).parts)
    return [folder.name]


def page_name(folder: pathlib.Path, roots: Sequence[pathlib.Path]) -> str:
    """The page's file name (without .html) for a run folder: shown_path joined by '--', each part
    file-safe. A name over MAX_NAME characters is cut and ends with a hash of the whole path."""
    folder = folder.resolve()
    name = "--".join(safe_part(p) for p in shown_path(folder, roots))
    if len(name) > MAX_NAME:
        name = name[:MAX_NAME - 9] + "-" + hashlib.sha1(str(folder).encode()).hexdigest()[:8]
    return name


def size_text(n: int) -> str:
    """'3.1 MB', '142 kB'."""
    return f"{n / 1e6:.1f} MB" if n >= 1e6 else f"{n / 1e3:.0f} kB"


def why_not(e: BaseException, folder: pathlib.Path) -> str:
    """One line saying why a run's page could not be made, naming files within the run folder."""
    if isinstance(e, InputFileError):
        p = pathlib.Path(e.path)
        try:
            where = p.resolve().relative_to(folder.resolve()).as_posix()
        except ValueError:
            where = p.name
        where = "the run folder" if where in ("", ".") else where
        return f"{where}" + (f" line {e.line}" if e.line is not None else "") + f": {e.what}"
    return f"{e.__class__.__name__}: {e}"[:300]


class Viewers:
    """The viewer pages of one report: which runs have one (href), which could not (why), which
    were shown without one (over the limit)."""

    def __init__(self, out: pathlib.Path, roots: Sequence[Union[str, pathlib.Path]], shown_runs: int, limit: Optional[int] = None) -> None:
        self.dir = pathlib.Path(out) / FOLDER
        self.roots = [pathlib.Path(r).resolve() for r in roots]
        self.limit = LIMIT if limit is None else limit
        self.all = shown_runs <= self.limit  # link every run shown, else only those shown on their own
        self.hrefs: dict[pathlib.Path, str] = {}
        self.failed: dict[pathlib.Path, tuple[str, str]] = {}  # folder -> (run title, why)
        self.skipped: set[pathlib.Path] = set()
        self.names: dict[str, pathlib.Path] = {}
        self.bytes = 0
        self.links: list[tuple[str, str]] = []  # (href, text) of each token
        self.dir.mkdir(parents=True, exist_ok=True)
        for old in self.dir.glob("*.html"):  # pages of an earlier report in the same folder
            old.unlink()

    def _name(self, folder: pathlib.Path) -> str:
        name = page_name(folder, self.roots)
        if self.names.get(name, folder) != folder:  # two folders, one name: the later one gets a hash
            name = name[:MAX_NAME - 9] + "-" + hashlib.sha1(str(folder).encode()).hexdigest()[:8]
        self.names[name] = folder
        return name

    def href(self, run: Run, own: bool, title: str = "") -> Optional[str]:
        """The page of run (written the first time it is asked for), or None: not written (over the
        limit, or the run's files do not make one; self.failed says why). own: the report shows the
        run on its own (its plot, an outlier, a real-robot run), which links even over the limit."""
        folder = run.folder.resolve()
        if folder in self.hrefs:
            return self.hrefs[folder]
        if folder in self.failed:
            return None
        if (not self.all and not own) or len(self.hrefs) >= self.limit:
            self.skipped.add(folder)
            return None
        try:
            page = render(load_run(folder, None, images=False))
            name = self._name(folder)
            path = self.dir / f"{name}.html"
            fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=self.dir)
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as f:
                    f.write(page)
                os.chmod(tmp, 0o644)
                os.replace(tmp, path)
            except BaseException:
                if os.path.exists(tmp):
                    os.unlink(tmp)
                raise
        except Exception as e:  # noqa: BLE001 -- a malformed run must never stop the report
            self.failed[folder] = (title or str(run.folder.name), why_not(e, folder))
            return None
        self.skipped.discard(folder)
        self.bytes += path.stat().st_size
        self.hrefs[folder] = f"{FOLDER}/{path.name}"
        return self.hrefs[folder]

    def token(self, href: str, text: str) -> str:
        self.links.append((href, text))
        return TOKEN.format(len(self.links) - 1)


def viewers_of(rep: Writer) -> Optional[Viewers]:
    """The report's viewer pages; None for a writer without them (the terminal's TextReport)."""
    v = getattr(rep, "viewers", None)
    return v if isinstance(v, Viewers) else None


def cell(rep: Writer, run: Run, text: str = "view", own: bool = False, title: str = "") -> str:
    """A table cell linking the run's page; '-' where it has none (the report says why elsewhere)."""
    v = viewers_of(rep)
    href = v.href(run, own, title) if v else None
    return v.token(href, text) if v and href else "-"


def line(rep: Writer, run: Run, own: bool, title: str = "") -> None:
    """A line after a run's heading or figure: the link to its page, or why it has none."""
    v = viewers_of(rep)
    if v is None:
        return
    href = v.href(run, own, title)
    if href:
        rep.raw_html(f"<p class='viewer'>{v.token(href, 'Run viewer')}: this run frame by frame (poses over the field, errors, events)</p>",
                     f"{v.token(href, 'Run viewer')}: this run frame by frame (poses over the field, errors, events)")
    elif run.folder.resolve() in v.failed:
        rep.para(f"No viewer page for this run: {v.failed[run.folder.resolve()][1]}")


def section(rep: Writer) -> None:
    """The report's own section on its viewer pages: how many, their size, how to make the others,
    and one line for each run whose page could not be made."""
    v = viewers_of(rep)
    if v is None or not (v.hrefs or v.failed or v.skipped):
        return
    rep.heading("Run viewers", 2, "run-viewers")
    rep.para(f"{len(v.hrefs)} run(s) of this report link to their viewer page (folder viewers/ beside this report, "
             f"{size_text(v.bytes)} in all): one self-contained page per run to step through it frame by frame, the true and "
             "estimated poses over the field, the errors over time and the events (docs/viewer.md). The pages are made with the "
             "viewer's defaults, without camera images; line points, particles and covariance where the run folder holds "
             "view.jsonl (a run made with `--debug-view`). `omniloc view RUN_DIR` makes the page of any run, with camera images "
             "from its recording (`--recording DIR`).")
    if v.skipped:
        rep.para(f"{len(v.skipped)} run(s) shown in this report have no page here: a report that shows more than {v.limit} runs "
                 f"links only the runs it shows on their own (their plot, an outlying seed, a real-robot run), at most {v.limit} "
                 "pages. Make any other with `omniloc view RUN_DIR`.")
    if v.failed:
        rep.para(f"{len(v.failed)} run(s) have no viewer page: their files do not make one (a missing or malformed file; "
                 "`omniloc view RUN_DIR` says the same).")
        if len(v.failed) > 5:
            rep.details(f"{len(v.failed)} runs without a viewer page, and why")
        for folder, (title, why) in sorted(v.failed.items(), key=lambda kv: kv[1][0]):
            rep.para(f"No viewer page for {title} (`{'/'.join(shown_path(folder, v.roots))}`): {why}")
        if len(v.failed) > 5:
            rep.end_details()


class ViewerReport(Report):
    """Report with the runs' viewer pages (Viewers): writes the links where the sections put tokens."""

    viewers: Viewers

    def __init__(self, out: Union[str, pathlib.Path], title: str, roots: Sequence[Union[str, pathlib.Path]], shown_runs: int,
                 limit: Optional[int] = None) -> None:
        super().__init__(out, title)
        self.viewers = Viewers(self.out, roots, shown_runs, limit)

    def write(self) -> None:
        links = self.viewers.links

        def md(m: re.Match[str]) -> str:
            href, text = links[int(m.group(1))]
            return f"[{text}]({href})"

        def htm(m: re.Match[str]) -> str:
            href, text = links[int(m.group(1))]
            return f"<a href='{html.escape(href, quote=True)}'>{html.escape(text)}</a>"
        self.md = [TOKEN_RE.sub(md, x) for x in self.md]
        self.html = [TOKEN_RE.sub(htm, x) for x in self.html]
        super().write()
