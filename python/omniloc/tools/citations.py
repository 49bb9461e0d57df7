"""The writer's language for the papers: the bibliography the report ends with, citations ('Lu et al.
2013 [3]' for 'paper 002') and the abbreviations spelled out at their first use. Data and text only:
the writer (omniloc.tools.markup) cites and expands with it, the papers' side (omniloc.paper.labels)
names claims and tables with it.
"""
from __future__ import annotations

import re
from dataclasses import dataclass


@dataclass(frozen=True)
class Reference:
    """One paper of the bibliography: its number in papers.json ("002"), the short citation, and the
    entry as printed."""
    paper: str
    short: str
    authors: str
    title: str
    venue: str
    year: int
    note: str


# The five papers, numbered as the report's bibliography numbers them. Venue and year as printed on
# the papers; where a paper's text does not print them, "note" says where they come from.
BIBLIOGRAPHY: list[Reference] = [
    Reference(paper="000", short="Xiong et al. 2012", authors="Dan Xiong, Huimin Lu, Zhiqiang Zheng",
              title="A self-localization method based on omnidirectional vision and MTi for soccer robots",
              venue="Proceedings of the 10th World Congress on Intelligent Control and Automation (WCICA), Beijing", year=2012,
              note="National University of Defense Technology, Changsha; bilingual (English and Chinese). The text prints neither venue nor year "
                   "(its latest reference is from 2010): venue and year as we know them, not verified against the paper."),
    Reference(paper="001", short="Xu et al. 2012", authors="Jiaming Xu, Lun Xie, Zhiliang Wang, Shanchao Ni",
              title="Target localization algorithm for cooperative multi-soccer robots based on Hough space",
              venue="Journal of Image and Graphics (Zhongguo Tuxiang Tuxing Xuebao) 17(6): 687-695", year=2012,
              note="University of Science and Technology Beijing; in Chinese."),
    Reference(paper="002", short="Lu et al. 2013", authors="Huimin Lu, Xun Li, Hui Zhang, Mei Hu, Zhiqiang Zheng",
              title="Robust and real-time self-localization based on omnidirectional vision for soccer robots",
              venue="Advanced Robotics (doi:10.1080/01691864.2013.785473)", year=2013,
              note="National University of Defense Technology, Changsha (the NuBot team)."),
    Reference(paper="003", short="Zhuang and Cao 2009", authors="Huimin Zhuang, Qixin Cao",
              title="Global localization of explorer based on visible landmarks",
              venue="Journal of Shanghai Jiao Tong University, no. 6, pp. 871-874", year=2009,
              note="Research Institute of Robotics, Shanghai Jiao Tong University; in Chinese."),
    Reference(paper="004", short="Luo et al. 2012", authors="Jia-Ning Luo, Shu-Ying Chiang, Dong-Liang Li, Ching-Yi Chen, Kun-Yu Chen",
              title="Design of a positioning system module for omni-direction soccer robot",
              venue="conference paper, Department of Information and Telecommunications Engineering, Ming Chuan University (Taiwan)", year=2012,
              note="In Chinese. The text prints neither venue nor year: 2012 is inferred from its references (consulted in May 2012); "
                   "author names romanised from the Chinese."),
]


NUMBERED = {b.paper: (k + 1, b) for k, b in enumerate(BIBLIOGRAPHY)}  # paper -> (its number, the entry)


def cite(paper: str) -> str:
    """'Lu et al. 2013 [3]' for a paper number ('002'); the number itself when unknown."""
    if paper not in NUMBERED:
        return f"paper {paper}"
    n, b = NUMBERED[paper]
    return f"{b.short} [{n}]"


AUTHORS = r"[A-Z][a-z]+(?:(?:, | and | & )[A-Z][a-z]+)*(?: et al\.)?(?: \d{4})?"


def cite_text(text: str) -> str:
    """Prose with every 'paper 00N' (and 'Lu et al. 2013 (paper 002)', 'papers 002 and 000') made
    a citation of the bibliography."""
    text = str(text)
    if "aper" not in text:
        return text
    text = re.sub(AUTHORS + r" \([Pp]aper (00[0-4])\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]aper (00[0-4]) \(" + AUTHORS + r"\)", lambda m: cite(m.group(1)), text)
    text = re.sub(r"\b[Pp]apers (00[0-4]) and (00[0-4])\b", lambda m: f"{cite(m.group(1))} and {cite(m.group(2))}", text)
    return re.sub(r"\b[Pp]aper (00[0-4])\b", lambda m: cite(m.group(1)), text)


# Abbreviations the report uses, spelled out at their first use (Report.expand).
ABBREVIATIONS = {
    "MCL": "Monte Carlo localization", "RPROP": "resilient propagation, a gradient-sign optimiser",
    "MFBPF": "modified fission bootstrap particle filter", "FBPF": "fission bootstrap particle filter",
    "BPF": "bootstrap particle filter", "RMSE": "root mean square error", "MSL": "RoboCup Middle Size League",
    "MTi": "XSens inertial heading sensor", "E_k": "mean matching error of grid sample k",
    "N_th": "resampling threshold on the effective sample size", "N_eff": "effective sample size",
    "CDF": "cumulative distribution function",
}
