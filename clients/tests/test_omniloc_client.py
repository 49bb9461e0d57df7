#!/usr/bin/env python3
"""Unit tests of clients/python/omniloc_client.py without omniloc: hand-made olp/1 byte streams
through run() / serve(), in memory and through a real child process."""
import io
import json
import math
import os
import subprocess
import sys
import unittest
from pathlib import Path

CLIENTS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(CLIENTS / "python"))
import omniloc_client as olp  # noqa: E402

CAMERA = {
    "width": 4, "height": 2, "channels": 3, "layout": "HWC", "mirror_centre_px": [2.0, 1.0], "latency_s": 0.033, "mount_height_m": 0.75, "vibration_rad": 0.005,
    "calibration": {
        "bearings_rad": [0.0, math.pi / 2, math.pi, 3 * math.pi / 2],
        "radii_px": [[1.0, 2.0, 4.0]] * 4,
        "distances_m": [[0.2, 0.4, 1.2], [0.2, 0.5, 1.4], [0.2, 0.4, 1.2], [0.2, 0.4, 1.2]],
        "min_radius_px": 1.0, "max_radius_px": 4.0,
    },
}
FIELD = {"name": "tiny", "length": 4.0, "width": 2.0, "margin": 0.5, "line_width": 0.1,
         "segments": [[-2, -1, 2, -1], [-2, 1, 2, 1], [-2, -1, -2, 1], [2, -1, 2, 1], [0, -1, 0, 1]],
         "arcs": [[0, 0, 0.5, 0, 2 * math.pi]], "spots": [[0, 0, 0.05]], "goals": [[2, 1, 0.5], [-2, 1, 0.5]],
         "goal_colours": ["yellow", "blue"], "landmarks": []}
HELLO = {"type": "hello", "protocol": "olp/1", "omniloc": "test", "robot": 3, "scenario": "unit",
         "camera_rate_hz": 30, "duration_s": 0.1, "hello_timeout_s": 60, "frame_timeout_s": 10,
         "exit_timeout_s": 5, "params": {"gain": 2.5}, "field": FIELD, "camera": CAMERA,
         "vision": {"line_points": True, "blobs": False}, "a_future_field": [1, 2]}


def line(obj) -> bytes:
    return json.dumps(obj).encode() + b"\n"


def frame(k, odo=(0.0, 0.0, 0.0), image=None, **more):
    m = {"type": "frame", "k": k, "t": k / 30, "odometry": list(odo), "heading": None, "camera_ok": True,
         "line_points": [[1.0, 0.5]], "blobs": []}
    m.update(more)
    if image is None:
        return line(m)
    m["binary"] = [{"name": "image", "dtype": "uint8", "shape": [2, 4, 3], "bytes": len(image)}]
    return line(m) + image


IMAGE = bytes(range(24))


def stream(*chunks) -> bytes:
    return b"".join(chunks)


class Recorder(olp.Localizer):
    """Records what it sees; answers with the odometry dead reckoning."""
    name = "recorder"
    version = "9.9"
    needs_start_pose = True

    def __init__(self, wants_image=False):
        self.wants_image = wants_image
        self.frames, self.resets, self.ended, self.hello_seen = [], [], False, None

    def ready(self, hello):
        self.hello_seen = hello

    def reset(self, seed, start):
        self.resets.append((seed, start))
        self.pose = start if start is not None else (0.0, 0.0, 0.0)

    def update(self, f):
        self.frames.append(f)
        print("a stray print from user code")  # must not reach the protocol stream
        self.pose = olp.compose_odometry(self.pose, f.odometry)
        return olp.Estimate(self.pose, covariance=[0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.02], mode="tracking",
                            extra={"b_n": 2, "a_n": 1.5})

    def end(self):
        self.ended = True


class Trickle(io.RawIOBase):
    """A raw stream that returns at most `n` bytes per read (as a pipe may)."""

    def __init__(self, data, n):
        self.data, self.pos, self.n = data, 0, n

    def readable(self):
        return True

    def readinto(self, b):
        chunk = self.data[self.pos:self.pos + min(self.n, len(b))]
        b[:len(chunk)] = chunk
        self.pos += len(chunk)
        return len(chunk)


def run(loc, data, inp=None):
    out, err = io.BytesIO(), io.StringIO()
    status = olp.run(loc, inp if inp is not None else io.BytesIO(data), out, err)
    return status, [json.loads(x) for x in out.getvalue().splitlines()], err.getvalue(), out.getvalue()


