"""Every key of every input file, every wrong JSON type: `omniloc validate` exits 2 and names the key's
JSON path (a sweep localizer's "label" of the wrong type once exited 1 with a raw library
message).

The keys come from walking the JSON Schemas omniloc publishes (`omniloc schema` for scenario files,
`omniloc schema --sweep` for sweep files): properties, array items, the per-localizer-type branches.
Each key is set, in a valid document that holds its parent object (a shipped file where one has it,
else one built from the schema's defaults), to each JSON type the schema does not allow there
(object, array, string, number, boolean, null), and must be rejected with exit 2 and an error that
names the key's path. A value the schema allows must still give 0 or 2, never anything else.

Run by ctest as `wrong_types_py` with OMNILOC_BIN set (Debian's python3 with python3-jsonschema)."""
import copy
import glob
import json
import os
import re
import shutil
import subprocess
import tempfile
import unittest

import jsonschema

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("OMNILOC_BIN", os.path.join(ROOT, "build", "omniloc"))

WRONG = {"object": {"x": 1}, "array": [1], "string": "x", "number": 1.5, "integer": 3, "boolean": True, "null": None}
BASE = {"robots": [{"start": [0.0, 0.0, 0.0]}], "duration": 1.0}
# Localizers whose nested objects hold keys of their own.
LOCALIZERS = {"hybrid": {"type": "hybrid", "matching": {}, "mcl": {}}, "grid_global": {"type": "grid_global", "matching": {}}}
EXTERNAL = {"type": "external", "command": ["/usr/bin/perl", os.path.join(ROOT, "tests", "protocol_clients", "perl_dead_reckoning.pl")]}


def omniloc(*args, cwd=ROOT):
    return subprocess.run([BIN, *args], cwd=cwd, capture_output=True, text=True)


def pointer(path):
    return "".join("/" + str(p).replace("~", "~0").replace("/", "~1") for p in path)


def key_patterns(schema, prefix=(), variant=None):
    """(pattern, variant) for every property the schema names: a pattern is a tuple of keys and '*'
    (any array index); variant is the {"type": X} its parent object must carry (per-type branches)."""
    if not isinstance(schema, dict):
        return
    for k, sub in schema.get("properties", {}).items():
        yield prefix + (k,), variant
        yield from key_patterns(sub, prefix + (k,))
    if isinstance(schema.get("items"), dict):
        yield from key_patterns(schema["items"], prefix + ("*",))
    for comb in ("allOf", "oneOf", "anyOf"):
        for branch in schema.get(comb, []):
            then = branch.get("then", branch)
            const = then.get("properties", {}).get("type", {}).get("const") if isinstance(then, dict) else None
            yield from key_patterns(then, prefix, {"type": const} if const else variant)


def locations(doc, pattern, at=()):
    """Concrete paths in `doc` that match `pattern` (every '*' an existing index)."""
    if not pattern:
        yield at
        return
    head, rest = pattern[0], pattern[1:]
    if head == "*":
        if isinstance(doc, list):
            for i, v in enumerate(doc):
                yield from locations(v, rest, at + (i,))
    elif isinstance(doc, dict) and head in doc:
        yield from locations(doc[head], rest, at + (head,))


def get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


