"""The viewer's optional inputs beside the run folder: view.jsonl (`--debug-view`, docs/viewer.md
section 4), a recording's frames (line points, blobs) and its images (docs/recording.md), and the
camera frames `omniloc run --frames DIR` wrote."""
from __future__ import annotations

import base64
import gzip
import json
import os
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

from omniloc.view.model import (T_TOLERANCE, ViewInputError, Blob, Debug, _check_file, _finite, _read_text)

# ----------------------------------------------------------------------------------- debug inputs

def _points(v: Any, width: int, path: Path, line: int, key: str) -> List[Tuple[float, ...]]:
    what = f"`{key}`: expected a list of [{', '.join(['x', 'y', 'theta', 'weight'][:width])}] number lists"
    if not isinstance(v, list):
        raise ViewInputError(path, what, line)
    out: List[Tuple[float, ...]] = []
    for p in v:
        if not isinstance(p, list) or len(p) != width or not all(_finite(x) for x in p):
            raise ViewInputError(path, what + f", got {json.dumps(p)[:60]}", line)
        out.append(tuple(float(x) for x in p))
    return out


def _blobs(v: Any, path: Path, line: int) -> List[Blob]:
    if v is None:
        return []
    if not isinstance(v, list):
        raise ViewInputError(path, "`blobs`: expected a list of olp/1 blob objects", line)
    out: List[Blob] = []
    for b in v:
        if not isinstance(b, dict) or not _finite(b.get("bearing")):
            raise ViewInputError(path, "`blobs`: expected objects with a number `bearing` (olp/1 frame.blobs)", line)
        d = b.get("distance")
        if d is not None and not _finite(d):
            raise ViewInputError(path, "`blobs`: expected `distance` a number or null", line)
        out.append(Blob(colour=str(b.get("colour", "")), kind=str(b.get("kind", "region")), bearing=float(b["bearing"]),
                        distance=None if d is None else float(d)))
    return out


def _covariance(v: Any, path: Path, line: int) -> Optional[List[float]]:
    if v is None:
        return None
    what = "`covariance`: expected 3 rows of 3 numbers (x, y, theta; m^2, rad^2) or 9 numbers row-major"
    if isinstance(v, list) and len(v) == 3 and all(isinstance(r, list) and len(r) == 3 for r in v):
        flat = [x for r in v for x in r]
    elif isinstance(v, list) and len(v) == 9:
        flat = list(v)
    else:
        raise ViewInputError(path, what, line)
    if not all(_finite(x) for x in flat):
        raise ViewInputError(path, what + " (finite)", line)
    return [float(x) for x in flat]


