"""Tests may import the study scripts (``studies/<name>.py``) by their module names."""

import sys
from pathlib import Path

STUDIES = Path(__file__).resolve().parents[1] / "studies"
if str(STUDIES) not in sys.path:
    sys.path.insert(0, str(STUDIES))
