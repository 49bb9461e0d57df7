#!/usr/bin/env python3
"""Comparison report of omniloc results: report.md and a self-contained report.html.

usage: report.py RESULTS... -o DIR [--title TEXT] [--max-runs N] [--baseline RESULTS] [--history DIR]

RESULTS are folders: a run (summary.json), a sweep (aggregate.json with runs/ inside), an
experiment (PNG / JSON / markdown files written by `omniloc experiment`), or any folder holding
such folders (searched recursively). The report is laid out for a reader with ten minutes
(docs/results.md), in this order:
  - a headline of two or three sentences, computed from the results: what reproduces and what does
    not, our error against the papers' (median ratio), the main gap and its measured cause;
  - the reproduction scorecard: every claim of results/reference/papers.json with our figure, the
    paper's, the ratio and the verdict computed by the rule written next to the claim, counted
    apart by kind (accuracy / robustness / timing), judged on every axis a published row states,
    with the field_robot runs judged by the same rules in their own column; then the contents;
  - real robots (scripts/real_robots.py): the global localizers on real robots' frames
    (scenarios/sweeps/real_robots.json: data/real/nubot), each run classified found / twin / wrong
    against the reference pose and its 180-degree twin, and the real line points' noise by range
    beside the simulated robot and field_robot profiles' (from the paper suite sweeps' recordings);
    without those results it says what to run;
  - provenance: which omniloc builds (git describe, compiler, build type) made the results, when,
    and the machine (CPU model, cores);
  - every published table beside the runs that reproduce it, paired BY KEY (scenario, localizer,
    configuration values; scripts/omniloc_results.py), never by position; a row whose runs are
    missing says "not run" and prints the command that runs it; below each, every seed beside the
    mean (intervals by the one rule of docs/results.md "Intervals": t95 for n >= 5, the seeds' range below), a strip plot of the seeds, and each outlying seed
    plotted with its cause read from its frames.csv and events.jsonl;
  - with --baseline: our metrics against another result set (e.g. another commit), per metric
    with the difference and Welch's t-test over seeds (scripts/compare.py);
  - every sweep's aggregate and per-seed table, each run's table and plots (collapsed), error
    CDFs, timing per stage;
  - every experiment's pictures and notes (tables a section above shows are not repeated);
  - on a page of its own (history.html, linked), for developers: instruction counts and benchmark
    wall times per workload over the commits (--history DIR, default results/history);
  - the references: the five papers, cited in the text as 'Lu et al. 2013 [3]' (paper_claims.BIBLIOGRAPHY).
Coverage first (docs/results.md "Coverage and recall"): an error is over the frames a localizer
answered, so wherever the report shows one it shows the share of frames answered beside it, and
wherever localizers or conditions stand side by side (the scorecard, the published tables, the sweep
tables, the per-seed tables, the global-start table, the error CDF) the recall at the headline
threshold ("within 25 cm / 10 deg": the share of ALL frames within it, a frame without an estimate
counting as outside) comes first. A statistic over no answered frame reads "no estimate" (or "no
estimate in k of n runs"), never a number; results made before recall was scored show as before.
The text speaks to a reader: claims and tables by readable labels, never papers.json keys or issue
numbers, abbreviations spelled out at first use (paper_claims.py; scripts/check_report_html.py checks).
Pictures are embedded, compressed (palette PNG, JPEG for camera frames) so that report.html stays
under 3 MB; no absolute path reaches the report (Report.clean).
Everything except the published numbers is read from the result files. Needs Python 3 and
Debian's python3-matplotlib (no PyPI).
"""
import argparse
import base64
import html
import json
import math
import os
import pathlib
import platform
import re
import statistics
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import omniloc_results as R  # noqa: E402
import paper_claims as C  # noqa: E402
import real_robots as RR  # noqa: E402

EVENT_COLOURS = {"kidnap": "red", "cover": "black", "teleport": "red", "occlude": "grey", "lights": "orange", "camera": "purple"}
VERDICT_CLASS = {"holds": "ok", "partly": "partly", "does not": "no", "not run": "notrun", "n/a": "notrun",
                 C.EXPLAINED: "ok", C.NOT_MEASURED: "notrun", C.CONTRADICTED: "no", C.UNEXPLAINED: "no"}
fnum = R.fnum


# A cell is a number (right-aligned) only when the WHOLE cell is one: a number with an optional
# unit, an interval "[lo, hi]", an "(n=3 ...)" note or "a / b" counts. Claim text that starts with
# a number ("50 % occlusion degrades ...") stays text (left-aligned).
NUMERIC_CELL = re.compile(r"^[-+]?((0|[1-9]\d*)(\.\d*)?|\.\d+)(e[-+]?\d+)?( ?(%|cm|mm|m|ms|s|rad|deg|x|ns))?"
                          r"( \[[^\]]*\])?( \([^)]*\))?( / [-+]?\d+(\.\d+)?)?$")


def numeric_class(cell):
    """Numbers right-aligned, text left-aligned (see NUMERIC_CELL)."""
    return " class='num'" if NUMERIC_CELL.match(str(cell).strip()) else ""


# Where the repository's docs/ lies seen from the report's folder (results/report/ by default);
# Report sets it for its own folder. A doc named in the text (docs/x.md#anchor) becomes a link.
DOCS_HREF = "../../docs/"


def md_links(text):
    """report.md's text with each doc of the repository (docs/x.md#anchor) as a markdown link."""
    return re.sub(r"(?<![\w/.\[`-])docs/([\w/.-]+?\.md)(#[\w-]+(?:\.[\w-]+)*)?", lambda m: f"[docs/{m.group(1)}]({DOCS_HREF}{m.group(1)}{m.group(2) or ''})", text)


def inline_markdown(text):
    """HTML of one line of markdown: `code`, **bold** and *italic*, and a doc of the repository
    (docs/x.md, optionally #anchor) as a link; everything else escaped. The report's own text and
    the experiments' markdown use these, and a reader must never see the raw markers in the HTML."""
    out, pos = [], 0
    for m in re.finditer(r"`([^`]+)`|\*\*([^*]+)\*\*|(?<![\w*])\*([^*\s][^*]*?)\*(?![\w*])|(?<![\w/.-])docs/([\w/.-]+?\.md)(#[\w-]+(?:\.[\w-]+)*)?", text):
        out.append(html.escape(text[pos:m.start()]))
        if m.group(1) is not None:
            out.append(f"<code>{html.escape(m.group(1))}</code>")
        elif m.group(2) is not None:
            out.append(f"<b>{html.escape(m.group(2))}</b>")
        elif m.group(4) is not None:
            out.append(f"<a href='{html.escape(DOCS_HREF + m.group(4) + (m.group(5) or ''))}'>docs/{html.escape(m.group(4))}</a>")
        else:
            out.append(f"<i>{html.escape(m.group(3))}</i>")
        pos = m.end()
    out.append(html.escape(text[pos:]))
    return "".join(out)


def slug(text):
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:60] or "section"


TOC_MARK = "<!--toc-->"
# A command of omniloc in running text, shown as code: `build/omniloc sweep scenarios/sweeps/x.json -j 2`.
COMMAND = re.compile(r"(?<![`\w/])(build/omniloc (?:sweep|experiment|run)(?: [\w./=-]+)+)")
# The part before a repository folder of an absolute path (/any/checkout/scenarios/x.json -> scenarios/x.json).
REPO_PATH = re.compile(r"(?<![\w.~-])/(?:[\w.+-]+/)+?(?=(?:scenarios|results|build|docs|scripts|data|experiments|tests)/)")


class Report:
    """report.md and report.html built side by side. Sections are functions that call heading /
    para / table / figure; a heading of level 2 becomes an entry of the table of contents, which
    write() puts where mark_toc() was called (after the scorecard)."""

    def __init__(self, out, title, page="report"):
        self.out = pathlib.Path(out)
        self.page = page
        (self.out / "img").mkdir(parents=True, exist_ok=True)
        for old in (self.out / "img").glob(f"{page}_*"):  # pictures of an earlier report in the same folder
            old.unlink()
        self.md = [f"# {title}", ""]
        self.html = []
        self.toc = []
        self.n_img = 0
        self.title = title
        self.anchors = set()
        self.titles = {}
        self.plotted = set()
        # Absolute paths never reach the report (it is shared): every folder the report could name
        # is shown relative to the working folder, or by its last two parts when outside it.
        self.roots = sorted({str(p) for p in (pathlib.Path.cwd(), R.ROOT, pathlib.Path.home(), pathlib.Path(tempfile.gettempdir()),
                                              self.out.resolve())}, key=len, reverse=True)
        self.expanded = set()  # abbreviations already spelled out (expand)
        global DOCS_HREF
        out = self.out.resolve()
        DOCS_HREF = (os.path.relpath(R.ROOT / "docs", out).replace(os.sep, "/") + "/") if out.is_relative_to(R.ROOT) else "../../docs/"

    def add_root(self, path):
        p = str(pathlib.Path(path).resolve())
        self.roots = sorted(set(self.roots) | {p}, key=len, reverse=True)

    def clean(self, text):
        """text with every absolute path under a known root made relative (see __init__)."""
        text = C.cite_text(text)  # 'paper 002' -> 'Lu et al. 2013 [3]' (the bibliography at the end)
        if "/" not in text:
            return text
        cwd = pathlib.Path.cwd()

        def rel(m):
            p = pathlib.Path(m.group(0))
            try:
                return p.relative_to(cwd).as_posix() or "."
            except ValueError:
                return "/".join(p.parts[-2:]) if len(p.parts) > 2 else p.name
        for root in self.roots:
            if root != "/" and root in text:
                # The root as a whole folder name: /root must not eat the start of /rootfs.
                text = re.sub(re.escape(root) + r"(?![\w.-])(/[^\s'\"<>,;:()\[\]]*)?", rel, text)
        # A path of another checkout (an experiment records the description file it read, with the
        # folder omniloc was built in): from the repository's own folder on. Commands as code.
        return COMMAND.sub(r"`\1`", REPO_PATH.sub("", text))

    def expand(self, text):
        """The text with each abbreviation of C.ABBREVIATIONS spelled out at its first use in the
        report (outside `code`): 'MCL (Monte Carlo localization)'. Headings are left as they are."""
        text = str(text)
        for abbr, full in C.ABBREVIATIONS.items():
            if abbr in self.expanded or abbr not in text:
                continue
            for m in re.finditer(r"(?<![\w/.-])" + re.escape(abbr) + r"(?![\w-])", text):
                if text.count("`", 0, m.start()) % 2:  # inside `code`
                    continue
                self.expanded.add(abbr)
                text = text[:m.end()] + f" ({full})" + text[m.end():]
                break
        return text

    def heading(self, text, level=2, anchor=None):
        text = self.clean(text)
        anchor = anchor or slug(text)
        while anchor in self.anchors:  # unique ids: two runs can share a title
            anchor += "-"
        self.anchors.add(anchor)
        self.titles[anchor] = text
        if level == 2:
            self.toc.append((anchor, text))
        self.md += ["#" * level + " " + text, ""]
        self.html.append(f'<h{level} id="{html.escape(anchor)}">{inline_markdown(text)}</h{level}>')  # `code` in a run's parameters
        return anchor

    def para(self, text, cls=None, ident=None):
        text = self.expand(self.clean(text))
        self.md += [md_links(text), ""]
        c = (f' class="{cls}"' if cls else "") + (f' id="{ident}"' if ident else "")
        self.html.append(f"<p{c}>{inline_markdown(text)}</p>")

    def raw_html(self, fragment, md=None):
        self.html.append(fragment)
        if md:
            self.md += [md, ""]

    def details(self, summary):
        """Opens a collapsed block (HTML <details>); end_details() closes it. report.md keeps it flat."""
        self.html.append(f"<details><summary>{inline_markdown(self.clean(summary))}</summary>")

    def end_details(self):
        self.html.append("</details>")

    def mark_toc(self):
        self.html.append(TOC_MARK)

    def table(self, header, rows, caption=None, row_classes=None):
        """rows: lists of cells; row_classes: one CSS class per row (e.g. "paper" for published rows).
        A cell that is a verdict (holds, partly, ...) is coloured by itself."""
        if caption:
            self.para(caption, "caption")
        header = [self.expand(self.clean(c)) for c in header]
        rows = [[self.expand(self.clean(c)) for c in r] for r in rows]
        self.md.append("| " + " | ".join(header) + " |")
        # The first column labels the row (even "50 %"): left; the others by their cells.
        self.md.append("|" + "|".join("---:" if i and rows and numeric_class(rows[0][i]) else "---" for i in range(len(header))) + "|")
        for k, r in enumerate(rows):
            cells = [md_links(str(c).replace("|", "\\|")) for c in r]
            if row_classes and row_classes[k] == "paper":
                cells = [f"*{c}*" if c not in ("", "-") else c for c in cells]
            self.md.append("| " + " | ".join(cells) + " |")
        self.md.append("")
        h = "<div class='scroll'><table><tr>" + "".join(f"<th>{inline_markdown(str(c))}</th>" for c in header) + "</tr>"
        for k, r in enumerate(rows):
            cls = row_classes[k] if row_classes and row_classes[k] else ""
            h += (f"<tr class='{cls}'>" if cls else "<tr>")
            for i, c in enumerate(r):
                v = VERDICT_CLASS.get(str(c))
                h += f"<td class='v-{v}'>" if v else f"<td{numeric_class(c) if i else ''}>"
                h += inline_markdown(str(c)) + "</td>"
            h += "</tr>"
        self.html.append(h + "</table></div>")

    def markdown(self, text, skip=()):
        """An experiment's markdown: headings, paragraphs and pipe tables as real HTML. skip: pairs
        (heading text, anchor): a table under a heading containing that text is left out, with a
        link to the section that shows it from the experiment's JSON (one copy of each table)."""
        text = self.expand(self.clean(text))
        lines = text.splitlines()
        i, para, kept = 0, [], []
        current = ""

        def flush():
            if para:
                self.html.append("<p>" + inline_markdown(" ".join(para)) + "</p>")
                para.clear()
        while i < len(lines):
            ln = lines[i].rstrip()
            if ln.startswith("```"):  # a fenced block (an experiment's fixed-width table): kept as it is
                flush()
                j = i + 1
                while j < len(lines) and not lines[j].startswith("```"):
                    j += 1
                self.html.append("<pre>" + html.escape("\n".join(lines[i + 1:j])) + "</pre>")
                kept += lines[i:j + 1]
                i = j + 1
                continue
            if ln.startswith("#"):
                current = ln
                flush()
                level = min(6, len(ln) - len(ln.lstrip("#")) + 2)
                self.html.append(f"<h{level}>{inline_markdown(ln.lstrip('#').strip())}</h{level}>")
                kept.append("#" * level + " " + ln.lstrip("#").strip())  # below the report's own sections, as in the HTML
            elif ln.startswith("|"):
                flush()
                rows, block = [], []
                while i < len(lines) and lines[i].strip().startswith("|"):
                    block.append(lines[i])
                    cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                    if not all(set(c) <= set("-: ") for c in cells):
                        rows.append(cells)
                    i += 1
                shown = [(h, a) for h, a in skip if h in current]
                if shown:
                    note = f"(This table is shown once, in the section \"{self.titles.get(shown[0][1], shown[0][0])}\" above.)"
                    self.html.append(f"<p class='caption'><a href='#{html.escape(shown[0][1])}'>{html.escape(note)}</a></p>")
                    kept += [note, ""]
                    continue
                kept += block
                if rows:
                    h = "<div class='scroll'><table><tr>" + "".join(f"<th>{inline_markdown(c)}</th>" for c in rows[0]) + "</tr>"
                    for r in rows[1:]:
                        h += "<tr>" + "".join(f"<td{numeric_class(c)}>{inline_markdown(c)}</td>" for c in r) + "</tr>"
                    self.html.append(h + "</table></div>")
                continue
            elif not ln.strip():
                flush()
                kept.append("")
            else:
                para.append(ln)
                kept.append(ln)
            i += 1
        flush()
        self.md += kept + [""]

    def figure(self, fig, name, caption, dpi=80):
        self.n_img += 1
        path = self.out / "img" / f"{self.page}_{self.n_img:03d}_{name}.png"
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
        plt.close(fig)
        self._embed(compress_png(path), caption)

    def image(self, path, caption):
        """A picture an experiment wrote: copied next to the report, compressed, embedded."""
        path = pathlib.Path(path)
        self.n_img += 1
        dst = self.out / "img" / f"{self.page}_{self.n_img:03d}_{path.name}"
        dst.write_bytes(path.read_bytes())
        self._embed(compress_png(dst), caption)

    def _embed(self, path, caption):
        caption = self.expand(self.clean(caption))
        rel = path.relative_to(self.out)
        self.md += [f"![{caption}]({rel.as_posix()})", "", f"*{caption}*", ""]
        b64 = base64.b64encode(path.read_bytes()).decode()
        mime = "image/jpeg" if path.suffix == ".jpg" else "image/png"
        self.html.append(f'<figure><img src="data:{mime};base64,{b64}" alt="{html.escape(caption)}"><figcaption>{inline_markdown(caption)}</figcaption></figure>')

    def toc_html(self):
        items = "".join(f'<li><a href="#{html.escape(a)}">{inline_markdown(t)}</a></li>' for a, t in self.toc)
        return f'<nav id="contents"><h2>Contents</h2><ol>{items}</ol></nav>'

    def write(self):
        md = list(self.md)
        toc_md = ["## Contents", ""] + [f"{k + 1}. [{t}](#{a})" for k, (a, t) in enumerate(self.toc)] + [""]
        if "<!--toc-->" in md:
            k = md.index("<!--toc-->")
            md[k:k + 1] = toc_md
        tmp = self.out / f"{self.page}.md.tmp"
        tmp.write_text("\n".join(md) + "\n")
        tmp.replace(self.out / f"{self.page}.md")
        style = ("body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222}"
                 ".scroll{overflow-x:auto}table{border-collapse:collapse;margin:0.5em 0 1.2em;font-size:13px}"
                 "td,th{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top}td.num{text-align:right;white-space:nowrap}"
                 "th{background:#eee}tr.paper td{background:#fff6dc;font-style:italic}tr.ratio td{color:#555;font-size:12px}"
                 "tr.missing td{color:#999}td.v-ok{background:#d8f5d8}td.v-partly{background:#fff0b3}"
                 "td.v-no{background:#f8d0d0}td.v-notrun{background:#e8e8e8}tr.outlier td{background:#fde2e2}"
                 "figure{margin:1em 0}img{max-width:100%}p.caption{font-size:13px;color:#444;margin-bottom:0.2em}"
                 "figcaption{font-size:13px;color:#555}h2{border-bottom:1px solid #ccc;padding-top:0.6em}code{background:#f3f3f3}"
                 "details{margin:0.4em 0 0.8em;border-left:3px solid #ddd;padding-left:0.7em}summary{cursor:pointer;font-weight:bold}"
                 "p.totals{font-size:15px}nav#contents ol{columns:2;font-size:14px}")
        body = "\n".join(self.html).replace(TOC_MARK, self.toc_html() if self.toc else "")
        doc = (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(self.title)}</title><style>{style}</style></head>"
               f"<body><h1>{html.escape(self.title)}</h1>" + body + "</body></html>\n")
        tmp = self.out / f"{self.page}.html.tmp"
        tmp.write_text(doc)
        tmp.replace(self.out / f"{self.page}.html")


