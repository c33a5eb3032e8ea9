"""The examples in the docstrings run, imported as users import them (``barymesh.*``).

pytest's ``--doctest-modules`` would import ``core/`` under the folder's name, ``core``, so
the same module would be loaded twice under two names; here every module of the installed
package is imported by its package name and its examples run with :mod:`doctest`.
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil

import pytest

import barymesh
import barymesh.app


def _modules(package) -> list[str]:
    names = [package.__name__]
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        if info.name.endswith("__main__") or info.name.startswith("barymesh.app") != (
            package is barymesh.app
        ):
            continue
        names.append(info.name)
    return sorted(names)


CORE = _modules(barymesh)
APP = _modules(barymesh.app)


def test_every_core_folder_is_walked():
    # the walk sees the subpackages (a broken walk would make the tests below vacuous)
    assert {"barymesh.cell", "barymesh.io", "barymesh.mom", "barymesh.mesh"} <= set(CORE)
    assert {"barymesh.app.cli", "barymesh.app.teach.inspector"} <= set(APP)


@pytest.mark.parametrize("name", CORE + APP)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    has_examples = ">>>" in inspect.getsource(module)
    result = doctest.testmod(module, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
    # a module whose source holds examples runs some (doctest finds every one it should)
    assert (result.attempted > 0) == has_examples
