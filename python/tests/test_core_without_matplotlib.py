"""The core is read without matplotlib (like evo's core): every module of omniloc.core, and the
modules that judge results without drawing them (the paper's tables and claims, compare, gate,
global start), import and work in an interpreter where matplotlib cannot be imported at all.
"""
import subprocess
import textwrap

from helpers import PY

# Modules that must never need matplotlib, not even through another module they import.
WITHOUT_PLOTS = ["omniloc.core.paths", "omniloc.core.rundir", "omniloc.core.pairing", "omniloc.core.stats", "omniloc.core.metrics",
                 "omniloc.core.aggregate", "omniloc.core.events", "omniloc.core.files", "omniloc.core.framedata", "omniloc.core.jsonvalue",
                 "omniloc.core.recording", "omniloc.core.runfiles", "omniloc.core.verdicts", "omniloc.core.viewlog", "omniloc.tools.citations",
                 "omniloc.paper.data", "omniloc.paper.labels", "omniloc.paper.tables", "omniloc.paper.quantity", "omniloc.paper.claims",
                 "omniloc.paper.causes", "omniloc.global_start", "omniloc.compare", "omniloc.gate"]

BLOCKED = textwrap.dedent("""
    import importlib.abc, sys

    class NoMatplotlib(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "matplotlib" or name.startswith("matplotlib."):
                raise ImportError(f"{name} is blocked: the core must not need it")
            return None

    sys.meta_path.insert(0, NoMatplotlib())
""")


def run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([PY, "-c", BLOCKED + textwrap.dedent(code)], capture_output=True, text=True, timeout=60)


def test_the_blocker_blocks():
    p = run("import matplotlib")
    assert p.returncode != 0 and "is blocked" in p.stderr


def test_core_imports_and_works_without_matplotlib(tmp_path):
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "summary.json").write_text('{"scenario": "tracking", "localizer": "mcl", "seed": 1, '
                                                   '"robots": [{"robot": 0, "x_cm": {"mean": 2.5}, "valid_fraction": 1.0}]}')
    p = run(f"""
        import importlib, sys
        for m in {WITHOUT_PLOTS!r}:
            importlib.import_module(m)
        from omniloc.core import metrics, pairing, rundir, stats
        runs, sweeps, experiments = rundir.discover([{str(tmp_path)!r}])
        assert [r.seed for r in runs] == [1] and not sweeps and not experiments
        assert metrics.run_stats(runs, "x_cm/mean").mean == 2.5
        assert stats.interval([1.0, 2.0, 3.0]).kind == stats.RANGE
        assert pairing.profile_of(runs[0]) == "robot"
        assert not any(k == "matplotlib" or k.startswith("matplotlib.") for k in sys.modules)
        print("ok")
    """)
    assert p.returncode == 0 and p.stdout.strip() == "ok", p.stderr