class TextReport:
    """The Report interface written to the terminal (scripts/paper_table.py): tables aligned (or
    as markdown), figures left out. With only=ANCHOR just the section of that heading anchor."""

    def __init__(self, only=None, markdown=False):
        self.only, self.markdown_tables, self.on, self.printed = only, markdown, only is None, False
        self.plotted, self.n_img = set(), 0

    def clean(self, text):
        return str(text)

    def heading(self, text, level=2, anchor=None):
        anchor = anchor or slug(text)
        if self.only is not None:
            self.on = anchor == self.only
        if self.on:
            print(("#" * level + " " if self.markdown_tables else "== ") + text + "\n")
            self.printed = True
        return anchor

    def para(self, text, cls=None):
        if self.on:
            print(text + "\n")

    def table(self, header, rows, caption=None, row_classes=None):
        if not self.on:
            return
        if caption:
            print(caption)
        cells = [[str(c) for c in header]] + [[str(c) for c in r] for r in rows]
        if self.markdown_tables:
            for k, r in enumerate(cells):
                print("| " + " | ".join(r) + " |")
                if k == 0:
                    print("|" + "---|" * len(r))
        else:
            w = [max(len(r[i]) for r in cells) for i in range(len(header))]
            for r in cells:
                print("  ".join(c.rjust(w[i]) if i and numeric_class(c) else c.ljust(w[i]) for i, c in enumerate(r)).rstrip())
        print()

    def figure(self, fig, name, caption, dpi=80):
        plt.close(fig)

    def image(self, path, caption):
        pass

    def markdown(self, text, skip=()):
        if self.on:
            print(text)

    def details(self, summary):
        pass

    def end_details(self):
        pass

    def mark_toc(self):
        pass

    def raw_html(self, fragment, md=None):
        pass


def compress_png(path):
    """Re-encodes a picture so that report.html, which embeds every one, stays under 3 MB without
    leaving one out: plots (few colours) as an optimised 256-colour palette PNG; camera frames and
    other photographic pictures, which stay large as a palette PNG, as JPEG (quality 85). Keeps the
    original where that is smaller. Returns the path written (the suffix may change to .jpg).
    Without PIL (Debian's python3-pil, a dependency of python3-matplotlib) nothing changes."""
    try:
        from PIL import Image
    except ImportError:
        return path
    import io
    with Image.open(path) as im:
        im.load()
    has_alpha = im.mode in ("RGBA", "LA") or (im.mode == "P" and "transparency" in im.info)
    src = im.convert("RGBA") if has_alpha else im.convert("RGB")
    q = src.quantize(colors=256, method=Image.Quantize.FASTOCTREE) if has_alpha else src.quantize(colors=256)
    buf = io.BytesIO()
    q.save(buf, format="PNG", optimize=True)
    best, data = path.stat().st_size, None
    if buf.tell() < best:
        best, data = buf.tell(), buf.getvalue()
    if best > 120_000 and not has_alpha:  # still large: a photograph-like picture
        jbuf = io.BytesIO()
        src.save(jbuf, format="JPEG", quality=85, optimize=True)
        if jbuf.tell() < best / 2:
            path.unlink()
            path = path.with_suffix(".jpg")
            path.write_bytes(jbuf.getvalue())
            return path
    if data is not None:
        path.write_bytes(data)
    return path


# ---- provenance ---------------------------------------------------------------------------

def cpu_model():
    """The CPU model of this machine (from /proc/cpuinfo; the platform's name elsewhere)."""
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_text():
    return f"{cpu_model()}, {os.cpu_count()} cores, {platform.system()} {platform.machine()}"


def provenance(rep, runs, sweeps):
    """Which builds made the results, on what, when. summary.json's "omniloc" block names the build
    (version, compiler, build type) and, where the build records them, the machine (cpu, cores) and
    date; where it does not, the machine is the one that made this report (scripts/run.sh makes both
    on the same machine) and the date is the run files' modification time."""
    versions = {}
    for r in runs:
        o = dict(r.summary.get("omniloc") or {})
        o.update(o.get("host") or {})  # the run's machine (summary.json omniloc.host: cpu, cores)
        when = o.get("date") or time.strftime("%Y-%m-%d", time.gmtime((r.folder / "summary.json").stat().st_mtime))
        k = (o.get("version", "unrecorded"), o.get("compiler", "-"), o.get("build_type", "-"),
             f"{o['cpu']}, {o.get('cores', '?')} cores" if o.get("cpu") else "this report's machine (below)")
        d = versions.setdefault(k, {"n": 0, "dates": set()})
        d["n"] += 1
        d["dates"].add(when)
    rep.heading("Provenance", 2, "provenance")
    rows = [[v, c, b, m, " to ".join(sorted({min(d["dates"]), max(d["dates"])})), d["n"]] for (v, c, b, m), d in sorted(versions.items())]
    rep.table(["omniloc version (git describe)", "compiler", "build type", "machine", "runs dated (UTC)", "runs"], rows,
              f"Builds that made these results. This report: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {machine_text()}.")
    if len(versions) > 1:
        rep.para("Warning: the results come from more than one build; compare like with like (scripts/compare.py).")


# ---- scorecard and published tables ----------------------------------------------------------

KIND_TEXT = {"accuracy": "Accuracy", "robustness": "Robustness",
             "timing": "Timing (indicative: the papers' 1.66 GHz CPU against ours; not evidence of accuracy)"}


def field_robot_runs(runs):
    return [r for r in runs if profile_of(r) == "field_robot"]


def judge_claims(ctx):
    """(claims, field_claims by id or None, causes): the verdicts for the robot profile and, where
    there are field_robot runs, for those by the same rules; with the causes of every verdict other
    than holds, each profile's evidence read from its own runs."""
    claims = C.evaluate_claims(ctx)
    field = field_robot_runs(ctx.runs)
    field_claims, fctx = None, None
    if field:
        with R.pairing_profile("field_robot"):
            fctx = C.Context(ctx.papers, field, [])
            fctx.experiments = ctx.experiments
            field_claims = {c["id"]: c for c in C.evaluate_claims(fctx)}
    causes = C.explain(claims, ctx, "robot")
    if field_claims:
        with R.pairing_profile("field_robot"):  # the evidence of the field_robot verdicts is read from its own runs
            causes += C.explain([field_claims[c["id"]] for c in claims if c["uses_runs"]], fctx, "field_robot")
    return claims, field_claims, causes


def scorecard(rep, ctx, judged=None):
    """The papers' claims with our verdicts, counted apart by kind (accuracy / robustness / timing),
    for the robot profile and, in a column of their own by the same rules, the field_robot runs.
    judged: judge_claims(ctx) when the caller has it. Returns (claims, field_claims or None, totals
    text) for the summary and the terminal."""
    claims, field_claims, causes = judged or judge_claims(ctx)
    rep.heading("Reproduction scorecard", 2, "scorecard")
    totals = C.totals_text(C.totals(claims))
    ftotals = C.totals_text(C.totals([field_claims[c["id"]] for c in claims if c["uses_runs"]])) if field_claims else None
    rep.para(f"**Robot profile** — {totals}." + (f" **field_robot profile** (claims judged from runs) — {ftotals}." if ftotals else ""), "totals")
    rep.para("One line per published claim, grouped by what it is about. The verdict is computed by the rule written next to the "
             "claim in results/reference/papers.json; a claim stated on a row of a published error table is judged on every axis "
             "the paper states there (mean x, y and heading): all hold: holds, some: partly. Claims that do not hold stay "
             "visible, and no model is tuned to turn one.")
    # Coverage of the runs behind each claim first (recall at the headline threshold, share answered):
    # the papers' figures are errors over the frames answered. Results made before recall: no column.
    cov = lambda c: C.coverage_text(c.get("coverage"))
    show_cov = any(cov(c) != "-" for c in claims)
    show_fcov = field_claims is not None and any(cov(f) != "-" for f in field_claims.values())
    if show_cov:
        rep.para("'Our runs' gives, for a claim judged from runs, the share of their frames within the headline threshold and the share "
                 "answered (docs/results.md, coverage and recall): our figure beside it is an error over the answered frames only; a claim "
                 "whose runs gave no estimate in some run is not judged on the others (does not).")
    for kind in C.KINDS:
        mine = [c for c in claims if c["kind"] == kind]
        if not mine:
            continue
        rows = []
        for c in mine:
            pub = c["published"]
            pub_text = (fnum(pub, 3) + ("" if c["unit"] in ("x", "", "recovered") else f" {c['unit']}")) if isinstance(pub, (int, float)) else (pub or "-")
            row = [C.cite_field(c["paper"]), c["claim"]] + ([cov(c)] if show_cov else []) + [
                c["ours_text"] + ("" if not c["notes"] else " (" + "; ".join(c["notes"]) + ")"), pub_text,
                fnum(c["ratio"], 2) if c["ratio"] is not None else "-", C.verdict_text(c)]
            if field_claims is not None:
                f = field_claims[c["id"]]
                row += ([cov(f) if c["uses_runs"] else "-"] if show_fcov else []) + (
                    [f["ours_text"].replace("sweeps/paper_suite.json", "sweeps/paper_suite_field_robot.json"), C.verdict_text(f)]
                    if c["uses_runs"] else ["same as robot (experiment)", "-"])
            rows.append(row + [c["rule_text"]])
        header = ["paper", "claim"] + (["our runs: coverage"] if show_cov else []) + [
            "ours (robot profile)", "paper's", "ours / paper", "verdict"]
        if field_claims is not None:
            header += (["our runs: coverage (field_robot)"] if show_fcov else []) + ["ours (field_robot)", "verdict (field_robot)"]
        cap = f"{KIND_TEXT[kind]}: " + C.totals_text({kind: C.totals(mine)[kind]}).split(": ", 1)[1] + "."
        if kind == "timing":
            cap += f" Ours: median wall time on {machine_text()}."
        rep.table(header + ["rule"], rows, cap)
    causes_section(rep, claims, field_claims, causes)
    ctext = causes_totals(causes)
    return claims, field_claims, totals + (f" | field_robot: {ftotals}" if ftotals else "") + (f" | {ctext}" if ctext else "")


