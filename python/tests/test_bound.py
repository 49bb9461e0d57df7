"""The accuracy limit in the results package (omniloc.core.bound; docs/results.md): the typed reader of
summary.json's bound, efficiency and RPE blocks, and what compare, gate, paper-table, the report and
the viewer make of them, on synthetic run folders written as omniloc writes them (helpers.limit_blocks)
beside folders of runs made before the bound, whose outputs must not change.
"""
import json
import pathlib
import subprocess

import pytest

from helpers import PY, SCORING, limit_blocks, no_limit_blocks, robot, scored, write_run, write_viewable_run
from omniloc import compare, gate
from omniloc.core import bound, metrics
from omniloc.core.aggregate import AggregateGroup
from omniloc.core.rundir import Run, discover
from omniloc.report import limit
from omniloc.view.load import load_run
from omniloc.view.page import render

RMSE = 0.039  # robot(3.9): position_m.rmse = 3.9 / 100 m


def bounded(eff, share=0.97, extra=None):
    """A current robot block (coverage scored) whose RMSE is `eff` times its posterior bound."""
    r = scored(robot(3.9))
    r.update(limit_blocks(RMSE, eff, share=share))
    r.update(extra or {})
    return r


def write_side(folder, effs, scenario="tracking", localizer="matching"):
    """One condition over seeds 1..n; an efficiency of None: a run without a bound (no truth)."""
    for seed, eff in enumerate(effs, 1):
        rob = bounded(eff) if eff is not None else dict(scored(robot(3.9)), **no_limit_blocks())
        write_run(pathlib.Path(folder) / f"s{seed}", scenario, localizer, seed, {}, rob, start_pose_given=True, scoring=SCORING)
    return discover([folder])[0]


# ---- the reader -------------------------------------------------------------------------------

def test_reader_gives_typed_records_with_the_share():
    rb = bound.read_robot_bound(bounded(1.3))
    assert rb is not None and rb.bound is not None and rb.bound.posterior is not None and rb.efficiency is not None
    assert rb.efficiency.position == 1.3 and rb.efficiency.against == "posterior" and rb.efficiency.frames == 97
    assert rb.bound.posterior.position_rms_m == pytest.approx(RMSE / 1.3)
    assert rb.bound.posterior.share == 0.97
    assert rb.bound.no_bound.frames == 3 and rb.bound.no_bound.why == {"points on one line": 3}
    assert rb.bound.noise is not None and rb.bound.noise.declared_sigma_m == [0.03, 0.04, 0.08, None]
    assert rb.rpe is not None and rb.rpe.one_second is not None and rb.rpe.one_second.pairs == 70
    assert rb.limit_m == pytest.approx(RMSE / 1.3)


def test_the_carried_errors_are_read_and_said_and_older_blocks_say_nothing():
    r = bounded(1.3)
    r["bound"]["posterior"]["carried_errors"] = {"share": 0.29, "per_frame": 0.97, "lags": 30, "pairs": 1799}
    r["bound"]["posterior_white"] = {"position_rms_m": 0.0048, "heading_rms_rad": 0.0017, "frames": 97, "share": 0.97}
    rb = bound.read_robot_bound(r)
    assert rb is not None and rb.bound is not None and rb.bound.carried_share == 0.29
    assert rb.bound.posterior_white is not None and rb.bound.posterior_white.position_rms_m == 0.0048
    assert bound.carried_errors_text(rb.bound) == ("The posterior bound carries 0.29 of each frame's error variance to the next frames "
                                                  "(measured at the truth: the same lines at nearly the same pixels); taking the frames "
                                                  "as independent it would be 0.48 cm.")
    old = bound.read_robot_bound(bounded(1.3))
    assert old is not None and old.bound is not None and old.bound.carried_share is None and old.bound.posterior_white is None
    assert bound.carried_errors_text(old.bound) == ""
    r["bound"]["posterior"]["carried_errors"]["share"] = 0.0  # too short a run to measure: independent frames
    rb0 = bound.read_robot_bound(r)
    assert rb0 is not None and rb0.bound is not None and bound.carried_errors_text(rb0.bound) == ""


