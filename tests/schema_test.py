"""`omniloc schema`: the JSON Schema of scenario files and the generated parameter
reference. The schema must accept every shipped scenario, reject misspelt keys and wrong types, and
agree with the strict reader (`omniloc validate`) on every parameter key it lists.

Run by ctest as `schema_py` with OMNILOC_BIN set (Debian's python3 with python3-jsonschema)."""
import copy
import glob
import json
import os
import subprocess
import tempfile
import unittest

import jsonschema

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("OMNILOC_BIN", os.path.join(ROOT, "build", "omniloc"))


def omniloc(*args):
    return subprocess.run([BIN, *args], cwd=ROOT, capture_output=True, text=True)


def shipped_scenarios():
    out = []
    for f in sorted(glob.glob(os.path.join(ROOT, "scenarios", "**", "*.json"), recursive=True)):
        with open(f) as fh:
            j = json.load(fh)
        if isinstance(j, dict) and "robots" in j and "experiment" not in j:
            out.append((os.path.relpath(f, ROOT), j))
    return out


BASE = {"robots": [{"start": [0.0, 0.0, 0.0]}], "duration": 1.0}


class Schema(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        r = omniloc("schema")
        assert r.returncode == 0, r.stderr
        cls.schema = json.loads(r.stdout)
        jsonschema.Draft202012Validator.check_schema(cls.schema)
        cls.validator = jsonschema.Draft202012Validator(cls.schema)

    def errors(self, doc):
        return [list(e.absolute_path) for e in self.validator.iter_errors(doc)]

    def validate_cli(self, doc):
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as fh:
            json.dump(doc, fh)
        try:
            return omniloc("validate", fh.name).returncode
        finally:
            os.unlink(fh.name)

    def test_every_shipped_scenario_is_valid(self):
        found = shipped_scenarios()
        self.assertGreaterEqual(len(found), 10)
        for name, doc in found:
            with self.subTest(name):
                self.assertEqual(self.errors(doc), [])

    def test_misspelt_keys_and_wrong_types_are_flagged(self):
        cases = {
            "top-level typo": ({"duraton": 3}, []),
            "robot typo": ({"robots": [{"start": [0, 0, 0], "strat": 1}]}, ["robots", 0]),
            "localizer parameter typo": ({"localizer": {"type": "mcl", "particle": 10}}, ["localizer"]),
            "parameter of another localizer": ({"localizer": {"type": "matching", "particles": 10}}, ["localizer"]),
            "unknown localizer": ({"localizer": {"type": "magic"}}, ["localizer", "type"]),
            "parameter as a string": ({"localizer": {"type": "mcl", "particles": "many"}}, ["localizer", "particles"]),
            "parameter out of range": ({"localizer": {"type": "mcl", "particles": 5}}, ["localizer", "particles"]),
            "nested matching typo": ({"localizer": {"type": "hybrid", "matching": {"cc": 1}}}, ["localizer", "matching"]),
            "scan-line typo": ({"vision": {"scan_lines": {"ray": 10}}}, ["vision", "scan_lines"]),
            "unknown event": ({"events": [{"type": "explode", "t": 1}]}, ["events", 0, "type"]),
            "unknown noise profile": ({"noise_profile": "noisy"}, ["noise_profile"]),
            "odometry typo": ({"robots": [{"start": [0, 0, 0], "odometry": {"trans": 0.1}}]}, ["robots", 0, "odometry"]),
        }
        for name, (patch, path) in cases.items():
            with self.subTest(name):
                doc = copy.deepcopy(BASE)
                doc.update(patch)
                errs = self.errors(doc)
                self.assertTrue(errs, "the schema accepted it")
                self.assertIn(path, errs)
                self.assertEqual(self.validate_cli(doc), 2, "the reader must reject it too")

    def test_reader_accepts_every_listed_parameter(self):
        # Each localizer's keys at their schema defaults: what the schema lists, the reader reads.
        cases = self.schema["properties"]["localizer"]["allOf"]
        self.assertGreaterEqual(len(cases), 5)
        for case in cases:
            props = case["then"]["properties"]
            doc = copy.deepcopy(BASE)
            doc["localizer"] = {"type": props["type"]["const"]}
            for key, s in props.items():
                if "default" in s:
                    doc["localizer"][key] = s["default"]
            for key in case["then"].get("required", []):  # external: the client program (docs/protocol.md)
                if key == "command":
                    doc["localizer"]["command"] = ["/usr/bin/perl", os.path.join(ROOT, "tests", "protocol_clients", "perl_dead_reckoning.pl")]
            with self.subTest(doc["localizer"]["type"]):
                self.assertEqual(self.errors(doc), [])
                self.assertEqual(self.validate_cli(doc), 0)

    def test_parameter_reference_is_up_to_date(self):
        r = omniloc("schema", "--markdown")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(ROOT, "docs", "localizers.md")) as fh:
            self.assertEqual(fh.read(), r.stdout, "docs/localizers.md is stale: build/omniloc schema --markdown -o docs/localizers.md")


if __name__ == "__main__":
    unittest.main()