def causes_totals(causes):
    """'5 verdicts other than holds: 4 explained, 1 evidence not in these results' (empty without any)."""
    if not causes:
        return ""
    counts = {}
    for c in causes:
        counts[c["status"]] = counts.get(c["status"], 0) + 1
    order = [C.EXPLAINED, C.NOT_MEASURED, C.CONTRADICTED, C.UNEXPLAINED]
    return f"{len(causes)} verdicts other than holds: " + ", ".join(f"{counts[k]} {k}" for k in order if counts.get(k))


def ratio_text(c):
    """ours / paper of one claim, short: one ratio per axis the paper states ('x 0.34x, heading
    0.23x'), or the claim's ratio, or our figures; '-' when nothing was measured."""
    if c is None:
        return "-"
    rs = [(ch["label"], ch["ratio"]) for ch in c["checks"] if ch["ratio"] is not None]
    if rs:
        return ", ".join(f"{re.sub(r'^mean ', '', l)} {fnum(r, 2)}x" for l, r in rs)
    if c["ratio"] is not None and c["ours"] is not None and isinstance(c["published"], (int, float)):
        return f"{fnum(c['ours'], 2)} / {fnum(c['published'], 2)} = {fnum(c['ratio'], 2)}x"
    # Runs that gave no estimate: say so, not '-' (which reads as "not measured").
    none = c["ours_text"] if C.no_estimate(c.get("ours_text")) else "-"
    if c["checks"]:
        return "; ".join(f"{ch['label']}: {fnum(ch['ours'], 3)}" for ch in c["checks"] if ch["ours"] is not None) or none
    return fnum(c["ours"], 3) if c["ours"] is not None else none


def per_profile(values):
    """One text where both profiles agree, else 'robot: a; field_robot: b' ({profile: text})."""
    texts = [v for v in values.values() if v]
    if len(set(texts)) <= 1:
        return texts[0] if texts else "-"
    return "; ".join(f"{p}: {v}" for p, v in values.items() if v)


def causes_section(rep, claims, field_claims, causes):
    """Why each claim that does not hold does not, as one table: a row per claim with its verdict
    per profile, ours / paper, and the cause in one sentence (results/reference/causes.json: written
    once where it holds for both profiles), whether its evidence, read from these results, bears it
    out; the full argument and the evidence collapsed below. A verdict without a cause, or whose
    evidence now says otherwise, is shown as such, never hidden."""
    if not causes:
        return
    rep.heading("Why a claim does not hold", 3, "causes")
    rep.para(causes_totals(causes) + ". A cause counts as explained only when every measurement it rests on is in these results and "
             "inside the range the argument needs (written next to the claim in results/reference/causes.json); the measurements are "
             "collapsed under the table. No model was tuned to turn a verdict.")
    by_claim = {}
    for k in causes:
        by_claim.setdefault(k["id"], {})[k["profile"]] = k
    profiles = ["robot"] + (["field_robot"] if field_claims else [])
    header = ["claim", "paper"] + [f"verdict: {p}" for p in profiles] + ["ours / paper", "cause", "cause borne out by these results"]
    rows, classes = [], []
    for c in claims:
        ks = by_claim.get(c["id"])
        if not ks:
            continue
        judged = {"robot": c}
        if field_claims and c["uses_runs"]:
            judged["field_robot"] = field_claims[c["id"]]
        verdicts = [C.verdict_text(judged[p]) if p in judged else "same as robot (experiment)" for p in profiles]
        ratio = per_profile({p: ratio_text(judged[p]) for p in judged if judged[p]["verdict"] not in ("not run", "n/a")})
        cause = per_profile({p: k["summary"] or "no cause recorded" for p, k in ks.items()})
        status = per_profile({p: k["status"] for p, k in ks.items()})
        rows.append([C.claim_label(c["id"]), C.cite_field(c["paper"])] + verdicts + [ratio, cause, status])
        classes.append("" if all(k["status"] == C.EXPLAINED for k in ks.values()) else "outlier")
    rep.table(header, rows, "Claims whose verdict is not 'holds': one row per claim, its verdict under each noise profile.", classes)
    rep.details("The argument behind each cause and the measurements it rests on")
    for c in claims:
        ks = by_claim.get(c["id"])
        if not ks:
            continue
        texts = {p: k["text"] for p, k in ks.items() if k["text"]}
        docs = sorted({k["doc"] for k in ks.values() if k["doc"]})
        argument = per_profile(texts) if texts else "No cause recorded."
        rep.para(f"**{C.claim_label(c['id'])}** ({C.cite_field(c['paper'])}). {argument}" + (f" Details: {', '.join(docs)}." if docs else ""))
        ev = [[p, C.evidence_text(e)] for p, k in ks.items() for e in k["evidence"]]
        if ev:
            rep.table(["profile", "measured in these results (and the range the argument needs)"], ev)
    rep.end_details()


# The claim the headline names as the main gap: the first of these that does not hold, else the
# first accuracy claim that does not.
MAIN_GAP = ("tracking_accuracy", "occlusion_mild", "mcl_alone", "lighting_autoadjust", "kidnap_002", "kidnap_000")


def error_ratios(papers, runs, used=None):
    """Ours / paper over the published error-table rows these runs reproduce (each set of runs
    once): (median over mean x and mean y, median over mean heading, rows). `used`, a list, receives
    the runs of those rows (for their coverage)."""
    pos, head, seen = [], [], set()
    keys = [f"{a}/{s}" for a, s in R.TABLE_KEYS]
    for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
        for p in C.pair_table(papers, table, runs, include_extra=False):
            ident = tuple(sorted(str(r.folder) for r in p["runs"]))
            if not p["runs"] or not p["published"] or ident in seen:
                continue
            seen.add(ident)
            if used is not None:
                used.extend(p["runs"])
            pub = dict(zip(keys, p["published"]))
            for m, bucket in (("x_cm/mean", pos), ("y_cm/mean", pos), ("theta_rad/mean", head)):
                v = p["stats"][m]["mean"]
                if v is not None and pub.get(m):
                    bucket.append(v / pub[m])
    med = lambda v: statistics.median(v) if v else None
    return med(pos), med(head), len(seen)


def coverage_sentence(runs):
    """'errors over the frames answered: those runs answered 100.0 % of their frames, 97.3 % within
    25 cm / 10 deg' (means over the runs; '' for runs made before coverage was scored)."""
    key = R.headline_key(runs)
    ans = R.run_stats(runs, "valid_fraction")["mean"]
    rec = R.run_stats(runs, f"recall/{key}")["mean"] if key else None
    if ans is None and rec is None:
        return ""
    return ("errors over the frames answered: those runs answered " + R.percent(ans) + " of their frames"
            + (f", {R.percent(rec)} within {R.recall_label(key)}" if rec is not None else ""))


def lower_first(label):
    return label if label[:2].isupper() or not label[:1].isalpha() else label[0].lower() + label[1:]


def headline(rep, ctx, claims, field_claims, causes):
    """Two or three sentences a researcher can quote, first after the title, all computed from the
    results: what reproduces and what does not, how our error compares with the papers', and the
    main gap with its measured cause."""
    judged = [c for c in claims if c["verdict"] in ("holds", "partly", "does not")]
    names = lambda cs: ", ".join(lower_first(C.claim_label(c["id"])) for c in cs)
    parts = []
    if not judged:
        parts.append(f"None of the {len(claims)} published claims can be judged from these results: each needs runs or experiments "
                     "that are not among them (the scorecard names the command for each).")
    else:
        by = {v: [c for c in judged if c["verdict"] == v] for v in ("holds", "partly", "does not")}
        verb = {"holds": ("holds", "hold"), "partly": ("holds partly", "hold partly"), "does not": ("does not", "do not")}
        said = [f"{len(by[v])} {verb[v][len(by[v]) != 1]} ({names(by[v])})" for v in ("holds", "partly", "does not") if by[v]]
        rest = len(claims) - len(judged)
        s = (f"Of the {len(judged)} published claims these results judge (robot profile), " + (", ".join(said[:-1]) + " and " if len(said) > 1 else "")
             + said[-1] + (f"; {rest} more need runs or experiments not included here" if rest else "") + ".")
        if field_claims:
            fj = [f for f in field_claims.values() if f["verdict"] in ("holds", "partly", "does not")]
            if fj:
                cnt = {v: sum(f["verdict"] == v for f in fj) for v in ("holds", "partly", "does not")}
                s += (f" Under the field_robot profile (the camera blurred, defocused and tilted, its mirror decentred) {cnt['holds']} of "
                      f"{len(fj)} hold, {cnt['partly']} partly, {cnt['does not']} do not.")
        parts.append(s)
    used = []
    pos, head, n = error_ratios(ctx.papers, ctx.runs, used)
    if pos is not None and head is not None:
        s = (f"Our simulated tracking error is about {fnum(pos, 2)}x the papers' in position and {fnum(head, 2)}x in heading "
             f"(median of ours / paper over the {n} published error-table row{'s' if n != 1 else ''} we ran, robot profile")
        cov = coverage_sentence(used)
        if cov:
            s += f"; {cov}"
        field = field_robot_runs(ctx.runs)
        if field:
            with R.pairing_profile("field_robot"):
                fp, fh, fn = error_ratios(ctx.papers, field)
            if fp is not None and fh is not None:
                s += f"; field_robot: {fnum(fp, 2)}x and {fnum(fh, 2)}x over {fn} row{'s' if fn != 1 else ''}"
        parts.append(s + ").")
    failing = {c["id"]: c for c in judged if c["verdict"] != "holds"}
    gap = next((failing[i] for i in MAIN_GAP if i in failing), None) or next((c for c in judged if c["verdict"] != "holds" and c["kind"] == "accuracy"), None)
    if gap:
        k = next((k for k in causes if k["id"] == gap["id"] and k["profile"] == "robot"), None)
        s = f"The main gap is {lower_first(C.claim_label(gap['id']))} ({gap['verdict']}; ours / paper: {ratio_text(gap)}). "
        if k and k["summary"]:
            measured = next((e for e in k["evidence"] if e["value"] is not None), None)
            s += "Cause: " + k["summary"].rstrip(".") + "." + (f" Measured here: {C.evidence_text(measured)}." if measured else "")
            if k["status"] != C.EXPLAINED:
                s += f" (Cause status: {k['status']}.)"
        else:
            s += "no cause is recorded for it yet."
        parts.append(s)
    elif judged:
        parts.append("Every claim these results judge holds.")
    rep.para("**In short.** " + " ".join(parts), "headline", "headline")


# ---- few seeds: every seed's value, intervals that say their method, outliers with their cause ----

SEED_METRICS = [("x_cm/mean", "mean x cm", 2), ("y_cm/mean", "mean y cm", 2), ("theta_rad/mean", "mean th rad", 4)]


def coverage_cols(runs):
    """The coverage columns of a table of these runs, shown before its errors: [(metric, header)]
    for the recall at the runs' headline threshold and the share of frames answered, each where the
    runs record it (runs made before recall was scored: answered only, or nothing)."""
    head = R.headline_key(runs)
    cols = [(f"recall/{head}", f"within {R.recall_label(head)}")] if head else []
    if any(r.lookup("valid_fraction")[0] for r in runs):
        cols.append(("valid_fraction", "answered"))
    return cols


def seed_values_text(sel, values, flagged, digits, nulls=()):
    """'s1 3.10, s2 806.00 (outlier), s3 no estimate': every seed's value beside the mean."""
    nulls = set(nulls)
    return ", ".join(f"s{r.seed}\u00a0" + ("no estimate" if i in nulls else fnum(v, digits)) + ("\u00a0(outlier)" if i in flagged else "")
                     for i, (r, v) in enumerate(zip(sel, values)))


def interval_text(st, digits):
    """One metric over seeds as every tool prints it (R.interval_text: t95 for n >= 5, the seeds'
    range below, n = 1 marked)."""
    return R.interval_text(st, digits)


def flag_outliers(sel, metric="x_cm/mean", phase="tracking"):
    """The runs of one row (seeds) whose error is far above the others' (R.outliers)."""
    vals = [r.metric(metric, phase) for r in sel]
    return [sel[i] for i in R.outliers(vals)] if None not in vals else []


