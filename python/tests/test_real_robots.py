"""The report's real-robot section on the NuBot frames (data/real/nubot).
"""
import json
import math
import re
import pathlib
import subprocess
import tempfile
import unittest

from helpers import OMNILOC, PY, REAL, ROOT, needs_omniloc, real_reference, robot, write_occlusion_sweep, write_real_run, write_sim_recording
from omniloc.core import rundir as RD
from omniloc.report import real_robots as RR
from omniloc.tools import markup as MU


class RealRobots(unittest.TestCase):
    """The report's "Real robots" section (omniloc.report.real_robots): runs on the real NuBot frames
    classified found / twin / wrong against the reference pose and its twin, and the line-point
    noise of the real frames beside the simulated profiles'."""

    @needs_omniloc
    def test_found_twin_and_wrong_from_a_real_sweep_and_faked_runs(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            # A tiny real-robots sweep: one real recording, two localizers, by the binary.
            (tmp / "rr.json").write_text(json.dumps({"name": "real_robots", "scenarios": [{"recording": str(REAL / "robot1")}], "localizers": [
                {"type": "grid_global"}, {"type": "mcl", "adapt_to_no_compass": False, "label": "mcl_as_published"}]}))
            out = subprocess.run([OMNILOC, "sweep", str(tmp / "rr.json"), "-o", str(tmp / "results" / "real_robots"), "-j", "2"],
                                 capture_output=True, text=True, timeout=300)
            self.assertEqual(out.returncode, 0, out.stderr)
            loose = tmp / "results" / "loose"
            ref2 = real_reference("robot2")
            twin2 = ref2["twin"]
            # robot 2, mcl: no estimate for 10 frames, then 2 cm and 0.01 rad from the TWIN: found as the twin.
            write_real_run(loose, "robot2", "mcl", 1, [None] * 10 + [(twin2[0] + 0.02, twin2[1], twin2[2] + 0.01)] * 20)
            # robot 4, hybrid: on the reference, then 1.2 m off at the end: wrong.
            ref4 = real_reference("robot4")["reference"]
            write_real_run(loose, "robot4", "hybrid", 1, [tuple(ref4)] * 20 + [(ref4[0] - 1.2, ref4[1], ref4[2])] * 10)
            # robot 5, hybrid: right, then no estimate in the last frame.
            ref5 = real_reference("robot5")["reference"]
            write_real_run(loose, "robot5", "hybrid", 1, [tuple(ref5)] * 29 + [None])
            # robot 1, grid_global at seed 2, ending on the twin: two seeds of one frame are counted.
            twin1 = real_reference("robot1")["twin"]
            write_real_run(loose, "robot1", "grid_global", 2, [tuple(twin1)] * 30)
            runs, sweeps, _ = RD.discover([tmp / "results"])
            judged = {(x.label, x.folder.name, x.run.seed): x.judged for x in RR.real_runs(runs)}
            self.assertEqual(judged[("grid_global", "robot1", 1)].outcome, "found")  # the exhaustive grid: reference or twin, here the reference
            self.assertLess(judged[("grid_global", "robot1", 1)].error_m, 0.05)
            self.assertEqual(judged[("grid_global", "robot1", 1)].first_fix_s, 0.0)
            self.assertIn(judged[("mcl_as_published", "robot1", 1)].outcome, ("found", "twin", "wrong", "none"))
            j = judged[("mcl", "robot2", 1)]
            self.assertEqual(j.outcome, "twin")
            self.assertAlmostEqual(j.error_m, 0.02, places=6)
            self.assertAlmostEqual(j.error_deg, math.degrees(0.01), delta=0.001)  # the header's twin is rounded to 1e-5 rad
            self.assertAlmostEqual(j.answered, 20 / 30)
            self.assertAlmostEqual(j.first_fix_s, 10 / 30, places=3)
            self.assertEqual(judged[("hybrid", "robot4", 1)].outcome, "wrong")
            self.assertAlmostEqual(judged[("hybrid", "robot4", 1)].error_m, 1.2, places=6)
            self.assertEqual(judged[("hybrid", "robot4", 1)].first_fix_s, 0.0)
            self.assertEqual(judged[("hybrid", "robot5", 1)].outcome, "none")
            self.assertEqual(judged[("grid_global", "robot1", 2)].outcome, "twin")
            # The report: the section right after the scorecard, every case as classified.
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True, cwd=str(tmp))
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            doc = (tmp / "rep" / "report.html").read_text()
            h2 = re.findall(r"<h2 id=\"([^\"]+)\"", doc)
            self.assertEqual(h2[:3], ["scorecard", "real-robots", "provenance"])
            section = md.split("## Real robots", 1)[1].split("\n## ", 1)[0]
            self.assertIn("| mcl | data/real/nubot/robot2 | 1 | twin | 2.0 cm | 0.6 deg | 66.7 % | 0.33 s |", section)
            self.assertIn("| hybrid | data/real/nubot/robot4 | 1 | wrong | 1.20 m | 0.0 deg | 100.0 % | 0.00 s |", section)
            self.assertIn("| hybrid | data/real/nubot/robot5 | 1 | no estimate at the end |", section)
            self.assertIn("| grid_global | data/real/nubot/robot1 | 1, 2 | 2 of 2 found or twin (1 found, 1 twin) |", section)
            self.assertIn("| mcl_as_published (Lu et al. 2013 [3]'s 600-particle MCL as published: `adapt_to_no_compass` false) | data/real/nubot/robot1 | 1 |",
                          section)
            # Totals per localizer.
            self.assertIn("| grid_global | 2 | 1 | 1 | 1 | 0 | 0 | 2 of 2 |", section)
            self.assertIn("| hybrid | 2 | 2 | 0 | 0 | 1 | 1 | 0 of 2 |", section)
            self.assertIn("not by any localizer under test", section)
            self.assertIn("lower bound", section)
            self.assertNotIn("Not run**: no replay", section)
            # The real runs stay out of the pooled CDF (scored there against the reference only).
            self.assertNotIn("Error CDF per localizer", md)
            for text in (doc, md):
                self.assertNotIn(str(tmp), text)

    def test_noise_table_real_and_simulated(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            # The real figures equal those the recordings' headers carry (the converter's).
            for robot in ("robot1", "robot2", "robot4", "robot5"):
                head = json.loads((REAL / robot / "recording.json").read_text())
                got = RR.real_noise(RR.read_header(REAL / robot))
                for g, want in zip(got, head["reference"]["line_point_noise"]["bands"]):
                    self.assertEqual((g.range_m, g.points), (want["range_m"], want["points"]))
                    for k in ("median_cm", "p90_cm"):
                        if want[k] is None:
                            self.assertIsNone(getattr(g, k))
                        else:
                            self.assertAlmostEqual(getattr(g, k), want[k], delta=0.006, msg=f"{robot} {k}")
            write_sim_recording(tmp / "paper_suite")
            _, sweeps, _ = RD.discover([tmp / "paper_suite"])
            rep = MU.Report(tmp / "out", "t")
            RR.section(rep, [], sweeps)
            rep.write()
            md = (tmp / "out" / "report.md").read_text()
            self.assertIn("| range m | real: robot1 | real: robot2 | real: robot4 | real: robot5 | simulated: robot profile | simulated: field_robot profile |", md)
            self.assertIn("| 0-1.5 | 0 points | 0 points | 0 points | 0 points | 1: 22.5 / 22.5 | not run |", md)
            self.assertIn("| 1.5-3 | 261: 2.7 / 5.1 | 332: 1.5 / 3.8 | 318: 2.6 / 6.3 | 327: 1.6 / 3.5 | 2: 4.5 / 4.9 | not run |", md)
            self.assertIn("| 3-5 | 744: 4.4 / 10.1 | 709: 5.4 / 10.4 | 781: 4.5 / 10.8 | 698: 5.4 / 10.5 | 2: 1.5 / 2.7 | not run |", md)
            self.assertIn("| 5-7.5 | 762: 6.2 / 16.2 | 1052: 5.1 / 12.4 | 880: 4.8 / 12.9 | 918: 4.2 / 11.9 | 2: 7.5 / 9.5 | not run |", md)
            self.assertIn("robot: 1 recording of the tracking path (seed 1), every frame, 1 frames", md)
            self.assertIn("build/omniloc sweep scenarios/sweeps/paper_suite_field_robot.json -j 2", md)  # what to run for the missing profile

    def test_without_real_results_the_section_says_what_to_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = pathlib.Path(tmp)
            write_occlusion_sweep(tmp / "results" / "s", [0.0])
            out = subprocess.run([PY, "-m", "omniloc.commands.report", str(tmp / "results"), "-o", str(tmp / "rep"), "--history", "none"],
                                 capture_output=True, text=True, cwd=str(tmp))
            self.assertEqual(out.returncode, 0, out.stderr)
            md = (tmp / "rep" / "report.md").read_text()
            section = md.split("## Real robots", 1)[1].split("\n## ", 1)[0]
            self.assertIn("**Not run**: no replay of a real recording among these results. Run `build/omniloc sweep scenarios/sweeps/real_robots.json -j 2`",
                          section)
            self.assertIn("| 3-5 | 744: 4.4 / 10.1 |", section)  # the shipped frames' own figures need no run
            self.assertIn("`build/omniloc sweep scenarios/sweeps/paper_suite.json -j 2`", section)
            self.assertIn("`build/omniloc sweep scenarios/sweeps/paper_suite_field_robot.json -j 2`", section)

    def test_the_shipped_sweep_names_every_real_frame_and_localizer(self):
        spec = json.loads((ROOT / "scenarios/sweeps/real_robots.json").read_text())
        self.assertEqual(sorted(pathlib.Path(e["recording"]).name for e in spec["scenarios"]), ["robot1", "robot2", "robot4", "robot5"])
        for e in spec["scenarios"]:
            self.assertTrue((ROOT / "scenarios/sweeps" / e["recording"] / "recording.json").exists(), e)
        labels = [l.get("label", l["type"]) for l in spec["localizers"]]
        self.assertEqual(labels, ["mcl", "hybrid", "grid_global", "mcl_as_published"])
        self.assertIs(spec["localizers"][3]["adapt_to_no_compass"], False)
