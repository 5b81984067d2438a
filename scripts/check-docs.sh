#!/usr/bin/env bash
# Checks that the documentation, code comments and test names describe what dyncull does rather than how
# it was developed (that belongs in git log), that relative links in README.md and docs/*.md resolve, and
# (scripts/check-casts.sh) that no float-to-int conversion in include/ and src/ is raw, and
# (scripts/check-function-length.py) that no function there or in apps/ is over 80 lines.
# Prints file:line: text for every hit and exits 1 if there is any. Usage: scripts/check-docs.sh
set -euo pipefail
cd "$(dirname "$0")/.."

paths=(README.md docs include examples apps integrations tests bench scripts cmake CMakeLists.txt .ci)
exts=(--include='*.md' --include='*.hpp' --include='*.h' --include='*.cpp' --include='*.cc' --include='*.sh'
      --include='*.cmake' --include='*.in' --include='*.txt' --include='*.py' --include=run)

# Extended regular expressions, matched case-insensitively. Each is written with character classes so
# that this file does not match itself.
patterns=(
  '(^|[^[:alnum:]_])sessions?[[:space:]]+#?[0-9]+'             # a numbered development session
  '(^|[^[:alnum:]_])sessions?[[:space:]]+[n](['"'"'s]|[[:space:]]|$)' # "session N" as a placeholder
  '(^|[^[:alnum:]_])findings?[[:space:]]+#?[0-9]+'             # a numbered finding of a review
  '(^|[^[:alnum:]_])issues?[[:space:]]*#[0-9]+'                # an issue number
  '(^|[^[:alnum:]_-])(19|20)[0-9]{2}-[01][0-9]-[0-3][0-9]([^[:alnum:]]|$)' # a date (YYYY-MM-DD)
  '(^|[^[:alnum:]_.~$-])/(tmp|work)/'                          # a path of one machine
  '(^|[^[:alnum:]_.~$-])/home/[[:alnum:]_]'                    # a home directory
  '(^|[^[:alnum:]_])commit[[:space:]]+[0-9a-f]{7,40}([^[:alnum:]]|$)' # a commit hash in prose
)
# Lines allowed to name /tmp: temporary directories made at run time.
allowed='mktemp|TMPDIR'

status=0
for pattern in "${patterns[@]}"; do
  # grep exits 1 when nothing matches; only real errors (2) stop the script.
  hits=$(grep -rnIiE "${exts[@]}" -e "$pattern" "${paths[@]}" 2>/dev/null | grep -vE "$allowed" || true)
  if [[ -n "$hits" ]]; then
    printf '%s\n' "$hits"
    status=1
  fi
done
if [[ $status -ne 0 ]]; then
  echo "check-docs: development history above (sessions, findings, issue numbers, dates, machine paths," \
       "commit hashes); say what the code does instead, the history is in git log" >&2
fi

# Relative Markdown links [text](target) in README.md and docs/*.md must name an existing file.
link_status=0
for md in README.md docs/*.md; do
  dir=$(dirname "$md")
  while IFS=: read -r line target; do
    target=${target%%#*}
    target=${target%% *}
    [[ -z "$target" ]] && continue
    case "$target" in
      http://*|https://*|mailto:*|ftp://*) continue ;;
    esac
    if [[ ! -e "$dir/$target" ]]; then
      echo "$md:$line: broken link: $target"
      link_status=1
    fi
  done < <(grep -noE '\]\([^)]+\)' "$md" | sed -E 's/^([0-9]+):\]\(([^)]*)\)$/\1:\2/')
done
if [[ $link_status -ne 0 ]]; then
  echo "check-docs: relative links above point to files that do not exist" >&2
  status=1
fi

# The README's integration is the snippet of examples/front_end.cpp (which ctest runs), word for word.
if ! python3 - <<'PY'
import sys
src = open("examples/front_end.cpp").read()
snippet = src.split("// --- README snippet begins ---\n")[1].split("// --- README snippet ends ---")[0]
lines = [l[2:] if l.startswith("  ") else l for l in snippet.rstrip().split("\n")]
sys.exit(0 if "\n".join(lines).strip() in open("README.md").read() else 1)
PY
then
  echo "README.md: its integration snippet differs from the one in examples/front_end.cpp" >&2
  status=1
fi

# Every float-to-int conversion of user data goes through core/pixel.hpp's checked helpers, or says why it
# is in range (scripts/check-casts.sh).
if ! scripts/check-casts.sh; then
  status=1
fi

# No function body in include/, src/ and apps/ longer than 80 lines (scripts/check-function-length.py).
if ! python3 scripts/check-function-length.py; then
  status=1
fi

if [[ $status -eq 0 ]]; then
  echo "check-docs: no development history, all relative links resolve, README snippet current, no raw float-to-int,"\
       "no function over 80 lines"
fi
exit $status
