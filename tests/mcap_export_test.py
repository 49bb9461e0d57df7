#!/usr/bin/env python3
"""`omniloc export` (docs/viewer.md) checked by readers that are not ours: short runs and recordings
are made, exported, and every file is read by tests/mcap_reader/check.js with the MCAP project's
own reader (@mcap/core, pinned in tests/mcap_reader/package-lock.json), which checks the records,
the CRCs, the summary and indexes, decodes every message and validates it against the Foxglove
JSON schemas of @foxglove/schemas, and compares every estimate with est.tum's row and every line
point with view.jsonl's (or the recording's frames). Also: a sweep folder (one file per run), the
same input giving the same bytes, and bad input (exit 2 naming the file, nothing written).

    OMNILOC_BIN=build/omniloc PYTHONPATH=python /usr/bin/python3 tests/mcap_export_test.py

The Node packages are installed with `npm ci` from the lockfile into $OMNILOC_MCAP_READER_DIR
(default build/mcap_reader). Without node or npm, or when npm cannot install (no network), the file
says why and exits 77 (ctest: skipped), unless OMNILOC_MCAP_CHECK=required (.ci/run sets it after
installing them with `scripts/install-deps.sh --mcap-check`): then a missing reader fails the test.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc"))
PY = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable
ENV = dict(os.environ, PYTHONPATH=str(ROOT / "python") + os.pathsep + os.environ.get("PYTHONPATH", ""), PYTHONDONTWRITEBYTECODE="1")
READER_SRC = ROOT / "tests" / "mcap_reader"
READER = Path(os.environ.get("OMNILOC_MCAP_READER_DIR", str(ROOT / "build" / "mcap_reader")))
SKIP = 77


def prepare_reader():
    """The checker and its pinned packages in READER; the reason in words where that cannot be."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        return None, f"{'node' if node is None else 'npm'} is not installed (Debian: apt-get install nodejs npm; scripts/install-deps.sh)"
    READER.mkdir(parents=True, exist_ok=True)
    lock = (READER_SRC / "package-lock.json").read_bytes()
    stamp = READER / "installed-lock.json"
    for name in ("package.json", "package-lock.json", "check.js"):
        shutil.copyfile(READER_SRC / name, READER / name)
    if not (stamp.exists() and stamp.read_bytes() == lock and (READER / "node_modules").is_dir()):
        r = subprocess.run([npm, "ci", "--no-audit", "--no-fund", "--loglevel=error"], cwd=READER, capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            first = " / ".join(line.strip() for line in r.stderr.strip().splitlines()[:2])
            return None, f"npm ci could not install the pinned @mcap/core and @foxglove/schemas (no network?): {first[:300]}"
        stamp.write_bytes(lock)
    return node, None


NODE, WHY_NOT = prepare_reader()


def omniloc(*args):
    r = subprocess.run([BIN, *map(str, args)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"omniloc {' '.join(map(str, args))}: exit {r.returncode}: {r.stderr[-2000:]}"
    return r


def export(*args):
    env = dict(ENV, OMNILOC_EXPORT_PROG="omniloc export")
    return subprocess.run([PY, "-m", "omniloc.commands.export", *map(str, args)], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=300)


def scenario(base, duration, name, **extra):
    s = json.loads((ROOT / "scenarios" / base).read_text())
    s.update(duration=duration, name=name, **extra)
    return s


@unittest.skipIf(NODE is None, WHY_NOT or "")
class Export(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="omniloc_mcap_"))
        # 4 s of the paper's tracking path with matching, and with MCL (particles), both with view.jsonl.
        cls.runs = {}
        for loc in ("matching", "mcl"):
            sc = cls.tmp / f"{loc}.json"
            sc.write_text(json.dumps(scenario("paper/tracking.json", 4.0, f"mcap_{loc}", localizer={"type": loc})))
            cls.runs[loc] = cls.tmp / f"run_{loc}"
            omniloc("run", sc, "--debug-view", "-o", cls.runs[loc], "--quiet")
        # 2 s of the landmark scenario (coloured landmarks: blobs).
        sc = cls.tmp / "landmarks.json"
        sc.write_text(json.dumps(scenario("paper/landmarks_003.json", 2.0, "mcap_landmarks")))
        cls.run_lm = cls.tmp / "run_landmarks"
        omniloc("run", sc, "--debug-view", "-o", cls.run_lm, "--quiet")
        # 1 s recorded with images, and a run replayed from it (line points and images from the recording).
        sc = cls.tmp / "images.json"
        sc.write_text(json.dumps(scenario("paper/tracking.json", 1.0, "mcap_images")))
        cls.rec_img = cls.tmp / "rec_img"
        omniloc("record", sc, "--images", "-o", cls.rec_img, "--quiet")
        cls.run_img = cls.tmp / "run_img"
        omniloc("replay", cls.rec_img, "--localizer", '{"type": "matching"}', "-o", cls.run_img, "--quiet")
        # A kidnap and an occlusion (events, invalid frames), no view.jsonl.
        sc = cls.tmp / "kidnap.json"
        sc.write_text(json.dumps(scenario("paper/kidnap_002.json", 6.0, "mcap_kidnap", events=[
            {"type": "kidnap", "t": 2.0, "pose": [-6.75, 3.25, 1.571], "duration": 1.0},
            {"type": "occlude", "t": 4.0, "robot": 0, "duration": 1.0, "fraction": 0.5}])))
        cls.run_k = cls.tmp / "run_kidnap"
        omniloc("run", sc, "-o", cls.run_k, "--quiet")
        # Two localized robots (odometry only): est.tum and est_r1.tum.
        q = scenario("quickstart.json", 2.0, "mcap_two")
        q["robots"][1]["localize"] = True
        sc = cls.tmp / "two.json"
        sc.write_text(json.dumps(q))
        cls.run_2 = cls.tmp / "run_two"
        omniloc("run", sc, "-o", cls.run_2, "--quiet")
        cls.out = cls.tmp / "out"
        cls.out.mkdir()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def exported(self, source, name, *args):
        out = self.out / name
        r = export(source, "-o", out, *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(out.is_file())
        self.assertIn(f"wrote {out}", r.stdout)
        return out

    def read(self, mcap, *args, ok=True):
        """check.js's verdict on the file; its summary (what it read) where it passed."""
        r = subprocess.run([NODE, str(READER / "check.js"), str(mcap), *map(str, args)], cwd=READER, capture_output=True, text=True,
                           timeout=300)
        if ok:
            self.assertEqual(r.returncode, 0, r.stderr[-3000:])
            return json.loads(r.stdout.strip().splitlines()[-1])
        self.assertEqual(r.returncode, 1, r.stdout + r.stderr)
        return r.stderr

    def frames(self, run):
        return len((run / "gt.tum").read_text().splitlines())

    def test_tracking_run_round_trip(self):
        run = self.runs["matching"]
        s = self.read(self.exported(run, "matching.mcap"), "--run", run)
        n = self.frames(run)
        self.assertEqual(s["compression"], "lz4")
        for topic in ("/r0/truth", "/r0/numbers", "/r0/line_points"):
            self.assertEqual(s["topics"][topic], n, topic)
        self.assertEqual(s["topics"]["/tf"], 2 * n)
        self.assertEqual(s["topics"]["/field"], 1)
        valid = sum(1 for line in (run / "frames.csv").read_text().splitlines()[1:] if line.split(",")[12] == "1")
        self.assertEqual(s["topics"]["/r0/estimate"], valid)
        self.assertEqual(s["round_trip"]["poses"], valid + n)
        points = sum(len(json.loads(line)["line_points"]) for line in (run / "view.jsonl").read_text().splitlines())
        self.assertGreater(points, 1000)
        self.assertEqual(s["round_trip"]["line_points"], points)

    def test_particles_and_ellipse(self):
        run = self.runs["mcl"]
        s = self.read(self.exported(run, "mcl.mcap"), "--run", run)
        n = self.frames(run)
        self.assertEqual(s["topics"]["/r0/particles"], n)
        self.assertEqual(s["topics"]["/r0/uncertainty"], n)
        fewer = self.read(self.exported(run, "mcl_few.mcap", "--particles", "10"))
        self.assertEqual(fewer["topics"]["/r0/particles"], n)
        none = self.read(self.exported(run, "mcl_none.mcap", "--particles", "0"))
        self.assertNotIn("/r0/particles", none["topics"])

    def test_recording_and_images(self):
        s = self.read(self.exported(self.rec_img, "rec.mcap"), "--recording", self.rec_img)
        n = json.loads((self.rec_img / "recording.json").read_text())["frames"]
        self.assertEqual(s["images"], n)
        self.assertEqual(s["topics"]["/r0/truth"], n)
        self.assertGreater(s["round_trip"]["line_points"], 100)
        # A run replayed from it: its line points and images from --recording.
        s = self.read(self.exported(self.run_img, "run_img.mcap", "--recording", self.rec_img, "--image-every", "5"),
                      "--run", self.run_img, "--recording", self.rec_img)
        self.assertEqual(s["images"], len(range(0, n, 5)))
        self.assertEqual(s["topics"]["/r0/line_points"], n)
        s = self.read(self.exported(self.run_img, "run_noimg.mcap", "--recording", self.rec_img, "--no-images"))
        self.assertNotIn("/r0/camera", s["topics"])

    def test_blobs(self):
        s = self.read(self.exported(self.run_lm, "landmarks.mcap"), "--run", self.run_lm)
        blobs = sum(len(json.loads(line).get("blobs") or []) for line in (self.run_lm / "view.jsonl").read_text().splitlines())
        self.assertGreater(blobs, 10)
        self.assertEqual(s["blobs"], blobs)

    def test_every_frames_csv_column_is_plottable(self):
        """The accuracy bound's columns (and any other a build adds to frames.csv) reach the numbers."""
        run = self.copy_run("with_bounds")
        rows = (run / "frames.csv").read_text().splitlines()
        bounds = ["bound_pos_m", "bound_heading_rad", "pbound_pos_m", "pbound_heading_rad"]
        if set(bounds) <= set(rows[0].split(",")):
            # This build writes them: one frame without a finite bound is made, as a run has them.
            head = rows[0].split(",")
            cells = [row.split(",") for row in rows[1:]]
            for c in bounds:
                cells[3][head.index(c)] = ""
            out = [rows[0]] + [",".join(c) for c in cells]
        else:
            out = [rows[0] + "," + ",".join(bounds)]
            out += [row + (",,,," if k == 3 else f",0.0{k % 7 + 1},0.00{k % 5 + 1},0.1,0.02") for k, row in enumerate(rows[1:])]
        (run / "frames.csv").write_text("\n".join(out) + "\n")
        s = self.read(self.exported(run, "bounds.mcap"), "--run", run)
        self.assertTrue(set(bounds) <= set(s["number_keys"]["/r0/numbers"]), s["number_keys"])
        self.assertEqual(s["numbers"], (len(out) - 1) * (len(out[0].split(",")) - 1))  # every cell but robot
        self.assertTrue({"err_pos", "err_theta", "valid", "mode", "match_error", "line_points"} <= set(s["number_keys"]["/r0/numbers"]))

    def test_handwritten_recording(self):
        """A log written from the format's documentation alone: no field markings, plain frames.jsonl."""
        rec = ROOT / "tests" / "data" / "handwritten_recording"
        s = self.read(self.exported(rec, "handwritten.mcap"), "--recording", rec)
        self.assertEqual(s["topics"]["/r0/line_points"], 30)
        self.assertNotIn("/field", s["topics"])

    def test_events_and_invalid_frames(self):
        s = self.read(self.exported(self.run_k, "kidnap.mcap"), "--run", self.run_k)
        events = [json.loads(line) for line in (self.run_k / "events.jsonl").read_text().splitlines() if line.strip()]
        self.assertGreater(len(events), 2)
        self.assertEqual(s["topics"]["/events"], len(events))
        self.assertLess(s["topics"]["/r0/estimate"], self.frames(self.run_k))
        self.assertNotIn("/r0/line_points", s["topics"])

    def test_two_robots(self):
        s = self.read(self.exported(self.run_2, "two.mcap"), "--run", self.run_2)
        self.assertEqual(s["topics"]["/r1/numbers"], self.frames(self.run_2))
        self.assertGreater(s["round_trip"]["poses"], 4 * self.frames(self.run_2) - 8)

    def test_same_input_same_bytes(self):
        a = self.exported(self.runs["mcl"], "a.mcap")
        b = self.exported(self.runs["mcl"], "b.mcap")
        self.assertEqual(a.read_bytes(), b.read_bytes())

    def test_sweep_folder_one_file_per_run(self):
        sweep = self.tmp / "sweep"
        for name, run in (("a__matching__s1", self.runs["matching"]), ("b__mcl__s1", self.runs["mcl"])):
            shutil.copytree(run, sweep / "runs" / name)
        out = self.out / "sweep_out"
        r = export(sweep, "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(p.name for p in out.iterdir()), ["a__matching__s1.mcap", "b__mcl__s1.mcap"])
        self.read(out / "b__mcl__s1.mcap", "--run", sweep / "runs" / "b__mcl__s1")

    def test_the_checker_fails_on_a_damaged_file(self):
        """The reader's verdict means something: a flipped byte in a chunk, a wrong estimate."""
        good = self.exported(self.runs["matching"], "good.mcap")
        data = bytearray(good.read_bytes())
        data[len(data) // 3] ^= 0x40  # inside the first chunk's compressed records
        bad = self.out / "flipped.mcap"
        bad.write_bytes(bytes(data))
        self.assertIn("FAIL", self.read(bad, ok=False))
        run = self.tmp / "moved_estimate"
        shutil.copytree(self.runs["matching"], run)
        rows = (run / "est.tum").read_text().splitlines(True)
        parts = rows[5].split()
        parts[1] = f"{float(parts[1]) + 0.001:.6f}"
        rows[5] = " ".join(parts) + "\n"
        (run / "est.tum").write_text("".join(rows))
        self.assertIn("est.tum row", self.read(good, "--run", run, ok=False))

    def assert_bad(self, args, names, out):
        r = export(*args, "-o", out)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("omniloc export: "), lines[0])
        for n in names:
            self.assertIn(n, lines[0])
        self.assertFalse(Path(out).exists(), "nothing may be written")
        folder = Path(out).parent if Path(out).parent.exists() else Path(out).parent.parent
        self.assertEqual([p.name for p in folder.iterdir() if p.name.startswith(".")], [], "no temporary file may be left")
        return lines[0]

    def copy_run(self, name):
        d = self.tmp / name
        shutil.rmtree(d, ignore_errors=True)
        shutil.copytree(self.runs["matching"], d)
        return d

    def test_bad_input(self):
        out_dir = self.tmp / "bad_out"
        out_dir.mkdir(exist_ok=True)
        out = out_dir / "x.mcap"
        self.assert_bad([self.tmp / "no_such_run"], ["no_such_run", "No such file or directory", "run folder"], out)
        empty = self.tmp / "empty"
        empty.mkdir(exist_ok=True)
        self.assert_bad([empty], ["empty", "not a run folder", "recording.json"], out)
        d = self.copy_run("no_est")
        (d / "est.tum").unlink()
        self.assert_bad([d], ["est.tum", "missing"], out)
        d = self.copy_run("bad_view")
        lines = (d / "view.jsonl").read_text().splitlines(True)
        lines[6] = "{not json\n"
        (d / "view.jsonl").write_text("".join(lines))
        self.assert_bad([d], ["view.jsonl line 7", "JSON"], out)
        d = self.copy_run("bad_field")
        (d / "field.json").write_text('{"length": -1}')
        self.assert_bad([d], ["field.json", "length"], out)
        d = self.copy_run("bad_frames")
        (d / "frames.csv").write_text("t,robot\n")
        self.assert_bad([d], ["frames.csv", "missing"], out)
        rec = self.tmp / "cut_rec"
        shutil.copytree(self.rec_img, rec)
        (rec / "images" / "r0_000003.png").write_bytes(b"not a png")
        self.assert_bad([rec], ["r0_000003.png", "PNG"], out)
        hw = self.tmp / "nan_truth"
        shutil.copytree(ROOT / "tests" / "data" / "handwritten_recording", hw)
        lines = (hw / "frames.jsonl").read_text().splitlines(True)
        frame = json.loads(lines[2])
        frame["robots"][0]["truth"] = [1.0, "x", 0.2]
        lines[2] = json.dumps(frame) + "\n"
        (hw / "frames.jsonl").write_text("".join(lines))
        self.assert_bad([hw], ["frames.jsonl line 3", "`truth`", "finite numbers"], out)
        self.assert_bad([self.run_k, "--recording", self.rec_img], ["recording.json", "frames"], out)
        self.assert_bad([self.runs["matching"], "--recording", self.tmp / "no_rec"], ["no_rec", "--recording"], out)
        self.assert_bad([self.runs["matching"]], ["missing_folder: missing", "existing folder"], out_dir / "missing_folder" / "x.mcap")
        # a file already there is left as it was
        out.write_bytes(b"old")
        r = export(self.tmp / "no_such_run", "-o", out)
        self.assertEqual(r.returncode, 2)
        self.assertEqual(out.read_bytes(), b"old")
        out.unlink()

    def test_layout_names_what_an_export_writes(self):
        """docs/foxglove_layout.json's panels show topics and fields the exports write (the bound
        columns only where frames.csv has them)."""
        layout = json.loads((ROOT / "docs" / "foxglove_layout.json").read_text())
        wanted = set()
        for pid, cfg in layout["configById"].items():
            wanted.update(cfg.get("topics", {}))
            wanted.update(p["value"] for p in cfg.get("paths", []))
            for key in ("topicToRender",):
                if key in cfg:
                    wanted.add(cfg[key])
            if cfg.get("imageMode", {}).get("imageTopic"):
                wanted.add(cfg["imageMode"]["imageTopic"])
        written = set()
        for src, name, extra in ((self.runs["mcl"], "l_mcl.mcap", []), (self.run_lm, "l_lm.mcap", []),
                                 (self.run_img, "l_img.mcap", ["--recording", self.rec_img])):
            s = self.read(self.exported(src, name, *extra))
            written.update(s["topics"])
            for topic, keys in s["number_keys"].items():
                written.update(f"{topic}.{k}" for k in keys)
        missing = {w for w in wanted - written if not w.split(".")[-1].startswith("bound_")}
        self.assertEqual(missing, set(), "the layout shows what no export writes")
        self.assertIn("/r0/numbers.err_pos", wanted)
        self.assertIn("/r0/camera", wanted)

    def test_help(self):
        r = export("--help")
        self.assertEqual(r.returncode, 0)
        self.assertTrue(r.stdout.startswith("usage: omniloc export"), r.stdout[:200])
        for word in ("MCAP", "Foxglove", "--recording", "--particles", "sweep", "exit status"):
            self.assertIn(word, r.stdout)


if __name__ == "__main__":
    if NODE is None:
        required = os.environ.get("OMNILOC_MCAP_CHECK") == "required"
        print(f"mcap_export_test: {'FAILED (OMNILOC_MCAP_CHECK=required)' if required else 'skipped'}: {WHY_NOT}", file=sys.stderr)
        sys.exit(1 if required else SKIP)
    result = unittest.main(exit=False, verbosity=2).result
    sys.exit(0 if result.wasSuccessful() else 1)