def test_a_block_from_before_the_bound_has_none_and_a_null_bound_is_never_zero():
    assert bound.read_robot_bound(scored(robot(3.9))) is None
    rb = bound.read_robot_bound(dict(scored(robot(3.9)), **no_limit_blocks()))
    assert rb is not None and rb.efficiency is not None and rb.bound is not None and rb.bound.posterior is not None
    assert rb.efficiency.position is None and rb.bound.posterior.position_rms_m is None and rb.limit_m is None
    assert bound.robot_limit_text(rb) == "3.9 cm, no bound (no truth to place the line points at)"


def test_texts():
    assert bound.limit_text(0.038, 1.3, 0.97) == "3.8 cm, 1.30x the limit (bound in 97 % of frames)"
    assert bound.limit_text(0.12, 2.47, 1.0) == "12 cm, 2.5x the limit (bound in 100 % of frames)"
    assert bound.share_text(0.996) == "bound in 99 % of frames"  # never rounded up to every frame
    assert bound.ratio_text(None) == "no bound"
    assert bound.family("occlusion_002") == "occlusion" and bound.family("lighting_002_sun") == "lighting"
    assert bound.family("tracking") == "tracking"
    assert bound.NoBound(frames=5, why={"no points": 1, "points on one line": 4}).text() == \
        "5 frames without a bound: 4 points on one line, 1 no points"


def with_tracking_phase(r, rmse_m, eff):
    """A robot block of a run with kidnaps as omniloc writes it (harness/scoring/bound.cpp): the
    tracking phase's errors in tracking_phase, its efficiencies inside the run's efficiency blocks."""
    phase = limit_blocks(rmse_m, eff)
    r = dict(r, tracking_phase=scored(robot(rmse_m * 100)))
    r["efficiency"] = dict(r["efficiency"], tracking_phase=phase["efficiency"])
    r["efficiency_single_frame"] = dict(r["efficiency_single_frame"], tracking_phase=phase["efficiency_single_frame"])
    return r


def test_tracking_phase_is_read_where_omniloc_writes_it():
    r = with_tracking_phase(bounded(1.3), 0.02, 1.1)
    rb = bound.robot_bound(r)
    assert rb is not None and rb.efficiency is not None and rb.efficiency.position == 1.1
    assert rb.error_m == pytest.approx(0.02) and rb.limit_m == pytest.approx(0.02 / 1.1)
    assert rb.efficiency_single_frame is not None and rb.efficiency_single_frame.position == pytest.approx(1.1 / 1.4)
    assert rb.bound is not None and rb.bound.posterior is not None  # the run's bound figures
    all_frames = bound.robot_bound(r, phase="all")
    assert all_frames is not None and all_frames.efficiency is not None and all_frames.efficiency.position == 1.3
    # a run without kidnaps: the whole run, for either phase
    assert bound.robot_bound(bounded(1.3)).efficiency.position == 1.3


def test_the_run_table_and_the_aggregate_read_the_tracking_phase(tmp_path):
    write_run(tmp_path / "k", "kidnap_002", "hybrid", 1, {}, with_tracking_phase(bounded(30.0), 0.02, 1.1),
              start_pose_given=False, scoring=SCORING)
    run = discover([tmp_path / "k"])[0][0]
    names = [row[0] for row in limit.robot_rows(run)]
    assert names[0] == "r0 all frames" and names[1] == "r0 tracking phase"
    assert [r[3] for r in limit.localizer_rows([run])] == ["1.10x"] and [r[5] for r in limit.localizer_rows([run])] == ["2 cm"]
    m = {"n": 3, "mean": 1.1, "ci95": [1.0, 1.2], "interval": "range", "no_value": 0}
    g = AggregateGroup.from_json({"metrics": {"r0/efficiency/position": dict(m, mean=30.0),
                                              "r0/efficiency/tracking_phase/position": m,
                                              "r0/efficiency/tracking_phase/bound_rms_m": dict(m, mean=0.018),
                                              "r0/efficiency/tracking_phase/share": dict(m, mean=0.9),
                                              "r0/efficiency/share": dict(m, mean=0.97)}})
    assert g.limit_metric("efficiency_position", phase=True).mean == 1.1
    assert g.limit_metric("efficiency_position").mean == 30.0
    assert g.limit_metric("bound_position_rms_m", phase=True).mean == 0.018
    assert limit.aggregate_share_cell(g, True) == "90 %" and limit.aggregate_share_cell(g, False) == "97 %"