def outlier_cause(run, wrong_m=0.5):
    """What happened in an outlying run, read from frames.csv (robot 0) and events.jsonl: when the
    position error went above `wrong_m` for good and what the localizer said it was doing then."""
    frames = [f for f in run.frames() if f.get("robot", "0") == "0" and f.get("err_pos") not in (None, "")]  # scored frames (with truth)
    if not frames:
        return "no frames.csv to read the cause from"
    events = []
    ev = run.folder / "events.jsonl"
    if ev.exists():
        for line in ev.read_text().splitlines():
            try:
                e = json.loads(line)
            except json.JSONDecodeError:
                continue
            if e.get("type") in EVENT_COLOURS:
                events.append(e)
    err = [(float(f["t"]), float(f["err_pos"]) if f.get("valid") == "1" else math.nan, f.get("mode", "")) for f in frames]
    bad = lambda e: not (e <= wrong_m)  # a frame without an estimate counts as wrong
    e_end = err[-1][1]
    if bad(e_end):
        k = len(err) - 1
        while k > 0 and bad(err[k - 1][1]):
            k -= 1
        stretch = err[k:]
        t0 = stretch[0][0]
        valid = sorted(e for _, e, _ in stretch if not math.isnan(e))
        typical = f"{fnum(R.percentile(valid, 0.5), 2)} m from the truth (median)" if valid else "no estimate"
        before = [e for e in events if e["t"] <= t0 + 0.5]
        after_event = f", after the {before[-1]['type']} at t = {before[-1]['t']:.1f} s" if before else ""
        since = "from the start" if k == 0 else f"from t = {t0:.1f} s{after_event}"
        # The localizer claimed a pose (a mode other than searching / lost) that was wrong: the
        # worst failure, as it does not know it is lost.
        sure = [(t, e, m) for t, e, m in stretch if not math.isnan(e) and m not in ("global", "lost", "coasting", "searching", "")]
        if sure:
            share = 100.0 * len(sure) / len(stretch)
            return (f"converged to a wrong pose at t = {sure[0][0]:.1f} s: {typical}, mode '{sure[0][2]}' in {share:.0f} % of the frames "
                    f"{since} to the end; " + (f"never within {wrong_m} m" if k == 0 else f"not within {wrong_m} m again"))
        return f"lost {since}: {typical}, no confident estimate (mode '{stretch[-1][2]}') to the end"
    # Right at the end: what made the seed's mean large is the time it spent on a wrong pose, not a
    # momentary "peak" (a seed 8.8 m off for 37 s of 60 is a failure of 37 s): say how long, when and how far.
    times = [t for t, _, _ in err]
    steps = [b - a for a, b in zip(times, times[1:])]
    dt = statistics.median(steps) if steps else 0.0
    dur = lambda k: (times[k + 1] - times[k]) if k + 1 < len(times) else dt  # a frame lasts to the next one
    total = times[-1] - times[0] + dt
    wrong = [k for k, (_, e, _) in enumerate(err) if not math.isnan(e) and e > wrong_m]
    if not wrong:
        worst = max(err, key=lambda x: -1 if math.isnan(x[1]) else x[1])
        return f"never on a wrong pose (> {wrong_m} m off): at most {fnum(worst[1], 2)} m at t = {worst[0]:.1f} s"
    # The longest stretch of consecutive wrong frames: from its first frame to the next right one.
    stretches, cur = [], [wrong[0]]
    for k in wrong[1:]:
        if k == cur[-1] + 1:
            cur.append(k)
        else:
            stretches.append(cur)
            cur = [k]
    stretches.append(cur)
    longest = max(stretches, key=lambda st: sum(dur(k) for k in st))
    a, b = times[longest[0]], times[longest[-1]] + dur(longest[-1])
    before = [e for e in events if e["t"] <= a + 0.5]
    off = statistics.median(err[k][1] for k in longest)
    return (f"on a wrong pose (> {wrong_m} m off) for {sum(dur(k) for k in wrong):.1f} s of {total:.1f} s"
            + (", longest" if len(stretches) > 1 else ",") + f" from t = {a:.1f} to {b:.1f} s"
            + (f" (after the {before[-1]['type']} at t = {before[-1]['t']:.1f} s)" if before else "")
            + f", {fnum(off, 2)} m off (median); within {wrong_m} m at the end")


def seed_table(rep, rows_runs, phase="tracking", caption_extra=""):
    """Per row: every seed's value of mean x, y and heading, their median, mean and 95 % interval
    with its method, and the outlying seeds with their cause. rows_runs: [(label, runs sorted by
    seed)]. Returns the outlying runs, which the caller plots."""
    rows, classes, flagged_runs, methods = [], [], [], set()
    rep.__dict__.setdefault("seeded", set()).update(r.folder for _, sel in rows_runs for r in sel)  # shown once (report_sweep)
    # Coverage first (percent of all frames), then the errors over the answered frames.
    metrics = [(m, f"{h}, % of frames", 1, 100.0) for m, h in coverage_cols([r for _, sel in rows_runs for r in sel])] + \
        [(m, name, digits, 1.0) for m, name, digits in SEED_METRICS]
    for label, sel in rows_runs:
        if not sel:
            continue
        out = flag_outliers(sel, phase=phase)
        flagged_runs += out
        row = [label, len(sel)]
        for metric, _, digits, scale in metrics:
            found = [r.lookup(metric, phase) for r in sel]
            vals = [v * scale if R.is_number(v) else None for _, v in found]
            nulls = [i for i, (f, v) in enumerate(found) if f and v is None]  # no estimate in that seed
            st = R.stats(vals)
            if st["method"]:
                methods.add(st["method"])
            flagged = {i for i, r in enumerate(sel) if r in out} if metric == "x_cm/mean" else set()  # the metric flagged on
            # One cell per metric (the mean with its interval, the median, every seed): a table a
            # reader takes in without scrolling sideways.
            if not st["n"] and nulls:
                row.append(R.no_estimate_text(len(nulls), len(sel)))
                continue
            row.append(f"mean {interval_text(st, digits)}; median {fnum(st['median'], digits)}; seeds: {seed_values_text(sel, vals, flagged, digits, nulls)}"
                       + (f" ({R.no_estimate_text(len(nulls), len(sel))}: the mean is over the others)" if nulls else ""))
        row.append("; ".join(f"s{r.seed}: {outlier_cause(r)}" for r in out) or "-")
        rows.append(row)
        classes.append("outlier" if out else "")
    if not rows:
        return []
    header = ["row", "n"] + [name for _, name, _, _ in metrics]
    rep.table(header + ["outlying seeds and cause"], rows,
              "Every seed beside the mean: mean with its interval; median; each seed's value. "
              + ("The share of frames within the headline threshold (a frame without an estimate counts as outside) and the share answered come "
                 "first; the errors after them are over the answered frames, and a seed without any says 'no estimate'. "
                 if len(metrics) > len(SEED_METRICS) else "")
              + "The " + R.INTERVAL_RULE_TEXT + ". A seed is flagged as an outlier when its mean x error lies above 3x "
              "the median of the other seeds and further from it than 3x their range; its cause is read from its frames.csv and events.jsonl."
              + caption_extra, classes)
    return flagged_runs


def strip_plot(rep, title, rows_runs, phase="tracking"):
    """Each seed's mean x error (cm) and mean heading error (rad) as dots per row, the mean as a bar:
    a reader sees at once whether a mean is one seed's doing. Log scale where values span > 30x."""
    rows_runs = [(l, s) for l, s in rows_runs if s]
    if not rows_runs:
        return
    fig, axes = plt.subplots(1, 2, figsize=(10, 0.42 * len(rows_runs) + 1.3), sharey=True)
    # A seed without an estimate has no dot: its row's label says so (never a dot at 0).
    missing = [sum(1 for r in sel if r.lookup("x_cm/mean", phase) == (True, None)) for _, sel in rows_runs]
    for ax, (metric, unit) in zip(axes, [("x_cm/mean", "mean x error per seed (cm)"), ("theta_rad/mean", "mean heading error per seed (rad)")]):
        allv = []
        for k, (label, sel) in enumerate(rows_runs):
            vals = [r.metric(metric, phase) for r in sel]
            vals = [v for v in vals if v is not None]
            if not vals:
                continue
            out = set(R.outliers(vals))
            jitter = [(i - (len(vals) - 1) / 2) * 0.12 for i in range(len(vals))]
            ax.scatter([v for i, v in enumerate(vals) if i not in out], [k + jitter[i] for i in range(len(vals)) if i not in out],
                       s=18, color="#1f77b4", zorder=3)
            if out:
                ax.scatter([vals[i] for i in out], [k + jitter[i] for i in out], s=30, color="#d62728", marker="D", zorder=4,
                           label="outlying seed" if not ax.get_legend_handles_labels()[1] else None)
            m = sum(vals) / len(vals)
            ax.plot([m, m], [k - 0.3, k + 0.3], color="black", lw=1.5, zorder=2)
            allv += vals
        pos = [v for v in allv if v > 0]
        if pos and max(pos) / max(min(pos), 1e-12) > 30:
            log_axis(ax.xaxis, ax, "x")
            unit += ", log scale"
        else:
            ax.set_xlim(left=0)
            ax.xaxis.set_major_locator(MaxNLocator(6))
        ax.set_xlabel(unit)
        ax.grid(axis="x", alpha=0.3)
        if ax.get_legend_handles_labels()[1]:
            ax.legend(fontsize=7, loc="lower right")
    axes[0].set_yticks(range(len(rows_runs)))
    axes[0].set_yticklabels([l + (f" ({R.no_estimate_text(k, len(sel))})" if k else "") for (l, sel), k in zip(rows_runs, missing)], fontsize=8)
    axes[0].invert_yaxis()
    rep.figure(fig, "seeds", f"{title}: every seed (dots; red diamonds: outlying seeds), the mean over seeds (black bar)")


def log_axis(axis, ax, which):
    """A log axis with several labelled ticks (1, 2, 5 per decade) in plain numbers, not one lone 10^k."""
    from matplotlib.ticker import LogLocator, FuncFormatter, NullFormatter
    (ax.set_xscale if which == "x" else ax.set_yscale)("log")
    lo, hi = ax.get_xlim() if which == "x" else ax.get_ylim()
    decades = math.log10(hi / lo) if lo > 0 and hi > lo else 1.0
    # 1-2-5 per decade on a short axis; on a long one they would collide: decades only.
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0) if decades <= 3.2 else (1.0,), numticks=15))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())



def command(cmd):
    """The command that runs a missing row: under the field_robot profile, its own suite."""
    if R.DEFAULT_PROFILE == "field_robot":
        return cmd.replace("sweeps/paper_suite.json", "sweeps/paper_suite_field_robot.json")
    return cmd


def error_table(rep, papers, table, runs):
    t = papers[table]
    rep.heading(C.table_label(table) + profile_suffix(), 3, table)
    pairs = C.pair_table(papers, table, runs)
    cov, cov_head = C.table_coverage(pairs)
    rep.para(f"Published: {t.get('source', table)} (results/reference/papers.json); th: heading. Ours: mean over seeds of each run's statistic (robot 0), with n; "
             "runs with kidnaps or covers use their tracking phase (see docs/results.md). Paper rows in italics, then ours / paper."
             + (" Our rows lead with the share of all frames within the headline threshold (a frame without an estimate counts as outside) "
                "and the share answered: the errors after them, like the papers', are over the answered frames only; 'no estimate' where "
                "a run answered no frame." if cov else ""))
    header = ["row", "source"] + cov_head + R.TABLE_COLS + ["line points / frame", "seeds"]
    rows, classes = [], []
    for p in pairs:
        st = p["stats"]
        if p["runs"]:
            label = p["shown"] + (" (tracking phase)" if p["phased"] else "")
            rows.append([label, "omniloc"] + C.row_cells(st, cov, p["runs"]))
            classes.append("")
        else:
            rows.append([p["label"], "not run"] + ["-"] * (len(cov) + 9) + ["-", 0])
            classes.append("missing")
        for peer in p.get("peers", []):  # external localizers (docs/protocol.md), same scenario, configuration and start pose
            rows.append([peer["row"], f"external: {peer['name']}"] + C.row_cells(peer["stats"], cov, peer["runs"]))
            classes.append("")
        if p["published"]:
            rows.append([p["label"], "paper"] + ["-"] * len(cov) + [fnum(v, 3) for v in p["published"]] + ["-", "-"])
            classes.append("paper")
            if p["runs"]:
                mean = lambda m: st[m]["mean"]
                rows.append([p["label"], "ours / paper"] + [""] * len(cov) + [fnum(mean(f"{a}/{s}") / v, 2) if v and mean(f"{a}/{s}") is not None else "-"
                                                                             for (a, s), v in zip(R.TABLE_KEYS, p["published"])] + ["", ""])
                classes.append("ratio")
    rep.table(header, rows, row_classes=classes)
    missing = [p for p in pairs if not p["runs"]]
    if missing:  # one line each, collapsed: the command is what a reader needs, not a page of it
        rep.details(f"{len(missing)} row(s) not run, and the command that runs them")
        for p in missing:
            rep.para(f"Not run: \"{p['label']}\" ({R.describe_key(p['key'])}). Run: `{command(p['command'])}`")
        rep.end_details()
    # Every seed beside its mean, and the outlying seeds plotted with their cause.
    rows_runs = [(p["shown"], p["runs"]) for p in pairs] + [(f"{q['row']} (external: {q['name']})", q["runs"]) for p in pairs for q in p.get("peers", [])]
    flagged = seed_table(rep, rows_runs)
    strip_plot(rep, t.get("source", table), rows_runs)
    for run in flagged:
        plot_run(rep, run, f"outlying seed: {run_title(run)}: {outlier_cause(run)}")


