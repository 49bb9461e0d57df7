#!/usr/bin/env python3
"""The layering rule of docs/architecture.md, checked on every #include (ctest: layering).

usage: check_layers.py [ROOT]      scan ROOT (default: the repository), exit 1 naming file:line of
                                   every include of a layer the including layer may not use
       check_layers.py --self-test a small tree with known violations must give exactly those

Includes are written from the source root ("sim/world.hpp"); a quoted include is first looked up
beside the including file, as the compiler does, so "../sim/x.hpp" and "x.hpp" are judged by where
they land. Headers of other projects (<Eigen/Core>, <GL/osmesa.h>) and generated headers
(omniloc_version.hpp) name no layer and are not judged.

Two more rules, on the same includes:
- rooms: inside a layer, some folders keep their own direction (ROOMS below: the recording format
  at the bottom of harness/recording/, scoring apart from the running code, the world cache apart
  from scoring);
- units: no two units (a header and its source file: foo.hpp with foo.cpp) include each other's
  header anywhere in the tree. A pair that does is one unit split in two; the shared declarations
  belong in a header of their own, or one of the two belongs below the other.
"""
import os
import re
import sys
import tempfile

# Which top-level folders each layer may include (its own always). experiments/ (apps -> experiments ->
# harness) and testing/ (scenes for tests and benchmarks) are listed before they exist so the check
# needs no edit when they appear. tests/, bench/ and fuzz/ may include everything and are not scanned;
# no layer below may include them.
ALLOWED = {
    "core": set(),
    "sim": {"core"},
    "localization": {"core"},  # never sim/: it gets what a real robot gets
    "external": {"core", "localization"},  # the olp/1 host: speaks to a process, never sees sim/
    "harness": {"core", "sim", "localization", "external"},
    "batch": {"core", "sim", "localization", "external", "harness"},  # many runs, above the single run
    "experiments": {"core", "sim", "localization", "external", "harness", "batch"},
    "apps": {"core", "sim", "localization", "external", "harness", "batch", "experiments"},
    "testing": {"core", "sim", "localization", "external", "harness", "batch", "experiments"},
}
UNSCANNED = {"tests", "bench", "fuzz"}

# Rooms: folders inside a layer with a direction of their own. A file is judged by the longest room
# that holds it; `only` lists what (inside its layer) it may include besides system and lower-layer
# headers, `never` what it may not. Paths are relative to the source root; a path ending in "/" is a
# folder.
ROOMS = {
    # The recording format (header, frame codec, limits): what a recording is, not how it is made or
    # read back. It knows the frame type and nothing else of the harness.
    "harness/recording/format/": {"only": ("harness/recording/format/", "harness/frame_data.hpp")},
    # Its reader, writer and frame source sit above it and below the world cache and scoring.
    "harness/recording/": {"never": ("harness/cache/", "harness/scoring/")},
    # Scoring judges records (run_record) against the scenario's events; it never runs anything.
    "harness/scoring/": {"only": ("harness/scoring/", "harness/events.hpp", "harness/run_record.hpp")},
    # The world cache keeps drawn worlds and machine-level files; what a run scores is not its business.
    "harness/cache/": {"never": ("harness/scoring/",)},
}
LAYERS = set(ALLOWED) | UNSCANNED
SOURCE_EXT = (".hpp", ".cpp", ".h", ".cc", ".hh", ".inl")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')


def layer_of(root, path):
    """The top-level folder of `path` (absolute, inside root) if it is a layer, else None."""
    rel = os.path.relpath(path, root)
    top = rel.split(os.sep, 1)[0]
    return top if top in LAYERS and not rel.startswith("..") else None


def included_layer(root, including, style, name):
    """The layer an include lands in, or None for a header outside the layers."""
    if style == '"':
        beside = os.path.normpath(os.path.join(os.path.dirname(including), name))
        if os.path.isfile(beside):
            return layer_of(root, beside)
    first = os.path.normpath(name).split(os.sep, 1)[0]
    return first if first in LAYERS and os.sep in os.path.normpath(name) else None


def included_path(root, including, style, name):
    """The file an include lands in, relative to root ("harness/scoring/metrics.hpp"), or None for
    a header outside the source tree (<Eigen/Core>, a generated header)."""
    if style == '"':
        beside = os.path.normpath(os.path.join(os.path.dirname(including), name))
        if os.path.isfile(beside):
            rel = os.path.relpath(beside, root)
            return None if rel.startswith("..") else rel.replace(os.sep, "/")
    rel = os.path.normpath(name)
    return rel.replace(os.sep, "/") if included_layer(root, including, style, name) else None


def room_of(rel):
    """The longest room holding the file `rel` (relative to root), or None."""
    rooms = [r for r in ROOMS if rel.startswith(r)]
    return max(rooms, key=len) if rooms else None


