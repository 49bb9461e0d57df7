"""The reader's language: papers cited by authors and year with the bibliography's number, claims and
published tables by what they are (never their papers.json keys), a cause in one sentence.
"""
from __future__ import annotations

import re

from omniloc.core.jsonvalue import JSON, JSONObject, text
from omniloc.paper.data import CLAIM_LABELS, TABLE_LABELS, TIMING_LABELS
from omniloc.tools.citations import cite


def cite_field(field: JSON) -> str:
    """A claim's "paper" field ('002 / 000', '002 refs [7], [8]') with each paper cited."""
    out = re.sub(r"\b(00[0-4])\b", lambda m: cite(m.group(1)), str(field))
    return out.replace("] refs [", "], its refs [")


def claim_label(cid: str) -> str:
    return CLAIM_LABELS.get(cid, str(cid).replace("_", " "))


def table_label(key: str) -> str:
    """'Lu et al. 2013 [3], table 1: tracking error under occlusion' for a papers.json key."""
    if key not in TABLE_LABELS:
        return str(key).replace("_", " ")
    papers, what = TABLE_LABELS[key]
    return " and ".join(cite(p) for p in papers.split()) + f", {what}"


def timing_label(row: str) -> str:
    paper, what = TIMING_LABELS.get(row, ("", str(row).replace("_", " ")))
    return f"{what} ({cite(paper)})" if paper else what


def cause_summary(cause: JSONObject) -> str:
    """One sentence for the why-table: the cause's "summary" (causes.json), else its first sentence."""
    summary = text(cause.get("summary"))
    if summary:
        return summary
    argument = text(cause.get("text", "")) or ""
    m = re.match(r"(.+?[.;])(\s|$)", argument)
    return m.group(1) if m else argument