def profile_suffix():
    """' (field_robot profile)' in a heading of a table paired under another profile than the
    scenarios' own: each section heading once in the report."""
    return "" if R.DEFAULT_PROFILE == R.SCENARIO_DEFAULT_PROFILE else f" ({R.DEFAULT_PROFILE} profile)"


def kidnap_table(rep, papers, runs):
    rep.heading("Kidnap recovery (papers 002 and 000)" + profile_suffix(), 3, "kidnapping")
    rows, classes = [], []
    for table in ("002_kidnapping", "000_kidnapping"):
        t = papers[table]
        for label, key in t["reproduced_by"]["rows"].items():
            sel = R.select(runs, key)
            if sel:
                # Counts: a run without a recovery block counts none. Statistics: run_stats, so that a
                # null (no kidnap recovered, no estimate) reads as such, never as 0.
                ep = sum(r.metric("recovery/episodes", "all") or 0 for r in sel)
                rec = sum(r.metric("recovery/recovered", "all") or 0 for r in sel)
                fal = sum(r.metric("recovery/false_recoveries", "all") or 0 for r in sel)
                med = R.run_stats(sel, "recovery/recovery_time_s/median", "all")
                after = R.run_stats(sel, "recovery/after_recovery/x_cm/mean", "all")
                phase = R.run_stats(sel, "x_cm/mean", "tracking")
                allf = R.run_stats(sel, "x_cm/mean", "all")
                per_seed = ", ".join(f"s{r.seed}\u00a0{r.metric('recovery/recovered', 'all') or 0:.0f}/{r.metric('recovery/episodes', 'all') or 0:.0f}"
                                     f"\u00a0{seed_cell(r, 'x_cm/mean', 'tracking', 2)}" for r in sel)
                rows.append([f"{C.table_label(table)}: {label}", "omniloc", f"{rec:.0f} / {ep:.0f}", f"{fal:.0f}",
                             R.stat_cell(med, 2) if med["n"] or not med["no_value"] else "none recovered", R.stat_cell(after, 2),
                             answered_beside(R.stat_cell(phase, 2), sel, "tracking"), answered_beside(R.stat_cell(allf, 1), sel, "all"), per_seed, len(sel)])
                classes.append("")
            else:
                rows.append([f"{C.table_label(table)}: {label}", "not run", "-", "-", "-", "-", "-", "-", "-", 0])
                classes.append("missing")
            rows.append([f"{C.table_label(table)}: {label}", "paper", f"{t['recovered']} / {t['kidnaps']}", "-", "-", "-", "-", "-", "-", "-"])
            classes.append("paper")
    rep.table(["case", "source", "recovered / kidnaps", "false recoveries", "median recovery s", "after recovery: mean x cm",
               "tracking phase: mean x cm", "all frames: mean x cm", "per seed: recovered, tracking-phase mean x cm", "seeds"], rows,
              "Over all seeds, and every seed beside the means. Recovered: error under 0.3 m and 0.2 rad for 1 s. The tracking phase leaves out the carried period and the time to recovery; "
              "'all frames' includes them (that is why it is large). The errors are over the frames answered (their share beside them); "
              "'no estimate' where a run answered none, 'no kidnap recovered' where no recovery left a frame to score.", classes)


def seed_cell(run, path, phase, digits):
    """One run's statistic: its value, or "no estimate" where it is null (see R.Run.lookup)."""
    found, v = run.lookup(path, phase)
    return R.NO_ESTIMATE if found and v is None else fnum(run.metric(path, phase), digits)


def answered_beside(cell, runs, phase):
    """An error cell with the share of frames answered beside it: '2.31 (answered 98.0 %)' (mean
    over the runs; the cell alone for runs made before valid_fraction)."""
    st = R.run_stats(runs, "valid_fraction", phase)
    return f"{cell} (answered {R.percent(st['mean'])})" if st["n"] else cell


def timing_table(rep, papers, runs):
    t = papers["timings_ms"]
    rep.heading("Timings (papers 002 and 000)", 3, "timings_ms")
    rows, classes = [], []
    for row, key in t["reproduced_by"]["rows"].items():
        med, frames, sel = C.timing_ms(papers, row, runs)
        lo, hi = t[row]
        rows.append([C.timing_label(row), key["what"], fnum(med, 2) if med is not None else "not run", f"{lo}-{hi}", fnum(med / hi, 2) if med is not None else "-", frames])
        classes.append("" if med is not None else "missing")
    rep.table(["published figure", "what", "ours: median ms", "paper ms", "ours / paper's upper bound", "frames"], rows,
              f"Ours: wall time on {machine_text()}, runs of a sweep share the cores; paper: {t['cpu']}.", classes)


def experiment_section(rep, ctx, key, title):
    """Heading of a published table reproduced by an experiment; (table, the experiment's JSON or None)."""
    t = ctx.papers[key]
    rb = t["reproduced_by"]
    j = ctx.experiment_json(rb["experiment"], rb["file"])
    rep.heading(title, 3, key)
    if j is None:
        rep.para(f"Not run: {rb['command']}")
    return t, j


def experiment_tables(rep, papers, ctx):
    # 001: equal vs 1/L weights.
    t, j = experiment_section(rep, ctx, "001_cooperative_mean_error_mm", "Paper 001: cooperative ball localisation, equal vs 1/L weights")
    rb = t["reproduced_by"]
    if j is not None:
        eq, w = R.pointer(j, rb["equal_weights"])[1], R.pointer(j, rb["weighted"])[1]
        rows = [["omniloc", fnum(eq, 1), fnum(w, 1), fnum(w / eq, 3) if eq else "-", (j.get("trials") or {}).get("path", "-")],
                ["paper", fnum(t["equal_weights"], 1), fnum(t["weighted"], 1), fnum(t["weighted"] / t["equal_weights"], 3), "-"],
                ["ours / paper", fnum(eq / t["equal_weights"], 2), fnum(w / t["weighted"], 2), "", ""]]
        rep.table(["source", "equal weights mm", "1/L weights mm", "1/L / equal", "trials"], rows,
                  "Published: results/reference/papers.json; ours from results/experiments/cooperative_001/cooperative_001.json (headline).",
                  ["", "paper", "ratio"])
    g = (j or {}).get("growth_model") or {}
    rep.heading("Paper 001: FBPF vs MFBPF on the growth model", 3, "001_growth_model")
    if g:
        rows = [[k, fnum(v.get("mean"), 3), fnum(v.get("std"), 3), fnum(v.get("median"), 3)] for k, v in g.items() if isinstance(v, dict) and "std" in v]
        rep.table(["filter", "mean RMSE", "std", "median"], rows, f"paper: {papers['001_growth_model']['claim']} ({papers['001_growth_model']['setup']}); "
                  f"ours: {g.get('verdict', '')}")
    else:
        rep.para(f"Not run: {papers['001_growth_model']['reproduced_by']['command']}")
    rv = (j or {}).get("robots_vs_error") or []
    rep.heading("Paper 001: error against the number of robots (fig. 10)", 3, "001_simulation_setup")
    if rv:
        rep.table(["robots", "equal, all subsets mm", "1/L, all subsets mm", "1/L median mm"],
                  [[r["robots"], fnum(r["equal_all_mm"], 1), fnum(r["weighted_all_mm"], 1), fnum(r["weighted_median_all_mm"], 1)] for r in rv],
                  f"paper: {papers['001_simulation_setup']['robots_vs_error']}")
        fig, ax = plt.subplots(figsize=(6.5, 3.6))
        ks = [r["robots"] for r in rv]
        ax.plot(ks, [r["equal_all_mm"] for r in rv], "o-", label="equal weights")
        ax.plot(ks, [r["weighted_all_mm"] for r in rv], "s-", label="1/L weights")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylim(bottom=0)
        ax.set_xlabel("number of robots")
        ax.set_ylabel("mean ball error (mm)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        rep.figure(fig, "robots_vs_error", "paper 001 fig. 10 reproduced: mean ball error against the number of robots (all subsets)")
    else:
        rep.para(f"Not run: {papers['001_simulation_setup']['reproduced_by']['command']}")
    rep.para(f"{C.table_label('001_real_mean_error_cm')} (8.6 -> 4.5 cm) needs real robots and is not reproduced.")

    # 004 table 1.
    t, j = experiment_section(rep, ctx, "004_table1_cm", "Paper 004 table 1: two-circle and three-point fixes (cm)")
    if j is not None:
        tab = (j.get("tables") or [{}])[0]
        rows, classes = [], []
        for k, r in enumerate(tab.get("rows", [])):
            ours = r.get("ours", {})
            err = lambda solver: (ours.get(solver) or {}).get("mean_err_cm")
            tc, tp = err("two_circle_004"), err("three_point_004")
            pub = t["rows"][k] if k < len(t["rows"]) else None
            rows.append([f"({r['true_cm'][0]:.0f}, {r['true_cm'][1]:.0f})", "omniloc", fnum(tc, 2), fnum(tp, 2),
                         fnum(err("two_circle_eq8_literal"), 1), fnum(err("two_circle_eq9_literal"), 1)])
            classes.append("")
            if pub:
                rows.append(["", "paper", fnum(pub[4], 2), fnum(pub[7], 2), "", ""])
                classes.append("paper")
                rows.append(["", "ours / paper", fnum(tc / pub[4], 2) if tc is not None else "-", fnum(tp / pub[7], 2) if tp is not None else "-", "", ""])
                classes.append("ratio")
        rep.table(["true position", "source", "two-circle error", "three-point error", "eq. (8) as printed", "eq. (9) as printed"], rows,
                  f"mean error (cm) over {tab.get('trials', '-')} trials per position, bearing noise N(0, {tab.get('bearing_sigma_deg', '-')} deg); "
                  f"the last two columns evaluate paper 004's two-circle equations literally (diagnostic, see docs/landmarks.md); {tab.get('trend', '')}", classes)

    # 003 simulation.
    t, j = experiment_section(rep, ctx, "003_simulation", "Paper 003: landmark groups with voting (simulation)")
    if j is not None:
        rows = []
        for case, v in j.items():
            s = v.get("all_paths") if isinstance(v, dict) else None
            if s:
                rows.append([case.replace("_", " "), s.get("frames"), s.get("group_fixes"), fnum(s.get("fixes_max_m"), 2), fnum(s.get("no_voting_mean_m"), 3),
                             fnum(s.get("no_voting_max_m"), 2), fnum(s.get("voting_mean_m"), 3), fnum(s.get("voting_max_m"), 2)])
        rep.table(["case", "frames", "group fixes", "worst fix m", "no voting: mean m", "max m", "voting: mean m", "max m"], rows,
                  f"paper: {t['source']}; max error after voting about {t['max_error_m_after_voting']} m")


def profile_of(run):
    found, prof = R.pointer(run.config, "/noise_profile")
    return prof if found else R.SCENARIO_DEFAULT_PROFILE


def field_robot_tables(rep, papers, runs):
    """The published rows again, from runs under the field_robot profile (issue 17)."""
    field = [r for r in runs if profile_of(r) == "field_robot"]
    if not field:
        return
    rep.heading("Published tables under the field_robot profile", 2, "field_robot")
    rep.para("The same keyed rows from runs under the field_robot noise profile: the robot profile plus defocus, motion blur, tilt "
             "from acceleration and a 9 px decentred mirror that calibration estimates (docs/camera.md). Compare with the tables "
             "above (robot profile). Nothing here is tuned to the papers' numbers; what moves is reported as measured.")
    with R.pairing_profile("field_robot"):  # the same keys, these runs
        for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
            error_table(rep, papers, table, field)
        kidnap_table(rep, papers, field)


def error_budget_section(rep, ctx):
    """Table and bar chart of `omniloc experiment error_budget` (issue 17)."""
    d = ctx.experiments.get("error_budget")
    f = d / "error_budget.json" if d else None
    if not f or not f.exists():
        return
    j = json.loads(f.read_text())
    rep.heading("Error budget: which source dominates", 2, "error_budget")
    rep.para(f"`omniloc experiment error_budget`{' --quick' if j.get('quick') else ''}: the tracking path for {j['duration_s']:.0f} s, "
             f"{j['seeds']} seed(s) from {j['first_seed']}; each row adds one error source to the baseline (ideal camera, exact odometry "
             "and compass, exact calibration map), the last rows put them all together. Position RMSE in cm (mean over seeds). "
             "`decentring` goes through the model-free calibration: compare it with `calibration map`.")
    rows_by_source, locs = {}, []
    for r in j["rows"]:
        rows_by_source.setdefault(r["source"], {})[r["localizer"]] = r
        if r["localizer"] not in locs:
            locs.append(r["localizer"])
    def cell(r, key):
        """mean [95 % interval] over the seeds (issue 29), or the mean alone for one seed or an old file."""
        if key not in r:
            return "failed" if key == "position_rmse_cm" else "-"
        if r[key] is None:  # over no answered frame: never a number
            return R.NO_ESTIMATE
        seeds = [x.get(key) for x in r.get("per_seed", [])]
        if len(seeds) < 2:
            return fnum(r[key], 2)
        if any(v is None for v in seeds):
            return fnum(r[key], 2) + f" ({R.no_estimate_text(sum(v is None for v in seeds), len(seeds))})"
        st = R.stats(seeds)
        if max(seeds) - min(seeds) <= 1e-9 * max(1.0, abs(st["mean"])):
            return f"{fnum(st['mean'], 2)} (= every seed)"
        return R.interval_text(st, 2)
    table = []
    for src, per in rows_by_source.items():
        line = [src]
        for l in locs:
            r = per.get(l, {})
            line += [cell(r, "position_rmse_cm"), cell(r, "position_p50_cm"), cell(r, "heading_rmse_deg")]
        table.append(line)
    header = ["source"] + [f"{l} {m}" for l in locs for m in ("RMSE cm", "p50 cm", "heading RMSE deg")]
    seeds_text = (f"Mean over {j['seeds']} seeds; {R.INTERVAL_RULE_TEXT}; "
                  "'= every seed' where every seed gave the same figure (the ideal baseline has no random source for "
                  "matching, so a row that adds a deterministic source is a systematic difference, not noise). ") if j.get("seeds", 1) > 1 else \
                 "One seed (quick mode): no interval; `omniloc experiment error_budget` runs three. "
    rep.table(header, table, seeds_text + f"Runs: {j['sweep']}; description: {j['config_file']}.")
    reference_error_text(rep, rows_by_source, ctx)
    import matplotlib.pyplot as plt
    sources = list(rows_by_source)
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(sources) + 1.5))
    h = 0.8 / max(1, len(locs))
    for i, l in enumerate(locs):
        vals = [v if R.is_number(v := rows_by_source[s].get(l, {}).get("position_rmse_cm")) else float("nan") for s in sources]
        ax.barh([k + i * h for k in range(len(sources))], vals, height=h, label=l)
    ax.set_yticks([k + 0.4 - h / 2 for k in range(len(sources))])
    ax.set_yticklabels(sources)
    ax.invert_yaxis()
    log_axis(ax.xaxis, ax, "x")
    ax.set_xlabel("position RMSE, cm (log scale)")
    ax.legend()
    ax.grid(axis="x", alpha=0.3)
    rep.figure(fig, "error_budget", "Position RMSE of the tracking path with each error source alone and all together.")


