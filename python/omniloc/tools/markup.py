"""The one writer of the report: report.md and a self-contained report.html built side by side
(Report), or the same interface printed on the terminal (TextReport, for `omniloc paper-table`).

Sections are functions that call heading / para / table / figure / image / markdown; a heading of
level 2 becomes an entry of the table of contents. Cells are numbers (right-aligned) only when the
whole cell is one (NUMERIC_CELL). No absolute path reaches the report (Report.clean); abbreviations
are spelled out at their first use (Report.expand) and papers cited (omniloc.tools.citations).
Figures come from omniloc.tools.plot (the only module that imports matplotlib): Report.figure saves
and closes them through it.
"""
from __future__ import annotations

import base64
import html
import os
import pathlib
import re
import tempfile
from typing import TYPE_CHECKING, Optional, Sequence, Union

from omniloc.core import paths
from omniloc.core.verdicts import CONTRADICTED, DOES_NOT, EXPLAINED, HOLDS, NOT_APPLICABLE, NOT_MEASURED, NOT_RUN, PARTLY, UNEXPLAINED
from omniloc.tools.citations import ABBREVIATIONS, cite_text
from omniloc.tools.images import compress_png

if TYPE_CHECKING:  # the writer takes figures; only omniloc.tools.plot imports matplotlib
    from matplotlib.figure import Figure

# A table cell: text, or a number shown as str() shows it.
Cell = Union[str, int, float]


VERDICT_CLASS = {HOLDS: "ok", PARTLY: "partly", DOES_NOT: "no", NOT_RUN: "notrun", NOT_APPLICABLE: "notrun",
                 EXPLAINED: "ok", NOT_MEASURED: "notrun", CONTRADICTED: "no", UNEXPLAINED: "no"}


# A cell is a number (right-aligned) only when the WHOLE cell is one: a number with an optional
# unit, an interval "[lo, hi]", an "(n=3 ...)" note or "a / b" counts. Claim text that starts with
# a number ("50 % occlusion degrades ...") stays text (left-aligned).
NUMERIC_CELL = re.compile(r"^[-+]?((0|[1-9]\d*)(\.\d*)?|\.\d+)(e[-+]?\d+)?( ?(%|cm|mm|m|ms|s|rad|deg|x|ns))?"
                          r"( \[[^\]]*\])?( \([^)]*\))?( / [-+]?\d+(\.\d+)?)?$")


def numeric_class(cell: Cell) -> str:
    """Numbers right-aligned, text left-aligned (see NUMERIC_CELL)."""
    return " class='num'" if NUMERIC_CELL.match(str(cell).strip()) else ""


# Where the repository's docs/ lies seen from the report's folder (results/report/ by default);
# Report sets it for its own folder. A doc named in the text (docs/x.md#anchor) becomes a link.
DOCS_HREF = "../../docs/"


def md_links(text: str) -> str:
    """report.md's text with each doc of the repository (docs/x.md#anchor) as a markdown link."""
    return re.sub(r"(?<![\w/.\[`-])docs/([\w/.-]+?\.md)(#[\w-]+(?:\.[\w-]+)*)?", lambda m: f"[docs/{m.group(1)}]({DOCS_HREF}{m.group(1)}{m.group(2) or ''})", text)


def inline_markdown(text: str) -> str:
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


