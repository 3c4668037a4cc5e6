"""The one rule of the layout: ``algorithms/`` never imports MuJoCo (nor the simulator)."""

from __future__ import annotations

import pkgutil
import subprocess
import sys
from pathlib import Path

import algorithms

MODULES = sorted(m.name for m in pkgutil.walk_packages(algorithms.__path__, "algorithms."))


def test_every_algorithms_module_imports_without_mujoco():
    assert len(MODULES) > 20
    code = (
        "import sys\n"
        "sys.modules['mujoco'] = None  # any import of mujoco now fails\n"
        f"for name in {MODULES!r}:\n"
        "    __import__(name)\n"
        "bad = [m for m in sys.modules if m == 'mjswarm' or m.startswith('mjswarm.')]\n"
        "assert not bad, bad\n"
    )
    root = Path(algorithms.__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
