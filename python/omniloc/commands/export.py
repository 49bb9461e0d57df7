"""`omniloc export RUN_DIR|RECORDING|SWEEP -o OUT`: a run or a recording as an MCAP file of Foxglove
messages (docs/viewer.md). Run as `python3 -m omniloc.commands.export`; the program name in --help
and errors is $OMNILOC_EXPORT_PROG (default "omniloc export").

Exit status: 0 written; 2 bad input (one line on stderr naming the file and what was expected;
nothing half written).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import BinaryIO, Callable, List, Optional

from omniloc.tools.cliargs import Parser, at_least
from omniloc.core import pathcheck, rundir
from omniloc.core.files import InputFileError
from omniloc.core.recording import load_header
from omniloc.core.runfiles import read_frame_table
from omniloc.export.encode import encode
from omniloc.export.scene import Scene, image_path, recording_scene, run_scene
from omniloc.view.load import load_run

DESCRIPTION = """\
Writes an MCAP file (mcap.dev) that Foxglove opens: the field, the true and estimated poses and
their transforms (world -> r0/truth, world -> r0/estimate), the frame's line points in the robot
frame, particles, the 2-sigma ellipse and blobs (from RUN_DIR/view.jsonl, `omniloc run
--debug-view`, else from --recording), camera images (a recording made with --images), frames.csv's
numbers for plots and the events as a log. Messages use the Foxglove schemas in JSON encoding and
are stamped with their frame's t. docs/foxglove_layout.json (installed: /usr/share/doc/omniloc/) is
a Foxglove layout for them.

