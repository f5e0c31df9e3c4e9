"""The tutorial script of docs/python.md runs as a reader runs it."""

import subprocess
import sys
from pathlib import Path


def test_the_tutorial_runs(tmp_path):
    """docs/python/tutorial.py, as a reader runs it, with 5 keyframes."""
    script = Path(__file__).resolve().parents[2] / "docs" / "python" / "tutorial.py"
    run = subprocess.run([sys.executable, str(script), str(tmp_path), "5"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "margins grow more: midrib" in run.stdout
    assert (tmp_path / "petal-1.glb").read_bytes()[:4] == b"glTF"
    assert (tmp_path / "project" / "lily-margins.anthesis.toml").is_file()
