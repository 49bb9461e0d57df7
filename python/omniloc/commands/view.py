"""`omniloc view RUN_DIR [-o FILE.html]`: writes one self-contained HTML page to step through a run
frame by frame (docs/viewer.md). Run as `python3 -m omniloc.commands.view`; the program name in
--help and errors is $OMNILOC_VIEW_PROG (default "omniloc view").

Exit status: 0 written; 2 bad input (one line on stderr naming the file and what was expected;
nothing written).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path
from typing import List, Optional

from omniloc.tools.cliargs import Parser, at_least
from omniloc.core import pathcheck
from omniloc.core.files import InputFileError
from omniloc.view.load import load_run
from omniloc.view.page import render

DESCRIPTION = """\
Writes one HTML file (self-contained: opens from disk in any browser, no server, no network) to
step through a run frame by frame: the field, the true and estimated trajectories and poses with
their headings, the estimate's 2-sigma covariance ellipse, the frame's line points placed at the
estimate (a bad match shows as points off the lines; optionally also at the truth), blobs as
bearing rays, particles coloured by weight, the mode, errors, the scenario's events on the
timeline, and the position and heading error over time (click to go there). Keys: left / right
step a frame (shift: 10), space plays and pauses.

Line points, blobs, covariance and particles come from RUN_DIR/view.jsonl (`omniloc run
--debug-view`), else line points and blobs from the recording given by --recording; without
either the page says so. Camera images come from that recording (made with --images) or from the
PNGs `omniloc run --frames DIR` wrote (--frames DIR)."""

EPILOG = """\
size: a 60 s run at 30 Hz (1801 frames) is about 1 MB with line points, about 3 MB with 100
particles a frame (docs/viewer.md). Line points are kept to the millimetre, particles to the
millimetre and milliradian, at most --particles a frame (an even stride through the localizer's
list) on every --particles-every-th frame. Camera images are the recording's (or the --frames
folder's) PNGs embedded as base64: each adds about 0.7 MB (a 640 x 640 panorama), so a 60 s run at
30 Hz with --image-every 30 (one a second) adds about 42 MB and --image-every 1 about 1.2 GB;
--no-images leaves them out.

exit status: 0 written; 2 bad input (one line naming the file and what was expected; nothing is
written). The output is written to a temporary file beside FILE and renamed into place."""


_positive = at_least(1)
_count = at_least(0)


def parser(prog: str) -> argparse.ArgumentParser:
    p = Parser(prog=prog, description=DESCRIPTION, epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run_dir", metavar="RUN_DIR", help="a run folder (omniloc run / replay -o DIR)")
    p.add_argument("-o", dest="output", metavar="FILE", help="the page to write (default: RUN_DIR/view.html); replaced if it exists")
    p.add_argument("--recording", metavar="DIR",
                   help="a recording of the run's scenario and seed (the one it was replayed from, or omniloc record of the "
                        "same scenario and seed): its line points and blobs when the run has no view.jsonl, and its camera "
                        "images when recorded with --images")
    p.add_argument("--frames", metavar="DIR",
                   help="the camera frames omniloc run --frames DIR wrote for this run (PNG): its images, in place of a "
                        "recording's")
    p.add_argument("--image-every", type=_positive, default=30, metavar="N",
                   help="embed every N-th frame's camera image (default 30: one a second at 30 Hz; with --frames, the "
                        "first PNG and then each at least N frames after the last one embedded); the page shows the last "
                        "embedded image at or before the frame")
    p.add_argument("--no-images", action="store_true", help="embed no camera images")
    p.add_argument("--particles", type=_count, default=100, metavar="N",
                   help="at most N particles a frame (default 100; view.jsonl holds up to 200; 0: none)")
    p.add_argument("--particles-every", type=_positive, default=1, metavar="N",
                   help="particles on every N-th frame only (default 1: every frame)")
    p.add_argument("--quiet", action="store_true", help="print nothing when written")
    return p


def _write_atomically(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def main(argv: Optional[List[str]] = None) -> int:
    prog = os.environ.get("OMNILOC_VIEW_PROG") or "omniloc view"
    args = parser(prog).parse_args(argv)
    run_dir = Path(args.run_dir)
    out = Path(args.output) if args.output else run_dir / "view.html"
    try:
        # Every path given, before anything is read: pathlib's is_dir() raises on a name over
        # NAME_MAX and reading a FIFO blocks, so each is asked about in words first.
        checks = [(run_dir, "RUN_DIR", "a run folder (omniloc run / replay -o DIR)"),
                  (args.recording, "--recording", "a recording folder (omniloc record)"),
                  (args.frames, "--frames", "the folder omniloc run --frames DIR wrote")]
        for path, where, what in checks:
            why = pathcheck.why_not_readable_folder(path) if path is not None else None
            if why:
                raise InputFileError(pathcheck.shown(path), f"{why}: {where} expects {what}")
        why = pathcheck.why_not_writable(out, False)
        if why:
            raise InputFileError(pathcheck.shown(out), f"{why}: {'-o' if args.output else 'the page RUN_DIR/view.html'} is written there")
        if out.is_dir():
            raise InputFileError(out, "a folder: expected the name of the HTML file to write")
        if not out.parent.is_dir() and run_dir.is_dir():
            raise InputFileError(out.parent, "missing: expected an existing folder to write the page into")
        run = load_run(run_dir, Path(args.recording) if args.recording else None, image_every=args.image_every,
                       images=not args.no_images, frames_dir=Path(args.frames) if args.frames else None)
        page = render(run, max_particles=args.particles, particles_every=args.particles_every)
        _write_atomically(out, page)
    except InputFileError as e:
        print(f"{prog}: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"{prog}: {out}: cannot write the page ({e.strerror or e})", file=sys.stderr)
        return 2
    if not args.quiet:
        n = len(page.encode("utf-8"))
        src = {"view.jsonl": "line points from view.jsonl", "recording": "line points from the recording"}.get(
            run["debug_source"] or "", "no line points")
        images = sum(len(r["images"]) for r in run["robots"])
        print(f"wrote {out} ({n / 1e6:.1f} MB: {run['frames']} frames, {len(run['robots'])} robot(s), {src}, {images} image(s))")
    return 0


if __name__ == "__main__":
    sys.exit(main())