def reference_error_text(rep, rows_by_source, ctx):
    """Which real-robot error the simulation lacks (issue 29, item 4): the papers' heading error per
    cm of position error against every budget row's, and the reference wander the gap needs."""
    ratios = []
    for src, per in rows_by_source.items():
        r = per.get("matching", {})
        if r.get("position_rmse_cm") and R.is_number(r.get("heading_rmse_deg")):
            ratios.append((r["heading_rmse_deg"] / r["position_rmse_cm"], src))
    if not ratios:
        return
    top, top_src = max(ratios)
    # The paper 000 / 002 tracking row, ours (robot profile: the pairing default) and published.
    row = ["000_tracking", "tracking"]
    pub_x, pub_th = (C._published_cell(ctx.papers, row, m) for m in ("x_cm/mean", "theta_rad/mean"))
    x, n_note = C.quantity({"row": row, "metric": "x_cm/mean"}, ctx)
    th, _ = C.quantity({"row": row, "metric": "theta_rad/mean"}, ctx)
    gap = ""
    if x is not None and th is not None:
        wx = math.sqrt(max(0.0, pub_x ** 2 - x ** 2) * math.pi / 2)
        wt = math.degrees(math.sqrt(max(0.0, pub_th ** 2 - th ** 2) * math.pi / 2))
        gap = (f" Our tracking row (robot profile, {n_note}) has mean x {fnum(x, 2)} cm and heading {fnum(math.degrees(th), 2)} deg "
               f"against the papers' {pub_x} cm and {fnum(math.degrees(pub_th), 2)} deg; in quadrature (Gaussian errors, sigma = mean x sqrt(pi/2)) "
               f"the difference needs a reference that wanders by about {fnum(wx, 1)} cm and yaws by about {fnum(wt, 1)} deg per axis. "
               "Those are the magnitudes of a person pushing a 0.5 m robot along a painted line (argued, not measured: no real robot here).")
    rep.para("**Which real-robot error is missing.** The papers scored a robot pushed by hand along straight tracks against "
             "those tracks (paper 002 sec. 6), so their reference itself errs; ours is exact. The papers' table has "
             f"{fnum(math.degrees(pub_th) / pub_x, 2)} deg of heading error per cm of position error; the most any row above gives with "
             f"matching is {fnum(top, 2)} deg/cm (`{top_src}`). Every simulated source moves heading and position together, so none of them, "
             "scaled up to the papers' position error, reaches the papers' heading error: an error of the reference, which has no such "
             f"link, is the missing one.{gap} See docs/error_budget.md.")


def published_tables(rep, papers, ctx):
    rep.heading("Published tables beside ours", 2, "published")
    for table in ("002_table1_occlusion", "002_table2_lighting", "000_tracking"):
        error_table(rep, papers, table, ctx.runs)
    kidnap_table(rep, papers, ctx.runs)
    timing_table(rep, papers, ctx.runs)
    lo, hi = papers["mcl_only_mean_position_error_cm"]
    rep.para(f"{C.table_label('mcl_only_mean_position_error_cm')}: {lo}-{hi} cm, beside our MCL-alone row of the "
             f"{C.table_label('000_tracking')} above and the scorecard's claim \"{C.claim_label('mcl_alone')}\".")
    experiment_tables(rep, papers, ctx)


# ---- sweeps, runs, plots -------------------------------------------------------------------------

def global_start_section(rep, sweeps):
    """Issue 29: sweeps of scenarios/sweeps/global_tracking.json, each run judged apart by
    scripts/global_start.py. A mean over all frames hides one run 8 m off among nineteen at 3 cm, so
    MCL alone is shown as a success rate (Wilson 95 %), the error while right, and the mean over all."""
    import global_start as G
    for sw in sweeps:
        if not sw.name.startswith("global_tracking"):
            continue
        by = G.collect([sw])
        if not by:
            continue
        rep.heading(f"Global start, judged per run: {sw.name}", 2, "global_start")
        rows = []
        table = {loc: G.summarise([r for _, r in by[loc]]) for loc in sorted(by, key=lambda k: (k not in ("mcl", "hybrid", "grid_global"), k))}
        with_recall = any(g.get("recall_key") for g in table.values())
        none = lambda v, d, g: (R.NO_ESTIMATE if g["runs_without_estimate"] == g["runs"] else "-") if v is None else fnum(v, d)
        for loc, g in table.items():
            rows.append([loc] + ([R.percent(g["recall_mean"]), R.percent(g["answered_mean"]),
                                  fnum(g["first_within_median_s"], 2) + (f" ({g['runs_never_within']} never)" if g["runs_never_within"] else "")]
                                 if with_recall else []) +
                        [f"{g['ended_right']} / {g['runs']}", f"{100 * g['wilson95'][0]:.0f}-{100 * g['wilson95'][1]:.0f} %",
                         fnum(g["t_first_median_s"], 2), none(g["right_mean_x_cm"], 2, g), none(g["right_mean_y_cm"], 2, g),
                         none(g["right_mean_theta_rad"], 4, g), fnum(g["wrong_frame_fraction"] * 100 if g["wrong_frame_fraction"] is not None else None, 2),
                         none(g["all_mean_pos_cm"], 1, g)])
        head = G.recall_header(table)
        rep.table(["localizer"] + ([head, "answered", "first within it: median s"] if with_recall else []) +
                  ["ended right", "Wilson 95 %", "first correct convergence median s", "while right: mean x cm", "mean y cm",
                   "mean th rad", "wrong frames %", "mean position error over all valid frames cm"], rows,
                  "scripts/global_start.py (definitions there and in docs/global_localization.md). Paper 002's 'MCL alone 15-40 cm' "
                  "is to be read on the success rate and the error while right, not on the mean over all frames."
                  + (f" '{head}': the share of all frames within it (a frame without an estimate counts as outside), mean over runs; "
                     "'answered': the share of frames with an estimate." if with_recall else ""))


def field_lines(ax, run):
    f = run.folder / "field.json"
    if not f.exists():
        return
    fj = json.loads(f.read_text())
    kw = dict(color="#9a9a9a", lw=0.8, zorder=0)
    for ax_, ay, bx, by in fj.get("segments", []):
        ax.plot([ax_, bx], [ay, by], **kw)
    for cx, cy, r, start, sweep in fj.get("arcs", []):
        n = max(8, int(abs(sweep) / 0.05))
        ts = [start + sweep * i / n for i in range(n + 1)]
        ax.plot([cx + r * math.cos(t) for t in ts], [cy + r * math.sin(t) for t in ts], **kw)
    for gx, gw, gd in fj.get("goals", []):
        s = 1 if gx >= 0 else -1
        ax.plot([gx, gx + s * gd, gx + s * gd, gx], [-gw / 2, -gw / 2, gw / 2, gw / 2], color="#6a6a6a", lw=0.8, zorder=0)
    hx, hy = fj["length"] / 2 + fj["margin"], fj["width"] / 2 + fj["margin"]
    ax.set_xlim(-hx, hx)
    ax.set_ylim(-hy, hy)


def plot_run(rep, run, title):
    frames = run.frames()
    if not frames or run.folder in rep.plotted:  # each run's figure once (an outlier is plotted where it is flagged first)
        return
    rep.plotted.add(run.folder)
    events = [json.loads(l) for l in (run.folder / "events.jsonl").read_text().splitlines() if l.strip()] if (run.folder / "events.jsonl").exists() else []
    by_robot = {}
    for f in frames:
        by_robot.setdefault(f["robot"], []).append(f)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), gridspec_kw={"width_ratios": [1.3, 1, 1]})
    ax = axes[0]
    field_lines(ax, run)
    for rid, fr in sorted(by_robot.items()):
        gx, gy = [], []
        for f in fr:  # a break where the truth jumps (teleport / kidnap), not a line across the field
            x, y = float(f["gt_x"] or "nan"), float(f["gt_y"] or "nan")  # no truth: a gap
            if gx and not math.isnan(gx[-1]) and math.hypot(x - gx[-1], y - gy[-1]) > 0.5:
                gx.append(float("nan"))
                gy.append(float("nan"))
            gx.append(x)
            gy.append(y)
        ax.plot(gx, gy, "-", lw=1.2, label=f"truth r{rid}")
        v = [f for f in fr if f["valid"] == "1"]
        ax.plot([float(f["est_x"]) for f in v], [float(f["est_y"]) for f in v], ".", ms=1.5, label=f"estimate r{rid}")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("trajectory on the field", fontsize=10)
    ax.legend(fontsize=7, loc="upper right")
    kinds = sorted({e["type"] for e in events if e.get("type") in EVENT_COLOURS})
    for k, (col, label, unit, scale) in enumerate([("err_pos", "position error", "cm", 100.0), ("err_theta", "heading error", "deg", 180.0 / math.pi)]):
        ax = axes[1 + k]
        for rid, fr in sorted(by_robot.items()):
            v = [f for f in fr if f["valid"] == "1" and f.get(col) not in (None, "")]  # no error without truth
            ax.plot([float(f["t"]) for f in v], [abs(float(f[col])) * scale for f in v], lw=0.8, label=f"r{rid}", zorder=3)
        # Events: a triangle above the plotting area and a faint dashed line BEHIND the data, so a
        # mark never hides the error it explains.
        for e in events:
            c = EVENT_COLOURS.get(e.get("type"))
            if c:
                ax.axvline(e["t"], color=c, lw=0.6, ls=(0, (3, 3)), alpha=0.45, zorder=1)
                ax.plot([e["t"]], [1.0], marker="v", color=c, ms=6, transform=ax.get_xaxis_transform(), clip_on=False, zorder=4)
        t_end = max(float(f["t"]) for f in frames)
        for r in run.summary.get("robots", []):  # left out of the tracking phase: shaded
            for a, b in (r.get("tracking_phase") or {}).get("excluded", []):
                ax.axvspan(a, min(b, t_end), color="#999999", alpha=0.15, lw=0)
        ax.set_ylim(bottom=0)
        ax.xaxis.set_major_locator(MaxNLocator(8))
        ax.yaxis.set_major_locator(MaxNLocator(6))
        ax.set_xlabel("t (s)")
        ax.set_ylabel(f"{label} ({unit})")
        ax.grid(alpha=0.3)
        ax.set_title(label + (" (events, triangles: " + ", ".join(f"{k} {EVENT_COLOURS[k]}" for k in kinds) + ")" if kinds else ""), fontsize=9, pad=9)
    rep.figure(fig, "run", f"{title}: trajectory over the field, position and heading error over time"
               + (" (shaded: carried, blind or recovering, left out of the tracking phase)" if any("tracking_phase" in r for r in run.summary.get("robots", [])) else ""))


def params_text(params):
    """A sweep's parameters of a run ('occlusion={"fraction":0.5}') as code: configuration keys are
    what a reader writes in a sweep file, not prose."""
    return f"`{params}`" if params and params != "default" else (params or "")


def run_title(run, params=None, name=None):
    """'scenario / localizer / params / seed N (profile)'; name: the sweep's row name of the localizer
    (its label: two configurations of one localizer type in a sweep, e.g. mcl and mcl_as_published)."""
    s = run.summary
    parts = [s["scenario"], name or s["localizer"]] + ([params_text(params)] if params and params != "default" else []) + [f"seed {s['seed']}"]
    if ((s.get("omniloc") or {}).get("replay") or {}).get("recorded_with") == "not omniloc":
        return " / ".join(str(p) for p in parts) + " (a log not made by omniloc: no noise profile)"
    prof = profile_of(run)
    return " / ".join(str(p) for p in parts) + (f" ({prof} profile)" if prof != R.SCENARIO_DEFAULT_PROFILE else "")


# Position error statistics of a run's table (summary.json position_m): the mean is the typical
# error, the RMSE weighs the large ones more; a run from before position_m.mean shows "-".
POSITION_COLS = ["position mean m", "position RMSE m", "position p95 m"]


def block_cell(block, path, digits):
    """A statistic of one summary.json block: its value; where it is null, the block's why_null in
    short ("no estimate", "no kidnap recovered"); "-" where the block lacks it (an older run)."""
    found, v = R.find(block or {}, path)
    if found and v is None:
        why = (block or {}).get("why_null") or ""
        return why if why and not why.startswith(R.NO_ESTIMATE) else R.NO_ESTIMATE
    return fnum(v if R.is_number(v) else None, digits)


def position_cells(block):
    return [block_cell(block, f"position_m/{k}", 3) for k in ("mean", "rmse", "p95")]


