#!/usr/bin/env bash
# mypy --strict over moveplan's source tree. The repository root is the package `moveplan`
# (pyproject maps moveplan.core -> core/, ...), which mypy cannot see from the tree itself: a
# folder holding one link, moveplan -> the root, gives it the package's real names.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
python="${PYTHON:-$root/.venv/bin/python}"
names="$(mktemp -d)"
trap 'rm -rf "$names"' EXIT
ln -s "$root" "$names/moveplan"
cd "$names"
MYPYPATH="$names" "$python" -m mypy --config-file "$root/pyproject.toml" --cache-dir "$root/.mypy_cache" \
    -p moveplan.core -p moveplan.cli -p moveplan.commander "$@"
