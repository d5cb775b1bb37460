#!/usr/bin/env bash
# Create .venv with a Python >= 3.12 (if missing) and install wheelrail with its dependencies.
set -eu
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/python ]; then
    py=$(bash tools/find_python.sh)
    echo "setup: creating .venv with $py" >&2
    "$py" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip
.venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[all,dev]"
# numba compiles the dynamics and contact kernels on first use and caches them on disk: do it once here, with
# progress, so that the first `wheelrail run` does not wait silently for a minute or more
echo "setup: compiling the numba kernels once (about 2 minutes on a 2-core machine)" >&2
.venv/bin/python -m wheelrail.warmup
touch .venv/.installed