GOOD = stream(line(HELLO), line({"type": "reset", "seed": 2 ** 53 - 1, "start": [1.0, -0.5, 0.25]}),
              frame(0, image=IMAGE), frame(1, (0.1, 0.02, 0.01), image=IMAGE), frame(2, (0.1, -0.02, -0.3), image=IMAGE),
              line({"type": "end"}))


class ServeTest(unittest.TestCase):
    def test_whole_session(self):
        loc = Recorder(wants_image=True)
        status, msgs, err, raw = run(loc, GOOD)
        self.assertEqual(status, 0, err)
        self.assertTrue(loc.ended)
        self.assertEqual(msgs[0], {"type": "ready", "protocol": "olp/1", "name": "recorder", "version": "9.9",
                                   "needs_start_pose": True, "wants_image": True})
        self.assertEqual([m["k"] for m in msgs[1:]], [0, 1, 2])
        self.assertEqual(len(msgs), 4)
        self.assertTrue(all(m["type"] == "estimate" and m["valid"] is True and m["mode"] == "tracking" for m in msgs[1:]))
        self.assertEqual(list(msgs[1]["extra"]), ["a_n", "b_n"])  # sorted: deterministic bytes
        pose = (1.0, -0.5, 0.25)
        for m, odo in zip(msgs[1:], [(0, 0, 0), (0.1, 0.02, 0.01), (0.1, -0.02, -0.3)]):
            pose = olp.compose_odometry(pose, odo)
            self.assertEqual(m["pose"], list(pose))  # floats round-trip exactly through JSON
        self.assertEqual(loc.resets, [(2 ** 53 - 1, (1.0, -0.5, 0.25))])
        self.assertEqual(loc.hello_seen.robot, 3)
        self.assertEqual(loc.hello_seen.params, {"gain": 2.5})
        self.assertEqual(loc.hello_seen.field.goal_colours, ["yellow", "blue"])
        self.assertEqual(loc.hello_seen.camera.latency_s, 0.033)
        self.assertEqual(olp.Camera.from_json({}).latency_s, 0.0)  # an omniloc from before latency_s: not declared
        self.assertEqual((loc.hello_seen.camera.mount_height_m, loc.hello_seen.camera.vibration_rad), (0.75, 0.005))
        self.assertEqual((olp.Camera.from_json({}).mount_height_m, olp.Camera.from_json({}).vibration_rad), (None, None))  # not told
        f = loc.frames[1]
        self.assertEqual((f.k, f.odometry, f.heading, f.camera_ok, f.line_points), (1, (0.1, 0.02, 0.01), None, True, [(1.0, 0.5)]))
        self.assertEqual(f.image_shape, (2, 4, 3))
        if olp._np is not None:
            self.assertEqual(f.image.shape, (2, 4, 3))
            self.assertEqual(int(f.image[1, 3, 2]), 23)
        else:
            self.assertEqual(f.image, IMAGE)
        self.assertTrue(raw.endswith(b"\n") and b"stray" not in raw)

    def test_image_as_bytes_without_numpy(self):
        saved, olp._np = olp._np, None
        try:
            loc = Recorder(wants_image=True)
            status, _, err, _ = run(loc, GOOD)
        finally:
            olp._np = saved
        self.assertEqual(status, 0, err)
        self.assertEqual(loc.frames[2].image, IMAGE)

    def test_partial_reads(self):
        for n in (1, 3, 7, 4096):
            with self.subTest(chunk=n):
                loc = Recorder(wants_image=True)
                status, msgs, err, _ = run(loc, None, inp=Trickle(GOOD, n))
                self.assertEqual(status, 0, err)
                self.assertEqual(len(msgs), 4)
                self.assertEqual(bytes(loc.frames[2].image_shape and loc.frames[2].image.tobytes()
                                       if olp._np is not None else loc.frames[2].image), IMAGE)

    def test_unknown_fields_ignored_and_blobs(self):
        blob = {"colour": "yellow", "kind": "left_edge", "bearing": 0.5, "left_bearing": 0.5, "right_bearing": 0.2,
                "distance": None, "area_px": 40, "left_occluded": False, "right_occluded": True, "new": 1}
        data = stream(line(HELLO), line({"type": "reset", "seed": 7, "start": None, "later": "x"}),
                      frame(0, blobs=[blob], heading=1.25, future={"a": 1}), line({"type": "end"}))
        loc = Recorder()
        status, msgs, err, _ = run(loc, data)
        self.assertEqual(status, 0, err)
        self.assertEqual(loc.resets, [(7, None)])
        b = loc.frames[0].blobs[0]
        self.assertEqual((b.colour, b.kind, b.distance, b.right_occluded), ("yellow", "left_edge", None, True))
        self.assertEqual(loc.frames[0].heading, 1.25)

    def test_eof_is_an_error(self):
        for cut in (0, len(line(HELLO)), len(GOOD) - len(line({"type": "end"})), len(GOOD) - 30, len(line(HELLO)) - 5):
            with self.subTest(cut=cut):
                status, _, err, _ = run(Recorder(wants_image=True), GOOD[:cut])
                self.assertNotEqual(status, 0)
                self.assertIn("end of input", err)

    def test_protocol_errors(self):
        cases = {
            "not json": stream(line(HELLO), b"{nope\n"),
            "not an object": stream(line(HELLO), b"[1, 2]\n"),
            "wrong protocol": line(dict(HELLO, protocol="olp/2")),
            "frame first": stream(line(HELLO), frame(0)),
            "unknown type": stream(line(HELLO), line({"type": "dance"})),
            "hello twice": stream(line(HELLO), line(HELLO)),
        }
        for what, data in cases.items():
            with self.subTest(what):
                status, msgs, err, _ = run(Recorder(), data)
                self.assertNotEqual(status, 0)
                self.assertIn("protocol error", err)

    def test_user_errors(self):
        class Bad(Recorder):
            def update(self, f):
                return olp.Estimate((math.nan, 0.0, 0.0))

        status, msgs, err, _ = run(Bad(), GOOD)
        self.assertEqual(status, 1)
        self.assertIn("pose must be 3 finite numbers", err)
        self.assertEqual([m["type"] for m in msgs], ["ready"])  # no NaN ever reaches omniloc

        class Raises(Recorder):
            def update(self, f):
                raise RuntimeError("boom")

        status, _, err, _ = run(Raises(), GOOD)
        self.assertEqual(status, 1)
        self.assertIn("boom", err)
        self.assertIn("update() of frame 0", err)

        class BadName(Recorder):
            name = "has space"

        status, msgs, err, _ = run(BadName(), GOOD)
        self.assertEqual((status, msgs), (1, []))
        self.assertIn("Localizer.name", err)

    def test_serve_in_a_child_process(self):
        """serve() on real pipes: exit 0 after end, prints go to stderr, EOF before end exits 1."""
        code = ("import sys; sys.path.insert(0, %r)\n"
                "import omniloc_client as olp\n"
                "class L(olp.Localizer):\n"
                "    name = 'child'\n"
                "    def reset(self, seed, start): print('reset', seed)\n"
                "    def update(self, f):\n"
                "        print('frame', f.k); import os; os.write(1, b'raw fd 1 write\\n')\n"
                "        return olp.Estimate((f.k, 0.0, 0.0), valid=False)\n"
                "olp.serve(L())\n") % str(CLIENTS / "python")
        data = stream(line(HELLO), line({"type": "reset", "seed": 1, "start": None}), frame(0), frame(1), line({"type": "end"}))
        p = subprocess.run([sys.executable, "-c", code], input=data, capture_output=True, timeout=60)
        self.assertEqual(p.returncode, 0, p.stderr)
        out = [json.loads(x) for x in p.stdout.splitlines()]
        self.assertEqual([m["type"] for m in out], ["ready", "estimate", "estimate"])
        self.assertGreaterEqual(out[2].pop("compute_ms"), 0.0)  # run() reports the time update() took
        self.assertEqual(out[2], {"type": "estimate", "k": 1, "pose": [1.0, 0.0, 0.0], "valid": False})
        self.assertIn(b"frame 1", p.stderr)
        self.assertIn(b"raw fd 1 write", p.stderr)
        p = subprocess.run([sys.executable, "-c", code], input=data[:-len(line({"type": "end"}))], capture_output=True, timeout=60)
        self.assertEqual(p.returncode, 1)
        self.assertIn(b"end of input before end", p.stderr)


