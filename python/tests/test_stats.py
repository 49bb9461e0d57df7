"""Statistics for few seeds: the interval rule (docs/results.md "Intervals"), Welch, outliers.
"""
import pathlib
import tempfile
import unittest

from helpers import ROOT, load_script
from omniloc.core import stats
from omniloc.core.aggregate import AggregateMetric


class Statistics(unittest.TestCase):
    def test_student_t(self):
        self.assertAlmostEqual(stats.t_quantile_975(1), 12.706, places=3)
        self.assertAlmostEqual(stats.t_quantile_975(10), 2.228, places=3)
        self.assertAlmostEqual(stats.t_two_sided_p(2.228, 10), 0.05, places=4)

    def test_intervals_only_with_two_values(self):
        self.assertIsNone(stats.stats([4.75]).lo)
        self.assertEqual(stats.fstat(stats.stats([4.75])), "4.750 (n=1, no interval)")
        self.assertEqual(stats.interval([4.75]), stats.Interval(n=1, mean=4.75, lo=4.75, hi=4.75, kind=stats.NO_INTERVAL))
        self.assertEqual(stats.interval([None, float("nan")]).kind, None)


class IntervalRule(unittest.TestCase):
    """One interval rule everywhere (docs/results.md "Intervals"), the same as
    batch/aggregate.cpp's mean_ci95 (tests/sweep_test.cpp Sweep.ConfidenceInterval: same answers)."""

    def test_five_or_more_seeds_get_the_t_interval(self):
        # 1..5: mean 3, sd 1.58114, t(4) = 2.776445: half width 1.963243.
        iv = stats.interval([1.0, 2.0, 3.0, 4.0, 5.0])
        self.assertEqual(iv.kind, stats.T95)
        self.assertAlmostEqual(iv.hi - iv.mean, 1.963243, places=5)
        self.assertAlmostEqual(iv.mean - iv.lo, 1.963243, places=5)
        self.assertEqual(stats.interval_text(iv), "3.000 [1.037, 4.963] (n=5, t95)")
        s = stats.stats([1.0, 2.0, 3.0, 4.0, 5.0])
        self.assertEqual((s.lo, s.hi, s.method), (iv.lo, iv.hi, stats.T95))

    def test_fewer_than_five_seeds_get_their_range_marked_as_such(self):
        # One seed at 806 cm beside two at 3 cm (the MCL row): Student t gives [-881, 1422],
        # the old bootstrap [3.0, 712] (it never leaves the seeds' range and covers the mean ~60 %).
        iv = stats.interval([806.0, 3.0, 3.0])
        self.assertEqual((iv.lo, iv.hi, iv.kind), (3.0, 806.0, stats.RANGE))
        self.assertEqual(stats.interval_text(iv, 2), "270.67 (seeds' range 3.00 to 806.00, n=3)")
        self.assertEqual(stats.interval([1.0, 2.0, 3.0, 4.0]).kind, stats.RANGE)
        self.assertEqual(stats.interval_text(stats.interval([1.0, 2.0, 3.0, 4.0]), 2), "2.50 (seeds' range 1.00 to 4.00, n=4)")
        s = stats.stats([806.0, 3.0, 3.0])
        self.assertEqual((s.lo, s.hi, s.method, s.median), (3.0, 806.0, stats.RANGE, 3.0))
        self.assertEqual(s.values, [806.0, 3.0, 3.0])
        self.assertEqual(stats.stats([2.0, 2.0, 2.0]).lo, 2.0)

    def test_a_non_negative_sample_never_gets_a_negative_bound(self):
        # Unclipped t: mean 2.06 - 5.53 < 0; the clipped bound is 0; a signed sample keeps its t bound.
        for v in ([0.05, 0.1, 0.1, 0.05, 10.0], [0.0, 0.0, 0.0, 0.0, 7.0], [806.0, 3.0, 3.0], [1e-3, 5.0], [0.0] * 6, [0.1] * 4 + [40.0] * 2):
            iv = stats.interval(v)
            self.assertGreaterEqual(iv.lo, 0.0, v)
            self.assertLessEqual(iv.lo, iv.mean, v)
            self.assertLessEqual(iv.mean, iv.hi, v)
        self.assertEqual(stats.interval([0.05, 0.1, 0.1, 0.05, 10.0]).lo, 0.0)
        self.assertLess(stats.interval([-1.0, 0.05, 0.1, 0.05, 10.0]).lo, 0.0)

    def test_old_aggregates_still_read(self):
        # aggregate.json from before the rule: no "interval", an unclipped Student t for every n >= 2.
        self.assertEqual(AggregateMetric.from_json({"n": 3, "mean": 1.94, "ci95": [-6.19, 10.07]}).bounds(), (-6.19, 10.07, "t95 (old aggregate)"))
        self.assertEqual(AggregateMetric.from_json({"n": 1, "mean": 1.0, "ci95": [1.0, 1.0]}).bounds()[2], stats.NO_INTERVAL)
        self.assertEqual(AggregateMetric.from_json({"n": 3, "mean": 1.0, "ci95": [0.5, 2.0], "interval": "range"}).bounds(), (0.5, 2.0, stats.RANGE))

    def test_check_report_html_flags_negative_bounds_of_non_negative_quantities(self):
        H = load_script("check_report_html")
        self.assertEqual(H.negative_bounds("mean 1.94 [0.000, 10.07] (n=5, t95); 270.67 (seeds' range 3.00 to 806.00, n=3)"), [])
        self.assertEqual(H.negative_bounds("rmse 1.94 [-6.19, 10.07] n=3"), ["1.94 [-6.19, 10.07]"])
        with tempfile.TemporaryDirectory() as tmp:
            f = pathlib.Path(tmp) / "aggregate.csv"
            f.write_text("scenario,localizer,params,start_pose_given,metric,n,mean,ci95_low,ci95_high\n"
                         "tracking,mcl,default,true,r0/position_m/rmse,3,1.94,-6.19,10.07\n"
                         "tracking,mcl,default,true,r0/heading_bias,3,0.1,-0.2,0.4\n")  # a signed metric may
            bad = H.negative_bounds("", f)
            self.assertEqual(len(bad), 1)
            self.assertIn("r0/position_m/rmse", bad[0])

    def test_the_coverage_table_in_the_docs_names_the_rule(self):
        text = (ROOT / "docs" / "results.md").read_text()
        self.assertTrue("## Intervals" in text and "scripts/interval_coverage.py" in text, "docs/results.md has no section Intervals")

    def test_outlying_seed(self):
        self.assertEqual(stats.outliers([806.0, 3.0, 3.0]), [0])
        self.assertEqual(stats.outliers([2.9, 3.0, 3.3]), [])
        self.assertEqual(stats.outliers([3.0, 3.1, 2.9, 40.0]), [3])
        self.assertEqual(stats.outliers([3.0, 806.0]), [])  # two seeds: neither is "the odd one"
        self.assertEqual(stats.outliers([2.0, 3.0, 7.0]), [])  # 7 < 3 x 2.5: spread, not an outlier

    def test_welch(self):
        # Known case: a = 1..5, b = 3..7 (equal spread): t = 2 / sqrt(2.5/5 * 2) = 2, df = 8, p = 0.0805.
        w = stats.welch([1, 2, 3, 4, 5], [3, 4, 5, 6, 7])
        self.assertAlmostEqual(w.diff, 2.0)
        self.assertAlmostEqual(w.t, 2.0)
        self.assertAlmostEqual(w.df, 8.0)
        self.assertAlmostEqual(w.p, 0.0805, places=4)
