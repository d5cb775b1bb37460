#!/usr/bin/env bash
# Print the path of a Python >= 3.12: first on PATH, then among pyenv-installed versions.
# Exit 1 with a message saying what to install when there is none.
set -u
ok() { "$1" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 12) else 1)' >/dev/null 2>&1; }
for cand in python3.12 python3.13 python3; do
    p=$(command -v "$cand" 2>/dev/null) || continue
    if ok "$p"; then echo "$p"; exit 0; fi
done
roots=()
[ -n "${PYENV_ROOT:-}" ] && roots+=("$PYENV_ROOT")
roots+=("$HOME/.pyenv")
for root in "${roots[@]}"; do
    for p in $(ls -d "$root"/versions/3.1[2-9]*/bin/python3 2>/dev/null | sort -V); do
        if ok "$p"; then echo "$p"; exit 0; fi
    done
done
echo "wheelrail needs Python >= 3.12 (the FEniCSx wheel dolfinx-solver-real requires it)." >&2
echo "None was found on PATH (python3.12, python3.13, python3) or under pyenv (~/.pyenv/versions)." >&2
echo "Install one, e.g. 'pyenv install 3.12' or your system's python3.12 package, and run again." >&2
exit 1
