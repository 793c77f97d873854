"""The repository's lint rules (``[tool.ruff]`` in pyproject.toml) hold on every change.

Ruff checks the package, the tests, the bundled robots and the documentation's scripts; any finding fails the test.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_check_is_clean():
    completed = subprocess.run([sys.executable, "-m", "ruff", "check", "screwkit", "tests", "robots", "docs"],
                               cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, f"ruff check failed:\n{completed.stdout}\n{completed.stderr}"
