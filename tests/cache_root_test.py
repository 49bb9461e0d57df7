"""Caches where users expect them (docs/recording.md section 9).

- Every cache omniloc keeps (recorded worlds, distance tables, calibration maps, colour tables, bounds) lives
  under one root: $OMNILOC_CACHE, else $XDG_CACHE_HOME/omniloc (absolute only), else ~/.cache/omniloc;
  a run, a record and a replay write nothing into the working directory but what -o names.
- `omniloc cache list | size | prune` covers every kind of entry under the root.
- A cache that cannot be written (a full disk, a read-only folder, a root that cannot be created)
  costs no run: one warning line naming the cause, the run's files as without a cache, and no partial
  entry left; for run, sweep and replay. A run folder on a full disk fails with the system's words
  and leaves nothing half written.

The full and read-only file systems are small tmpfs mounts in a private user and mount namespace
(`unshare --user --map-root-user --mount`), which needs no root; where the kernel refuses that, those
cases skip and say so. Run by ctest as `cache_root_py` with OMNILOC_BIN set (Debian's python3)."""
import json
import re
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = os.environ.get("OMNILOC_BIN", str(ROOT / "build" / "omniloc"))
# Every file of a run folder but timing.csv (wall-clock) and summary.json's provenance block.
SAME = ["est.tum", "gt.tum", "frames.csv", "events.jsonl", "config.json", "field.json"]
WARNING = "omniloc: warning: the cache "


def clean_env(**extra):
    """The environment without any cache setting of the caller's (ctest sets OMNILOC_CACHE)."""
    env = {k: v for k, v in os.environ.items() if k not in ("OMNILOC_CACHE", "XDG_CACHE_HOME", "HOME")}
    env.update(extra)
    return env


def files_under(folder):
    return sorted(str(p.relative_to(folder)) for p in Path(folder).rglob("*")) if Path(folder).exists() else []


def summary_without_provenance(folder):
    s = json.loads((Path(folder) / "summary.json").read_text())
    s.pop("omniloc", None)
    return s


def namespaces_work():
    try:
        r = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c",
                            "d=$(mktemp -d) && mount -t tmpfs -o size=64k omniloc-probe \"$d\" && umount \"$d\" && rmdir \"$d\""],
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return r.returncode == 0


def make_inputs(cls):
    """A test class's folder, scenario, sweep and reference run."""
    cls.tmp = Path(tempfile.mkdtemp(prefix="omniloc_cache_root_"))
    # Two seconds of the paper's tracking path with matching: the camera is calibrated, the colour
    # table learned and the distance table built (all "auto", so all cached), and the world drawn.
    s = json.loads((ROOT / "scenarios" / "paper" / "tracking.json").read_text())
    s.update(name="cache_root", duration=2.0, seed=3, localizer={"type": "matching"})
    cls.scenario = cls.tmp / "cache_root.json"
    cls.scenario.write_text(json.dumps(s))
    cls.sweep = cls.tmp / "cache_root_sweep.json"
    cls.sweep.write_text(json.dumps({"name": "cache_root_sweep", "scenarios": [str(cls.scenario)], "seeds": [3],
                                     "localizers": [{"type": "matching"}, {"type": "mcl", "particles": 100}]}))
    # The reference: the same run with no cache at all.
    cls.reference = cls.tmp / "reference"
    r = subprocess.run([BIN, "run", str(cls.scenario), "-o", str(cls.reference), "--quiet", "--no-cache"],
                       cwd=cls.tmp, capture_output=True, text=True, timeout=600, env=clean_env(HOME=str(cls.tmp / "unused_home")))
    assert r.returncode == 0, r.stderr
    assert not (cls.tmp / "unused_home").exists(), "--no-cache wrote a cache"


