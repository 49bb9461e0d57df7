"""The papers' side of the results as data, apart from the code that judges: the readable labels of
claims and published tables and the kinds of claims. The published figures and the rules that judge
ours are data too, in results/reference/papers.json and causes.json (omniloc.core.pairing.load_papers
reads them); the bibliography and the abbreviations are the writer's (omniloc.tools.citations), the
verdicts' and causes' words the core's (omniloc.core.verdicts).
"""
from __future__ import annotations



GLOBAL_START = "(global start)"  # in a row's label: its localizer starts from an unknown pose


COVERAGE_METRICS: list[str] = ["valid_fraction"]  # with recall/<headline> (coverage_metrics)


WEAK_TEXT = "(1 seed: weak evidence)"


# What a claim is about, so that the scorecard counts them apart: four timing claims that hold by a
# factor of 100 on another CPU say nothing about accuracy. A claim may name its own "kind" in
# papers.json; otherwise: a timing quantity makes it "timing", these ids "robustness", the rest
# "accuracy".
KINDS = ("accuracy", "robustness", "timing")


ROBUSTNESS = {"occlusion_mild", "lighting_autoadjust", "kidnap_002", "kidnap_000", "entropy_peak"}


# The other axes of a published error-table row: a claim stated on mean x is judged on mean y and
# mean heading too, since the paper states them in the same row.
AXES: list[tuple[str, str]] = [("x_cm/mean", "x"), ("y_cm/mean", "y"), ("theta_rad/mean", "heading")]


# Each claim of papers.json by what it says (the report never shows its id).
CLAIM_LABELS: dict[str, str] = {
    "tracking_accuracy": "Tracking accuracy", "occlusion_mild": "Mild degradation under 50 % occlusion",
    "lighting_autoadjust": "Lighting: camera auto-adjustment", "kidnap_002": "Kidnap recovery (2 kidnaps)",
    "kidnap_000": "Kidnap recovery (5 kidnaps)", "mcl_alone": "MCL alone against matching",
    "weights_1_over_L": "1/L weights beat equal weights", "robots_flatten": "Error flattens at 3-5 robots",
    "mfbpf_vs_fbpf": "MFBPF below FBPF", "three_point_bounded": "Three-point stays bounded where two-circle explodes",
    "voting_bounded": "Voting keeps the error within 1 m", "entropy_peak": "Entropy peak moves in sun",
    "timing_mcl": "MCL time per cycle", "timing_matching": "Matching time per cycle", "timing_global": "Global localization time per frame",
    "timing_tracking": "Tracking time per frame", "real_cooperative": "Cooperation on real robots",
}


# The published tables and figures of papers.json (paper, what), for headings and captions.
TABLE_LABELS: dict[str, tuple[str, str]] = {
    "002_table1_occlusion": ("002", "table 1: tracking error under occlusion"),
    "002_table2_lighting": ("002", "table 2: tracking error under changing light"),
    "000_tracking": ("000", "tracking error table"),
    "002_kidnapping": ("002", "kidnapping"), "000_kidnapping": ("000", "kidnapping"),
    "timings_ms": ("002 000", "time per cycle or frame"),
    "mcl_only_mean_position_error_cm": ("002", "other teams' MCL-only mean position error (its refs [7], [8])"),
    "001_cooperative_mean_error_mm": ("001", "cooperative ball localization: mean error, equal and 1/L weights"),
    "001_simulation_setup": ("001", "simulation set-up and error against the number of robots (fig. 10)"),
    "001_real_mean_error_cm": ("001", "real-robot ball error with and without cooperation"),
    "001_growth_model": ("001", "FBPF and MFBPF on the growth model"),
    "004_table1_cm": ("004", "table 1: two-circle and three-point fixes"),
    "003_simulation": ("003", "simulation with landmark groups and voting"),
}


# Rows of papers.json's "timings_ms" by what they time.
TIMING_LABELS: dict[str, tuple[str, str]] = {"002_mcl": ("002", "MCL part per cycle"), "002_matching": ("002", "matching part per cycle"),
                 "000_global_per_frame": ("000", "global localization per frame"), "000_tracking_per_frame": ("000", "tracking per frame")}

