#!/usr/bin/env python3
"""The layering rule of docs/architecture.md, checked on every #include (ctest: layering).

usage: check_layers.py [ROOT]      scan ROOT (default: the repository), exit 1 naming file:line of
                                   every include of a layer the including layer may not use
       check_layers.py --self-test a small tree with known violations must give exactly those

Includes are written from the source root ("sim/world.hpp"); a quoted include is first looked up
beside the including file, as the compiler does, so "../sim/x.hpp" and "x.hpp" are judged by where
they land. Headers of other projects (<Eigen/Core>, <GL/osmesa.h>) and generated headers
(omniloc_version.hpp) name no layer and are not judged.
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


def violations(root):
    """(file relative to root, line number, text, message) for every include the rule forbids."""
    root = os.path.abspath(root)
    found = []
    for layer in sorted(ALLOWED):
        top = os.path.join(root, layer)
        for dirpath, dirnames, filenames in os.walk(top):
            dirnames.sort()
            for fn in sorted(filenames):
                if not fn.endswith(SOURCE_EXT):
                    continue
                path = os.path.join(dirpath, fn)
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, text in enumerate(f, 1):
                        m = INCLUDE.match(text)
                        if not m:
                            continue
                        target = included_layer(root, path, m.group(1), m.group(2))
                        if target is None or target == layer or target in ALLOWED[layer]:
                            continue
                        may = ", ".join(sorted(ALLOWED[layer] | {layer}))
                        found.append((os.path.relpath(path, root), number, text.strip(),
                                      f"{layer}/ may not include {target}/ (it may include: {may})"))
    return found


def check(root):
    bad = violations(root)
    for path, number, text, why in bad:
        print(f"{path}:{number}: {text}: {why}")
    if bad:
        print(f"layering: {len(bad)} forbidden include(s); the rule is in docs/architecture.md", file=sys.stderr)
        return 1
    print("layering: ok")
    return 0


def self_test():
    """The checker must find a violation of each kind, and nothing in allowed includes."""
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
    }
    expected = {
        ("core/bad.cpp", 1, "harness"),
        ("localization/mcl.cpp", 2, "sim"),
        ("localization/vision/blobs.cpp", 2, "sim"),
        ("harness/runner.hpp", 3, "testing"),
        ("experiments/maps.cpp", 2, "apps"),
        ("testing/scenes.hpp", 2, "bench"),
        ("apps/main.cpp", 2, "testing"),
    }
    with tempfile.TemporaryDirectory() as root:
        for rel, text in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w", encoding="utf-8") as f:
                f.write(text)
        got = {(p, n, re.search(r"may not include (\w+)/", why).group(1)) for p, n, _, why in violations(root)}
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
