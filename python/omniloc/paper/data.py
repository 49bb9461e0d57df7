"""The papers' side of the results as data, apart from the code that judges: the bibliography, the
readable labels of claims and published tables, the abbreviations, the kinds of claims and the
statuses of a cause. The published figures and the rules that judge ours are data too, in
results/reference/papers.json and causes.json (omniloc.core.pairing.load_papers reads them).
"""
from __future__ import annotations



GLOBAL_START = "(global start)"  # in a row's label: its localizer starts from an unknown pose


COVERAGE_METRICS = ["valid_fraction"]  # with recall/<headline> (coverage_metrics)


WEAK_TEXT = "(1 seed: weak evidence)"


# What a claim is about, so that the scorecard counts them apart: four timing claims that hold by a
# factor of 100 on another CPU say nothing about accuracy. A claim may name its own "kind" in
# papers.json; otherwise: a timing quantity makes it "timing", these ids "robustness", the rest
# "accuracy".
KINDS = ("accuracy", "robustness", "timing")


ROBUSTNESS = {"occlusion_mild", "lighting_autoadjust", "kidnap_002", "kidnap_000", "entropy_peak"}


# The other axes of a published error-table row: a claim stated on mean x is judged on mean y and
# mean heading too, since the paper states them in the same row.
AXES = [("x_cm/mean", "x"), ("y_cm/mean", "y"), ("theta_rad/mean", "heading")]


EXPLAINED, NOT_MEASURED, CONTRADICTED, UNEXPLAINED = "explained", "evidence not in these results", "evidence contradicts the cause", "no cause recorded"


# The five papers, numbered as the report's bibliography numbers them. Venue and year as printed on
# the papers; where a paper's text does not print them, "note" says where they come from.
BIBLIOGRAPHY = [
    {"paper": "000", "short": "Xiong et al. 2012", "authors": "Dan Xiong, Huimin Lu, Zhiqiang Zheng",
     "title": "A self-localization method based on omnidirectional vision and MTi for soccer robots",
     "venue": "Proceedings of the 10th World Congress on Intelligent Control and Automation (WCICA), Beijing", "year": 2012,
     "note": "National University of Defense Technology, Changsha; bilingual (English and Chinese). The text prints neither venue nor year "
             "(its latest reference is from 2010): venue and year as we know them, not verified against the paper."},
    {"paper": "001", "short": "Xu et al. 2012", "authors": "Jiaming Xu, Lun Xie, Zhiliang Wang, Shanchao Ni",
     "title": "Target localization algorithm for cooperative multi-soccer robots based on Hough space",
     "venue": "Journal of Image and Graphics (Zhongguo Tuxiang Tuxing Xuebao) 17(6): 687-695", "year": 2012,
     "note": "University of Science and Technology Beijing; in Chinese."},
    {"paper": "002", "short": "Lu et al. 2013", "authors": "Huimin Lu, Xun Li, Hui Zhang, Mei Hu, Zhiqiang Zheng",
     "title": "Robust and real-time self-localization based on omnidirectional vision for soccer robots",
     "venue": "Advanced Robotics (doi:10.1080/01691864.2013.785473)", "year": 2013,
     "note": "National University of Defense Technology, Changsha (the NuBot team)."},
    {"paper": "003", "short": "Zhuang and Cao 2009", "authors": "Huimin Zhuang, Qixin Cao",
     "title": "Global localization of explorer based on visible landmarks",
     "venue": "Journal of Shanghai Jiao Tong University, no. 6, pp. 871-874", "year": 2009,
     "note": "Research Institute of Robotics, Shanghai Jiao Tong University; in Chinese."},
    {"paper": "004", "short": "Luo et al. 2012", "authors": "Jia-Ning Luo, Shu-Ying Chiang, Dong-Liang Li, Ching-Yi Chen, Kun-Yu Chen",
     "title": "Design of a positioning system module for omni-direction soccer robot",
     "venue": "conference paper, Department of Information and Telecommunications Engineering, Ming Chuan University (Taiwan)", "year": 2012,
     "note": "In Chinese. The text prints neither venue nor year: 2012 is inferred from its references (consulted in May 2012); "
             "author names romanised from the Chinese."},
]


# Each claim of papers.json by what it says (the report never shows its id).
CLAIM_LABELS = {
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
TABLE_LABELS = {
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
TIMING_LABELS = {"002_mcl": ("002", "MCL part per cycle"), "002_matching": ("002", "matching part per cycle"),
                 "000_global_per_frame": ("000", "global localization per frame"), "000_tracking_per_frame": ("000", "tracking per frame")}


# Abbreviations the report uses, spelled out at their first use (Report.expand).
ABBREVIATIONS = {
    "MCL": "Monte Carlo localization", "RPROP": "resilient propagation, a gradient-sign optimiser",
    "MFBPF": "modified fission bootstrap particle filter", "FBPF": "fission bootstrap particle filter",
    "BPF": "bootstrap particle filter", "RMSE": "root mean square error", "MSL": "RoboCup Middle Size League",
    "MTi": "XSens inertial heading sensor", "E_k": "mean matching error of grid sample k",
    "N_th": "resampling threshold on the effective sample size", "N_eff": "effective sample size",
    "CDF": "cumulative distribution function",
}