def test_aggregate_group_limit_metric_under_either_name():
    m = {"n": 3, "mean": 1.3, "ci95": [1.2, 1.4], "interval": "range", "no_value": 0}
    flat = AggregateGroup.from_json({"metrics": {"r0/efficiency/position": m, "r0/bound/posterior/position_rms_m": dict(m, mean=0.03)}})
    own = AggregateGroup.from_json({"metrics": {}, "efficiency_position": dict(m, mean=1.5), "bound_position_rms_m": dict(m, mean=0.02)})
    old = AggregateGroup.from_json({"metrics": {"r0/position_m/rmse": m}})
    assert flat.limit_metric("efficiency_position").mean == 1.3 and flat.limit_metric("bound_position_rms_m").mean == 0.03
    assert own.limit_metric("efficiency_position").mean == 1.5 and own.limit_metric("bound_position_rms_m").mean == 0.02
    assert old.limit_metric("efficiency_position") is None
    assert limit.aggregate_limit_cell(flat, False) == "1.30x (bound 3 cm)" and limit.aggregate_limit_cell(old, False) == "-"


# ---- compare ----------------------------------------------------------------------------------

def rows_of(runs_a, runs_b):
    _, rows = compare.compare_rows(runs_a, runs_b)
    return {r[1]: r for r in rows}


def test_compare_carries_the_efficiency_and_says_no_bound(tmp_path):
    a = write_side(tmp_path / "a", [1.3, 1.3, 1.3])
    b = write_side(tmp_path / "b", [1.6, 1.7, None])
    rows = rows_of(a, a)
    assert rows["efficiency/position"][2] == "1.3000" and rows["efficiency/position"][8] == "same"
    assert rows["efficiency/share"][2] == "0.9700"
    assert rows["bound/posterior/position_rms_m"][2] == "0.0300"
    assert rows["rpe/1s/translation_rms_m"][2] == "0.0300"
    rows = rows_of(a, b)
    assert rows["efficiency/position"][4] == "1.6500" and rows["efficiency/position"][5] == 2
    assert rows["efficiency/position"][8] == "no bound in 1 of 3 runs (B)"
    assert "no bound in 1 of 3 runs" in compare.explanation(a + b) or "'no bound in k of n runs'" in compare.explanation(a + b)
    every_null = write_side(tmp_path / "c", [None, None])
    assert rows_of(every_null, every_null)["efficiency/position"][2] == "no bound"


def test_compare_of_runs_from_before_the_bound_has_no_limit_rows(tmp_path):
    for seed in (1, 2):
        write_run(tmp_path / "old" / f"s{seed}", "tracking", "matching", seed, {}, scored(robot(3.9)), start_pose_given=True, scoring=SCORING)
    old = discover([tmp_path / "old"])[0]
    rows = rows_of(old, old)
    assert not [m for m in rows if m.startswith(("efficiency", "bound", "rpe"))]
    assert compare.explanation(old) == compare.EXPLANATION


# ---- gate -------------------------------------------------------------------------------------

def run_gate(tmp_path, results, rules):
    f = tmp_path / "rules.json"
    f.write_text(json.dumps({"rules": rules}))
    return subprocess.run([PY, "-m", "omniloc.commands.gate", str(results), "--rules", str(f)], capture_output=True, text=True, timeout=120)


def test_gate_efficiency_rule_passes_and_fails(tmp_path):
    write_side(tmp_path / "r" / "good", [1.3, 1.3, 1.3], localizer="good")
    write_side(tmp_path / "r" / "far", [1.8, 1.9, 2.0], localizer="far")
    p = run_gate(tmp_path, tmp_path / "r", [{"metric": "efficiency.position", "max": 1.5}])
    assert p.returncode == 1, p.stdout + p.stderr
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith(("PASS", "FAIL"))]
    assert any(ln.startswith("PASS  tracking / good  r0/efficiency/position  mean 1.3 (n=3)") for ln in lines), lines
    assert any(ln.startswith("FAIL  tracking / far  r0/efficiency/position  mean 1.9 (n=3)") and "limit: mean 1.9 > max 1.5" in ln for ln in lines), lines


