#!/usr/bin/env python3
"""Convert one NuBot robot's published calibration frame to an omniloc recording (docs/recording.md,
format omniloc-recording/1, section 6: a log not made by omniloc).

Input: a folder `calib_results/<n>/` of NuBot's code (https://github.com/nubot-nudt/nubot_ws,
`src/nubot/omni_vision/calib_results/<n>/`, commit 627da6a93e104dfd47fd22042da0c1f69e908c65, licence
stated as "Apache" in its README; fetch it yourself). Read from it:

- `whites.txt`: white line pixels of one real omnidirectional image, one "column row" pair a line
  (image x = column to the right, y = row downwards; NuBot's calibration2.m plots them as
  `plot(linepoints(:,1), linepoints(:,2))` over the image, so column 1 is the image x);
- `mirror_calib.xml`: the mirror law NuBot's calibration2.m / costfcn.m fitted to those pixels:
  `center_coloum`, `center_row` (the mirror centre, pixels), `para_a` (m), `para_b` (1/pixel):
  floor distance d = para_a * tan(para_b * rho) metres at rho pixels from the centre (NuBot's
  Transfer::calculateRealDistance returns it in cm, x100), and `correction_x`, `correction_y` (cm):
  where the robot centre (ROI.xml's `center_point_*` pixel) lies seen from the mirror centre;
- `ROI.xml` (optional, recorded for provenance): image size and the robot-centre pixel.

The conversion (our own code; the method and conventions are NuBot's, read in omni_vision/src/
transfer.cpp, whites.cpp, omnivision.cpp and nubot_hwcontroller/src/nubot_teleop_joy.cpp):

    dx = column - center_coloum,  dy = row - center_row          (pixels)
    d  = para_a * tan(para_b * hypot(dx, dy))                       (metres)
    b  = atan2(dy, dx)                                              (robot bearing, anticlockwise)
    p  = d (cos b, sin b) - (correction_x, correction_y) / 100      (robot frame, metres)

Robot frame x forward, y left as omniloc's (docs/protocol.md section 4). NuBot takes the bearing of
a pixel as atan2(row offset, column offset) with no further rotation (Transfer::
calculateRealCoordinates: PPoint(temptrans.angle(), distance)), bearing 0 is the robot's front (the
teleop node turns the robot at w = the ball's bearing, so the ball ends in front) and bearings are
anticlockwise (NuBot's world frame is drawn x right, y up: Whites::showWhitePoints). Physically: a
camera looking up at the mirror sees the floor point at world azimuth a at image angle a measured
from the column axis towards the row axis, so (column, row) = (forward, left) is right-handed.
The correction is NuBot's Transfer::correct_offset (the published robot position is the mirror
centre's plus this offset, omnivision.cpp), so points are relative to the robot centre.

Duplicate pixels (the same column and row listed twice) are kept once, in file order; points beyond
`--max-range` (7.5 m: omniloc's own vision does not scan farther, docs/protocol.md section 5; the
mirror law is near its pole there, d -> infinity as rho -> pi / (2 para_b)) are left out.

Output: a recording of the robot standing still for `--frames` frames at `--rate` Hz (300 at 30 Hz:
10 s), every frame the same line points, odometry [0, 0, 0], heading null (no compass), no start
pose, ground truth = the reference pose found by scripts/nubot_reference_pose.py (an exhaustive
search, not an omniloc localizer), camera {} (points, no image). The header carries "source"
(repository, path, commit, licence, input SHA-256s), "conversion" (mirror law, centre, correction,
axes, counts) and "reference" (pose, twin, residual, next-best distinct pose, line-point noise by
range band).

    scripts/nubot_to_recording.py NUBOT_WS/src/nubot/omni_vision/calib_results/1 -o data/real/nubot/robot1 --robot 1
"""
import argparse
import json
import os
import sys

import numpy as np

# A developer's tool, run from a checkout: the results package and the recording client beside it.
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(REPO, "python"), os.path.join(REPO, "clients", "python")]
import omniloc_recording  # noqa: E402
from omniloc.data import nubot as refpose  # noqa: E402
from omniloc.data.nubot_frames import (SOURCE_COMMIT, SOURCE_REPOSITORY, reproducible_gzip, mirror_law, noise_by_band,  # noqa: E402
                                       pixels_to_robot, read_whites, read_xml_numbers, sha256_file)


