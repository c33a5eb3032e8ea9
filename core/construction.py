"""Moved to :mod:`barymesh.teach.construction`; this old name is the same module (scripts that
import it keep working)."""

import importlib
import sys

sys.modules[__name__] = importlib.import_module("barymesh.teach.construction")