def slug(text: str) -> str:
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

    def __init__(self, out: Union[str, pathlib.Path], title: str, page: str = "report") -> None:
        self.out = pathlib.Path(out)
        self.page = page
        (self.out / "img").mkdir(parents=True, exist_ok=True)
        for old in (self.out / "img").glob(f"{page}_*"):  # pictures of an earlier report in the same folder
            old.unlink()
        self.md = [f"# {title}", ""]
        self.html: list[str] = []
        self.toc: list[tuple[str, str]] = []
        self.n_img = 0
        self.title = title
        self.anchors: set[str] = set()
        self.titles: dict[str, str] = {}
        self.plotted: set[pathlib.Path] = set()  # run folders whose figure the report has (each once)
        self.seeded: set[pathlib.Path] = set()  # run folders a seed table has shown (a sweep does not repeat them)
        # Absolute paths never reach the report (it is shared): every folder the report could name
        # is shown relative to the working folder, or by its last two parts when outside it.
        self.roots = sorted({str(p) for p in (pathlib.Path.cwd(), paths.ROOT, pathlib.Path.home(), pathlib.Path(tempfile.gettempdir()),
                                              self.out.resolve())}, key=len, reverse=True)
        self.expanded: set[str] = set()  # abbreviations already spelled out (expand)
        global DOCS_HREF
        resolved = self.out.resolve()
        DOCS_HREF = (os.path.relpath(paths.ROOT / "docs", resolved).replace(os.sep, "/") + "/") if resolved.is_relative_to(paths.ROOT) else "../../docs/"

    def add_root(self, path: Union[str, pathlib.Path]) -> None:
        p = str(pathlib.Path(path).resolve())
        self.roots = sorted(set(self.roots) | {p}, key=len, reverse=True)

    def clean(self, text: Cell) -> str:
        """text with every absolute path under a known root made relative (see __init__)."""
        text = cite_text(str(text))  # 'paper 002' -> 'Lu et al. 2013 [3]' (the bibliography at the end)
        if "/" not in text:
            return text
        cwd = pathlib.Path.cwd()

        def rel(m: re.Match[str]) -> str:
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

    def expand(self, text: str) -> str:
        """The text with each abbreviation of ABBREVIATIONS spelled out at its first use in the
        report (outside `code`): 'MCL (Monte Carlo localization)'. Headings are left as they are."""
        text = str(text)
        for abbr, full in ABBREVIATIONS.items():
            if abbr in self.expanded or abbr not in text:
                continue
            for m in re.finditer(r"(?<![\w/.-])" + re.escape(abbr) + r"(?![\w-])", text):
                if text.count("`", 0, m.start()) % 2:  # inside `code`
                    continue
                self.expanded.add(abbr)
                text = text[:m.end()] + f" ({full})" + text[m.end():]
                break
        return text

    def heading(self, text: str, level: int = 2, anchor: Optional[str] = None) -> str:
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

    def para(self, text: str, cls: Optional[str] = None, ident: Optional[str] = None) -> None:
        text = self.expand(self.clean(text))
        self.md += [md_links(text), ""]
        c = (f' class="{cls}"' if cls else "") + (f' id="{ident}"' if ident else "")
        self.html.append(f"<p{c}>{inline_markdown(text)}</p>")

    def raw_html(self, fragment: str, md: Optional[str] = None) -> None:
        self.html.append(fragment)
        if md:
            self.md += [md, ""]

    def details(self, summary: str) -> None:
        """Opens a collapsed block (HTML <details>); end_details() closes it. report.md keeps it flat."""
        self.html.append(f"<details><summary>{inline_markdown(self.clean(summary))}</summary>")

    def end_details(self) -> None:
        self.html.append("</details>")

    def mark_toc(self) -> None:
        self.html.append(TOC_MARK)

    def table(self, header: Sequence[Cell], rows: Sequence[Sequence[Cell]], caption: Optional[str] = None,
              row_classes: Optional[Sequence[str]] = None) -> None:
        """rows: lists of cells; row_classes: one CSS class per row (e.g. "paper" for published rows).
        A cell that is a verdict (holds, partly, ...) is coloured by itself."""
        if caption:
            self.para(caption, "caption")
        head = [self.expand(self.clean(c)) for c in header]
        body = [[self.expand(self.clean(c)) for c in r] for r in rows]
        self.md.append("| " + " | ".join(head) + " |")
        # The first column labels the row (even "50 %"): left; the others by their cells.
        self.md.append("|" + "|".join("---:" if i and body and numeric_class(body[0][i]) else "---" for i in range(len(head))) + "|")
        for k, r in enumerate(body):
            cells = [md_links(str(c).replace("|", "\\|")) for c in r]
            if row_classes and row_classes[k] == "paper":
                cells = [f"*{c}*" if c not in ("", "-") else c for c in cells]
            self.md.append("| " + " | ".join(cells) + " |")
        self.md.append("")
        h = "<div class='scroll'><table><tr>" + "".join(f"<th>{inline_markdown(str(c))}</th>" for c in head) + "</tr>"
        for k, r in enumerate(body):
            cls = row_classes[k] if row_classes and row_classes[k] else ""
            h += (f"<tr class='{cls}'>" if cls else "<tr>")
            for i, c in enumerate(r):
                v = VERDICT_CLASS.get(str(c))
                h += f"<td class='v-{v}'>" if v else f"<td{numeric_class(c) if i else ''}>"
                h += inline_markdown(str(c)) + "</td>"
            h += "</tr>"
        self.html.append(h + "</table></div>")

    def markdown(self, text: str, skip: Sequence[tuple[str, str]] = ()) -> None:
        """An experiment's markdown: headings, paragraphs and pipe tables as real HTML. skip: pairs
        (heading text, anchor): a table under a heading containing that text is left out, with a
        link to the section that shows it from the experiment's JSON (one copy of each table)."""
        text = self.expand(self.clean(text))
        lines = text.splitlines()
        para: list[str]
        kept: list[str]
        i, para, kept = 0, [], []
        current = ""

        def flush() -> None:
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
                rows: list[list[str]] = []
                block: list[str] = []
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

    def figure(self, fig: Figure, name: str, caption: str, dpi: int = 80) -> None:
        self.n_img += 1
        path = self.out / "img" / f"{self.page}_{self.n_img:03d}_{name}.png"
        from omniloc.tools import plot  # matplotlib: only where there is a figure
        plot.save(fig, path, dpi)
        self._embed(compress_png(path), caption)

    def image(self, source: Union[str, pathlib.Path], caption: str) -> None:
        """A picture an experiment wrote: copied next to the report, compressed, embedded."""
        path = pathlib.Path(source)
        self.n_img += 1
        dst = self.out / "img" / f"{self.page}_{self.n_img:03d}_{path.name}"
        dst.write_bytes(path.read_bytes())
        self._embed(compress_png(dst), caption)

    def _embed(self, path: pathlib.Path, caption: str) -> None:
        caption = self.expand(self.clean(caption))
        rel = path.relative_to(self.out)
        self.md += [f"![{caption}]({rel.as_posix()})", "", f"*{caption}*", ""]
        b64 = base64.b64encode(path.read_bytes()).decode()
        mime = "image/jpeg" if path.suffix == ".jpg" else "image/png"
        self.html.append(f'<figure><img src="data:{mime};base64,{b64}" alt="{html.escape(caption)}"><figcaption>{inline_markdown(caption)}</figcaption></figure>')

    def toc_html(self) -> str:
        items = "".join(f'<li><a href="#{html.escape(a)}">{inline_markdown(t)}</a></li>' for a, t in self.toc)
        return f'<nav id="contents"><h2>Contents</h2><ol>{items}</ol></nav>'

    def write(self) -> None:
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
    """The Report interface written to the terminal (`omniloc paper-table`): tables aligned (or
    as markdown), figures left out. With only=ANCHOR just the section of that heading anchor."""

    def __init__(self, only: Optional[str] = None, markdown: bool = False) -> None:
        self.only, self.markdown_tables, self.on, self.printed = only, markdown, only is None, False
        self.plotted: set[pathlib.Path] = set()
        self.seeded: set[pathlib.Path] = set()
        self.n_img = 0

    def clean(self, text: Cell) -> str:
        return str(text)

    def heading(self, text: str, level: int = 2, anchor: Optional[str] = None) -> str:
        anchor = anchor or slug(text)
        if self.only is not None:
            self.on = anchor == self.only
        if self.on:
            print(("#" * level + " " if self.markdown_tables else "== ") + text + "\n")
            self.printed = True
        return anchor

    def para(self, text: str, cls: Optional[str] = None, ident: Optional[str] = None) -> None:
        if self.on:
            print(text + "\n")

    def table(self, header: Sequence[Cell], rows: Sequence[Sequence[Cell]], caption: Optional[str] = None,
              row_classes: Optional[Sequence[str]] = None) -> None:
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

    def figure(self, fig: Figure, name: str, caption: str, dpi: int = 80) -> None:
        from omniloc.tools import plot  # matplotlib: only where there is a figure
        plot.close(fig)

    def image(self, source: Union[str, pathlib.Path], caption: str) -> None:
        pass

    def markdown(self, text: str, skip: Sequence[tuple[str, str]] = ()) -> None:
        if self.on:
            print(text)

    def details(self, summary: str) -> None:
        pass

    def end_details(self) -> None:
        pass

    def mark_toc(self) -> None:
        pass

    def raw_html(self, fragment: str, md: Optional[str] = None) -> None:
        pass


Writer = Union[Report, TextReport]  # what a section writes to: the report files, or the terminal
