"""olp/1 end to end through the omniloc binary (docs/protocol.md): results of an external client
equal the built-in ones where they must, a client written from the protocol page alone (Perl) works,
a failing client fails the run loudly and leaves nothing that looks finished, sweeps record the
failure and --resume retries it, and no client outlives omniloc (Ctrl-C, kill -9).

Run by ctest (external_cli_py) with OMNILOC_BIN set, from tests/.
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc"))
PY = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable
FAULTY = str(ROOT / "tests" / "protocol_clients" / "faulty_client.py")
PERL = str(ROOT / "tests" / "protocol_clients" / "perl_dead_reckoning.pl")


def scenario(localizer, duration=3.0, seed=3):
    s = json.loads((ROOT / "scenarios" / "quickstart.json").read_text())
    s["duration"] = duration
    s["seed"] = seed
    s["localizer"] = localizer
    return s


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


class ExternalCli(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="olp_cli_"))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, name, obj):
        p = self.tmp / name
        p.write_text(json.dumps(obj, indent=1))
        return str(p)

    def env(self):
        # A world cache of this test's own (docs/recording.md section 9), never the source tree's.
        return dict(os.environ, OMNILOC_CACHE=str(self.tmp / "world_cache"))

    def omniloc(self, *args, check=True):
        r = subprocess.run([BIN, *args], cwd=ROOT, capture_output=True, text=True, timeout=600, env=self.env())
        if check and r.returncode != 0:
            self.fail(f"omniloc {' '.join(args)} exited {r.returncode}:\n{r.stdout}\n{r.stderr}")
        return r

    def run_scenario(self, localizer, out, name=None, **kw):
        f = self.write((name or out) + ".json", scenario(localizer, **kw))
        self.omniloc("run", f, "-o", str(self.tmp / out))
        return self.tmp / out

    def test_validate_names_the_bad_command(self):
        f = self.write("bad.json", scenario({"type": "external", "command": [PY, "no/such/client.py"]}))
        r = self.omniloc("validate", f, check=False)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/localizer/command/1", r.stderr)
        f = self.write("bad2.json", scenario({"type": "external", "command": ["/no/such/program"]}))
        r = self.omniloc("validate", f, check=False)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/localizer/command/0", r.stderr)
        f = self.write("bad3.json", scenario({"type": "external", "command": [PY, FAULTY], "frame_timeout_s": 0}))
        r = self.omniloc("validate", f, check=False)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/localizer/frame_timeout_s", r.stderr)

    def test_external_dead_reckoning_equals_odometry_only(self):
        ref = self.run_scenario({"type": "odometry_only"}, "builtin")
        for name, loc in [("python", {"type": "external", "command": [PY, FAULTY, "ok"]}),
                          ("perl", {"type": "external", "command": ["perl", PERL]})]:
            with self.subTest(client=name):
                out = self.run_scenario(loc, name)
                self.assertEqual((out / "est.tum").read_bytes(), (ref / "est.tum").read_bytes())
                self.assertEqual((out / "gt.tum").read_bytes(), (ref / "gt.tum").read_bytes())
                s = json.loads((out / "summary.json").read_text())
                self.assertEqual(s["localizer_type"], "external")
                self.assertEqual(s["localizer"], "faulty" if name == "python" else "perl_dead_reckoning")
                script = FAULTY if name == "python" else PERL
                digest = subprocess.run(["sha256sum", script], capture_output=True, text=True).stdout.split()[0]
                self.assertIn({"path": script, "sha256": digest}, s["external"]["files"])
                self.assertTrue((out / "client_r0.stderr.log").exists())
                timing = (out / "timing.csv").read_text().splitlines()
                self.assertGreater(len(timing), 10)

    def test_client_compute_time_and_extra_hashed_files(self):
        # The Python client library reports the time update() took (estimate.compute_ms): timing.csv
        # carries it beside the round trip; a built-in run has no such column.
        helper = self.tmp / "helper_module.py"
        helper.write_text("# a module the client imports\n")
        py = self.run_scenario({"type": "external", "command": [PY, str(ROOT / "clients" / "python" / "examples" / "dead_reckoning.py")],
                                "hash": [str(helper)]}, "py_compute", duration=1.0)
        rows = (py / "timing.csv").read_text().splitlines()
        head = rows[0].split(",")
        self.assertEqual(head[-2:], ["localize_ms", "compute_ms"])
        pairs = [(float(r.split(",")[head.index("localize_ms")]), float(r.split(",")[head.index("compute_ms")])) for r in rows[1:]]
        self.assertEqual(len(pairs), 31)
        self.assertTrue(all(0 <= c for _, c in pairs), pairs)
        # The client's own time is part of the round trip (median: single frames may straddle clock reads).
        self.assertLess(sorted(c for _, c in pairs)[15], sorted(l for l, _ in pairs)[15])
        s = json.loads((py / "summary.json").read_text())
        digest = subprocess.run(["sha256sum", str(helper)], capture_output=True, text=True).stdout.split()[0]
        self.assertIn({"path": str(helper), "sha256": digest}, s["external"]["files"])
        ref = self.run_scenario({"type": "odometry_only"}, "builtin_timing", duration=1.0)
        self.assertEqual((ref / "timing.csv").read_text().splitlines()[0], "t,robot,render_ms,vision_ms,localize_ms")
        # A file to hash that is not there is an input error naming its path, before any work.
        bad = self.write("bad_hash.json", scenario({"type": "external", "command": [PY, FAULTY, "ok"], "hash": ["no_such_module.py"]}))
        r = self.omniloc("validate", bad, check=False)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("/localizer/hash/0", r.stderr)

    def test_perl_client_reads_images(self):
        out = self.run_scenario({"type": "external", "command": ["perl", PERL], "env": {"OLP_WANTS_IMAGE": "1"}}, "perl_img",
                                duration=0.5)
        rows = (out / "frames.csv").read_text().splitlines()
        head = rows[0].split(",")
        self.assertIn("image_mean", head)
        means = [float(r.split(",")[head.index("image_mean")]) for r in rows[1:]]
        self.assertTrue(all(20 < m < 200 for m in means), means)  # a lit field, not zeros or garbage

    def test_rerun_is_byte_identical(self):
        loc = {"type": "external", "command": [PY, FAULTY, "ok"]}
        a, b = self.run_scenario(loc, "a", name="same"), self.run_scenario(loc, "b", name="same")
        for f in ["est.tum", "gt.tum", "frames.csv", "events.jsonl", "config.json"]:
            self.assertEqual((a / f).read_bytes(), (b / f).read_bytes(), f)
        sa, sb = (json.loads((d / "summary.json").read_text()) for d in (a, b))
        self.assertEqual(sa, sb)

    def test_failed_run_leaves_nothing(self):
        f = self.write("fail.json", scenario({"type": "external", "command": [PY, FAULTY, "exit_at:5"]}))
        out = self.tmp / "failed_out"
        r = self.omniloc("run", f, "-o", str(out), check=False)
        self.assertEqual(r.returncode, 1, r.stderr)
        for part in ["frame 5", "exited with status 3", "faulty_client: exit_at at frame 5"]:
            self.assertIn(part, r.stderr)
        self.assertFalse(out.exists())
        self.assertEqual([p.name for p in self.tmp.iterdir() if "partial" in p.name], [])

    def test_sweep_records_failure_and_resume_retries(self):
        flag = self.tmp / "flag"
        self.write("scenario.json", scenario({"type": "odometry_only"}, duration=1.0))
        sweep = self.write("sweep.json", {
            "name": "olp_sweep", "scenarios": ["scenario.json"],
            "localizers": [{"type": "odometry_only"},
                           {"type": "external", "command": [PY, FAULTY, f"fail_once:{flag}"], "label": "flaky"}],
            "seeds": [1, 2]})
        out = self.tmp / "sweep_out"
        r = self.omniloc("sweep", sweep, "-o", str(out), "-j", "2", check=False)
        self.assertNotEqual(r.returncode, 0)
        failed = list((out / "failed").glob("*.json"))
        self.assertEqual(len(failed), 1, r.stdout + r.stderr)
        record = json.loads(failed[0].read_text())
        self.assertIn("exited with status 3", json.dumps(record))
        # The progress line says why in one line: the run's exit and its log's last message.
        lines = [x for x in (r.stdout + r.stderr).splitlines() if "FAILED" in x]
        self.assertEqual(len(lines), 1, r.stdout + r.stderr)
        self.assertRegex(lines[0], r"FAILED [0-9.]+ s \(exit [1-9][0-9]*; logs/[^ ]+\.log: .*exited with status 3")
        self.assertEqual(len(list((out / "runs").iterdir())), 3)  # the other runs went on
        r = self.omniloc("sweep", sweep, "-o", str(out), "--resume")
        self.assertEqual(list((out / "failed").glob("*.json")), [])
        agg = json.loads((out / "aggregate.json").read_text())
        flaky = [g for g in agg["groups"] if g["localizer"] == "flaky"][0]
        self.assertEqual(flaky["finished"], 2)
        self.assertEqual(flaky["external"][0]["name"], "faulty")

    def test_slurm_submission_records_the_client(self):
        self.write("scenario.json", scenario({"type": "odometry_only"}, duration=1.0))
        sweep = self.write("sweep.json", {"name": "olp_slurm", "scenarios": ["scenario.json"],
                                          "localizers": [{"type": "external", "command": [PY, FAULTY, "ok"]}], "seeds": [1, 2]})
        out = self.tmp / "slurm_out"
        self.omniloc("sweep", sweep, "--slurm", "--dry-run", "--tasks", "2", "-o", str(out))
        sub = json.loads((out / "slurm" / "submission.json").read_text())
        digest = subprocess.run(["sha256sum", FAULTY], capture_output=True, text=True).stdout.split()[0]
        self.assertEqual(len(sub["external_clients"]), 1)
        self.assertIn({"path": FAULTY, "sha256": digest}, sub["external_clients"][0]["files"])
        self.assertEqual(sub["external_clients"][0]["cwd"], str(ROOT))  # anchored: tasks start it in the same place

    def interrupt(self, sig):
        pids = self.tmp / f"pids_{sig}"
        f = self.write(f"slow_{sig}.json", scenario({"type": "external", "command": [PY, FAULTY, "slow:0.05", str(pids)]}, duration=30))
        out = self.tmp / f"out_{sig}"
        p = subprocess.Popen([BIN, "run", f, "-o", str(out)], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env=self.env())
        deadline = time.time() + 60
        while time.time() < deadline and not (pids.exists() and pids.read_text().strip()):
            time.sleep(0.1)
        time.sleep(1.0)  # in the middle of the frames
        client = int(pids.read_text().split()[0])
        self.assertTrue(alive(client))
        staging = [x for x in os.listdir(self.tmp) if x.startswith(f".out_{sig}.partial-")]
        self.assertEqual(len(staging), 1, "the run stages its folder (with the client's stderr log) beside -o")
        p.send_signal(sig)
        _, err = p.communicate(timeout=30)
        deadline = time.time() + 5
        while time.time() < deadline and alive(client):
            time.sleep(0.05)
        self.assertFalse(alive(client), f"client {client} outlived omniloc after signal {sig}")
        self.assertFalse(out.exists())
        left = [x for x in os.listdir(self.tmp) if x.startswith(f".out_{sig}")]
        if sig == signal.SIGKILL:
            # kill -9 cannot be caught: the staging folder stays until the next run there clears it.
            self.assertEqual(left, staging)
            self.run_scenario({"type": "odometry_only"}, f"out_{sig}", name=f"again_{sig}", duration=0.5)
            self.assertEqual([x for x in os.listdir(self.tmp) if x.startswith(f".out_{sig}")], [])
            return
        # Dies of the signal itself, as shells expect (they print 130 / 143 / 129), after one line.
        self.assertEqual(p.returncode, -sig)
        self.assertEqual(left, [], "the staging folder must go with an interrupted run")
        lines = [x for x in err.splitlines() if x.startswith("omniloc: ")]
        self.assertEqual(len(lines), 1, err)
        self.assertIn({signal.SIGINT: "interrupted", signal.SIGTERM: "terminated", signal.SIGHUP: "hung up"}[sig], lines[0])
        self.assertIn("staging folder was removed", lines[0])

    def test_ctrl_c_ends_the_client(self):
        self.interrupt(signal.SIGINT)

    def test_kill_9_ends_the_client(self):
        self.interrupt(signal.SIGKILL)

    def test_sigterm_ends_the_client(self):  # what scancel and kill send first
        self.interrupt(signal.SIGTERM)

    def test_sighup_ends_the_client(self):  # a closed terminal or ssh session
        self.interrupt(signal.SIGHUP)

    def test_ctrl_c_removes_a_built_in_run_staging_folder(self):
        f = self.write("long.json", scenario({"type": "matching"}, duration=60))
        out = self.tmp / "out_builtin"
        # --draw-each: a live run, interrupted while it draws (a world from the cache would be done first).
        p = subprocess.Popen([BIN, "run", f, "-o", str(out), "--draw-each"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env=self.env())
        deadline = time.time() + 60
        while time.time() < deadline and not any(x.startswith(".out_builtin.partial-") for x in os.listdir(self.tmp)):
            time.sleep(0.05)
        time.sleep(0.5)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
        self.assertEqual(p.returncode, -signal.SIGINT, err)
        self.assertEqual([x for x in os.listdir(self.tmp) if x.startswith(".out_builtin")], [])
        self.assertFalse(out.exists())
        self.assertIn("omniloc: interrupted (SIGINT)", err)


if __name__ == "__main__":
    unittest.main()
