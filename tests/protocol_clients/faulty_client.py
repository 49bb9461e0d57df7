#!/usr/bin/env python3
"""An olp/1 client that misbehaves on purpose, one way per mode, for the failure tests of
docs/protocol.md section 7 (tests/external_test.cpp, tests/external_cli_test.py).

usage: faulty_client.py MODE [PID_FILE]
MODE: ok | no_ready | exit_at:N | kill_at:N | stall_at:N | garbage_at:N | wrong_k_at:N | nan_at:N |
      bad_name | bad_exit | linger | no_read | ignore_term_at:N | slow:SECONDS | fail_once:FLAG_FILE
fail_once exits with status 3 at frame 2 unless FLAG_FILE exists, and creates it (a sweep's --resume
then succeeds).
Up to its fault it dead-reckons from the start pose like the built-in odometry_only. PID_FILE, when
given, gets this process's pid and, in stall_at, a grandchild's pid (so tests can check that the
whole process group was ended).
"""
import json
import math
import os
import signal
import subprocess
import sys
import time

mode = sys.argv[1] if len(sys.argv) > 1 else "ok"
pid_file = sys.argv[2] if len(sys.argv) > 2 else None
kind, _, arg = mode.partition(":")
n_at = int(arg) if arg and kind not in ("slow", "fail_once") else -1
if kind == "fail_once":
    try:  # atomic: of clients started together exactly one creates the flag and fails
        os.close(os.open(arg, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        kind, n_at = "exit_at", 2
    except FileExistsError:
        kind = "ok"
inp, out = sys.stdin.buffer, sys.stdout.buffer


def note_pid(pid):
    if pid_file:
        with open(pid_file, "a") as f:
            f.write(f"{pid}\n")


def send(obj, raw=None):
    out.write(raw if raw is not None else (json.dumps(obj) + "\n").encode())
    out.flush()


def read_message():
    line = inp.readline()
    if not line:
        print("faulty_client: end of input", file=sys.stderr)
        sys.exit(1)
    msg = json.loads(line)
    for part in msg.get("binary", []):
        data = inp.read(part["bytes"])
        if len(data) != part["bytes"]:
            sys.exit(1)
    return msg


note_pid(os.getpid())
print(f"faulty_client: mode {mode}", file=sys.stderr, flush=True)
hello = read_message()
if kind == "no_ready":
    time.sleep(1000)
send({"type": "ready", "name": "mcl" if kind == "bad_name" else "faulty", "version": "1",
      "needs_start_pose": True, "wants_image": kind == "no_read"})
if kind == "no_read":
    time.sleep(1000)
x = y = th = 0.0
while True:
    msg = read_message()
    if msg["type"] == "reset":
        x, y, th = msg["start"]
        continue
    if msg["type"] == "end":
        if kind == "bad_exit":
            sys.exit(4)
        if kind == "linger":
            time.sleep(1000)
        sys.exit(0)
    k = msg["k"]
    dx, dy, dth = msg["odometry"]
    c, s = math.cos(th), math.sin(th)
    x, y, th = x + c * dx - s * dy, y + s * dx + c * dy, th + dth  # left to right, as Pose2::compose
    if kind == "stall_at" and k == n_at - 1:
        # The grandchild is started, and its pid noted, a frame before the stall and before this
        # frame's answer: started at the stall itself, on a busy machine the host's timeout could
        # end the client before the pid was written, and the test would not know the grandchild.
        child = subprocess.Popen(["sleep", "1000"])
        note_pid(child.pid)
    if k == n_at:
        print(f"faulty_client: {kind} at frame {k}", file=sys.stderr, flush=True)
        if kind == "exit_at":
            sys.exit(3)
        if kind == "kill_at":
            os.kill(os.getpid(), signal.SIGKILL)
        if kind == "stall_at":
            time.sleep(1000)
        if kind == "ignore_term_at":
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            time.sleep(1000)
        if kind == "garbage_at":
            send(None, b"hello world\n")
            continue
        if kind == "wrong_k_at":
            k += 1
        if kind == "nan_at":
            send(None, (json.dumps({"type": "estimate", "k": k, "pose": [x, float("nan"), th], "valid": True}) + "\n").encode())
            continue
    if kind == "slow":
        time.sleep(float(arg))
    send({"type": "estimate", "k": k, "pose": [x, y, th], "valid": True, "mode": "dead_reckoning"})
