#!/usr/bin/env python3
"""The results package's type check (ctest results_mypy) gives the same answer whatever typing Pillow,
numpy and matplotlib carry on the machine: Debian's Pillow 9.4 has none, numpy 1.24 some, and a
pip-installed library or a stub package (types-Pillow, numpy 2) other. Once the check followed them,
and an ignore comment that a typed Pillow needed was an "unused ignore" error on a fresh Debian 12.

Here stub packages for the three, placed first on MYPYPATH (ahead of site-packages), declare nothing:
any use of them that the check followed would be an error. python/mypy.ini must make them Any, so the
check passes; the same stubs with the third-party section's follow_imports lines taken out must fail
(which proves the stubs are read, so the first result means something). Exit 0 when both hold.
Usage: tests/mypy_third_party_test.py [SOURCE_DIR]   (default: this file's repository)
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

# An empty module for each: `Image.open`, `np.zeros`, `plt.subplots` are errors when followed.
STUBS = {
    "PIL/__init__.pyi": "",
    "PIL/Image.pyi": "",
    "numpy/__init__.pyi": "",
    "matplotlib/__init__.pyi": "",
    "matplotlib/pyplot.pyi": "",
}
# Checked beside the package: one use of each library, so the control run below shows that each stub
# was read, whatever the package itself happens to use.
PROBE = """from PIL import Image
import numpy as np
import matplotlib.pyplot as plt

im = Image.open("x.png")
a = np.zeros(3)
fig = plt.figure()
"""
PROBE_NAMES = {"PIL": "open", "numpy": "zeros", "matplotlib": "figure"}


def run_mypy(src: Path, config: Path, stubs: Path, probe: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, MYPYPATH=str(stubs), PYTHONDONTWRITEBYTECODE="1")
    return subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(config), str(src / "python/omniloc"),
                           str(probe)], cwd=src, env=env, capture_output=True, text=True)


def main() -> int:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent)
    config = src / "python/mypy.ini"
    with tempfile.TemporaryDirectory(prefix="omniloc-mypy-stubs.") as tmp:
        stubs = Path(tmp, "stubs")
        for rel, text in STUBS.items():
            (stubs / rel).parent.mkdir(parents=True, exist_ok=True)
            (stubs / rel).write_text(text)
        probe = Path(tmp, "third_party_probe.py")
        probe.write_text(PROBE)

        with_stubs = run_mypy(src, config, stubs, probe)
        print(f"mypy with empty typed stubs for {', '.join(sorted({k.split('/')[0] for k in STUBS}))} first on MYPYPATH:"
              f" exit {with_stubs.returncode}")
        print(with_stubs.stdout + with_stubs.stderr, end="")

        # The control: the same configuration, except that the third-party modules are followed.
        text = config.read_text()
        followed = re.sub(r"^follow_imports(_for_stubs)?\s*=.*\n", "", text, flags=re.M)
        if followed == text:
            print("FAIL: python/mypy.ini sets no follow_imports for the third-party modules")
            return 1
        control_ini = Path(tmp, "followed.ini")
        control_ini.write_text(followed)
        control = run_mypy(src, control_ini, stubs, probe)
        out = control.stdout + control.stderr
        print(f"control (third-party modules followed): exit {control.returncode}")
        print("\n".join(line for line in out.splitlines() if "third_party_probe" in line))

    ok = True
    if with_stubs.returncode != 0:
        print("FAIL: the check's result depends on the third-party libraries' typing")
        ok = False
    # Each library's stub must have been read by the control, or the first run proved nothing for it.
    for module, name in PROBE_NAMES.items():
        if not re.search(rf'third_party_probe\.py:\d+: error: Module has no attribute "{name}"', out):
            print(f"FAIL: the control run shows no error from the empty {module} stub (were the stubs read?)")
            ok = False
    if control.returncode != 1:
        print(f"FAIL: the control run should find errors (exit 1), got exit {control.returncode}")
        ok = False
    print("passed" if ok else "failed")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