def read_view_jsonl(path: Path, ids: Sequence[int], times: Dict[int, List[float]]) -> Dict[int, List[Debug]]:
    """view.jsonl: one object per (frame, robot), in frame order, every one present (docs/viewer.md)."""
    frames = len(times[ids[0]])
    out: Dict[int, List[Optional[Debug]]] = {rid: [None] * frames for rid in ids}
    text = _read_text(path, "view.jsonl, one JSON object per frame and robot (docs/viewer.md)")
    last_k = -1
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            o = json.loads(line)
        except json.JSONDecodeError as err:
            raise ViewInputError(path, f"expected one JSON object per line ({err.msg} at column {err.colno})", n) from None
        if not isinstance(o, dict):
            raise ViewInputError(path, "expected a JSON object {\"k\", \"t\", \"robot\", \"line_points\", ...}", n)
        k, t, rid = o.get("k"), o.get("t"), o.get("robot")
        if not isinstance(k, int) or isinstance(k, bool) or k < 0:
            raise ViewInputError(path, "`k`: expected the frame index, an integer >= 0", n)
        if k >= frames:
            raise ViewInputError(path, f"`k` {k}: the run has frames 0 to {frames - 1} (frames.csv)", n)
        if k < last_k:
            raise ViewInputError(path, f"`k` {k} after {last_k}: expected frame order", n)
        last_k = k
        if not isinstance(rid, int) or isinstance(rid, bool) or rid not in out:
            raise ViewInputError(path, f"`robot`: expected one of the run's robots {list(ids)}, got {json.dumps(rid)}", n)
        if not _finite(t):
            raise ViewInputError(path, "`t`: expected the frame's time in seconds", n)
        if abs(float(t) - times[rid][k]) > T_TOLERANCE:
            raise ViewInputError(path, f"`t` {t}: frames.csv has t = {times[rid][k]:.4f} for frame {k} of r{rid}", n)
        if out[rid][k] is not None:
            raise ViewInputError(path, f"frame {k} of r{rid} a second time: expected one line per frame and robot", n)
        if "line_points" not in o:
            raise ViewInputError(path, "`line_points`: expected a list of [x, y] (robot frame, metres)", n)
        lp = _points(o["line_points"], 2, path, n, "line_points")
        particles = _points(o["particles"], 4, path, n, "particles") if o.get("particles") is not None else None
        if particles is not None and any(p[3] < 0 for p in particles):
            raise ViewInputError(path, "`particles`: expected weights >= 0", n)
        points = _points(o["points"], 2, path, n, "points") if o.get("points") is not None else None
        out[rid][k] = Debug(line_points=[(p[0], p[1]) for p in lp], blobs=_blobs(o.get("blobs"), path, n),
                            covariance=_covariance(o.get("covariance"), path, n),
                            particles=[(p[0], p[1], p[2], p[3]) for p in particles] if particles is not None else None,
                            points=[(p[0], p[1]) for p in points] if points is not None else None)
    for rid in ids:
        for k, d in enumerate(out[rid]):
            if d is None:
                raise ViewInputError(path, f"no line for frame {k} of r{rid}: expected one line per frame and robot "
                                           f"({frames} frames x {len(ids)} robots)")
    return {rid: [d for d in out[rid] if d is not None] for rid in ids}


def read_recording(folder: Path, ids: Sequence[int], times: Dict[int, List[float]]) -> Tuple[Dict[int, List[Debug]], Dict[str, Any]]:
    """A recording's line points and blobs per robot and frame, and its header."""
    head_path = folder / "recording.json"
    if not folder.is_dir():
        raise ViewInputError(folder, "not a folder: expected a recording (omniloc record, docs/recording.md)")
    try:
        head = json.loads(_read_text(head_path, "recording.json of a recording (docs/recording.md)"))
    except json.JSONDecodeError as err:
        raise ViewInputError(head_path, f"expected a JSON object ({err.msg})", err.lineno) from None
    if not isinstance(head, dict) or head.get("format") != "omniloc-recording/1":
        raise ViewInputError(head_path, "expected `format` \"omniloc-recording/1\"")
    rec_ids = [r.get("id") for r in head.get("robots", []) if isinstance(r, dict)]
    if rec_ids != list(ids):
        raise ViewInputError(head_path, f"robots {rec_ids}: the run localized robots {list(ids)}")
    frames = len(times[ids[0]])
    if head.get("frames") != frames:
        raise ViewInputError(head_path, f"`frames` {head.get('frames')}: the run has {frames} frames (frames.csv)")
    name = head.get("frames_file", "frames.jsonl")
    fpath = folder / str(name)
    _check_file(fpath, "the recording's frames (docs/recording.md section 4)")
    try:
        raw = gzip.open(fpath).read() if str(name).endswith(".gz") else fpath.read_bytes()
        lines = raw.decode("utf-8").splitlines()
    except (OSError, EOFError, UnicodeDecodeError) as e:
        raise ViewInputError(fpath, f"unreadable ({e.__class__.__name__}): expected gzip of JSON lines") from None
    out: Dict[int, List[Debug]] = {rid: [] for rid in ids}
    for n, line in enumerate(lines, 1):
        try:
            f = json.loads(line)
        except json.JSONDecodeError as err:
            raise ViewInputError(fpath, f"expected one JSON object per frame ({err.msg})", n) from None
        if not isinstance(f, dict) or f.get("k") != n - 1 or not _finite(f.get("t")) or not isinstance(f.get("robots"), list):
            raise ViewInputError(fpath, f"expected a frame {{\"k\": {n - 1}, \"t\", \"robots\": [...]}}", n)
        if len(f["robots"]) != len(ids):
            raise ViewInputError(fpath, f"expected {len(ids)} robots per frame, got {len(f['robots'])}", n)
        for rid, r in zip(ids, f["robots"]):
            if n - 1 >= frames:
                break
            if abs(float(f["t"]) - times[rid][n - 1]) > T_TOLERANCE:
                raise ViewInputError(fpath, f"`t` {f['t']}: the run's frame {n - 1} has t = {times[rid][n - 1]:.4f} "
                                            "(a recording of another scenario or seed?)", n)
            if not isinstance(r, dict) or r.get("robot") != rid:
                raise ViewInputError(fpath, f"expected robot {rid} in place {ids.index(rid)}", n)
            lp = _points(r.get("line_points"), 2, fpath, n, "line_points")
            out[rid].append(Debug(line_points=[(p[0], p[1]) for p in lp], blobs=_blobs(r.get("blobs"), fpath, n),
                                  covariance=None, particles=None, points=None))
    if len(out[ids[0]]) != frames:
        raise ViewInputError(fpath, f"{len(out[ids[0]])} frames: the run has {frames} (frames.csv)")
    return out, head


