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


#: mjswarm's layers, bottom up; a module may import its own layer's modules and those of
#: the layers below. Experiments and outputs sit side by side: neither imports the other.
LAYERS = {"errors": 0, "core": 1, "arena": 1, "worlds": 2, "experiments": 3, "outputs": 3,
          "cli": 4}


def _mjswarm_imports(path: Path) -> list[str]:
    """The mjswarm modules ``path`` imports (at any depth of the file, type-only ones
    included)."""
    import ast

    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.append(node.module)
        elif isinstance(node, ast.Import):
            found += [a.name for a in node.names]
    return [m for m in found if m.startswith("mjswarm.")]


def test_mjswarm_layers_import_downwards_only():
    """Core, then worlds, then experiments and outputs side by side, then the
    CLI; the layer of a module is its first package under mjswarm/."""
    root = Path(algorithms.__file__).resolve().parents[1] / "mjswarm"
    bad = []
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[0] not in LAYERS:
            continue  # mjswarm/__init__.py and __main__: the package itself
        mine = LAYERS[parts[0]]
        for module in _mjswarm_imports(path):
            other = module.split(".")[1]
            if other == parts[0] or other not in LAYERS:
                continue
            if LAYERS[other] > mine or (LAYERS[other] == mine and mine != 1):
                bad.append(f"{'/'.join(parts)} imports {module}")
    assert not bad, bad


def test_importing_an_experiment_does_not_import_rerun():
    code = ("import sys\n"
            "import mjswarm.experiments.exploration, mjswarm.experiments.patrol\n"
            "import mjswarm.experiments.coverage, mjswarm.experiments.sweep\n"
            "assert 'rerun' not in sys.modules, 'rerun imported'\n")
    root = Path(algorithms.__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True,
                          text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
