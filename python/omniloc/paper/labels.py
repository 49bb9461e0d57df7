"""The reader's language: papers cited by authors and year with the bibliography's number, claims and
published tables by what they are (never their papers.json keys), a cause in one sentence.
"""
from __future__ import annotations

import re
from typing import Any

from omniloc.paper.data import BIBLIOGRAPHY, CLAIM_LABELS, TABLE_LABELS, TIMING_LABELS
from omniloc.core.rundir import Run


_BIB = {b["paper"]: (k + 1, b) for k, b in enumerate(BIBLIOGRAPHY)}


def cite(paper: Any) -> Any:
    """'Lu et al. 2013 [3]' for a paper number ('002'); the number itself when unknown."""
    if paper not in _BIB:
        return f"paper {paper}"
    n, b = _BIB[paper]
    return f"{b['short']} [{n}]"


def cite_field(field: list[Run]) -> Any:
    """A claim's "paper" field ('002 / 000', '002 refs [7], [8]') with each paper cited."""
    out = re.sub(r"\b(00[0-4])\b", lambda m: cite(m.group(1)), str(field))
    return out.replace("] refs [", "], its refs [")


_AUTHORS = r"[A-Z][a-z]+(?:(?:, | and | & )[A-Z][a-z]+)*(?: et al\.)?(?: \d{4})?"


def cite_text(text: str) -> Any:
    """Prose with every 'paper 00N' (and 'Lu et al. 2013 (paper 002)', 'papers 002 and 000') made
    a citation of the bibliography."""
    text = str(text)
    if "aper" not in text:
        return text
    text = re.sub(_AUTHORS + r" \([Pp]aper (00[0-4])\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]aper (00[0-4]) \(" + _AUTHORS + r"\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]apers (00[0-4]) and (00[0-4])\b", lambda m: f"{cite(m.group(1))} and {cite(m.group(2))}", text)
    return re.sub(r"\b[Pp]aper (00[0-4])\b", lambda m: cite(m.group(1)), text)


def claim_label(cid: Any) -> Any:
    return CLAIM_LABELS.get(cid, str(cid).replace("_", " "))


def table_label(key: Any) -> Any:
    """'Lu et al. 2013 [3], table 1: tracking error under occlusion' for a papers.json key."""
    if key not in TABLE_LABELS:
        return str(key).replace("_", " ")
    papers, what = TABLE_LABELS[key]
    return " and ".join(cite(p) for p in papers.split()) + f", {what}"


def timing_label(row: Any) -> Any:
    paper, what = TIMING_LABELS.get(row, ("", str(row).replace("_", " ")))
    return f"{what} ({cite(paper)})" if paper else what


def cause_summary(cause: Any) -> Any:
    """One sentence for the why-table: the cause's "summary" (causes.json), else its first sentence."""
    if cause.get("summary"):
        return cause["summary"]
    text = cause.get("text", "")
    m = re.match(r"(.+?[.;])(\s|$)", text)
    return m.group(1) if m else text