def room_breach(rel, target):
    """Why the room of `rel` may not include `target` (both relative to root), or None."""
    room = room_of(rel)
    if room is None or target is None:
        return None
    rule = ROOMS[room]
    layer = room.split("/", 1)[0]
    if "only" in rule and target.startswith(layer + "/") and not target.startswith(rule["only"]):
        return f"{room} may include from {layer}/ only {', '.join(rule['only'])}"
    if "never" in rule and target.startswith(rule["never"]):
        return f"{room} may not include {', '.join(rule['never'])}"
    return None


def source_files(root, layers):
    """(path, path relative to root) of every source file under the given top-level folders."""
    for layer in sorted(layers):
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, layer)):
            dirnames.sort()
            for fn in sorted(filenames):
                if fn.endswith(SOURCE_EXT):
                    path = os.path.join(dirpath, fn)
                    yield path, os.path.relpath(path, root).replace(os.sep, "/")


def includes(path):
    """(line number, text, style, name) of every #include in the file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        for number, text in enumerate(f, 1):
            m = INCLUDE.match(text)
            if m:
                yield number, text, m.group(1), m.group(2)


def unit_cycles(root):
    """(file, line, text, message) for every pair of units that include each other's header: one
    line per pair, the first include (in path order) of the second unit's header."""
    root = os.path.abspath(root)
    uses = {}  # unit -> {unit whose header it includes: (file, line, text)}
    for path, rel in source_files(root, LAYERS):
        unit = os.path.splitext(rel)[0]
        for number, text, style, name in includes(path):
            target = included_path(root, path, style, name)
            if target is None or not target.endswith((".hpp", ".h", ".hh")):
                continue
            other = os.path.splitext(target)[0]
            if other != unit:
                uses.setdefault(unit, {}).setdefault(other, (rel, number, text.strip()))
    found = []
    for a in sorted(uses):
        for b in sorted(uses[a]):
            if a < b and a in uses.get(b, {}):
                rel, number, text = uses[a][b]
                back = uses[b][a]
                found.append((rel, number, text,
                              f"units {a} and {b} include each other ({back[0]}:{back[1]} includes {a}'s header): "
                              "move what both need into a header of its own, or one below the other"))
    return found


def violations(root):
    """(file relative to root, line number, text, message) for every include the rule forbids."""
    root = os.path.abspath(root)
    found = []
    for path, rel in source_files(root, ALLOWED):
        layer = rel.split("/", 1)[0]
        for number, text, style, name in includes(path):
            target = included_layer(root, path, style, name)
            if target is None:
                continue
            if target != layer and target not in ALLOWED[layer]:
                may = ", ".join(sorted(ALLOWED[layer] | {layer}))
                found.append((rel, number, text.strip(), f"{layer}/ may not include {target}/ (it may include: {may})"))
                continue
            why = room_breach(rel, included_path(root, path, style, name))
            if why:
                found.append((rel, number, text.strip(), f"room: {why}"))
    return found + unit_cycles(root)


def check(root):
    bad = violations(root)
    for path, number, text, why in bad:
        print(f"{path}:{number}: {text}: {why}")
    if bad:
        print(f"layering: {len(bad)} forbidden include(s); the rule is in docs/architecture.md", file=sys.stderr)
        return 1
    print("layering: ok")
    return 0


def kind(why):
    """A violation's kind, for the self-test: the layer it may not include, "room R" or "units A B"."""
    m = re.search(r"^room: (\S+) may", why)
    if m:
        return f"room {m.group(1)}"
    m = re.search(r"^units (\S+) and (\S+) include each other", why)
    if m:
        return f"units {m.group(1)} {m.group(2)}"
    return re.search(r"may not include (\w+)/", why).group(1)


