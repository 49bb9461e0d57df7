"""pytest's set-up for the results package's tests (python/tests): the commands a test runs as
`python3 -m omniloc.commands.X` find the package through PYTHONPATH, whatever the caller set."""
import os
import pathlib

PACKAGE_ROOT = pathlib.Path(__file__).resolve().parents[1]  # <share>/python
if str(PACKAGE_ROOT) not in os.environ.get("PYTHONPATH", "").split(os.pathsep):
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(PACKAGE_ROOT), os.environ.get("PYTHONPATH", "")) if p)
