"""The layers of an infinite-array study: the spec's ``stack`` and its ``stack.…`` axes.

A study of a cell on a substrate gives the layers once, in the spec's ``stack`` key, in
either form that :mod:`barymesh.mom.stack` reads: the command line's text
(``"1.575mm eps=2.2 tand=0.0009; ground"``, :func:`barymesh.mom.parse_stack`) or the
mapping of :meth:`barymesh.mom.Stack.to_dict`. An axis varies one value of one layer by
its path, ``stack.below[0].thickness`` (mm), ``stack.below[0].eps_r``,
``stack.above[1].loss_tangent``, ``stack.below[0].mu_r``: ``above`` and ``below`` are
the stack's two lists (top first), the index a layer of that list.

Errors here are plain ``ValueError`` / ``TypeError`` messages; the spec
(:mod:`barymesh.study.spec`) adds the key they belong to.

>>> stack = study_stack("1.575mm eps=2.2; ground")
>>> layer_field(("stack", "below", 0, "eps_r"), stack)
('below', 0, 'eps_r')
>>> point_stack(stack, {"stack.below[0].eps_r": 4.4}).describe()
'1.575mm eps=4.4; ground'
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..mom.stack import Stack, parse_stack
from ..values import kind

#: The values of a layer an axis can vary (the fields of :class:`barymesh.mom.Layer`).
LAYER_FIELDS = ("thickness", "eps_r", "loss_tangent", "mu_r")
#: The first name of a stack axis's path.
STACK_PREFIX = "stack."


def study_stack(raw: Any) -> Stack:
    """The :class:`~barymesh.mom.Stack` of a spec's ``stack`` value (text or mapping)."""
    if isinstance(raw, str):
        return parse_stack(raw)
    if isinstance(raw, Mapping):
        return Stack.from_dict(raw)
    raise TypeError(
        f"{kind(raw)} {raw!r:.40}; expected the command line's text, e.g. "
        '"1.575mm eps=2.2 tand=0.0009; ground", or {"below": [{"thickness": 1.575, '
        '"eps_r": 2.2}], "ground": true}'
    )


def is_stack_path(path: str) -> bool:
    """True for an axis path into the stack (``stack.below[0].thickness``)."""
    return path.startswith(STACK_PREFIX)


def layer_field(tokens: tuple[str | int, ...], stack: Stack | None) -> tuple[str, int, str]:
    """(side, index, field) of a stack axis's parsed path, checked against ``stack``.

    Raises
    ------
    ValueError
        Not ``stack.above[i].FIELD`` or ``stack.below[i].FIELD``, a layer the stack
        does not have, or a field a layer does not have.
    """
    if len(tokens) < 2 or tokens[1] not in ("above", "below"):
        raise ValueError(
            "expected stack.above[i].FIELD or stack.below[i].FIELD (FIELD one of "
            f"{', '.join(LAYER_FIELDS)})"
        )
    side = str(tokens[1])
    if len(tokens) < 3 or not isinstance(tokens[2], int):
        raise ValueError(f"expected a layer index after stack.{side}, e.g. stack.{side}[0]")
    index = tokens[2]
    layers = () if stack is None else getattr(stack, side)
    if index >= len(layers):
        given = "the spec gives no stack" if stack is None else stack.describe() or "no layer"
        raise ValueError(
            f"the stack has {len(layers)} layer(s) {side} the sheet, so no "
            f"{side}[{index}] ({given})"
        )
    if len(tokens) != 4 or tokens[3] not in LAYER_FIELDS:
        shown = ".".join(str(t) for t in tokens[3:]) or "nothing"
        raise ValueError(
            f"a layer has no {shown!r}; expected stack.{side}[{index}].FIELD with FIELD one "
            f"of {', '.join(LAYER_FIELDS)}"
        )
    return side, index, str(tokens[3])


def point_stack(stack: Stack | None, values: Mapping[str, Any]) -> Stack | None:
    """The stack of one point: ``stack`` with each ``stack.…`` value of ``values`` set.

    Raises the :class:`~barymesh.mom.Layer`'s or the :class:`~barymesh.mom.Stack`'s
    ``ValueError`` / ``TypeError`` when a value makes the stack invalid.
    """
    for path, value in values.items():
        if is_stack_path(path):
            if stack is None:
                raise ValueError(f"{path}: the spec gives no stack")
            stack = stack.replaced(path[len(STACK_PREFIX) :], value)
    return stack
