#!/usr/bin/env bash
# docs/design.md's rule for the culler library, checked on the built archive and the public headers:
# dyncull::culler defines and calls no JSON reader, no detector, no host harness (settings, folder, log)
# and no throw expression (no call of __cxa_throw but with std::bad_alloc, which Eigen's allocations
# carry); its public headers (culling/culler.hpp, opencv/culler.hpp)
# and the dyncull headers they include contain no throw and include no eval/, host/ or detector header.
#   scripts/check-culler-library.sh path/to/libdyncull_culler.a
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
archive=${1:?usage: check-culler-library.sh ARCHIVE}
status=0

symbols=$(nm -C "$archive" 2>/dev/null)
[[ -n "$symbols" ]] || { echo "check-culler-library: no symbols read from $archive" >&2; exit 1; }
forbidden='dyncull::eval::|yolo_json|YoloJson|YoloDetector|cv::dnn::|dyncull::host::|HostCuller'
hits=$(grep -E "$forbidden" <<<"$symbols" | sort -u || true)
if [[ -n "$hits" ]]; then
  echo "check-culler-library: $archive holds symbols the culler library must not have:" >&2
  sed -n '1,20s/^/    /p' <<<"$hits" >&2
  status=1
fi
# The functions that call __cxa_throw with a type other than std::bad_alloc, from the relocations of the
# archive's disassembly: out of memory inside Eigen's and the standard library's allocations is not a
# throw of dyncull's (Eigen's aligned_malloc and resize carry it; inlined into more functions at -O1).
throwers=$(objdump -dr -C "$archive" 2>/dev/null | awk '
  function report() { if (throws && (other || !bad_alloc)) print fn }
  /^[0-9a-f]+ <.*>:$/ {
    report(); fn = $0; sub(/^[0-9a-f]+ </, "", fn); sub(/>:$/, "", fn); throws = other = bad_alloc = 0
  }
  /R_X86_64.*__cxa_throw/ { throws = 1 }
  /R_X86_64.*typeinfo for / { if ($0 ~ /typeinfo for std::bad_alloc/) bad_alloc = 1; else other = 1 }
  END { report() }' | sort -u || true)
if [[ -n "$throwers" ]]; then
  echo "check-culler-library: functions in $archive throw:" >&2
  sed -n '1,20s/^/    /p' <<<"$throwers" >&2
  status=1
fi

# The dyncull headers a host that includes the culler's two public headers reads (g++ -H lists them).
included=$(printf '#include "dyncull/culling/culler.hpp"\n#include "dyncull/opencv/culler.hpp"\n' |
  g++ -std=c++11 -fsyntax-only -H -I"$root/include" -isystem /usr/include/opencv4 -x c++ - 2>&1 >/dev/null |
  grep -oE '[^ ]*include/dyncull/[^ ]+\.hpp' | sort -u)
[[ -n "$included" ]] || { echo "check-culler-library: could not list the culler headers' includes" >&2; exit 1; }
for h in $included; do
  case "$h" in
    */dyncull/eval/*|*/dyncull/host/*|*/dyncull/opencv/yolo_*)
      echo "check-culler-library: the culler's public headers include $h" >&2; status=1 ;;
  esac
  # a throw outside comments
  if grep -nE '^[^/]*\bthrow\b' "$h" | grep -vE '^[0-9]+:\s*(///|//|\*)' >&2; then
    echo "check-culler-library: $h (included by the culler's public headers) throws" >&2
    status=1
  fi
done
((status == 0)) && echo "check-culler-library: $(wc -w <<<"$included") headers and $(basename "$archive"): no JSON reader, detector, host harness or throw"
exit $status