def coverage_cells(block, key, with_answered):
    """The share of the block's frames within the headline threshold and the share answered."""
    return ([R.percent((block.get("recall") or {}).get(key))] if key else []) + ([R.percent(block.get("valid_fraction"))] if with_answered else [])


def first_fix_text(s, key):
    """'robot 0: first estimate at 0.03 s, first within 25 cm / 10 deg at 0.50 s' (never: 'never')."""
    parts = []
    for r in s.get("robots", []):
        if "first_estimate_s" not in r and "first_within_s" not in r:
            continue
        t = lambda k: "never" if r.get(k) is None else f"at {r[k]:.2f} s"
        parts.append(f"robot {r.get('robot', 0)}: first estimate {t('first_estimate_s')}"
                     + (f", first within {R.recall_label(key)} {t('first_within_s')}" if key else ""))
    return "; ".join(parts)


def report_run(rep, run, plots, params=None, note=None, name=None):
    s = run.summary
    title = run_title(run, params, name) + (f" ({note})" if note else "")
    rep.heading(f"Run {title}", 3)
    rows = []
    key = run.headline
    answered = any("valid_fraction" in r for r in s.get("robots", []))
    for r in s.get("robots", []):
        rows.append([f"r{r['robot']}" + (" all frames" if "tracking_phase" in r else "")] + coverage_cells(r, key, answered) +
                    [block_cell(r, f"{a}/{st}", 3) for a, st in R.TABLE_KEYS] + position_cells(r) + [r.get("frames", "-")])
        if "tracking_phase" in r:
            tp = r["tracking_phase"]
            rows.append([f"r{r['robot']} tracking phase"] + coverage_cells(tp, key, answered) + [block_cell(tp, f"{a}/{st}", 3) for a, st in R.TABLE_KEYS]
                        + position_cells(tp) + [tp.get("frames", "-")])
    task = R.start_pose_text(run.start_pose_given)
    first = first_fix_text(s, key)
    rep.table(["robot"] + ([f"within {R.recall_label(key)}"] if key else []) + (["answered"] if answered else []) + R.TABLE_COLS + POSITION_COLS + ["frames"], rows,
              f"noise profile {s.get('noise_profile')}, {s.get('duration_s')} s at {s.get('camera_rate_hz')} Hz" + (f"; {task}" if task else "") +
              f"; omniloc {(s.get('omniloc') or {}).get('version', 'unrecorded')}"
              + ("; errors over the frames answered" if answered else "") + (f"; {first}" if first else ""))
    for r in s.get("robots", []):
        rec = r.get("recovery")
        if rec:
            rt = rec.get("recovery_time_s") or {}
            after = rec.get("after_recovery") or {}
            none = lambda v: "none recovered" if v is None and "recovery_time_s" in rec else fnum(v, 2)
            rep.table(["robot", "kidnaps", "recovered", "false", "mirrored", "median s", "max s", "after: mean x cm", "mean y cm"],
                      [[f"r{r['robot']}", rec.get("episodes", "-"), rec.get("recovered", "-"), rec.get("false_recoveries", "-"), rec.get("mirrored", "-"),
                        none(rt.get("median")), none(rt.get("max")), block_cell(after, "x_cm/mean", 2), block_cell(after, "y_cm/mean", 2)]],
                      "kidnap recovery (error under 0.3 m and 0.2 rad for 1 s)")
    if plots:
        plot_run(rep, run, title)


def sweep_runs(sweep, all_runs):
    """The sweep's runs in the aggregate's order (group by group, seeds in run order), with their
    params and the localizer name of their row: runs.csv's, the name the aggregate gives the row
    (docs/protocol.md "Which name"; a run missing from runs.csv: the name in its summary.json)."""
    by_folder = {r.folder: r for r in all_runs}
    order = {}
    for row in R.read_csv(sweep / "runs.csv"):
        order[row["id"]] = (int(row["index"]), row["params"], row.get("localizer"))
    agg = json.loads((sweep / "aggregate.json").read_text())
    group_rank = {(g.get("scenario"), g.get("localizer"), g.get("params")): k for k, g in enumerate(agg["groups"])}
    out = []
    for folder, run in by_folder.items():
        if folder.parent != sweep / "runs":
            continue
        idx, params, name = order.get(folder.name, (10 ** 9, "default", None))
        name = name or run.localizer
        rank = group_rank.get((run.scenario, name, params), 10 ** 9)
        out.append((rank, idx, run, params, name))
    return [(r, p, n) for _, _, r, p, n in sorted(out, key=lambda x: (x[0], x[1]))]


def aggregate_cell(metric, digits):
    """One metric of an aggregate.json group ({"n", "mean", "no_value", ...}): its mean; "no
    estimate" where no run had a value; "-" where the group lacks the metric."""
    if not metric:
        return "-"
    if metric.get("mean") is None:
        return R.NO_ESTIMATE if metric.get("no_value") else "-"
    return fnum(metric["mean"], digits)


