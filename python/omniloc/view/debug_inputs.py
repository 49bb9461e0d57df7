"""The viewer's optional inputs beside the run folder: a recording's frames (line points, blobs) and
its images (docs/recording.md), and the camera frames `omniloc run --frames DIR` wrote. view.jsonl
(`--debug-view`, docs/viewer.md section 4) is read by omniloc.core.viewlog."""
from __future__ import annotations

import base64
import os
from pathlib import Path
from typing import Dict, List, Sequence, Tuple

from omniloc.core.files import InputFileError, check_file
from omniloc.core.framedata import blobs, pairs
from omniloc.core.recording import RecordingHeader, load_header, read_frames
from omniloc.core.viewlog import T_TOLERANCE, Debug

# ----------------------------------------------------------------------------------- debug inputs

def read_recording(folder: Path, ids: Sequence[int], times: Dict[int, List[float]]) -> Tuple[Dict[int, List[Debug]], RecordingHeader]:
    """A recording's line points and blobs per robot and frame, and its header, checked against the
    run's robots and frame times (frames.csv)."""
    head = load_header(folder)
    head_path = folder / "recording.json"
    rec_ids = head.robot_ids
    if rec_ids != list(ids):
        raise InputFileError(head_path, f"robots {rec_ids}: the run localized robots {list(ids)}")
    frames = len(times[ids[0]])
    if head.frames != frames:
        raise InputFileError(head_path, f"`frames` {head.frames}: the run has {frames} frames (frames.csv)")
    fpath = head.frames_path
    out: Dict[int, List[Debug]] = {rid: [] for rid in ids}
    for f in read_frames(head):
        n = f.line
        if len(f.robots) != len(ids):
            raise InputFileError(fpath, f"expected {len(ids)} robots per frame, got {len(f.robots)}", n)
        for rid, r in zip(ids, f.robots):
            if n - 1 >= frames:
                break
            if abs(float(f.t) - times[rid][n - 1]) > T_TOLERANCE:
                raise InputFileError(fpath, f"`t` {f.t}: the run's frame {n - 1} has t = {times[rid][n - 1]:.4f} "
                                            "(a recording of another scenario or seed?)", n)
            if not isinstance(r, dict) or r.get("robot") != rid:
                raise InputFileError(fpath, f"expected robot {rid} in place {ids.index(rid)}", n)
            out[rid].append(Debug(line_points=pairs(r.get("line_points"), fpath, n, "line_points"), blobs=blobs(r.get("blobs"), fpath, n),
                                  covariance=None, particles=None, points=None))
    if len(out[ids[0]]) != frames:
        raise InputFileError(fpath, f"{len(out[ids[0]])} frames: the run has {frames} (frames.csv)")
    return out, head


def png_base64(p: Path, data: bytes) -> str:
    """A camera image's bytes as the page embeds them; anything but a PNG is refused."""
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise InputFileError(p, "expected a PNG image")
    return base64.b64encode(data).decode("ascii")


def read_images(folder: Path, ids: Sequence[int], frames: int, every: int) -> Dict[int, Dict[int, str]]:
    """Every `every`-th frame's PNG of each robot, base64."""
    out: Dict[int, Dict[int, str]] = {rid: {} for rid in ids}
    for rid in ids:
        for k in range(0, frames, every):
            p = folder / "images" / f"r{rid}_{k:06d}.png"
            check_file(p, "the frame's image (the recording says it holds every image)")
            try:
                data = p.read_bytes()
            except OSError:
                raise InputFileError(p, "missing: expected the frame's image (the recording says it holds every image)") from None
            out[rid][k] = png_base64(p, data)
    return out


def read_frame_images(folder: Path, ids: Sequence[int], frames: int, every: int) -> Dict[int, Dict[int, str]]:
    """The PNGs `omniloc run --frames DIR` wrote (r<id>_<frame, 6 digits>.png, every --frames-every-th
    frame), base64: of each robot the first one and then each at least `every` frames after the last
    one embedded. Frames without a file are skipped; a folder with none of the run's is an error."""
    if not folder.is_dir():
        raise InputFileError(folder, "missing: expected the folder omniloc run --frames DIR wrote the camera frames into")
    names = set(os.listdir(folder))
    out: Dict[int, Dict[int, str]] = {rid: {} for rid in ids}
    for rid in ids:
        last = -every
        for k in range(frames):
            name = f"r{rid}_{k:06d}.png"
            if k - last < every or name not in names:
                continue
            p = folder / name
            check_file(p, "the frame's PNG")
            try:
                out[rid][k] = png_base64(p, p.read_bytes())
            except OSError as err:
                raise InputFileError(p, f"unreadable ({err.strerror}): expected the frame's PNG") from None
            last = k
    if not any(out.values()):
        raise InputFileError(folder, f"no r{ids[0]}_NNNNNN.png of this run's frames: expected the PNGs omniloc run --frames DIR writes")
    return out
