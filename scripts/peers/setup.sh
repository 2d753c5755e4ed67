#!/usr/bin/env bash
# Makes the Python environment that the peer scripts run in: .venv-peers/ at the repository root,
# with numpy, pillow, moderngl, glcontext and OpenEXR from PyPI. With --system it first installs Mesa's EGL
# and OpenGL drivers through apt-get (Debian or Ubuntu, as root), which llvmpipe_bench.py needs.
#   scripts/peers/setup.sh [--system]
# Then, from the repository root:
#   .venv-peers/bin/python scripts/peers/llvmpipe_bench.py scenes/ground.toml --frames 10 --threads 2
set -euo pipefail
cd "$(dirname "$0")/../.."
if [ "${1:-}" = "--system" ]; then
  apt-get update
  apt-get install -y python3-venv libegl1 libegl-mesa0 libgl1-mesa-dri libgles2
fi
python3 -m venv .venv-peers
.venv-peers/bin/pip install --upgrade pip
.venv-peers/bin/pip install numpy pillow moderngl glcontext OpenEXR
.venv-peers/bin/python -c "import moderngl, numpy, PIL; print('peer environment ready: .venv-peers')"