def middle_recall_key(agg):
    """The middle recall threshold an aggregate names (its runs' headline where they do not say)."""
    keys = sorted({k.split("/")[-1] for g in agg.get("groups", []) for k in g.get("metrics", {}) if k.startswith("r0/recall/")}, key=R.recall_order)
    return keys[len(keys) // 2] if keys else None


def report_sweep(rep, sweep, all_runs, max_runs):
    agg = json.loads((sweep / "aggregate.json").read_text())
    name = agg.get("sweep", agg.get("name", sweep.name))
    rep.heading(f"Sweep {name}", 2)
    o = agg.get("omniloc") or {}
    rep.para(f"{sweep}: {agg.get('runs')} runs; aggregated by omniloc {o.get('version', 'unrecorded')}; runs made by "
             + ", ".join(f"{v} ({n})" for v, n in (agg.get("run_versions") or {}).items()) + ".")
    rows = []
    # Groups given the start pose say so where the sweep also has groups that were not (a sweep
    # from before start_pose_given has neither).
    kinds = {g.get("start_pose_given") for g in agg["groups"]}
    mark = True in kinds and (False in kinds or "mixed" in kinds)
    runs = sweep_runs(sweep, all_runs)
    key = R.headline_key([r for r, _, _ in runs]) or middle_recall_key(agg)
    answered = any("r0/valid_fraction" in g["metrics"] for g in agg["groups"])
    for g in agg["groups"]:
        m = g["metrics"]
        phase = "r0/tracking_phase/x_cm/mean" in m
        name = lambda path: f"r0/tracking_phase/{path}" if phase else f"r0/{path}"
        cell = lambda path, digits: aggregate_cell(m.get(name(path)), digits)
        x = m.get("r0/x_cm/mean", {})
        n, without = x.get("n", 0), x.get("no_value", 0)
        given = g.get("start_pose_given")
        task = " (given the start pose)" if mark and given is True else " (start pose: mixed)" if given == "mixed" else ""
        rows.append([f"{g.get('scenario', '')} / {g.get('localizer', '')}{task} / {params_text(g.get('params', ''))}" + (" (tracking phase)" if phase else "")] +
                    ([R.percent((m.get(name(f"recall/{key}")) or {}).get("mean"))] if key else []) +
                    ([R.percent((m.get(name("valid_fraction")) or {}).get("mean"))] if answered else []) +
                    [cell(f"{a}/{s}", 3) for a, s in R.TABLE_KEYS] + [cell("position_m/mean", 3), cell("position_m/rmse", 3)] +
                    [f"{g.get('finished', '-')}/{g.get('failed', 0)}", f"{n}; {R.no_estimate_text(without, n + without)}" if without else n])
    rep.table(["group"] + ([f"within {R.recall_label(key)}"] if key else []) + (["answered"] if answered else []) + R.TABLE_COLS +
              ["position mean m", "position RMSE m", "runs ok/failed", "n"], rows,
              "mean over seeds of each run's statistics (robot 0); runs with kidnaps or covers: tracking phase. Published rows: see 'Published tables beside ours'."
              + (f" 'within {R.recall_label(key)}': the share of all frames within that threshold (a frame without an estimate counts as outside); "
                 "'answered': the share of frames with an estimate; the errors are over the answered frames, 'no estimate' where no run of the "
                 "group answered any, and n counts the runs with a value (aggregate.csv also counts those without one)." if key or answered else ""))
    groups = {}
    for run, params, name in runs:
        groups.setdefault((run.scenario, name, params), []).append(run)
    rows_runs = [(f"{k[0]} / {k[1]} / {params_text(k[2])}", sorted(v, key=lambda r: r.seed)) for k, v in groups.items()]
    # Groups whose every seed a published table above already showed are not shown again.
    seeded = rep.__dict__.get("seeded", set())
    shown = [k for k, (_, sel) in enumerate(rows_runs) if sel and all(r.folder in seeded for r in sel)]
    if shown:
        rep.para(f"{len(shown)} of this sweep's {len(rows_runs)} groups have every seed in a published table above (with their outlying seeds); "
                 "they are not repeated here.")
    shown_flagged = [r for k in shown for r in flag_outliers(rows_runs[k][1])]
    rows_runs = [rr for k, rr in enumerate(rows_runs) if k not in shown]
    flagged = shown_flagged + seed_table(rep, rows_runs, caption_extra=" The sweep's aggregate.json and aggregate.csv hold the same intervals by the same rule (column interval: t95 or range).")
    # Per run: its tables always; plots for the first seed of each group (every condition shown
    # once, at most max_runs) and for every outlying seed, collapsed: a reader opens what they need.
    rep.details(f"Runs of sweep {name}: {len(runs)} runs, tables and plots")
    plotted, seen = 0, set()
    for run, params, name in runs:
        first = (run.scenario, name, params) not in seen
        seen.add((run.scenario, name, params))
        report_run(rep, run, plots=(first and plotted < max_runs) or run in flagged, params=params,
                   note=f"outlying seed: {outlier_cause(run)}" if run in flagged else None, name=name)
        plotted += first
    rep.end_details()
    return [r for r, _, _ in runs]


def tracking_errors(run, counts=None):
    """Position errors (m) of the valid frames of the tracking phase (outside the excluded intervals).
    `counts`, a dict, receives "frames": every tracking-phase frame, answered or not."""
    excl = {}
    for r in run.summary.get("robots", []):
        excl[str(r.get("robot"))] = (r.get("tracking_phase") or {}).get("excluded", [])
    out, total = [], 0
    for f in run.frames():
        if f.get("err_pos") in (None, ""):  # no truth: not scored
            continue
        t = float(f["t"])
        if any(a - 1e-9 <= t < b - 1e-9 for a, b in excl.get(f["robot"], [])):
            continue
        total += 1
        if f["valid"] != "1":
            continue
        out.append(float(f["err_pos"]))
    if counts is not None:
        counts["frames"] = counts.get("frames", 0) + total
    return out


def pooled_coverage(runs, key):
    """(recall at threshold `key`, share answered) pooled over every robot's tracking-phase frames
    of the runs, from their summary.json (recall x frames_total summed); None where unknown."""
    within = answered = total = 0.0
    for run in runs:
        for r in run.summary.get("robots", []):
            b = r.get("tracking_phase") if isinstance(r.get("tracking_phase"), dict) else r
            n = b.get("frames_total")
            if not R.is_number(n) or not n:
                continue
            rec, vf = (b.get("recall") or {}).get(key), b.get("valid_fraction")
            if not (R.is_number(rec) and R.is_number(vf)):
                continue
            within, answered, total = within + rec * n, answered + vf * n, total + n
    return (within / total, answered / total) if total else (None, None)


def cdf_and_timing(rep, runs):
    """Error CDF and timing per localizer AND noise profile (issue 38): frames of robot and
    field_robot runs are never pooled into one curve, row or bar; every row names its profile and
    how many runs its frames come from."""
    errs, timing, nruns, frames, by_key = {}, {}, {}, {}, {}
    for run in runs:
        key = (run.localizer, profile_of(run))  # (localizer, noise profile)
        nruns[key] = nruns.get(key, 0) + 1
        by_key.setdefault(key, []).append(run)
        errs.setdefault(key, []).extend(tracking_errors(run, frames.setdefault(key, {})))
        for r in run.timing():
            d = timing.setdefault(key, {"render_ms": [], "vision_ms": [], "localize_ms": [], "compute_ms": []})
            for k in d:
                if r.get(k) not in (None, ""):  # compute_ms: only an external client that reports its own time
                    d[k].append(float(r[k]))
    # A localizer that answered no frame stays in the table ("no estimate"); it has no curve.
    errs = {k: v for k, v in errs.items() if v or frames[k].get("frames")}
    profiles = sorted({p for _, p in list(errs) + list(timing)})
    head = R.headline_key(runs)
    name = lambda key: f"{key[0]} ({key[1]} profile)"
    runs_text = lambda key: f"{nruns[key]} run{'s' if nruns[key] != 1 else ''}"
    apart = (f"Per localizer and noise profile ({', '.join(profiles)}): runs of different profiles are never pooled." if len(profiles) > 1
             else f"All runs here are of the {profiles[0]} profile." if profiles else "")
    if errs:
        rep.heading("Error CDF per localizer and noise profile (tracking phase)", 2)
        fig, ax = plt.subplots(figsize=(7, 4))
        styles = {p: s for p, s in zip(profiles, ["-", "--", ":", "-."] * 4)}
        for key, e in sorted(errs.items()):
            if not e:
                continue
            # Over ALL tracking-phase frames: a frame without an estimate is never within any error,
            # so a curve levels off at the share answered (a localizer that answers only easy frames
            # does not look better).
            n = max(frames[key].get("frames", 0), len(e))
            e = sorted(max(x, 1e-4) for x in e)
            ax.plot(e, [(i + 1) / n for i in range(len(e))], styles[key[1]],
                    label=f"{name(key)}: {len(e)} of {n} frames answered, {runs_text(key)}")
        log_axis(ax.xaxis, ax, "x")
        ax.set_ylim(0, 1)
        ax.set_xlabel("position error (m, log scale)")
        ax.set_ylabel("share of all frames within the error")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        rep.figure(fig, "cdf", "position error CDF over the reported runs' tracking phases (carried periods and recoveries left out), "
                   "one curve per localizer and noise profile (line style: profile), over all their frames: a frame without an estimate "
                   "counts as never within, so each curve levels off at the share of frames answered. " + apart)
        q = lambda e, f: fnum(sorted(e)[int(f * (len(e) - 1))], 4) if e else R.NO_ESTIMATE
        cov = {key: pooled_coverage(by_key[key], head) if head else (None, None) for key in errs}
        rep.table(["localizer", "profile", "runs"] + ([f"within {R.recall_label(head)}", "answered"] if head else []) + ["frames", "median m", "p90 m", "p99 m"],
                  [[key[0], key[1], nruns[key]] + ([R.percent(cov[key][0]), R.percent(cov[key][1])] if head else []) +
                   [len(e), fnum(statistics.median(e), 4) if e else R.NO_ESTIMATE, q(e, 0.9), q(e, 0.99)] for key, e in sorted(errs.items())],
                  ("Coverage first: the share of all tracking-phase frames within the headline threshold (a frame without an estimate "
                   "counts as outside) and the share answered, pooled over the localizer's runs; then " if head else "")
                  + "the errors of the valid (answered) tracking-phase frames pooled over the localizer's runs (seeds and scenarios) under that one profile. " + apart)
    if timing:
        rep.heading("Timing per stage, per localizer and noise profile", 2)
        rows = []
        for key, d in sorted(timing.items()):
            rows.append([key[0], key[1], nruns[key]] + [fnum(statistics.median(v), 3) if v else "-" for v in d.values()] + [len(d["render_ms"])])
        rep.table(["localizer", "profile", "runs", "render ms (median)", "vision ms", "localize ms", "client's own ms", "frames"], rows,
                  f"wall time per frame on {machine_text()}; runs in a sweep share the cores. " + apart + " "
                  "For an external localizer (docs/protocol.md) 'localize' is the protocol's round trip: frame sent to estimate read, "
                  "the client's own computation included; 'client's own ms' is the time the client reported for its computation "
                  "(estimate.compute_ms; '-' where it reports none, and for the built-in localizers, whose 'localize' is their computation)")
        fig, ax = plt.subplots(figsize=(max(7, 1.2 * len(timing)), 3.5))
        keys = sorted(timing)
        labels = [f"{l}\n{p}" for l, p in keys]
        bottom = [0.0] * len(keys)
        for k in ["render_ms", "vision_ms", "localize_ms"]:
            vals = [statistics.median(timing[key][k]) if timing[key][k] else 0 for key in keys]
            ax.bar(labels, vals, bottom=bottom, label=k.replace("_ms", ""))
            bottom = [b + v for b, v in zip(bottom, vals)]
        ax.set_ylim(bottom=0)
        ax.set_ylabel("ms per frame (median)")
        ax.legend(fontsize=8)
        rep.figure(fig, "timing", "median time per frame and stage, per localizer and noise profile (under each bar)")


def load_jsonl(path):
    out = []
    if path.exists():
        for line in path.read_text().splitlines():
            if line.strip():
                try:
                    out.append(json.loads(line))
                except json.JSONDecodeError:
                    pass  # a line cut by an interrupted append: the others still count
    return out


def history_plot(rep, records, field, key, ylabel, caption, fmt):
    """One line per workload: `field` of every record, relative to the workload's first record, in
    the order the records were appended (one point per measured commit)."""
    series = {}
    for i, rec in enumerate(records):
        for w, v in rec.get(field, {}).items():
            if isinstance(v, (int, float)) and v > 0:
                series.setdefault(w, []).append((i, v))
    if not series:
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    for w, pts in sorted(series.items()):
        base = pts[0][1]
        ax.plot([i for i, _ in pts], [v / base for _, v in pts], marker="o", ms=3, label=w)
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_xticks(range(len(records)))
    ax.set_xticklabels([r.get("commit", "?") for r in records], rotation=60, ha="right", fontsize=7)
    ax.set_ylim(bottom=0)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=6, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    rep.figure(fig, key, caption)
    rows = []
    for w, pts in sorted(series.items()):
        (i0, v0), (i1, v1) = pts[0], pts[-1]
        rows.append([w, records[i0].get("commit", "?"), fmt(v0), records[i1].get("commit", "?"), fmt(v1), fnum(v1 / v0, 3)])
    rep.table(["workload", "first commit", "first", "last commit", "last", "last / first"], rows)


def report_history(rep, folder, reference=None):
    # The committed baseline history (one record per baseline change) first, then this machine's runs.
    reference = pathlib.Path(reference or pathlib.Path(__file__).resolve().parent.parent / "results" / "reference" / "icount_history.jsonl")
    icount = load_jsonl(reference) + load_jsonl(folder / "icount.jsonl")
    bench = load_jsonl(folder / "bench.jsonl")
    if not (icount or bench):
        return False
    rep.heading("Speed over commits", 2, "history")
    rep.para(f"From {reference} (committed baselines) and {folder} (this machine): every run of scripts/icount.sh and scripts/bench.sh appends its figures with the commit. "
             "Instruction counts (callgrind, fixed work) do not depend on the machine's load; wall times do, so compare "
             "wall times only between records measured in the same minutes.")
    if icount:
        history_plot(rep, icount, "instructions", "history_icount", "instructions / first record",
                     "instructions per workload (scripts/icount.sh), relative to each workload's first record",
                     lambda v: f"{v:,.0f}")
    if bench:
        history_plot(rep, bench, "real_time_ns", "history_bench", "median wall time / first record",
                     "Google Benchmark median wall time per benchmark (scripts/bench.sh), relative to its first record",
                     lambda v: f"{v:,.1f} ns")
    return True


def picture_order(p):
    # Before / after pairs in that order (alphabetically "after" would come first).
    return str(p).replace("_before", "_0before").replace("_after", "_1after")


# Tables of an experiment's markdown that a published-table section already shows (from the
# experiment's JSON): (text of the heading they stand under, that section's anchor).
SHOWN_ELSEWHERE = {
    "cooperative_001": [("Error against the number of robots", "001_simulation_setup"), ("Growth-model benchmark", "001_growth_model")],
    "error_budget": [("error_budget: which error source dominates", "error_budget")],
}


def identical_maps(exp):
    """{solver: [solvers whose error map is the same cell for cell]} from an experiment's
    maps_004.csv (landmark_maps: the exact solvers are one estimator, so their heat maps are one
    picture under different titles). Empty without the file."""
    rows = R.read_csv(exp / "maps_004.csv") if (exp / "maps_004.csv").exists() else []
    cols = [k[:-len("_mean_err_cm")] for k in (rows[0] if rows else {}) if k.endswith("_mean_err_cm")]
    groups = {}
    for s in cols:
        try:
            vals = tuple(round(float(r[f"{s}_mean_err_cm"]), 3) if r[f"{s}_mean_err_cm"] != "nan" else None for r in rows)
        except ValueError:
            continue
        groups.setdefault(vals, []).append(s)
    return {g[0]: g for g in groups.values()}


def shown_elsewhere(exp):
    """SHOWN_ELSEWHERE, and for landmark_maps the noise level of paper 004's table 1 that the
    published-table section shows from table1_004.json."""
    skip = list(SHOWN_ELSEWHERE.get(exp.name, ()))
    f = exp / "table1_004.json"
    if f.exists():
        try:
            sigma = json.loads(f.read_text())["tables"][0]["bearing_sigma_deg"]
            skip.append((f"Bearing noise N(0, {sigma:.1f} deg)", "004_table1_cm"))
        except (ValueError, KeyError, IndexError, TypeError):
            pass
    return skip


def report_experiment(rep, exp):
    rep.heading(f"Experiment {exp.name}", 2)
    pngs = sorted(exp.glob("*.png"), key=picture_order)
    same = identical_maps(exp)
    hidden = {f"map_{s}.png" for g in same.values() for s in g[1:]}
    for png in pngs:
        if png.name in hidden:
            continue
        twins = next((g for g in same.values() if png.name == f"map_{g[0]}.png"), [])
        rep.image(png, f"{exp.name}: `{png.name}`" + (
            f"; the maps of {', '.join(f'`{s}`' for s in twins[1:])} are identical to it, cell for cell (maps_004.csv), and are not shown"
            if len(twins) > 1 else ""))
    mds = sorted(exp.glob("*.md"))
    if mds:  # the experiment's own notes and tables, long: collapsed
        rep.details(f"{exp.name}: the experiment's notes and tables ({', '.join(m.name for m in mds)})")
        rep.raw_html("<div class='quoted'>")  # the experiment's own output, quoted as it wrote it
        for md in mds:
            rep.markdown(md.read_text(), skip=shown_elsewhere(exp))
        rep.raw_html("</div>")
        rep.end_details()


def bibliography(rep):
    """The five papers, numbered as the report cites them ('Lu et al. 2013 [3]')."""
    rep.heading("References", 2, "references")
    items = []
    for k, b in enumerate(C.BIBLIOGRAPHY):
        items.append(f"[{k + 1}] {b['authors']}. {b['title']}. {b['venue']}, {b['year']}. {b['note']}")
    rep.raw_html("<ol id='bibliography'>" + "".join(f"<li id='ref-{k + 1}'>{html.escape(t.split('] ', 1)[1])}</li>" for k, t in enumerate(items))
                 + "</ol>", "\n".join(f"{t}  " for t in items))


def main():
    ap = argparse.ArgumentParser(prog=os.environ.get("OMNILOC_REPORT_PROG", "scripts/report.py"), description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--title", default="omniloc report")
    ap.add_argument("--max-runs", type=int, default=24, help="trajectory plots for at most this many conditions per sweep, first seed of each (default 24)")
    ap.add_argument("--baseline", nargs="+", help="result folders to compare with (e.g. another commit's), per metric with Welch's t")
    ap.add_argument("--accept-incomplete", action="store_true", help="use sweep folders whose aggregate is not final (the report says so)")
    ap.add_argument("--history", help="folder with icount.jsonl / bench.jsonl (default results/history if it exists; 'none' to leave out)")
    a = ap.parse_args()
    papers = R.load_papers()
    runs, sweeps, experiments = R.discover(a.results, a.accept_incomplete)
    if not (runs or sweeps or experiments):
        sys.exit("report.py: no results (summary.json, aggregate.json or experiment pictures) under " + " ".join(a.results))
    rep = Report(a.out, a.title)
    for x in a.results + (a.baseline or []):
        rep.add_root(x)
    ctx = C.Context(papers, runs, experiments)
    judged = judge_claims(ctx)
    headline(rep, ctx, *judged)  # first after the title: what a researcher quotes
    rep.para(f"{len(sweeps)} sweep(s), {len(runs)} run(s), {len(experiments)} experiment(s). Published numbers: results/reference/papers.json; "
             f"everything else is read from the result files. The scorecard comes first, then the contents; details follow.")
    for d in R.INCOMPLETE:
        rep.para(f"**Incomplete sweep** (--accept-incomplete): {pathlib.Path(d).name} has no final aggregate; only its finished runs are reported.")
    _, _, totals = scorecard(rep, ctx, judged)
    rep.mark_toc()
    # The only real data: right after the scorecard. Its runs are judged against the reference pose
    # and its twin there, and left out of the pooled CDF (which scores against the reference only).
    real = {r.folder for r in RR.section(rep, runs, sweeps)}
    provenance(rep, runs, sweeps)
    published_tables(rep, papers, ctx)
    global_start_section(rep, sweeps)
    field_robot_tables(rep, papers, runs)
    error_budget_section(rep, ctx)
    if a.baseline:
        import compare
        base_runs, _, _ = R.discover(a.baseline, a.accept_incomplete)
        rep.heading("Comparison with the baseline", 2, "baseline")
        header, rows = compare.compare_rows(base_runs, runs)
        # Metric names as the reader types them (aggregate.csv's, summary.json's): code.
        rows = [r[:1] + ([f"`{r[1]}`"] if not str(r[1]).startswith("(") else r[1:2]) + r[2:] for r in rows]
        explanation = compare.EXPLANATION.replace("recall/T", "`recall/T`").replace("valid_fraction", "`valid_fraction`")
        rep.table(header, rows, f"baseline: {' '.join(a.baseline)}; this report's results as 'new'. "
                  + explanation)
    in_sweeps = set()
    for sw in sweeps:
        for r in report_sweep(rep, sw, runs, a.max_runs):
            in_sweeps.add(r.folder)
    loose = [r for r in runs if r.folder not in in_sweeps]
    if loose:
        rep.heading("Runs", 2)
        rep.details(f"{len(loose)} runs outside sweeps: tables and plots")
        for run in loose:
            report_run(rep, run, plots=True)
        rep.end_details()
    cdf_and_timing(rep, [r for r in runs if r.folder not in real])
    for exp in experiments:
        report_experiment(rep, exp)
    # Developers' charts (speed over commits) are not results: a page of their own, linked here.
    history = a.history or str(pathlib.Path(__file__).resolve().parent.parent / "results" / "history")
    if history != "none":
        hist = Report(a.out, f"{a.title}: speed over commits", page="history")
        if report_history(hist, pathlib.Path(history)):
            hist.write()
            rep.heading("For developers", 2, "developers")
            rep.raw_html("<p>Instruction counts and benchmark times over the commits (not results of the papers' experiments): "
                         "<a href='history.html'>history.html</a> beside this report.</p>",
                         "Instruction counts and benchmark times over the commits: [history.md](history.md) beside this report.")
    bibliography(rep)
    rep.write()
    html_path = rep.out / "report.html"
    print(f"scorecard: {totals}")
    print(f"report: {html_path} ({html_path.stat().st_size / 1e6:.1f} MB, {rep.n_img} pictures) and {rep.out / 'report.md'}")


if __name__ == "__main__":
    main()
