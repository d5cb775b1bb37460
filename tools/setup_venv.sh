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
.venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[dev]"
touch .venv/.installed