class WrongTypes(unittest.TestCase):
    maxDiff = None

    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="omniloc_wrong_types_")
        # Sweeps name scenario files relative to themselves: their variants go beside a copy of them.
        shutil.copytree(os.path.join(ROOT, "scenarios"), os.path.join(cls.work, "scenarios"))
        for name in ("clients", "tests", "data"):
            os.symlink(os.path.join(ROOT, name), os.path.join(cls.work, name))
        os.symlink(os.path.dirname(os.path.abspath(BIN)), os.path.join(cls.work, "build"))
        # A tiny recording for the sweeps' {"recording": ...} entries (docs/recording.md).
        tiny = os.path.join(cls.work, "tiny.json")
        with open(tiny, "w") as fh:
            json.dump(dict(BASE, duration=0.1), fh)
        r = subprocess.run([BIN, "record", tiny, "-o", os.path.join(cls.work, "scenarios", "sweeps", "tiny_rec"), "--quiet"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)

    def schema(self, *args):
        r = omniloc("schema", *args)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = json.loads(r.stdout)
        jsonschema.Draft202012Validator.check_schema(s)
        return s

    def contexts(self, kind):
        """Valid documents of this kind: small ones made here first (a case is one validation, and a
        shipped sweep validates dozens of scenario combinations), then the shipped files."""
        docs, shipped = [], []
        for f in sorted(glob.glob(os.path.join(ROOT, "scenarios", "**", "*.json"), recursive=True)):
            with open(f) as fh:
                j = json.load(fh)
            is_sweep = os.sep + "sweeps" + os.sep in f
            if kind == "sweep" and is_sweep:
                shipped.append(j)
            elif kind == "scenario" and not is_sweep and isinstance(j, dict) and "robots" in j and "experiment" not in j:
                shipped.append(j)
        if kind == "scenario":
            for t in ["odometry_only", "matching", "mcl", "hybrid", "grid_global", "landmarks", "ukf_mh"]:
                docs.append(dict(BASE, localizer=LOCALIZERS.get(t, {"type": t})))
            docs.append(dict(BASE, localizer=dict(EXTERNAL)))
            docs.append(dict(BASE, lighting={"lamp_grid": {}}))
            docs.append(dict(BASE, lighting={"lamps": [{"centre": [0, 0]}], "sun": [{"centre": [0, 0]}]}, camera={},
                             vision={"blobs": {}, "exposure_control": {}, "scan_lines": {}},
                             robots=[{"start": [0, 0, 0], "odometry": {}, "heading": {}, "motion": {"type": "still"}}]))
            docs.append(dict(BASE, scoring={"recall": [{"position_m": 0.25, "heading_deg": 10}]}))
        else:
            docs.append({"scenarios": [{"file": "../paper/tracking.json", "localizers": [{"type": "mcl"}], "parameters": {"/duration": [1]}}],
                         "seeds": {"first": 1, "count": 1}})
            docs.append({"scenarios": ["../paper/tracking.json"], "localizers": [dict(EXTERNAL, label="x")]})
            docs.append({"scenarios": [{"file": "../paper/tracking.json", "localizers": list(LOCALIZERS.values())}]})
            docs.append({"scenarios": ["../paper/tracking.json"], "localizers": list(LOCALIZERS.values())})
            docs.append({"scenarios": [{"recording": "tiny_rec", "localizers": [{"type": "matching", "label": "m"}]}]})
        return docs + shipped

    def cases(self, schema, kind):
        """(document, path, value, schema says wrong) for every key and JSON type."""
        docs = self.contexts(kind)
        validator = jsonschema.Draft202012Validator(schema)
        out, uncovered = [], []
        seen = set()
        for pattern, variant in key_patterns(schema):
            if (pattern, json.dumps(variant)) in seen or pattern[-1] in ("comment", "description"):
                continue
            seen.add((pattern, json.dumps(variant)))
            parent = pattern[:-1]
            found = None
            # A parent object of the right variant, preferably one that holds the key already.
            for want_key in (True, False):
                for d in docs:
                    for loc in locations(d, parent):
                        p = get(d, loc)
                        if not isinstance(p, dict) or (variant and p.get("type") != variant["type"]):
                            continue
                        if want_key and pattern[-1] not in p:
                            continue
                        found = (d, loc)
                        break
                    if found:
                        break
                if found:
                    break
            if not found and variant:
                # No parent of this localizer type anywhere: one put in place of another localizer.
                for d in docs:
                    locs = [loc for loc in locations(d, parent) if isinstance(get(d, loc), dict)]
                    if locs:
                        d = copy.deepcopy(d)
                        minimal = dict(EXTERNAL) if variant["type"] == "external" else dict(variant)
                        if locs[0]:
                            get(d, locs[0][:-1])[locs[0][-1]] = minimal
                        found = (d, locs[0])
                        break
            if not found:
                uncovered.append(pointer(pattern))
                continue
            d, loc = found
            for tname, value in WRONG.items():
                doc = copy.deepcopy(d)
                get(doc, loc)[pattern[-1]] = value
                path = loc + (pattern[-1],)
                wrong = any(tuple(e.absolute_path)[:len(path)] == path for e in validator.iter_errors(doc))
                out.append((doc, pointer(path), tname, wrong))
        return out, uncovered

    def run_cases(self, cases, kind):
        """Writes every case and validates them in batches (omniloc validate forks per file)."""
        folder = os.path.join(self.work, "scenarios", "sweeps") if kind == "sweep" else self.work
        files = []
        for i, (doc, path, tname, wrong) in enumerate(cases):
            f = os.path.join(folder, f"wt_{kind}_{i:05d}.json")
            with open(f, "w") as fh:
                json.dump(doc, fh)
            files.append(f)
        verdicts = {}
        for b in range(0, len(files), 200):
            chunk = files[b:b + 200]
            r = subprocess.run([BIN, "validate", *chunk], cwd=self.work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=1800)
            text = ""
            for line in r.stdout.splitlines(keepends=True):
                m = re.match(r"\[(exit|signal) (\d+)\] (.*)\n?$", line)
                if m:
                    verdicts[m.group(3)] = (int(m.group(2)) if m.group(1) == "exit" else -int(m.group(2)), text)
                    text = ""
                else:
                    text += line
        for f in files:
            os.unlink(f)
        return [verdicts.get(f, (None, "no verdict")) for f in files]

    def check(self, kind, schema_args, min_keys):
        schema = self.schema(*schema_args)
        cases, uncovered = self.cases(schema, kind)
        keys = {c[1] for c in cases}
        print(f"{kind}: {len(keys)} keys x {len(WRONG)} JSON types = {len(cases)} documents; keys without a context: {uncovered}")
        self.assertGreaterEqual(len(keys), min_keys)
        self.assertEqual(uncovered, [], "keys of the schema no test document can hold")
        # The documents the cases start from are valid, so an error can only be the case's own.
        contexts = [(d, "", "context", False) for d in self.contexts(kind)]
        bad = [f"context document {i} is not valid: exit {code}: {text.strip()[:300]}"
               for i, (code, text) in enumerate(self.run_cases(contexts, kind)) if code != 0]
        for (doc, path, tname, wrong), (code, text) in zip(cases, self.run_cases(cases, kind)):
            if code not in (0, 2):
                bad.append(f"{path} = {tname}: exit {code}: {text.strip()[:300]}")
            elif wrong and code != 2:
                bad.append(f"{path} = {tname}: the schema rejects it, validate exited {code}")
            elif wrong and path not in text:
                bad.append(f"{path} = {tname}: the error does not name the path: {text.strip()[:300]}")
        self.assertEqual(bad, [])

    def test_scenario_keys(self):
        self.check("scenario", [], 200)

    def test_sweep_keys(self):
        self.check("sweep", ["--sweep"], 10)


if __name__ == "__main__":
    unittest.main()
