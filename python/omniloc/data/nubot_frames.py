"""NuBot's calibration frames (nubot_ws): their white pixels and mirror law, the conversion of pixels
to robot-frame points and back, and the line points' noise by range. The reusable part of
scripts/nubot_to_recording.py, which writes the recordings of data/real/nubot.
"""
from __future__ import annotations

import gzip
import hashlib
import math
import os
import re
from typing import Optional, Union

import numpy as np

from omniloc.data import nubot
from omniloc.data.nubot import Markings, Pose


SOURCE_REPOSITORY = "https://github.com/nubot-nudt/nubot_ws"


SOURCE_COMMIT = "627da6a93e104dfd47fd22042da0c1f69e908c65"


BANDS = [(0.0, 1.5), (1.5, 3.0), (3.0, 5.0), (5.0, 7.5)]


def read_xml_numbers(path: Union[str, os.PathLike[str]]) -> dict[str, float]:
    """The numeric leaf elements of an OpenCV FileStorage XML file: {tag: float}."""
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    out = {}
    for tag, val in re.findall(r"<([A-Za-z_][A-Za-z0-9_]*)>\s*([-+0-9.eE]+)\s*</\1>", text):
        out[tag] = float(val)
    return out


def read_whites(path: Union[str, os.PathLike[str]]) -> tuple["np.ndarray", int]:
    """Integer (column, row) pairs in file order, duplicates removed (first kept); and the raw count."""
    pix = []
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            f = line.split()
            if len(f) >= 2:
                pix.append((float(f[0]), float(f[1])))
    seen: set[tuple[float, float]] = set()
    uniq: list[tuple[float, float]] = []
    for p in pix:
        if p not in seen:
            seen.add(p)
            uniq.append(p)
    return np.array(uniq, dtype=float).reshape(-1, 2), len(pix)


def mirror_law(calib: dict[str, float]) -> dict[str, float]:
    """The mirror calibration's numbers the conversion needs (SystemExit naming the missing ones)."""
    need = ["center_coloum", "center_row", "para_a", "para_b", "correction_x", "correction_y"]
    missing = [k for k in need if k not in calib]
    if missing:
        raise SystemExit(f"mirror_calib.xml: missing {', '.join(missing)}")
    return calib


def pixels_to_robot(pix: "np.ndarray", law: dict[str, float]) -> tuple["np.ndarray", "np.ndarray"]:
    """(N, 2) (column, row) pixels -> (N, 2) robot-frame floor points in metres (module docstring)."""
    dx = pix[:, 0] - law["center_coloum"]
    dy = pix[:, 1] - law["center_row"]
    rho = np.hypot(dx, dy)
    arg = law["para_b"] * rho
    ok = arg < 0.5 * math.pi
    d = np.where(ok, law["para_a"] * np.tan(np.where(ok, arg, 0.0)), np.inf)
    b = np.arctan2(dy, dx)
    x = d * np.cos(b) - law["correction_x"] / 100.0
    y = d * np.sin(b) - law["correction_y"] / 100.0
    return np.c_[x, y], ok


def robot_to_pixels(pts: "np.ndarray", law: dict[str, float]) -> "np.ndarray":
    """Inverse of pixels_to_robot (continuous pixels): for tests and synthetic frames."""
    mx = pts[:, 0] + law["correction_x"] / 100.0
    my = pts[:, 1] + law["correction_y"] / 100.0
    d = np.hypot(mx, my)
    rho = np.arctan(d / law["para_a"]) / law["para_b"]
    b = np.arctan2(my, mx)
    return np.c_[law["center_coloum"] + rho * np.cos(b), law["center_row"] + rho * np.sin(b)]


def noise_by_band(markings: Markings, pose: Pose, pts: "np.ndarray") -> list[dict[str, Union[list[float], int, Optional[float]]]]:
    """Distance of each point (placed with `pose`) to the nearest marking, per range band (the
    bands a recording's header carries under reference.line_point_noise)."""
    wx, wy = nubot.world_points(pose, pts)
    d = nubot.distance_to_markings(markings, wx, wy)
    r = np.hypot(pts[:, 0], pts[:, 1])
    out: list[dict[str, Union[list[float], int, Optional[float]]]] = []
    for lo, hi in BANDS:
        sel = (r >= lo) & (r < hi)
        n = int(sel.sum())
        out.append({"range_m": [lo, hi], "points": n,
                    "median_cm": round(float(np.median(d[sel])) * 100, 2) if n else None,
                    "p90_cm": round(float(np.percentile(d[sel], 90)) * 100, 2) if n else None})
    return out


def sha256_file(path: Union[str, os.PathLike[str]]) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def reproducible_gzip(path: str) -> None:
    """Rewrites a gzip file with no time stamp and no file name in its header (the content and the
    recording's frames_sha256 of it are unchanged), so that reruns give byte-identical files."""
    with gzip.open(path, "rb") as fh:
        data = fh.read()
    with open(path + ".tmp", "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0, compresslevel=9) as fh:
            fh.write(data)
    os.replace(path + ".tmp", path)
