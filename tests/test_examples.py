"""Every script in examples/ runs, and says what it should."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run(script: str, *args: str, cwd: Path) -> str:
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=cwd,
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_every_example_is_tested():
    assert {p.name for p in EXAMPLES.glob("*.py")} == {
        "random_walk.py", "my_strategy.py", "coverage_plot.py"}


def test_a_user_controller_runs_on_points_and_mujoco_and_is_recorded(tmp_path):
    out = run("random_walk.py", "--robots", "6", "--seconds", "8", "--out", str(tmp_path),
              cwd=tmp_path)
    assert "point: 8 s simulated" in out and "mujoco: 8 s simulated" in out
    assert "0 contacts" in out
    for world in ("point", "mujoco"):
        assert (tmp_path / f"random_walk_{world}.rrd").stat().st_size > 10_000


def test_a_user_strategy_explores_both_worlds(tmp_path):
    out = run("my_strategy.py", "--arena", "fig9", cwd=tmp_path)
    assert "graph world:    completed=True, map correct=True" in out
    assert "embodied world: completed=True, map correct=True" in out and "0 contacts" in out


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_an_experiment_run_from_python_is_plotted(tmp_path, suffix):
    target = tmp_path / f"coverage{suffix}"
    out = run("coverage_plot.py", "--episodes", "4", "--out", str(target), cwd=tmp_path)
    assert "cr 2: mean S-coverage" in out and target.stat().st_size > 5_000


def test_examples_run_from_any_directory_and_write_where_they_say(tmp_path):
    """From another directory the default output goes to the repository's recordings/
    folder (neither a failure nor a file in the working directory)."""
    target = EXAMPLES.parent / "recordings" / "coverage.png"
    existed = target.exists()
    before = target.stat().st_mtime_ns if existed else None
    out = run("coverage_plot.py", "--episodes", "2", cwd=tmp_path)
    try:
        assert f"plot: {target}" in out and target.stat().st_mtime_ns != before
        assert list(tmp_path.iterdir()) == []  # nothing left in the working directory
    finally:
        if not existed:
            target.unlink(missing_ok=True)