class CacheRoot(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        make_inputs(cls)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def omniloc(self, *args, env, cwd, expect=0):
        r = subprocess.run([BIN, *args], cwd=cwd, capture_output=True, text=True, timeout=600, env=env)
        if expect is not None and r.returncode != expect:
            self.fail(f"omniloc {' '.join(args)} exited {r.returncode}, expected {expect}:\n{r.stdout}\n{r.stderr}")
        return r

    def fresh(self, name):
        d = self.tmp / name
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
        return d

    def assert_same_as_reference(self, run):
        for f in SAME:
            self.assertEqual((self.reference / f).read_bytes(), (Path(run) / f).read_bytes(), f)
        self.assertEqual(summary_without_provenance(self.reference), summary_without_provenance(run))

    def assert_full_root(self, root):
        """Every kind of entry a run of the scenario leaves, under `root`."""
        root = Path(root)
        worlds = [p for p in (root / "worlds").iterdir() if not p.name.startswith(".")]
        self.assertEqual(len(worlds), 1, files_under(root))
        self.assertTrue((worlds[0] / "entry.json").is_file())
        self.assertEqual(len(list((root / "fieldmaps").glob("*/fieldmap_*.bin"))), 1, files_under(root))
        self.assertEqual(len(list((root / "vision").glob("*/calibration_v2_*.json"))), 1, files_under(root))
        self.assertEqual(len(list((root / "vision").glob("*/colour_v2_*.lut"))), 1, files_under(root))
        # The world's bounds, computed when it was drawn: for a localizer given its start pose and one not.
        self.assertEqual(len(list((root / "bounds").glob("*/*.bound"))), 2, files_under(root))

    def test_default_root_is_the_users_cache_and_the_working_directory_stays_empty(self):
        home, cwd, out = self.fresh("home"), self.fresh("cwd"), self.fresh("out")
        env = clean_env(HOME=str(home))
        self.omniloc("run", str(self.scenario), "-o", str(out / "run"), "--quiet", env=env, cwd=cwd)
        self.assertEqual(files_under(cwd), [])
        self.assert_full_root(home / ".cache" / "omniloc")
        self.assert_same_as_reference(out / "run")
        # A second run of the same world from another folder: replayed from the cache, nothing drawn.
        other = self.fresh("cwd2")
        r = self.omniloc("run", str(self.scenario), "-o", str(out / "again"), env=env, cwd=other)
        self.assertIn("world cache: cache_root, seed 3 from " + str(home / ".cache" / "omniloc" / "worlds"), r.stderr + r.stdout)
        self.assert_same_as_reference(out / "again")
        # record and replay (the replay builds its distance table: from the cache).
        self.omniloc("record", str(self.scenario), "-o", str(out / "rec"), "--quiet", env=env, cwd=cwd)
        self.omniloc("replay", str(out / "rec"), "--localizer", '{"type": "mcl", "particles": 100}', "-o", str(out / "rep"), "--quiet",
                     env=env, cwd=cwd)
        self.assertEqual(files_under(cwd), [])
        self.assertEqual(files_under(other), [])

        # omniloc cache: every kind, then pruned empty. Two bounds (the world's, drawn with it): matching
        # read the one with its start pose given, mcl the other.
        r = self.omniloc("cache", "list", env=env, cwd=cwd)
        kinds = [line.split()[0] for line in r.stdout.splitlines()[1:-1]]
        self.assertEqual(sorted(kinds), ["bound", "bound", "calibration", "colour", "fieldmap", "world"], r.stdout)
        self.assertRegex(r.stdout, r"cache_root, seed 3, \d+ frames")
        self.assertTrue(r.stdout.splitlines()[-1].startswith("6 entries, "), r.stdout)
        r = self.omniloc("cache", "size", env=env, cwd=cwd)
        for kind, n in (("world", 1), ("fieldmap", 1), ("calibration", 1), ("colour", 1), ("bound", 2)):
            self.assertRegex(r.stdout, rf"\n  {kind} +{n} entries ")
        r = self.omniloc("cache", "prune", "--max-size", "0", env=env, cwd=cwd)
        self.assertTrue(r.stdout.startswith("removed 6 entries"), r.stdout)
        left = [f for f in files_under(home / ".cache" / "omniloc")
                if not f.startswith("worlds/.locks") and f not in ("worlds", "fieldmaps", "vision", "bounds")]
        self.assertEqual(left, [])
        self.assertEqual(files_under(cwd), [])

    def test_xdg_cache_home_and_omniloc_cache(self):
        home, xdg, cwd, out = self.fresh("home_x"), self.fresh("xdg"), self.fresh("cwd_x"), self.fresh("out_x")
        self.omniloc("run", str(self.scenario), "-o", str(out / "xdg"), "--quiet", env=clean_env(HOME=str(home), XDG_CACHE_HOME=str(xdg)), cwd=cwd)
        self.assert_full_root(xdg / "omniloc")
        self.assertEqual(files_under(home), [])
        # A relative XDG_CACHE_HOME is ignored (the XDG Base Directory specification): the home's.
        self.omniloc("run", str(self.scenario), "-o", str(out / "rel"), "--quiet", env=clean_env(HOME=str(home), XDG_CACHE_HOME="rel"), cwd=cwd)
        self.assert_full_root(home / ".cache" / "omniloc")
        # (Mesa's own shader cache takes a relative XDG_CACHE_HOME from the working directory: not ours.)
        self.assertEqual([f for f in files_under(cwd) if not f.startswith("rel/mesa_shader_cache") and f != "rel"], [])
        # OMNILOC_CACHE wins over both; a relative one is taken from the working directory.
        self.omniloc("run", str(self.scenario), "-o", str(out / "own"), "--quiet",
                     env=clean_env(HOME=str(home), XDG_CACHE_HOME=str(xdg), OMNILOC_CACHE="own_cache"), cwd=cwd)
        self.assert_full_root(cwd / "own_cache")
        # --cache DIR names the root on the command line.
        self.omniloc("run", str(self.scenario), "-o", str(out / "flag"), "--quiet", "--cache", str(self.tmp / "flag_cache"),
                     env=clean_env(HOME=str(home)), cwd=cwd)
        self.assert_full_root(self.tmp / "flag_cache")
        for name in ("xdg", "rel", "own", "flag"):
            self.assert_same_as_reference(out / name)

    def test_a_root_that_cannot_be_created_costs_no_run(self):
        # A component of the root is a file ("Not a directory"), a name over NAME_MAX ("File name too
        # long"): the system refuses both, also to root.
        cwd, out = self.fresh("cwd_nodir"), self.fresh("out_nodir")
        (cwd / "afile").write_text("not a folder\n")
        for name, root, cause in (("nodir", cwd / "afile" / "cache", "Not a directory"), ("long", cwd / ("x" * 300) / "cache", "File name too long")):
            with self.subTest(root=name):
                env = clean_env(HOME=str(self.tmp / "home_nodir"), OMNILOC_CACHE=str(root))
                r = self.omniloc("run", str(self.scenario), "-o", str(out / name), "--quiet", env=env, cwd=cwd)
                warnings = [line for line in r.stderr.splitlines() if line.startswith(WARNING)]
                self.assertEqual(len(warnings), 1, r.stderr)
                self.assertIn(cause, warnings[0])
                self.assertIn("going on without it", warnings[0])
                self.assert_same_as_reference(out / name)
                self.assertEqual(files_under(cwd), ["afile"])
                r = self.omniloc("cache", "list", env=env, cwd=cwd)
                self.assertTrue(r.stdout.splitlines()[-1].startswith("0 entries, "), r.stdout)


@unittest.skipUnless(namespaces_work(), "unshare --user --mount is refused here: no small file system can be mounted without root")
class Unwritable(unittest.TestCase):
    """A full and a read-only cache on a small tmpfs in a private mount namespace."""

    @classmethod
    def setUpClass(cls):
        make_inputs(cls)
        cls.rec = cls.tmp / "rec"
        r = subprocess.run([BIN, "record", str(cls.scenario), "-o", str(cls.rec), "--quiet"],
                           capture_output=True, text=True, timeout=600, env=clean_env(HOME=str(cls.tmp / "unused_home"), OMNILOC_CACHE="off"))
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    assert_same_as_reference = CacheRoot.assert_same_as_reference

    def in_namespace(self, mode, command, name):
        """Mounts a 256 KiB tmpfs at a fresh folder, makes it full (filled to the last block) or
        read-only, runs `command` (with $C the mount point) with OMNILOC_CACHE=$C, and returns the exit
        code, stderr and what the tmpfs held afterwards (it is gone once the namespace ends)."""
        mnt = self.tmp / f"mnt_{name}"
        mnt.mkdir()
        prepare = {"full": 'dd if=/dev/zero of="$C/filler" bs=4096 2>/dev/null || true',
                   "readonly": 'mount -o remount,ro "$C"'}[mode]
        script = (f'set -u; C="{mnt}"; mount -t tmpfs -o size=256k omniloc-test "$C" || exit 99; {prepare}\n'
                  f'{command} >"{self.tmp}/{name}.out" 2>"{self.tmp}/{name}.err"; echo "rc=$?"\n'
                  'find "$C" -mindepth 1 | sed "s|^$C/||" | sort\n')
        r = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c", script],
                           capture_output=True, text=True, timeout=900, env=clean_env(HOME=str(self.tmp / "ns_home"), OMNILOC_CACHE=str(mnt)))
        self.assertNotEqual(r.returncode, 99, r.stderr)
        lines = r.stdout.splitlines()
        self.assertTrue(lines and lines[0].startswith("rc="), r.stdout + r.stderr)
        return int(lines[0][3:]), (self.tmp / f"{name}.err").read_text(), lines[1:]

    def assert_one_warning(self, err, cause):
        warnings = [line for line in err.splitlines() if line.startswith(WARNING)]
        self.assertEqual(len(warnings), 1, err)
        self.assertIn(cause, warnings[0])

    def assert_no_partial_entry(self, left):
        # What may be left: the filler, the kinds' folders (this build's, empty) and the world cache's
        # lock files; no entry, no staging folder, no temporary file.
        for f in left:
            self.assertTrue(f in ("filler", "worlds", "worlds/.locks", "fieldmaps", "vision") or f.startswith("worlds/.locks/")
                            or re.fullmatch(r"(fieldmaps|vision)/[0-9a-f]{16}", f), left)

    def test_run_on_a_full_and_on_a_read_only_cache(self):
        for mode, cause in (("full", "No space left on device"), ("readonly", "Read-only file system")):
            with self.subTest(mode=mode):
                out = self.tmp / f"run_{mode}"
                rc, err, left = self.in_namespace(mode, f'"{BIN}" run "{self.scenario}" -o "{out}" --quiet', f"run_{mode}")
                self.assertEqual(rc, 0, err)
                self.assert_one_warning(err, cause)
                self.assert_same_as_reference(out)
                self.assertNotIn("world_cache", json.loads((out / "summary.json").read_text())["omniloc"])
                self.assert_no_partial_entry(left)

    def test_sweep_and_replay_on_a_full_cache(self):
        out = self.tmp / "sweep_full"
        rc, err, left = self.in_namespace("full", f'"{BIN}" sweep "{self.sweep}" -j 2 -o "{out}"', "sweep_full")
        self.assertEqual(rc, 0, err)
        self.assert_no_partial_entry(left)
        runs = sorted(p.name for p in (out / "runs").iterdir())
        self.assertEqual(len(runs), 2, runs)
        self.assertTrue((out / "aggregate.json").is_file())
        for run in runs:
            self.assert_one_warning((out / "logs" / f"{run}.log").read_text(), "No space left on device")
        matching = next(r for r in runs if "matching" in r)
        self.assert_same_as_reference(out / "runs" / matching)

        rep = self.tmp / "replay_full"
        rc, err, left = self.in_namespace("full", f'"{BIN}" replay "{self.rec}" --localizer \'{{"type": "matching"}}\' -o "{rep}" --quiet',
                                          "replay_full")
        self.assertEqual(rc, 0, err)
        self.assert_one_warning(err, "No space left on device")
        self.assert_no_partial_entry(left)
        for f in ("est.tum", "frames.csv"):
            self.assertEqual((self.reference / f).read_bytes(), (rep / f).read_bytes(), f)

    def test_a_run_folder_on_a_full_disk_names_the_cause_and_leaves_nothing(self):
        # The run's own folder on the full tmpfs (its caches too): the run fails (exit 1, not an input
        # error), saying the system's words; no run folder, no staging folder is left.
        rc, err, left = self.in_namespace("full", f'"{BIN}" run "{self.scenario}" -o "$C/run" --quiet', "run_folder_full")
        self.assertEqual(rc, 1, err)
        self.assertIn("No space left on device", err)
        self.assertEqual([f for f in left if "run" in f and not f.startswith("worlds/.locks")], [], left)


if __name__ == "__main__":
    unittest.main()