def _png_base64(p: Path, data: bytes) -> str:
    """A camera image's bytes as the page embeds them; anything but a PNG is refused."""
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        raise ViewInputError(p, "expected a PNG image")
    return base64.b64encode(data).decode("ascii")


def read_images(folder: Path, ids: Sequence[int], frames: int, every: int) -> Dict[int, Dict[int, str]]:
    """Every `every`-th frame's PNG of each robot, base64."""
    out: Dict[int, Dict[int, str]] = {rid: {} for rid in ids}
    for rid in ids:
        for k in range(0, frames, every):
            p = folder / "images" / f"r{rid}_{k:06d}.png"
            _check_file(p, "the frame's image (the recording says it holds every image)")
            try:
                data = p.read_bytes()
            except OSError:
                raise ViewInputError(p, "missing: expected the frame's image (the recording says it holds every image)") from None
            out[rid][k] = _png_base64(p, data)
    return out


def read_frame_images(folder: Path, ids: Sequence[int], frames: int, every: int) -> Dict[int, Dict[int, str]]:
    """The PNGs `omniloc run --frames DIR` wrote (r<id>_<frame, 6 digits>.png, every --frames-every-th
    frame), base64: of each robot the first one and then each at least `every` frames after the last
    one embedded. Frames without a file are skipped; a folder with none of the run's is an error."""
    if not folder.is_dir():
        raise ViewInputError(folder, "missing: expected the folder omniloc run --frames DIR wrote the camera frames into")
    names = set(os.listdir(folder))
    out: Dict[int, Dict[int, str]] = {rid: {} for rid in ids}
    for rid in ids:
        last = -every
        for k in range(frames):
            name = f"r{rid}_{k:06d}.png"
            if k - last < every or name not in names:
                continue
            p = folder / name
            _check_file(p, "the frame's PNG")
            try:
                out[rid][k] = _png_base64(p, p.read_bytes())
            except OSError as err:
                raise ViewInputError(p, f"unreadable ({err.strerror}): expected the frame's PNG") from None
            last = k
    if not any(out.values()):
        raise ViewInputError(folder, f"no r{ids[0]}_NNNNNN.png of this run's frames: expected the PNGs omniloc run --frames DIR writes")
    return out
