#!/usr/bin/env bash
# mypy --strict over moveplan's source tree. The repository root is the package `moveplan`
# (pyproject maps moveplan.core -> core/, ...), which mypy cannot see from the tree itself: a
# folder holding one link, moveplan -> the root, gives it the package's real names.
# The packages are named by path, not with -p: -p looks moveplan.core up, and an installed copy
# with py.typed (.ci/run installs one) wins that lookup over the tree, which would go unchecked.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
python="${PYTHON:-$root/.venv/bin/python}"
names="$(mktemp -d)"
trap 'rm -rf "$names"' EXIT
ln -s "$root" "$names/moveplan"
cd "$names"
MYPYPATH="$names" "$python" -m mypy --config-file "$root/pyproject.toml" --cache-dir "$root/.mypy_cache" \
    --explicit-package-bases moveplan/core moveplan/cli moveplan/commander "$@"
