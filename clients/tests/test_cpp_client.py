#!/usr/bin/env python3
"""The C++ header (clients/cpp/omniloc_client.hpp) through its example binary, without omniloc:
hand-made olp/1 streams on its stdin. Usage: test_cpp_client.py PATH/TO/olp_cpp_example
(or OLP_CPP_EXAMPLE in the environment)."""
import json
import os
import subprocess
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_omniloc_client import GOOD, HELLO, frame, line, olp, stream  # noqa: E402

BINARY = os.environ.get("OLP_CPP_EXAMPLE", "")


def talk(data):
    p = subprocess.run([BINARY], input=data, capture_output=True, timeout=60)
    return p.returncode, [json.loads(x) for x in p.stdout.splitlines()], p.stderr.decode(errors="replace")


class CppClientTest(unittest.TestCase):
    def test_whole_session_with_images(self):
        status, msgs, err = talk(GOOD)  # frames carry a binary image part the example ignores
        self.assertEqual(status, 0, err)
        self.assertEqual(msgs[0], {"type": "ready", "protocol": "olp/1", "name": "cpp_dead_reckoning", "version": "1.0",
                                   "needs_start_pose": True, "wants_image": False})
        pose = (1.0, -0.5, 0.25)
        for m, odo in zip(msgs[1:], [(0, 0, 0), (0.1, 0.02, 0.01), (0.1, -0.02, -0.3)]):
            pose = olp.compose_odometry(pose, odo)  # the C++ and Python helpers agree to the bit
            self.assertEqual(m["pose"], list(pose))
            self.assertEqual((m["valid"], m["mode"], m["extra"]["n_line_points"]), (True, "dead_reckoning", 1.0))
        self.assertEqual([m["k"] for m in msgs[1:]], [0, 1, 2])
        self.assertIn("frame 0", err)  # its printf went to stderr, not into the protocol

    def test_image(self):
        hello = dict(HELLO, params={"wants_image": True})
        status, msgs, err = talk(GOOD.replace(line(HELLO), line(hello), 1))
        self.assertEqual(status, 0, err)
        self.assertTrue(msgs[0]["wants_image"])
        for m in msgs[1:]:
            self.assertEqual(m["extra"], {"image_last_blue": 23.0, "image_mean": 11.5, "image_width": 4.0, "n_line_points": 1.0})

    def test_byte_at_a_time(self):
        # a pipe that delivers one byte per write: the reader must assemble lines and parts
        with subprocess.Popen([BINARY], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, bufsize=0) as p:
            for i in range(len(GOOD)):
                p.stdin.write(GOOD[i:i + 1])
            p.stdin.close()
            out = p.stdout.read()
            self.assertEqual(p.wait(timeout=60), 0)
        self.assertEqual(len(out.splitlines()), 4)

    def test_eof_and_protocol_errors(self):
        cases = {
            "eof before end": (GOOD[:-len(line({"type": "end"}))], "end of input before end"),
            "eof in an image": (GOOD[:len(GOOD) - 40], "end of input"),
            "empty": (b"", "end of input before hello"),
            "not json": (stream(line(HELLO), b"{nope\n"), "not a JSON line"),
            "wrong protocol": (line(dict(HELLO, protocol="olp/2")), "this client speaks olp/1"),
            "frame before reset": (stream(line(HELLO), frame(0)), "frame before reset"),
            "unknown type": (stream(line(HELLO), line({"type": "dance"})), "unexpected message type"),
        }
        for what, (data, text) in cases.items():
            with self.subTest(what):
                status, _, err = talk(data)
                self.assertNotEqual(status, 0)
                self.assertIn(text, err)


if __name__ == "__main__":
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        BINARY = sys.argv.pop(1)
    if not BINARY:
        sys.exit("usage: test_cpp_client.py PATH/TO/olp_cpp_example")
    unittest.main()
