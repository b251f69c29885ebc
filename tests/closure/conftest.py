"""The closure tests import their synthetic results (closure_fakes.py) by name; pytest runs with
--import-mode=importlib, which does not put test folders on sys.path, so this folder is added here."""

import sys
from pathlib import Path

HERE = str(Path(__file__).resolve().parent)
if HERE not in sys.path:
    sys.path.insert(0, HERE)
