#!/usr/bin/env bash
# Debian/Ubuntu packages the desktop app and its GUI tests need beyond the Python wheels:
# a virtual X server (Xvfb), Mesa's software OpenGL (llvmpipe) through GLX and EGL, the X11
# libraries PySide6's xcb platform plugin links against, and a font.
# Installs whatever is missing when run as root; otherwise names it and fails.
# Fast no-op (a single dpkg-query) when everything is present.
set -euo pipefail

PACKAGES=(
    # virtual X server for `make test` (pytest-xvfb starts it)
    xvfb
    # OpenGL: libglvnd front ends + Mesa vendor libraries + the llvmpipe software driver.
    # EGL is what VTK uses for off-screen rendering when there is no X server at all.
    libgl1 libglx-mesa0 libegl1 libegl-mesa0 libgl1-mesa-dri
    # X11 libraries VTK loads at run time (libX11.so.6, libXcursor.so.1)
    libx11-6 libxcursor1
    # PySide6 (Qt 6) xcb platform plugin, see `ldd .../PySide6/Qt/plugins/platforms/libqxcb.so`
    libx11-xcb1 libxcb1 libxcb-cursor0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1
    libxcb-randr0 libxcb-render0 libxcb-render-util0 libxcb-shape0 libxcb-shm0 libxcb-sync1
    libxcb-xfixes0 libxcb-xkb1 libxcb-glx0 libxkbcommon0 libxkbcommon-x11-0
    # rest of QtCore/QtGui/QtDBus
    libglib2.0-0 libdbus-1-3 libfontconfig1 libfreetype6
    # some font, or Qt and VTK draw no text
    fonts-dejavu-core
    # GNU OpenMP: the threading layer of the solver's compiled fill (numba); without it
    # numba falls back to its workqueue layer
    libgomp1
)
# Extra packages a make target needs beyond these, e.g. `make bench` (the gmsh wheel).
PACKAGES+=("$@")

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "system-deps: not a Debian-based system; install the equivalents of:" >&2
    echo "  ${PACKAGES[*]}" >&2
    exit 0
fi

missing=()
# One dpkg-query for all packages; unknown ones make it exit non-zero, hence `|| true`.
installed=$(dpkg-query -W -f='${Package} ${db:Status-Abbrev}\n' "${PACKAGES[@]}" 2>/dev/null || true)
for pkg in "${PACKAGES[@]}"; do
    if ! grep -qxF "$pkg ii " <<<"$installed"; then
        missing+=("$pkg")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
    echo "system-deps: missing Debian packages. Install them with:" >&2
    echo "  sudo apt-get install --no-install-recommends ${missing[*]}" >&2
    exit 1
fi

echo "system-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! { apt-get update -qq && apt-get install -y -qq --no-install-recommends "${missing[@]}"; } \
        >"$log" 2>&1; then
    cat "$log" >&2
    echo "system-deps: apt-get failed" >&2
    exit 1
fi
