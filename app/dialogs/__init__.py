"""The main window's dialogs (napari's ``_qt/dialogs``): each gets what it needs passed
in (settings, callables), not the window.

- :mod:`~barymesh.app.dialogs.screenshot_dialog`: File → Export screenshot;
- :mod:`~barymesh.app.dialogs.export_dialog`: File → Export mesh;
- :mod:`~barymesh.app.dialogs.help_dialog`: Help → About (F1).
"""
