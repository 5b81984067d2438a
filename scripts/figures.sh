#!/usr/bin/env bash
# Runs scripts/figures.py (the docs' plots from dynamic_vo's CSV) with the Python that has matplotlib:
# Debian's, for which scripts/install-deps.sh installs python3-matplotlib, before another python3 that
# may come first on the PATH. Arguments go to figures.py.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
for python in /usr/bin/python3 python3; do
  if "$python" -c 'import matplotlib' 2>/dev/null; then exec "$python" "$root/scripts/figures.py" "$@"; fi
done
exec python3 "$root/scripts/figures.py" "$@"  # says what is missing