class HelperTest(unittest.TestCase):
    def test_wrap_angle(self):
        for a, w in [(0.0, 0.0), (math.pi, math.pi), (-math.pi, math.pi), (3 * math.pi / 2, -math.pi / 2), (7.0, 7.0 - 2 * math.pi)]:
            self.assertAlmostEqual(olp.wrap_angle(a), w, places=12)

    def test_compose_odometry(self):
        x, y, th = olp.compose_odometry((1.0, 2.0, math.pi / 2), (0.5, 0.1, 0.2))
        self.assertAlmostEqual(x, 1.0 - 0.1)
        self.assertAlmostEqual(y, 2.0 + 0.5)
        self.assertAlmostEqual(th, math.pi / 2 + 0.2)

    def test_calibration(self):
        cal = olp.Calibration(CAMERA)
        # pixel centre (u + 0.5, v + 0.5) = (2.5, -1): 2 px up and 0.5 px right of (2, 1) -> bearing slightly right of forward
        r, b = cal.pixel_polar(2.0, -1.5)
        self.assertAlmostEqual(r, math.hypot(0.5, 2.0))
        self.assertAlmostEqual(b, math.atan2(-0.5, 2.0))
        # straight ahead at r = 3: halfway between 0.4 and 1.2 along bearing 0
        self.assertAlmostEqual(cal.distance(3.0, 0.0), 0.8)
        # bearing pi/4: halfway between bearing 0 (0.8) and pi/2 (0.95)
        self.assertAlmostEqual(cal.distance(3.0, math.pi / 4), 0.875)
        # left (+y) is image left: pixel centre 3 px left of the mirror centre
        x, y = cal.to_robot(2.0 - 3.0 - 0.5, 1.0 - 0.5)
        self.assertAlmostEqual(x, 0.0)
        self.assertAlmostEqual(y, 0.95)
        self.assertIsNone(cal.to_robot(1.5, 0.5))  # the mirror centre: the robot's body
        self.assertIsNone(cal.distance(4.5, 0.0))
        u, v = cal.pixel_of(3.0, math.pi / 2)
        self.assertAlmostEqual(cal.to_robot(u, v)[1], 0.95)
        self.assertAlmostEqual(cal.radius_for_distance(0.8, 0.0), 3.0, places=9)

    def test_field(self):
        f = olp.Field.from_json(FIELD)
        self.assertEqual(f.bounds(), (-2.5, 2.5, -1.5, 1.5))
        self.assertAlmostEqual(f.distance_to_lines(1.0, 0.0), 0.5)  # the circle (r 0.5) is nearer than the lines 1 m away
        self.assertAlmostEqual(f.distance_to_lines(0.0, 0.3), 0.0)   # on the centre line
        self.assertAlmostEqual(f.distance_to_lines(0.3, 0.0), 0.2)   # inside the circle
        pts = f.line_samples(0.05)
        self.assertTrue(all(f.distance_to_lines(x, y) < 1e-9 for x, y in pts))
        self.assertGreater(len(pts), (4 * 2 + 2 * 2 + 2 + math.pi) / 0.05)

    def test_estimate_message(self):
        m = olp.Estimate((1, 2, 3), valid=False).to_message(5)
        self.assertEqual(m, {"type": "estimate", "k": 5, "pose": [1.0, 2.0, 3.0], "valid": False})
        self.assertEqual(olp.Estimate((1, 2, 3), compute_ms=0.25).to_message(5)["compute_ms"], 0.25)
        with self.assertRaises(olp.ProtocolError):
            olp.Estimate((0, 0, 0), compute_ms=-1).to_message(0)
        with self.assertRaises(olp.ProtocolError):
            olp.Estimate((0, 0, 0), mode="Bad Mode").to_message(0)
        with self.assertRaises(olp.ProtocolError):
            olp.Estimate((0, 0, 0), covariance=[1, 2]).to_message(0)
        with self.assertRaises(olp.ProtocolError):
            olp.Estimate((0, 0, 0), extra={"line_points": 3}).to_message(0)  # a frames.csv column
        # What the run viewer draws (docs/protocol.md section 6): particles and points, checked.
        m = olp.Estimate((0, 0, 0), particles=[(1, 2, 0.5, 0.25)], points=[(3, 4)]).to_message(1)
        self.assertEqual((m["particles"], m["points"]), ([[1.0, 2.0, 0.5, 0.25]], [[3.0, 4.0]]))
        for bad in ({"particles": [(1, 2, 3)]}, {"particles": [(1, 2, 3, -1)]}, {"points": [(1, float("nan"))]},
                    {"points": [(0, 0)] * 10001}):
            with self.assertRaises(olp.ProtocolError):
                olp.Estimate((0, 0, 0), **bad).to_message(0)


if __name__ == "__main__":
    unittest.main()
