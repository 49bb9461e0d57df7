"""Recordings (docs/recording.md): `omniloc replay` of a recording equals `omniloc run` of the recorded
scenario and seed, file by file, for every built-in localizer and for external clients (their frame
messages byte for byte); a recording reads in plain Python without omniloc; bad recordings exit 2
before any work and leave nothing behind.

Run by ctest as `recording_py` with OMNILOC_BIN set (Debian's python3)."""
import gzip
import hashlib
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
EXAMPLES = ROOT / "clients" / "python" / "examples"
# Every file of a run folder but timing.csv (wall-clock) and summary.json's provenance block.
SAME = ["est.tum", "gt.tum", "frames.csv", "events.jsonl", "config.json", "field.json"]


def scenario(base, duration, seed=2, **extra):
    s = json.loads((ROOT / "scenarios" / base).read_text())
    s.update(duration=duration, seed=seed, **extra)
    return s


def summary_without_provenance(folder):
    s = json.loads((folder / "summary.json").read_text())
    s.pop("omniloc", None)
    return s


class Recording(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="omniloc_recording_"))
        # A short stretch of the paper's tracking path (robot noise, compass, exposure control on) and
        # of paper 002's kidnapping (covered lens, teleport, coasting): each recorded once.
        cls.scenarios = {
            "tracking": scenario("paper/tracking.json", 3.0),
            "kidnap": scenario("paper/kidnap_002.json", 4.0,
                               events=[{"type": "kidnap", "t": 1.5, "pose": [-6.75, 3.25, 1.571], "duration": 1.0}]),
            "landmarks": scenario("paper/landmarks_003.json", 4.0),
        }
        cls.files, cls.recordings = {}, {}
        for name, s in cls.scenarios.items():
            s["name"] = name  # a live run of the same scenario from another file keeps the name
            f = cls.tmp / f"{name}.json"
            f.write_text(json.dumps(s))
            cls.files[name] = f
            rec = cls.tmp / f"rec_{name}"
            r = subprocess.run([BIN, "record", str(f), "-o", str(rec), "--quiet"] + (["--images"] if name == "tracking" else []),
                               cwd=ROOT, capture_output=True, text=True, timeout=600)
            assert r.returncode == 0, r.stderr
            cls.recordings[name] = rec

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def omniloc(self, *args, check=True, cache="cache"):
        # A cache root of this test's own (docs/recording.md section 9), never the user's.
        env = dict(os.environ, OMNILOC_CACHE=str(self.tmp / cache))
        r = subprocess.run([BIN, *args], cwd=ROOT, capture_output=True, text=True, timeout=600, env=env)
        if check and r.returncode != 0:
            self.fail(f"omniloc {' '.join(args)} exited {r.returncode}:\n{r.stdout}\n{r.stderr}")
        return r

    def live_and_replay(self, name, localizer, tag):
        s = dict(self.scenarios[name], localizer=localizer)
        f = self.tmp / f"{name}_{tag}.json"
        f.write_text(json.dumps(s))
        live, rep = self.tmp / f"live_{name}_{tag}", self.tmp / f"replay_{name}_{tag}"
        self.omniloc("run", str(f), "-o", str(live), "--quiet", "--draw-each")  # live: simulated and rendered
        self.omniloc("replay", str(self.recordings[name]), "--localizer", json.dumps(localizer), "-o", str(rep), "--quiet")
        return live, rep

    def assert_same_run(self, live, rep, command_differs=False):
        for f in SAME:
            if f == "config.json" and command_differs:  # the tee'd wire log's file name is in the command
                a, b = (json.loads((d / f).read_text()) for d in (live, rep))
                for c in (a, b):
                    c["localizer"].pop("command")
                self.assertEqual(a, b, f)
                continue
            self.assertEqual((live / f).read_bytes(), (rep / f).read_bytes(), f)
        a, b = summary_without_provenance(live), summary_without_provenance(rep)
        if command_differs:
            for c in (a, b):
                c["external"].pop("command")
        self.assertEqual(a, b)
        # timing.csv: the same frames and columns; only the wall-clock numbers may differ.
        lt, rt = ((d / "timing.csv").read_text().splitlines() for d in (live, rep))
        self.assertEqual(lt[0], rt[0])
        self.assertEqual([x.split(",")[:2] for x in lt], [x.split(",")[:2] for x in rt])

    def test_every_built_in_localizer(self):
        cases = [("tracking", {"type": "odometry_only"}), ("tracking", {"type": "matching"}), ("tracking", {"type": "mcl"}),
                 ("tracking", {"type": "hybrid"}), ("tracking", {"type": "grid_global"}), ("kidnap", {"type": "hybrid"}),
                 ("kidnap", {"type": "matching"}), ("kidnap", {"type": "odometry_only"}), ("landmarks", {"type": "landmarks"})]
        for name, loc in cases:
            with self.subTest(scenario=name, localizer=loc["type"]):
                live, rep = self.live_and_replay(name, loc, loc["type"])
                self.assert_same_run(live, rep)
                prov = json.loads((rep / "summary.json").read_text())["omniloc"]["replay"]
                self.assertEqual(prov["format"], "omniloc-recording/1")
                self.assertEqual(prov["recorded_seed"], 2)

    def test_external_clients_see_the_same_frames(self):
        # The client tees what it is sent: live and replayed messages must be the same bytes (the
        # hello carries omniloc's version and is left out; the frames and reset are compared).
        cpp = Path(BIN).resolve().parent / "olp_cpp_example"  # the C++ header's example, built beside omniloc
        clients = [(f"'{PY}' '{EXAMPLES / 'dead_reckoning.py'}'", "py_dr", False), (f"'{PY}' '{EXAMPLES / 'particle_filter.py'}'", "py_pf", False),
                   (f"'{PY}' '{EXAMPLES / 'own_vision.py'}'", "py_ov", True), (f"'{cpp}'", "cpp_dr", False)]
        self.assertTrue(cpp.exists(), f"{cpp}: build it (scripts/build.sh builds it with omniloc)")
        for client, tag, images in clients:
            with self.subTest(client=tag):
                wire = {}
                # live; a stored recording; the world cache, first drawing the world (with images when
                # the client's ready asks for them) and then replaying it.
                for mode in ("live", "replay", "cache_cold", "cache_warm"):
                    log = self.tmp / f"wire_{tag}_{mode}.bin"
                    wire[mode] = log
                    loc = {"type": "external", "command": ["sh", "-c", f"tee '{log}' | {client}"], "label": tag}
                    if mode != "replay":
                        s = dict(self.scenarios["tracking"], localizer=loc)
                        f = self.tmp / f"tracking_{tag}_{mode}.json"
                        f.write_text(json.dumps(s))
                        self.omniloc("run", str(f), "-o", str(self.tmp / f"{mode}_ext_{tag}"), "--quiet",
                                     *(["--draw-each"] if mode == "live" else []), cache=f"ext_cache_{tag}")
                    else:
                        self.omniloc("replay", str(self.recordings["tracking"]), "--localizer", json.dumps(loc), "-o",
                                     str(self.tmp / f"replay_ext_{tag}"), "--quiet")
                live, rep = (wire[m].read_bytes() for m in ("live", "replay"))
                self.assertEqual(live.split(b"\n", 1)[1], rep.split(b"\n", 1)[1], "frame messages differ")
                for mode in ("cache_cold", "cache_warm"):  # the same program: every byte, hello included
                    self.assertEqual(live, wire[mode].read_bytes(), f"{mode}: messages differ")
                    self.assertTrue(json.loads((self.tmp / f"{mode}_ext_{tag}" / "summary.json").read_text())["omniloc"]["world_cache"])
                    self.assert_same_run(self.tmp / f"live_ext_{tag}", self.tmp / f"{mode}_ext_{tag}", command_differs=True)
                cached = [p for p in (self.tmp / f"ext_cache_{tag}" / "worlds").iterdir() if not p.name.startswith(".")]
                self.assertEqual(len(cached), 1)
                self.assertEqual(json.loads((cached[0] / "entry.json").read_text())["images"], images)
                self.assertGreater(live.count(b'"type":"frame"'), 80)
                if images:
                    self.assertGreater(len(live), 90 * 640 * 640 * 3)
                self.assert_same_run(self.tmp / f"live_ext_{tag}", self.tmp / f"replay_ext_{tag}", command_differs=True)

    def test_readable_without_omniloc(self):
        # What docs/recording.md promises a reader: plain JSON, the hash of frames.jsonl, one line a frame.
        rec = self.recordings["tracking"]
        head = json.loads((rec / "recording.json").read_text())
        self.assertEqual(head["format"], "omniloc-recording/1")
        self.assertEqual(head["frames_file"], "frames.jsonl.gz")
        data = gzip.decompress((rec / head["frames_file"]).read_bytes())
        self.assertEqual(hashlib.sha256(data).hexdigest(), head["frames_sha256"])
        frames = [json.loads(line) for line in data.splitlines()]
        self.assertEqual(len(frames), head["frames"])
        self.assertEqual([f["k"] for f in frames], list(range(len(frames))))
        r0 = frames[10]["robots"][0]
        self.assertEqual(r0["robot"], head["robots"][0]["id"])
        self.assertTrue(r0["line_points"] and all(len(p) == 2 for p in r0["line_points"]))
        self.assertEqual(len(r0["truth"]), 3)
        self.assertTrue((rec / "images" / "r0_000010.png").exists())
        # frames.csv of a replay is the truth recorded: gt.tum's poses are the recording's.
        gt = [line.split() for line in (self.tmp / "replay_tracking_matching" / "gt.tum").read_text().splitlines() if not line.startswith("#")] \
            if (self.tmp / "replay_tracking_matching").exists() else None
        if gt:
            self.assertAlmostEqual(float(gt[10][1]), r0["truth"][0], places=9)

    def test_sweeps_draw_each_world_once(self):
        sweep = self.tmp / "share.json"
        sweep.write_text(json.dumps({"name": "share", "scenarios": [str(self.files["kidnap"])], "seeds": [1, 2],
                                     "localizers": [{"type": "matching"}, {"type": "hybrid"}, {"type": "odometry_only"},
                                                    {"type": "external", "command": [PY, str(EXAMPLES / "dead_reckoning.py")], "label": "py_dr"}]}))
        shared, each, folder = self.tmp / "sweep_shared", self.tmp / "sweep_each", self.tmp / "sweep_folder_worlds"
        self.omniloc("sweep", str(sweep), "-j", "2", "-o", str(shared), cache="sweep_cache")
        self.omniloc("sweep", str(sweep), "-j", "2", "-o", str(each), "--draw-each", cache="sweep_cache")
        self.omniloc("sweep", str(sweep), "-j", "2", "-o", str(folder), "--no-cache", cache="sweep_cache")
        # The world cache: one world per seed, drawn once and replayed into matching, hybrid and the
        # client (which wants no images); odometry_only runs live. Nothing in the sweep folder.
        entries = sorted(p.name for p in (self.tmp / "sweep_cache" / "worlds").iterdir() if not p.name.startswith("."))
        self.assertEqual(len(entries), 2)
        self.assertFalse((shared / "recordings").exists())
        # Without the cache: one recording per seed in the sweep folder, shared by matching and hybrid.
        self.assertEqual(len(list((folder / "recordings").iterdir())), 2)
        self.assertFalse((each / "recordings").exists())
        runs = sorted(p.name for p in (each / "runs").iterdir())
        self.assertEqual(len(runs), 8)
        for run in runs:
            with self.subTest(run=run):
                self.assert_same_run(each / "runs" / run, shared / "runs" / run)
                self.assert_same_run(each / "runs" / run, folder / "runs" / run)
        self.assertEqual((shared / "aggregate.csv").read_bytes(), (each / "aggregate.csv").read_bytes())
        self.assertEqual((folder / "aggregate.csv").read_bytes(), (each / "aggregate.csv").read_bytes())
        prov = {r: json.loads((shared / "runs" / r / "summary.json").read_text())["omniloc"] for r in runs}
        self.assertEqual(sorted(r for r in runs if prov[r].get("world_cache") in entries), sorted(r for r in runs if "__odometry_only__" not in r))
        replayed = [r for r in runs if "replay" in json.loads((folder / "runs" / r / "summary.json").read_text())["omniloc"]]
        self.assertEqual(sorted(replayed), sorted(r for r in runs if "__matching__" in r or "__hybrid__" in r))
        # A second sweep of the same worlds with other localizers, into another folder: nothing drawn.
        stamps = {e: (self.tmp / "sweep_cache" / "worlds" / e / "last_used").stat().st_mtime_ns for e in entries}
        again = self.tmp / "sweep_again"
        r = self.omniloc("sweep", str(sweep), "-j", "2", "-o", str(again), "--localizer", '{"type": "mcl", "particles": 200}', cache="sweep_cache")
        self.assertEqual(sorted(p.name for p in (self.tmp / "sweep_cache" / "worlds").iterdir() if not p.name.startswith(".")), entries)
        for e in entries:
            self.assertGreaterEqual((self.tmp / "sweep_cache" / "worlds" / e / "last_used").stat().st_mtime_ns, stamps[e])
        for run in (again / "runs").iterdir():
            self.assertIn(json.loads((run / "summary.json").read_text())["omniloc"].get("world_cache"), entries, run.name)

        # A stored recording as a sweep's scenario: replayed into each localizer at its seed.
        stored = self.tmp / "stored.json"
        stored.write_text(json.dumps({"name": "stored", "scenarios": [{"recording": str(self.recordings["kidnap"]),
                                                                        "localizers": [{"type": "matching"}, {"type": "hybrid"}]}]}))
        out = self.tmp / "sweep_stored"
        self.omniloc("sweep", str(stored), "-o", str(out))
        live, _ = self.live_and_replay("kidnap", {"type": "matching"}, "stored_check")
        self.assert_same_run(live, out / "runs" / "kidnap__matching__recording__s2")
        self.assertEqual(len(list((out / "runs").iterdir())), 2)

    def bad_replay(self, rec, localizer=None, expect=()):
        out = self.tmp / "bad_out"
        r = self.omniloc("replay", str(rec), "--localizer", json.dumps(localizer or {"type": "matching"}), "-o", str(out), check=False)
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        for e in expect:
            self.assertIn(e, r.stderr)
        self.assertFalse(out.exists())
        self.assertEqual([p.name for p in self.tmp.iterdir() if p.name.startswith(".bad_out")], [])

    def copy(self, name, tag):
        dst = self.tmp / f"broken_{tag}"
        shutil.rmtree(dst, ignore_errors=True)
        shutil.copytree(self.recordings[name], dst)
        return dst

    def rewrite(self, rec, lines=None, gz=None, drop_hash=True):
        head = json.loads((rec / "recording.json").read_text())
        if drop_hash:
            head.pop("frames_sha256")
        (rec / "recording.json").write_text(json.dumps(head))
        if lines is not None:
            gz = gzip.compress(b"".join(lines))
        if gz is not None:
            (rec / "frames.jsonl.gz").write_bytes(gz)

    def lines(self, rec):
        return gzip.decompress((rec / "frames.jsonl.gz").read_bytes()).splitlines(keepends=True)

    def test_bad_recordings_exit_2_before_any_work(self):
        rec = self.copy("kidnap", "truncated_gz")  # the compressed file cut in half
        data = (rec / "frames.jsonl.gz").read_bytes()
        (rec / "frames.jsonl.gz").write_bytes(data[: len(data) // 2])
        self.bad_replay(rec, expect=["frames.jsonl.gz", "cut short"])

        rec = self.copy("kidnap", "truncated_lines")  # whole gzip, half the frames: the hash says so
        self.rewrite(rec, lines=self.lines(rec)[:60], drop_hash=False)
        self.bad_replay(rec, expect=["frames.jsonl.gz", "SHA-256"])

        rec = self.copy("kidnap", "truncated_unhashed")  # without the hash: the cut line says it
        lines = self.lines(rec)
        self.rewrite(rec, lines=lines[:50] + [lines[50][:100]])
        self.bad_replay(rec, expect=["frames.jsonl.gz line 51", "cut short"])

        rec = self.copy("kidnap", "fewer")  # whole lines, fewer than recording.json says
        self.rewrite(rec, lines=self.lines(rec)[:50])
        self.bad_replay(rec, expect=["50 frames", "cut short"])

        rec = self.copy("kidnap", "corrupt")
        lines = self.lines(rec)
        lines[7] = lines[7].replace(b'"odometry":[', b'"odometry":["x",', 1)
        self.rewrite(rec, lines=lines)
        self.bad_replay(rec, expect=["frames.jsonl.gz line 8", "/robots/0/odometry"])

        rec = self.copy("kidnap", "not_gzip")
        self.rewrite(rec, gz=b"this is not gzip")
        self.bad_replay(rec, expect=["frames.jsonl.gz", "gzip"])

        # Keys a later omniloc adds to version 1 are ignored (docs/recording.md): the replay is unchanged.
        rec = self.copy("kidnap", "added_keys")
        head = json.loads((rec / "recording.json").read_text())
        head["a_later_key"] = {"x": 1}
        head["robots"][0]["another"] = True
        (rec / "recording.json").write_text(json.dumps(head))
        lines = [json.loads(x) for x in self.lines(rec)]
        for f in lines:
            f["later"] = 1
            f["robots"][0]["later_too"] = [1, 2]
        self.rewrite(rec, lines=[json.dumps(f).encode() + b"\n" for f in lines])
        out = self.tmp / "added_keys_out"
        self.omniloc("replay", str(rec), "--localizer", '{"type": "matching"}', "-o", str(out), "--quiet")
        ref = self.tmp / "added_keys_ref"
        self.omniloc("replay", str(self.recordings["kidnap"]), "--localizer", '{"type": "matching"}', "-o", str(ref), "--quiet")
        self.assertEqual((out / "est.tum").read_bytes(), (ref / "est.tum").read_bytes())

        rec = self.copy("kidnap", "future")
        head = json.loads((rec / "recording.json").read_text())
        head["format"] = "omniloc-recording/2"
        (rec / "recording.json").write_text(json.dumps(head))
        self.bad_replay(rec, expect=["recording.json /format", "version 1"])

        rec = self.copy("kidnap", "robots")
        head = json.loads((rec / "recording.json").read_text())
        head["scenario"]["robots"][0]["localize"] = False
        (rec / "recording.json").write_text(json.dumps(head))
        self.bad_replay(rec, expect=["/robots"])

        rec = self.copy("tracking", "no_image")
        (rec / "images" / "r0_000042.png").unlink()
        self.bad_replay(rec, expect=["r0_000042.png", "No such file or directory"])

        # A client that wants the image, on a recording made without images.
        self.bad_replay(self.recordings["kidnap"], {"type": "external", "command": [PY, str(EXAMPLES / "own_vision.py")]},
                        expect=["without them", "--images"])
        self.bad_replay(self.tmp / "no_such_recording", expect=["a recording folder"])
        self.bad_replay(self.recordings["kidnap"], {"type": "matching", "particles": 3}, expect=["--localizer/particles"])


if __name__ == "__main__":
    unittest.main()
