"""Moved to :mod:`barymesh.teach.rwg_basis`; this old name is the same module (scripts that
import it keep working)."""

import importlib
import sys

sys.modules[__name__] = importlib.import_module("barymesh.teach.rwg_basis")