def test_gate_fails_a_group_without_a_bound(tmp_path):
    write_side(tmp_path / "r", [1.3, None])
    p = run_gate(tmp_path, tmp_path / "r", [{"metric": "r0/efficiency/position", "max": 1.5}])
    assert p.returncode == 1
    assert "mean 1.3 (n=1 of 2)" in p.stdout and "[no bound in 1 of 2 runs]" in p.stdout, p.stdout


@pytest.mark.parametrize("rule, fragment", [
    ({"metric": "efficiency/pos", "max": 1.5}, "/rules/0/metric: got \"efficiency/pos\", expected a number of the accuracy limit"),
    ({"metric": "bound/posterior/position_rms", "max": 0.1}, "/rules/0/metric: got \"bound/posterior/position_rms\""),
    ({"metric": "efficiency/position", "max": 0}, "/rules/0/max: got 0, expected a positive ratio"),
    ({"metric": "r0/efficiency_single_frame/heading", "min": -1}, "/rules/0/min: got -1, expected a positive ratio"),
])
def test_gate_bad_efficiency_rules_name_the_json_path(tmp_path, rule, fragment):
    write_side(tmp_path / "r", [1.3])
    p = run_gate(tmp_path, tmp_path / "r", [rule])
    assert p.returncode == 2 and fragment in p.stderr, p.stderr
    assert not p.stdout.strip(), "bad input is found before any verdict"


def test_gate_efficiency_rule_on_runs_from_before_the_bound(tmp_path):
    write_run(tmp_path / "old" / "s1", "tracking", "matching", 1, {}, scored(robot(3.9)), start_pose_given=True, scoring=SCORING)
    p = run_gate(tmp_path, tmp_path / "old", [{"metric": "efficiency/position", "max": 1.5}])
    assert p.returncode == 2 and "none of their runs carries the accuracy limit" in p.stderr, p.stderr


def test_gate_directions_and_units():
    assert not gate.higher_is_better("r0/efficiency/position") and gate.higher_is_better("r0/efficiency/share")
    assert gate.unit_of("r0/efficiency/position") == "x bound" and gate.unit_of("r0/bound/posterior/position_rms_m") == "m"
    assert gate.spelt("efficiency.position") == "efficiency/position" and gate.spelt("recall/12.5cm_5deg") == "recall/12.5cm_5deg"


# ---- the report -------------------------------------------------------------------------------

def test_headline_per_localizer_and_family_names_the_scenario_furthest_from_the_limit(tmp_path):
    runs = (write_side(tmp_path / "t", [1.2, 1.2], scenario="tracking") + write_side(tmp_path / "o", [1.6, 1.8], scenario="occlusion_002")
            + write_side(tmp_path / "m", [3.0], scenario="tracking", localizer="mcl"))
    s = limit.headline_sentence(runs)
    assert "matching is 1.70x the limit on occlusion (2 runs, bound in 97 % of frames); 1.20x on tracking (2 runs, bound in 97 % of frames)" in s, s
    assert "the scenario that leaves most on the table is occlusion_002 (1.70x the limit, 1.6 cm above the bound)" in s, s
    assert "mcl is 3.0x the limit on tracking (1 run, bound in 97 % of frames)" in s, s
    old = [Run.read(write_viewable_run(tmp_path / "old"))]
    assert limit.headline_sentence(old) == "" and limit.robot_rows(old[0]) == []


def test_run_table_rows_say_each_figure_with_its_share(tmp_path):
    run = write_side(tmp_path / "r", [1.3])[0]
    [row] = limit.robot_rows(run)
    assert row[:4] == ["r0", "3.9 cm, 1.30x the limit (bound in 97 % of frames)", "3 cm (bound in 97 % of frames)",
                       "4.2 cm (bound in 97 % of frames)"]
    assert row[5] == "3 frames without a bound: 3 points on one line"


