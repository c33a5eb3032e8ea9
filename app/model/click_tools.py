"""Which of the 3D view's click tools are on, and so where a click goes (no Qt).

The RWG inspector and the connectivity matrix pick triangles (through the view's picker),
the measure tool takes the clicks from them while it is on, and the drag tool takes a
press on a unit cell's element. With none of them on, a click selects what is under it.
The Teach tools, the View tools and the drag tool share one :class:`ClickTools`; their
actions and the picker follow it.

>>> clicks = ClickTools()
>>> clicks.click_goes_to()
'select'
>>> clicks.set_on("inspector", True), clicks.picking, clicks.click_goes_to()
(True, True, 'picker')
>>> clicks.set_on("measure", True), clicks.click_goes_to()
(True, 'measure')
>>> clicks.set_on("inspector", True)   # already on: nothing changes
False
"""

from __future__ import annotations

from barymesh.app.model.events import Event

#: The click tools, by name.
CLICK_TOOLS = ("inspector", "matrix", "measure", "drag")


class ClickTools:
    """The on/off state of each of :data:`CLICK_TOOLS`.

    Events: ``changed(tool, on)`` when a tool is switched.
    """

    def __init__(self) -> None:
        self.on: dict[str, bool] = dict.fromkeys(CLICK_TOOLS, False)
        self.changed = Event()

    def _check(self, tool: str) -> None:
        if tool not in self.on:
            raise ValueError(f"tool={tool!r} is unknown; expected one of {', '.join(CLICK_TOOLS)}")

    def is_on(self, tool: str) -> bool:
        self._check(tool)
        return self.on[tool]

    def set_on(self, tool: str, on: bool) -> bool:
        """Switch ``tool`` on or off; whether that changed anything."""
        self._check(tool)
        on = bool(on)
        if self.on[tool] == on:
            return False
        self.on[tool] = on
        self.changed.emit(tool, on)
        return True

    @property
    def picking(self) -> bool:
        """Whether a Teach tool (inspector, matrix) picks triangles: the picker is enabled."""
        return self.on["inspector"] or self.on["matrix"]

    @property
    def measuring(self) -> bool:
        """Whether the measure tool is on: it takes the clicks, the picker is suspended."""
        return self.on["measure"]

    def click_goes_to(self) -> str:
        """Who gets a click in the view: ``"measure"``, ``"picker"`` or ``"select"``.

        (The drag tool takes a press on an element before any of them, and a press
        elsewhere goes on to these.)
        """
        if self.measuring:
            return "measure"
        if self.picking:
            return "picker"
        return "select"
