"""Shared pytest configuration.

GUI tests run in a real X11 window: pytest-xvfb starts Xvfb (size and depth are set in
pyproject.toml) and exports DISPLAY, Qt draws through its xcb platform plugin, and VTK renders
into Qt's GLX context with Mesa's software rasteriser (llvmpipe). The Debian packages this
needs are installed by scripts/system-deps.sh (run by `make test`).
"""

import os

# Before anything imports Qt: use Xvfb's X server, not Wayland (if the session has one) nor
# the `offscreen` platform, which would not exercise a real window. An explicit choice wins.
os.environ.setdefault("QT_QPA_PLATFORM", "xcb")