def test_paper_table_limit_cell(tmp_path):
    from omniloc.report.text_tables import limit_cell
    assert limit_cell(write_side(tmp_path / "a", [1.3, 1.5])) == "1.40x (bound in 97 % of frames)"
    assert limit_cell(write_side(tmp_path / "b", [1.3, None])) == "1.30x (bound in 48 % of frames; no bound in 1 of 2 runs)"  # the share counts every run's frames
    assert limit_cell(write_side(tmp_path / "c", [None])) == "no bound"


# ---- the viewer -------------------------------------------------------------------------------

def with_bound_columns(folder, every_without=10):
    """frames.csv with the four bound columns, a frame in `every_without` without a bound."""
    f = pathlib.Path(folder) / "frames.csv"
    lines = f.read_text().splitlines()
    out = [lines[0] + "," + ",".join(bound.FRAME_COLUMNS)]
    for k, ln in enumerate(lines[1:]):
        out.append(ln + (",,,," if k % every_without == 0 else ",0.031,0.006,0.024,0.004"))
    f.write_text("\n".join(out) + "\n")


def page_data(html):
    start = html.index('id="omniloc-data"')
    body = html[html.index(">", start) + 1:]
    return json.loads(body[:body.index("</script>")].replace("<\\/", "</"))


def test_viewer_draws_the_posterior_bound_and_leaves_old_pages_alone(tmp_path):
    old = write_viewable_run(tmp_path / "old")
    new = write_viewable_run(tmp_path / "new")
    with_bound_columns(new)
    page_old, page_new = render(load_run(old, images=False)), render(load_run(new, images=False))
    r_new = page_data(page_new)["robots"][0]
    assert r_new["boundKind"] == "posterior" and r_new["boundPos"][:2] == [None, 0.024] and r_new["boundTh"][1] == 0.004
    assert r_new["extra"] == {}, "the bound's columns are omniloc's, not the localizer's own"
    assert "raw.boundPos" in page_new and "<bound>" in page_new
    assert "boundPos" not in page_data(page_old)["robots"][0]
    assert "bound" not in page_old.split('id="omniloc-data"')[1].split("</script>", 1)[1], "the bound's drawing is left out of an old page"


def test_seed_table_and_run_table_in_a_written_report(tmp_path):
    from omniloc.report import runs as RRUNS, seeds as RSEED
    from omniloc.tools import markup
    sel = write_side(tmp_path / "r", [1.3, 1.5, None])
    rep = markup.Report(tmp_path / "out", "t")
    RSEED.seed_table(rep, [("tracking", sorted(sel, key=lambda r: r.seed))])
    RRUNS.report_run(rep, sel[0], plots=False)
    rep.write()
    md = (tmp_path / "out" / "report.md").read_text()
    nb = "\u00a0"
    assert f"seeds: s1{nb}1.30, s2{nb}1.50, s3{nb}no bound (no bound in 1 of 3 runs: the mean is over the others) (bound in 64 % of frames" in md
    assert "| RMSE against the limit |" in md and "3.9 cm, 1.30x the limit (bound in 97 % of frames)" in md
    old = tmp_path / "old"
    write_run(old / "s1", "tracking", "matching", 1, {}, scored(robot(3.9)), start_pose_given=True, scoring=SCORING)
    rep = markup.Report(tmp_path / "out_old", "t")
    RSEED.seed_table(rep, [("tracking", discover([old])[0])])
    RRUNS.report_run(rep, discover([old])[0][0], plots=False)
    rep.write()
    md = (tmp_path / "out_old" / "report.md").read_text()
    assert "limit" not in md and "bound" not in md


