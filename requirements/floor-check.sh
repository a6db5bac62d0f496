#!/usr/bin/env bash
# Floor check: run the test suite with the oldest runtime versions that pyproject.toml allows
# (requirements/floor.txt); the test tools come from requirements/test.lock.  Uses its own
# virtual environment, .venv-floor, so the main .venv is left as it is.
set -euo pipefail
cd "$(dirname "$0")/.."
constraints="$(mktemp)"
trap 'rm -f "$constraints"' EXIT
# floor pins win over the lock's pins of the same distributions
names="$(grep -v '^#' requirements/floor.txt | sed -n 's/^\([A-Za-z0-9_.-]*\)==.*/\1/p' | tr 'A-Z_' 'a-z-')"
{
  grep -v '^#' requirements/floor.txt
  grep -v '^#' requirements/test.lock | while IFS= read -r line; do
    name="$(printf '%s' "${line%%==*}" | tr 'A-Z_' 'a-z-')"
    printf '%s\n' "$names" | grep -qxF "$name" || printf '%s\n' "$line"
  done
} > "$constraints"
python3 -m venv .venv-floor
.venv-floor/bin/pip install -q -c "$constraints" -e '.[dev]'
.venv-floor/bin/python - <<'PY'
import importlib.metadata as md
print("floor check with " + ", ".join(
    f"{n} {md.version(n)}" for n in ("numpy", "scipy", "pandas", "pyarrow", "matplotlib", "typer")))
PY
.venv-floor/bin/pytest -q -n 2 -p no:cacheprovider
