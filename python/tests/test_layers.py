"""The import order of the results package (docs/architecture.md "The results package"), checked on
every import of every module, as scripts/check_layers.py checks the C++ includes (ctest layering):

    core  <-  tools  <-  compare, gate, global_start, data  <-  paper  <-  view  <-  report  <-  commands
                                                                          view  <-  export  <-  commands

A module may import its own layer and those its layer lists in ALLOWED, nothing else of the package;
imports inside functions and those for the type checker alone count as well. The third-party
libraries stay where they are needed when the code runs (imports for the type checker alone, under
`if TYPE_CHECKING:`, do not count): matplotlib in tools.plot alone, PIL in tools.images alone, numpy
in data and the report's real robots section. Plain python3, run by pytest (ctest results_pytest).
"""
import ast
import pathlib
import textwrap

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "omniloc"

# The layer of a module: its subpackage, or the top-level module's own name for the three judges.
JUDGES = {"compare", "gate", "global_start"}
ALLOWED = {
    "core": set(),
    "tools": {"core"},  # the writer cites and draws; it judges nothing
    "judges": {"core"},  # compare, gate, global_start (gate pairs groups as compare does)
    "data": {"core"},  # NuBot's frames and the reference-pose search
    "paper": {"core", "tools", "judges"},  # the papers' tables and claims (a claim may read a global-start row)
    "view": {"core", "tools"},  # the run viewer
    "report": {"core", "tools", "judges", "data", "paper", "view"},  # the report, and the terminal's paper tables
    "export": {"core", "view"},  # MCAP for Foxglove: the run as the viewer loads it
    "commands": {"core", "tools", "judges", "data", "paper", "view", "report", "export"},
}
# Third-party modules and the only modules that may import them.
THIRD_PARTY = {"matplotlib": {"omniloc.tools.plot"}, "PIL": {"omniloc.tools.images"},
               "numpy": {"omniloc.data.nubot", "omniloc.data.nubot_frames", "omniloc.report.real_robots"},
               "lz4": {"omniloc.export.mcap"}}


def layer_of(module):
    """The layer of a module named omniloc.<...>, or None for the package itself."""
    parts = module.split(".")
    if len(parts) < 2:
        return None
    return "judges" if parts[1] in JUDGES else parts[1]


def module_name(path, root):
    rel = path.relative_to(root.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def is_module(name, root):
    """Whether `name` (dotted) is a module or subpackage of the package at root."""
    path = root.parent.joinpath(*name.split("."))
    return path.is_dir() or path.with_suffix(".py").is_file()


def typing_only(tree):
    """The nodes under `if TYPE_CHECKING:`: imports for the type checker, never run."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            out |= {id(n) for stmt in node.body for n in ast.walk(stmt)}
    return out


def imports(path, module, root, runtime_only=False):
    """(line, imported module) of every import in the file, relative imports resolved; `from a import b`
    counts as a.b where a.b is a module of the package, else as a. runtime_only: without the imports
    under `if TYPE_CHECKING:`."""
    tree = ast.parse(path.read_text(), str(path))
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    skip = typing_only(tree) if runtime_only else set()
    out = []
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            out += [(node.lineno, f"{base}.{a.name}" if is_module(f"{base}.{a.name}", root) else base) for a in node.names]
    return out


def violations(root):
    """'file:line: what' for every import the order forbids, and for every module outside the layers."""
    found = []
    for path in sorted(root.rglob("*.py")):
        module = module_name(path, root)
        layer = layer_of(module)
        if layer is None:
            continue
        if layer not in ALLOWED:
            found.append(f"{path.relative_to(root.parent)}: {module} is in no layer (add it to ALLOWED)")
            continue
        run = set(imports(path, module, root, runtime_only=True))
        for line, name in imports(path, module, root):
            top = name.split(".")[0]
            where = f"{path.relative_to(root.parent)}:{line}"
            if top in THIRD_PARTY and module not in THIRD_PARTY[top] and (line, name) in run:
                found.append(f"{where}: {module} imports {top}, which only {', '.join(sorted(THIRD_PARTY[top]))} may")
            if top != root.name:
                continue
            target = layer_of(name)
            if target is None or target == layer:
                continue
            if target not in ALLOWED[layer]:
                found.append(f"{where}: {module} ({layer}) imports {name} ({target})")
    return found


def test_the_package_keeps_its_import_order():
    assert violations(PACKAGE) == []


def test_the_core_imports_nothing_of_the_package_beyond_itself():
    # The strictest rule on its own: the core reads and computes, everything else builds on it.
    for path in sorted((PACKAGE / "core").rglob("*.py")):
        names = [n for _, n in imports(path, module_name(path, PACKAGE), PACKAGE)]
        assert all(not n.startswith("omniloc.") or n.startswith("omniloc.core") for n in names), (path, names)


def test_the_check_finds_what_it_must(tmp_path):
    # A small package with one import of each forbidden kind; the check must name exactly these.
    root = tmp_path / "omniloc"
    files = {
        "__init__.py": "",
        "core/__init__.py": "",
        "core/a.py": "from omniloc.tools import markup\n",  # core above itself
        "core/b.py": "from . import a\nimport json\n",  # allowed: its own layer, the standard library
        "tools/__init__.py": "",
        "tools/markup.py": "def f():\n    from omniloc.paper import data\n",  # inside a function: still counts
        "tools/plot.py": "import matplotlib\n",  # allowed
        "tools/images.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import matplotlib\n",  # allowed: never run
        "paper/__init__.py": "",
        "paper/data.py": "from ..report import x\nimport matplotlib.pyplot\n",  # relative import upwards; matplotlib
        "report/__init__.py": "",
        "report/x.py": "from omniloc import gate\nfrom omniloc.view import page\n",  # allowed
        "gate.py": "from omniloc.paper import data\n",  # a judge above itself
        "extra/__init__.py": "",  # a layer nobody listed
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(textwrap.dedent(text))
    found = violations(root)
    assert found == [
        "omniloc/core/a.py:1: omniloc.core.a (core) imports omniloc.tools.markup (tools)",
        "omniloc/extra/__init__.py: omniloc.extra is in no layer (add it to ALLOWED)",
        "omniloc/gate.py:1: omniloc.gate (judges) imports omniloc.paper.data (paper)",
        "omniloc/paper/data.py:1: omniloc.paper.data (paper) imports omniloc.report.x (report)",
        "omniloc/paper/data.py:2: omniloc.paper.data imports matplotlib, which only omniloc.tools.plot may",
        "omniloc/tools/markup.py:2: omniloc.tools.markup (tools) imports omniloc.paper.data (paper)",
    ], found
