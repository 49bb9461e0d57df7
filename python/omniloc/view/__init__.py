"""`omniloc view RUN_DIR`: one self-contained HTML page to step through a run frame by frame (the
field, the true and estimated poses, line points, particles, events, errors, camera images).

load.py reads the run folder, view.jsonl and a recording (through the core's readers) into the
page's dicts; page.py writes the page with viewer.js and viewer.css inlined (docs/viewer.md).
"""