def self_test():
    """The checker must find a violation of each kind (layers, rooms, units that include each
    other), and nothing in allowed includes."""
    files = {
        "core/pose2.hpp": '#include <Eigen/Core>\n#include "core/angles.hpp"\n',
        "core/angles.hpp": "",
        "core/bad.cpp": '#include "../harness/runner.hpp"\n',                  # relative path upwards
        "sim/world.hpp": '#include "core/pose2.hpp"\n#include <box2d/box2d.h>\n',
        "localization/mcl.cpp": '#include "mcl.hpp"\n  #  include "sim/world.hpp"\n',  # the rule of rules
        "localization/mcl.hpp": '// #include "sim/world.hpp" is only a comment\n',
        "localization/vision/blobs.cpp": '#include "localization/mcl.hpp"\n#include <sim/world.hpp>\n',
        "harness/runner.hpp": '#include "sim/world.hpp"\n#include "localization/mcl.hpp"\n#include "testing/scenes.hpp"\n',
        "harness/version.cpp": '#include "omniloc_version.hpp"\n',              # generated: not a layer
        "experiments/maps.cpp": '#include "harness/runner.hpp"\n#include "apps/main.cpp"\n',
        "testing/scenes.hpp": '#include "harness/runner.hpp"\n#include "bench/x.hpp"\n',
        "apps/main.cpp": '#include "experiments/maps.cpp"\n#include "testing/scenes.hpp"\n',
        "tests/a_test.cpp": '#include "testing/scenes.hpp"\n#include "apps/main.cpp"\n',  # not scanned
        # Rooms inside harness/.
        "harness/frame_data.hpp": "",
        "harness/events.hpp": "",
        "harness/run_record.hpp": "",
        "harness/simulation.hpp": "",
        "harness/recording/format/header.hpp": '#include "harness/frame_data.hpp"\n#include "core/pose2.hpp"\n',
        "harness/recording/format/header.cpp": '#include "header.hpp"\n#include "harness/recording/writer.hpp"\n',
        "harness/recording/writer.hpp": "",
        "harness/recording/format/codec.cpp": '#include "../source.hpp"\n#include "harness/simulation.hpp"\n',
        "harness/recording/source.hpp": '#include "harness/recording/format/header.hpp"\n#include "harness/simulation.hpp"\n',
        "harness/recording/source.cpp": '#include "harness/cache/world_cache.hpp"\n',
        "harness/scoring/metrics.hpp": '#include "harness/events.hpp"\n#include "harness/run_record.hpp"\n',
        "harness/scoring/metrics.cpp": '#include "harness/scoring/metrics.hpp"\n#include "harness/simulation.hpp"\n',
        "harness/cache/world_cache.hpp": '#include "harness/recording/writer.hpp"\n#include "harness/simulation.hpp"\n',
        "harness/cache/world_cache.cpp": '#include "harness/scoring/metrics.hpp"\n',
        # Units that include each other: a header each way, a source each way, a header-only unit.
        "sim/render/gl.hpp": '#include "sim/render/egl.hpp"\n',
        "sim/render/egl.hpp": "",
        "sim/render/egl.cpp": '#include "sim/render/egl.hpp"\n#include "gl.hpp"\n',
        "sim/motion.hpp": "",
        "sim/motion.cpp": '#include "sim/behaviour.hpp"\n',
        "sim/behaviour.hpp": '#include "sim/motion.hpp"\n',
        "localization/fix.hpp": '#include "localization/mcl.hpp"\n',  # mcl.hpp includes nothing: no pair
        "experiments/report.hpp": '#include "experiments/run.hpp"\n',
        "experiments/run.hpp": "",
        "experiments/run.cpp": '#include "experiments/report.hpp"\n',
    }
    expected = {
        ("core/bad.cpp", 1, "harness"),
        ("localization/mcl.cpp", 2, "sim"),
        ("localization/vision/blobs.cpp", 2, "sim"),
        ("harness/runner.hpp", 3, "testing"),
        ("experiments/maps.cpp", 2, "apps"),
        ("testing/scenes.hpp", 2, "bench"),
        ("apps/main.cpp", 2, "testing"),
        ("harness/recording/format/header.cpp", 2, "room harness/recording/format/"),
        ("harness/recording/format/codec.cpp", 1, "room harness/recording/format/"),  # "../source.hpp": where it lands
        ("harness/recording/format/codec.cpp", 2, "room harness/recording/format/"),
        ("harness/recording/source.cpp", 1, "room harness/recording/"),
        ("harness/scoring/metrics.cpp", 2, "room harness/scoring/"),
        ("harness/cache/world_cache.cpp", 1, "room harness/cache/"),
        ("experiments/report.hpp", 1, "units experiments/report experiments/run"),
        ("sim/behaviour.hpp", 1, "units sim/behaviour sim/motion"),
        ("sim/render/egl.cpp", 2, "units sim/render/egl sim/render/gl"),
        ("harness/runner.hpp", 3, "units harness/runner testing/scenes"),  # beside its layer breach
    }
    with tempfile.TemporaryDirectory() as root:
        for rel, text in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w", encoding="utf-8") as f:
                f.write(text)
        got = {(p, n, kind(why)) for p, n, _, why in violations(root)}
    if got != expected:
        print("check_layers self-test FAILED")
        for v in sorted(expected - got):
            print("  missed:", v)
        for v in sorted(got - expected):
            print("  wrongly reported:", v)
        return 1
    print(f"check_layers self-test: ok ({len(expected)} planted violations found, no false reports)")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if argv[1:] in (["-h"], ["--help"]):
        print(__doc__)
        return 0
    if len(argv) > 2 or (len(argv) == 2 and argv[1].startswith("-")):
        print(__doc__, file=sys.stderr)
        return 2
    root = argv[1] if len(argv) == 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    return check(root)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
