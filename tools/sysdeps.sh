#!/usr/bin/env bash
# Install the system libraries Skinlab needs (Mesa EGL/llvmpipe for headless GL, Xvfb for the
# viewer test) when they are missing. Debian/Ubuntu only; elsewhere it prints what to install.
set -euo pipefail
need=()
have_lib() { ldconfig -p 2>/dev/null | grep -q "$1"; }
have_lib 'libEGL.so.1'        || need+=(libegl1)
have_lib 'libEGL_mesa.so.0'   || need+=(libegl-mesa0)
have_lib 'libgbm.so.1'        || need+=(libgbm1)
have_lib 'libGL.so.1'         || need+=(libgl1)
have_lib 'libGLU.so.1'        || need+=(libglu1-mesa)
[ -e /usr/lib/x86_64-linux-gnu/dri/swrast_dri.so ] || [ -e /usr/lib/aarch64-linux-gnu/dri/swrast_dri.so ] \
    || ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1 || need+=(libgl1-mesa-dri)
command -v Xvfb >/dev/null 2>&1 || need+=(xvfb)
[ ${#need[@]} -eq 0 ] && exit 0
echo "sysdeps: missing system packages: ${need[*]}"
if ! command -v apt-get >/dev/null 2>&1; then
    echo "sysdeps: no apt-get here; install the equivalents of: ${need[*]}" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then SUDO="sudo -n"; else
        echo "sysdeps: not root and no passwordless sudo; run: sudo apt-get install -y ${need[*]}" >&2
        exit 0
    fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq || true
$SUDO apt-get install -y -qq --no-install-recommends "${need[@]}"