INPUT is a run folder (omniloc run / replay -o DIR), a recording (omniloc record -o DIR) or a sweep
folder (omniloc sweep): for a sweep, -o names a folder and each run becomes OUT/<run>.mcap."""

EPILOG = """\
size and speed: a 60 s tracking run at 30 Hz with view.jsonl exports in well under a second to a
file about the size of its run folder (docs/viewer.md has the measured figures). Chunks are LZ4
compressed (Debian's python3-lz4) where the module is present, else stored.

exit status: 0 written; 2 bad input (one line naming the file and what was expected). Each file is
written to a temporary name beside it and renamed into place, so none is ever half written."""


def parser(prog: str) -> argparse.ArgumentParser:
    p = Parser(prog=prog, description=DESCRIPTION, epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("input", metavar="INPUT", help="a run folder, a recording folder or a sweep folder")
    p.add_argument("-o", dest="output", metavar="OUT", required=True,
                   help="the MCAP file to write (replaced if it exists); for a sweep, the folder to write one file per run into")
    p.add_argument("--recording", metavar="DIR",
                   help="for a run: the recording of its scenario and seed, for line points and blobs when the run has no "
                        "view.jsonl, and for camera images when recorded with --images")
    p.add_argument("--image-every", type=at_least(1), default=1, metavar="N",
                   help="every N-th frame's camera image (default 1: all the recording holds)")
    p.add_argument("--no-images", action="store_true", help="no camera images")
    p.add_argument("--particles", type=at_least(0), default=200, metavar="N",
                   help="at most N particles a frame, an even stride through the localizer's list (default 200: all "
                        "view.jsonl holds; 0: none)")
    p.add_argument("--quiet", action="store_true", help="print nothing when written")
    return p


def write_atomically(path: Path, fill: Callable[[BinaryIO], str]) -> tuple[int, str]:
    """What `fill` writes, at `path`: written under a temporary name in the same folder and renamed
    into place; removed on any error. Returns the size and what `fill` returned."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            result = fill(f)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        size = os.path.getsize(tmp)
        os.replace(tmp, path)
        return size, result
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def kind_of(folder: Path) -> str:
    """"run", "recording" or "sweep": what INPUT holds; InputFileError where it is none of them."""
    why = pathcheck.why_not_readable_folder(folder)
    if why:
        raise InputFileError(pathcheck.shown(folder), f"{why}: INPUT expects a run folder, a recording or a sweep folder")
    if (folder / "frames.csv").exists() or (folder / "summary.json").exists():
        return "run"
    if (folder / "recording.json").exists():
        return "recording"
    if (folder / "aggregate.json").exists() or (folder / "runs").is_dir():
        return "sweep"
    raise InputFileError(folder, "not a run folder (no frames.csv or summary.json), a recording (no recording.json) or a sweep "
                                 "folder (no runs/): expected what omniloc run, record or sweep writes")


def scene_of(folder: Path, kind: str, args: argparse.Namespace) -> Scene:
    images = not args.no_images
    if kind == "recording":
        return recording_scene(load_header(folder), args.image_every, images)
    recording = Path(args.recording) if args.recording else None
    run = load_run(folder, recording, image_every=args.image_every, images=False)
    pngs: dict[int, dict[int, Path]] = {}
    if recording is not None and images and run["recording_images"]:
        for r in run["robots"]:
            pngs[r["id"]] = {k: image_path(recording, r["id"], k) for k in range(0, run["frames"], args.image_every)}
    scene = run_scene(run, read_frame_table(folder / "frames.csv"), pngs, args.particles)
    if run["debug_source"] is None:
        scene.notes.append("no view.jsonl (omniloc run --debug-view) and no --recording: no line points, particles or ellipse")
    return scene


def export_one(folder: Path, kind: str, out: Path, args: argparse.Namespace, prog: str) -> None:
    began = time.perf_counter()
    scene = scene_of(folder, kind, args)
    size, compression = write_atomically(out, lambda f: encode(scene, f))
    if not args.quiet:
        seconds = time.perf_counter() - began
        images = len(scene.images)
        print(f"wrote {out} ({size / 1e6:.2f} MB, {len(scene.messages) + images} messages on {len(scene.topics) + (1 if images else 0)} "
              f"topics, {images} image(s), chunks {compression or 'uncompressed'}, {seconds:.2f} s)")
        for note in scene.notes:
            print(f"{prog}: note: {note}")


def main(argv: Optional[List[str]] = None) -> int:
    prog = os.environ.get("OMNILOC_EXPORT_PROG") or "omniloc export"
    args = parser(prog).parse_args(argv)
    folder = Path(args.input)
    out = Path(args.output)
    try:
        kind = kind_of(folder)
        if args.recording is not None:
            why = pathcheck.why_not_readable_folder(args.recording)
            if why:
                raise InputFileError(pathcheck.shown(args.recording), f"{why}: --recording expects a recording folder (omniloc record)")
            if kind != "run":
                raise InputFileError(folder, f"a {kind} folder: --recording goes with a run folder")
        why = pathcheck.why_not_writable(out, kind == "sweep")
        if why:
            raise InputFileError(pathcheck.shown(out), f"{why}: -o names the {'folder' if kind == 'sweep' else 'MCAP file'} written")
        if kind != "sweep":
            if out.is_dir():
                raise InputFileError(out, "a folder: expected the name of the MCAP file to write")
            if not out.parent.is_dir():
                raise InputFileError(out.parent, "missing: expected an existing folder to write the MCAP file into")
            export_one(folder, kind, out, args, prog)
            return 0
        try:
            runs, _, _ = rundir.discover([folder])
        except SystemExit as e:
            raise InputFileError(folder, str(e.code)) from None
        if not runs:
            raise InputFileError(folder, "no runs (runs/*/summary.json): expected a sweep folder with finished runs")
        names = [r.folder.name for r in runs]
        if len(set(names)) != len(names):
            raise InputFileError(folder, "two runs of the same folder name: one file per run would collide")
        out.mkdir(parents=True, exist_ok=True)
        for r in runs:
            export_one(r.folder, "run", out / f"{r.folder.name}.mcap", args, prog)
    except InputFileError as e:
        print(f"{prog}: {e}", file=sys.stderr)
        return 2
    except ValueError as e:  # the JSON encoder refuses a number that is not finite: a reader let one through
        print(f"{prog}: {folder}: a value that is not a finite number ({e}); expected finite numbers everywhere", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"{prog}: {out}: cannot write ({e.strerror or e})", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
