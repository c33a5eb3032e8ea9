"""Shell completion of ``barymesh`` (bash, zsh, tcsh, fish), made by shtab from the parser.

::

    barymesh --print-completion bash > ~/.local/share/bash-completion/completions/barymesh
    barymesh --print-completion zsh > ~/.zfunc/_barymesh     # a folder on $fpath

The script is generated from :func:`barymesh.app.cli.build_parser`, so it knows every
subcommand and option of this version. Options that name files complete file names
(``-o``, ``--params``, ``--cell``, ``--mesh``, ``info FILE``, ``study SPEC.json``), and
``--preset`` and ``--cell-preset`` complete the names of the shipped presets.
"""

from __future__ import annotations

import argparse

#: Metavars of the arguments that name a file (completed with the shell's file names).
FILE_METAVARS = frozenset(
    {"FILE", "FILE.json", "FILE.cell.json", "OUT", "PNG", "PATH", "PATH|-", "SPEC.json"}
)
#: The shells shtab writes for.
SHELLS = ("bash", "zsh", "tcsh", "fish")


def _walk(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """Every action of ``parser`` and of its subcommands' parsers."""
    actions = []
    for action in parser._actions:
        actions.append(action)
        if isinstance(action, argparse._SubParsersAction):
            for sub in dict.fromkeys(action.choices.values()):  # aliases share a parser
                actions += _walk(sub)
    return actions


def _preamble(presets: list[str], cells: list[str]) -> dict[str, str]:
    """Shell functions listing the preset names (bash, zsh), named in ``complete``."""
    return {
        "bash": (
            f'_barymesh_presets() {{ compgen -W "{" ".join(presets)}" -- "$1"; }}\n'
            f'_barymesh_cell_presets() {{ compgen -W "{" ".join(cells)}" -- "$1"; }}\n'
        ),
        "zsh": (
            f"_barymesh_presets() {{ compadd -- {' '.join(presets)} }}\n"
            f"_barymesh_cell_presets() {{ compadd -- {' '.join(cells)} }}\n"
        ),
    }


def add_completion(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Mark the file and preset arguments of ``parser`` and add ``--print-completion``.

    Returns ``parser``.
    """
    import shtab

    from barymesh.cell import cell_preset_names
    from barymesh.presets import preset_names

    presets = {"bash": "_barymesh_presets", "zsh": "_barymesh_presets"}
    cells = {"bash": "_barymesh_cell_presets", "zsh": "_barymesh_cell_presets"}
    for action in _walk(parser):
        if "--preset" in action.option_strings:
            action.complete = presets  # type: ignore[attr-defined]
        elif "--cell-preset" in action.option_strings:
            action.complete = cells  # type: ignore[attr-defined]
        elif action.metavar in FILE_METAVARS:
            action.complete = shtab.FILE  # type: ignore[attr-defined]
    shtab.add_argument_to(
        parser,
        "--print-completion",
        help=f"print the shell completion script for {', '.join(SHELLS)} and exit",
        preamble=_preamble(preset_names(), cell_preset_names()),
    )
    return parser