def convert(calib_dir, out, robot_label, field="msl2012", frames=300, rate=30.0, max_range=7.5,
            source_path=None, source_commit=SOURCE_COMMIT, search_kw=None, quiet=False):
    whites_path = os.path.join(calib_dir, "whites.txt")
    calib_path = os.path.join(calib_dir, "mirror_calib.xml")
    roi_path = os.path.join(calib_dir, "ROI.xml")
    law = mirror_law(read_xml_numbers(calib_path))
    roi = read_xml_numbers(roi_path) if os.path.exists(roi_path) else None
    pix, raw_count = read_whites(whites_path)
    pts, ok = pixels_to_robot(pix, law)
    rng = np.hypot(pts[:, 0], pts[:, 1])
    keep = ok & (rng <= max_range)
    pts = pts[keep]
    if len(pts) < 10:
        raise SystemExit(f"{whites_path}: only {len(pts)} points within {max_range} m")
    # 1 mm: 35 times finer than a pixel's footprint on the floor at the nearest points (3.5 cm at 2.3 m),
    # and it keeps a frame's line under gzip's 32 KiB window, so 300 identical frames compress to one.
    pts = np.round(pts, 3)
    res = refpose.search(pts, field, **(search_kw or {}))
    markings = refpose.field_markings(field)
    ref = tuple(res["reference"])
    bands = noise_by_band(markings, ref, pts)
    if source_path is None:
        source_path = f"src/nubot/omni_vision/calib_results/{os.path.basename(os.path.normpath(calib_dir))}/"
    source = {
        "repository": SOURCE_REPOSITORY, "path": source_path, "commit": source_commit,
        "licence": "Apache-2.0",
        "licence_note": "nubot_ws's README states 'License: Apache' (no version, no LICENSE or NOTICE file at the "
                        "repository root); omni_vision's package.xml says BSD. Treated as Apache-2.0: attribution to "
                        "the NuBot team kept here, the files were converted (changed) by scripts/nubot_to_recording.py",
        "copyright": "NuBot team, National University of Defense Technology (nubot-nudt)",
        "files": {"whites.txt": sha256_file(whites_path), "mirror_calib.xml": sha256_file(calib_path)},
    }
    if roi is not None:
        source["files"]["ROI.xml"] = sha256_file(roi_path)
    conversion = {
        "mirror_law": "d = para_a * tan(para_b * rho) m, rho = pixels from (center_coloum, center_row)",
        "para_a_m": law["para_a"], "para_b_per_px": law["para_b"],
        "mirror_centre_px": [law["center_coloum"], law["center_row"]],
        "correction_cm": [law["correction_x"], law["correction_y"]],
        "axes": "robot x = image column direction (forward), robot y = image row direction (left); "
                "bearing = atan2(row - center_row, column - center_coloum), anticlockwise; "
                "point = d (cos b, sin b) - correction / 100 (relative to the robot centre)",
        "roi": roi,
        "pixels_in_file": raw_count, "distinct_pixels": int(len(pix)),
        "beyond_max_range": int((~keep).sum()), "max_range_m": max_range, "line_points": int(len(pts)),
    }
    reference = {k: v for k, v in res.items() if k != "seconds"}  # no wall-clock time: reruns are byte-identical
    reference["line_point_noise"] = {
        "what": "distance of each point, placed with the reference pose, to the nearest marking centre line",
        "bands": bands}
    name = f"nubot_robot{robot_label}"
    comment = (f"NuBot robot {robot_label}'s calibration frame (whites.txt: white line pixels of one real "
               f"omnidirectional image) converted to the robot frame with its mirror law (mirror_calib.xml). "
               f"Robot standing still for {frames} frames, no odometry motion, no compass, no start pose. "
               f"Truth = the reference pose of an exhaustive search (scripts/nubot_reference_pose.py), not a "
               f"measurement. Source: {SOURCE_REPOSITORY} {source_path} at {source_commit}, Apache-2.0, "
               f"(c) the NuBot team; converted by scripts/nubot_to_recording.py.")
    line_points = [[float(x), float(y)] for x, y in pts]
    truth = [float(v) for v in ref]
    with omniloc_recording.Writer(out, name=name, field=field, camera_rate_hz=rate,
                                  robots=[{"id": 0, "start": None, "camera": {}}],
                                  ground_truth=True, comment=comment) as w:
        w.header["written_by"] = "scripts/nubot_to_recording.py"
        w.header["source"] = source
        w.header["conversion"] = conversion
        w.header["reference"] = reference
        for k in range(frames):
            w.frame(k / rate, [{"robot": 0, "odometry": (0.0, 0.0, 0.0), "heading": None,
                                "line_points": line_points, "truth": truth}])
    reproducible_gzip(os.path.join(out, "frames.jsonl.gz"))
    if not quiet:
        print(json.dumps({"out": out, "line_points": len(pts), "reference": res["reference"], "twin": res["twin"],
                          "residual_m": res["residual_m"], "inliers": res["inliers"], "next_best": res["next_best"],
                          "noise": [[b["range_m"], b["points"], b["median_cm"], b["p90_cm"]] for b in bands],
                          "seconds": res["seconds"]}))
    return res, bands, conversion


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("calib_dir", help="NuBot's calib_results/<n>/ folder (whites.txt, mirror_calib.xml, ROI.xml)")
    ap.add_argument("-o", "--out", required=True, help="the recording folder to write (replaced if it exists)")
    ap.add_argument("--robot", default=None, help="robot label for the name and comment (default: the folder's name)")
    ap.add_argument("--field", default="msl2012",
                    help="omniloc field preset name, or a JSON field object (default msl2012: the field NuBot's frames 1, 2, 4, 5 fit)")
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--rate", type=float, default=30.0)
    ap.add_argument("--max-range", type=float, default=7.5)
    ap.add_argument("--source-path", default=None, help="the folder's path in nubot_ws (provenance)")
    ap.add_argument("--source-commit", default=SOURCE_COMMIT, help="the nubot_ws commit read (provenance)")
    ap.add_argument("--xy-step", type=float, default=0.05, help="reference search grid (m)")
    ap.add_argument("--theta-step", type=float, default=1.0, help="reference search heading step (deg)")
    a = ap.parse_args()
    field = json.loads(a.field) if a.field.lstrip().startswith("{") else a.field
    label = a.robot or os.path.basename(os.path.normpath(a.calib_dir))
    convert(a.calib_dir, a.out, label, field=field, frames=a.frames, rate=a.rate, max_range=a.max_range,
            source_path=a.source_path, source_commit=a.source_commit,
            search_kw={"xy_step": a.xy_step, "theta_step_deg": a.theta_step})


if __name__ == "__main__":
    main()