def test_localizer_rows_for_the_efficiency_table(tmp_path):
    runs = (write_side(tmp_path / "t", [1.2, 1.4], scenario="tracking") + write_side(tmp_path / "o", [None], scenario="occlusion_002")
            + write_side(tmp_path / "m", [3.0], scenario="tracking", localizer="mcl"))
    # matching on tracking: RMSE 3.9 cm in both runs, bounds 3.9 / 1.2 and 3.9 / 1.4 cm (mean 3.02 cm)
    assert limit.localizer_rows(runs) == [["matching", "occlusion", "1", "no bound", "no bound", "-", "no bound", "-", "1"],
                                          ["matching", "tracking", "2", "1.30x", "1.10x", "3.9 cm", "3.02 cm", "97 %", "0"],
                                          ["mcl", "tracking", "1", "3.00x", "1.10x", "3.9 cm", "1.3 cm", "97 %", "0"]]
    p = subprocess.run([PY, str(pathlib.Path(__file__).resolve().parents[2] / "scripts" / "limit_table.py"), str(tmp_path)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and "| matching | tracking | 2 | 1.30x | 1.10x | 3.9 cm | 3.02 cm | 97 % | 0 |" in p.stdout, p.stdout + p.stderr


def test_viewer_says_no_bound_where_the_columns_are_empty(tmp_path):
    run = write_viewable_run(tmp_path / "no_truth")
    with_bound_columns(run, every_without=1)  # every frame without a bound
    r = page_data(render(load_run(run, images=False)))["robots"][0]
    assert r["boundKind"] == "none" and set(r["boundPos"]) == {None}, "no bound is null, never 0"


def test_the_texts_take_the_rmse_over_the_frames_the_efficiency_covers():
    r = bounded(1.3)
    r["efficiency"] = dict(r["efficiency"], rmse_m=0.052, bound_rms_m=0.04)  # over the frames with a bound, not all answered ones
    rb = bound.read_robot_bound(r)
    assert rb.error_m == 0.052 and rb.limit_m == 0.04
    assert bound.robot_limit_text(rb) == "5.2 cm, 1.30x the limit (bound in 97 % of frames)"
    del r["efficiency"]["rmse_m"], r["efficiency"]["bound_rms_m"]
    rb = bound.read_robot_bound(r)
    assert rb.error_m == RMSE and rb.limit_m == pytest.approx(RMSE / 1.3)


def test_gate_a_recording_without_truth_has_no_bound(tmp_path):
    write_side(tmp_path / "r" / "a", [1.3], scenario="tracking")
    unscored = {"robot": 0, "frames": 30, "valid_frames": 30, "scored": False, "why": "the recording has no ground truth: nothing was scored"}
    write_run(tmp_path / "r" / "real", "nubot_robot1", "matching", 1, {}, unscored, start_pose_given=False)
    p = run_gate(tmp_path, tmp_path / "r", [{"metric": "efficiency/position", "max": 1.5}])
    assert p.returncode == 1, p.stdout + p.stderr
    assert "FAIL  nubot_robot1 / matching  r0/efficiency/position  no bound (n=0 of 1)" in p.stdout and "[no bound in 1 of 1 runs]" in p.stdout, p.stdout


def test_the_modern_references_target_is_said_with_the_bounds_own_filter_beside(tmp_path):
    def side(folder, effs, check, scenario):
        for seed, eff in enumerate(effs, 1):
            r = bounded(eff)
            if check is not None:
                r["bound"]["posterior"]["check"] = {"position_ratio": check, "heading_ratio": 1.0}
            write_run(pathlib.Path(folder) / f"s{seed}", scenario, "ukf_mh", seed, {}, r, start_pose_given=True, scoring=SCORING)
    side(tmp_path / "t", [1.0, 1.2], 1.05, "tracking")
    side(tmp_path / "o", [1.4, 1.6], 1.25, "occlusion_002")
    runs = [r for g in discover([tmp_path]) for r in g]
    assert limit.reference_sentence(runs) == (
        "The modern reference ukf_mh is, against its target of 1.3x the limit, within it on tracking (1.10x); above it on "
        "occlusion (1.50x), where the bound's own filter on the same frames (true association, the measured noise) is at 1.25x: "
        "ukf_mh is 1.20x what that filter has.")
    # Results without the modern reference, or made before the bound's check, say so or nothing.
    assert limit.reference_sentence([r for r in runs if r.scenario == "tracking"]).endswith("within it on tracking (1.10x).")
    side(tmp_path / "n", [1.5], None, "occlusion_002")
    only = [r for g in discover([tmp_path / "n"]) for r in g]
    assert limit.reference_sentence(only).endswith("above it on occlusion (1.50x; no check of the bound's own filter in these results).")
    write_side(tmp_path / "m", [1.4], localizer="matching")
    assert limit.reference_sentence([r for g in discover([tmp_path / "m"]) for r in g]) == ""
