"""A linear undo history of immutable states (no Qt): the pixel painter's strokes and edits.

>>> h = UndoHistory("a")
>>> h.push("b"), h.push("b"), h.push("c")
(True, False, True)
>>> h.undo(), h.undo(), h.undo(), h.current
('b', 'a', None, 'a')
>>> h.push("d"), h.states, h.can_redo   # a new state drops what could be redone
(True, ['a', 'd'], False)
"""

from __future__ import annotations

from typing import Generic, TypeVar

T = TypeVar("T")


class UndoHistory(Generic[T]):
    """States ``states[: position + 1]`` were done, ``states[position + 1 :]`` can be redone.

    Parameters
    ----------
    first : T
        The state a new document starts in (not undoable).
    """

    def __init__(self, first: T) -> None:
        self.states: list[T] = [first]
        self.position = 0

    @property
    def current(self) -> T:
        return self.states[self.position]

    @property
    def previous(self) -> T | None:
        """The state an :meth:`undo` would go back to, or None."""
        return self.states[self.position - 1] if self.position > 0 else None

    @property
    def can_undo(self) -> bool:
        return self.position > 0

    @property
    def can_redo(self) -> bool:
        return self.position < len(self.states) - 1

    def __len__(self) -> int:
        return len(self.states)

    def reset(self, first: T) -> None:
        """A new document: ``first`` and nothing to undo or redo."""
        self.states = [first]
        self.position = 0

    def push(self, state: T) -> bool:
        """Make ``state`` the current one, one undo step, dropping what could be redone;
        False (and nothing changes) when it equals the current state."""
        if state == self.current:
            return False
        del self.states[self.position + 1 :]
        self.states.append(state)
        self.position += 1
        return True

    def undo(self) -> T | None:
        """Go back one step; the state now current, or None when there is nothing to undo."""
        if not self.can_undo:
            return None
        self.position -= 1
        return self.current

    def redo(self) -> T | None:
        """Go forward one step; the state now current, or None when there is nothing to redo."""
        if not self.can_redo:
            return None
        self.position += 1
        return self.current
