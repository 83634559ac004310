#!/usr/bin/env bash
# The project's C++ layout by .clang-format (clang-format 14, Debian 12's); docs/TESTING.md, "Layout and lint".
#   scripts/format.sh               check: list the files clang-format would change and how many lines; exit 1 if any
#   scripts/format.sh --apply       rewrite them in place (one commit, its hash added to .git-blame-ignore-revs)
#   scripts/format.sh --check-long  list the lines an apply would make longer than 120 columns (that were not) or
#                                   join from three or more lines; exit 1 if any
#   scripts/format.sh --verify      prove an apply moves only whitespace: every token, literal and comment kept
#                                   (scripts/format_check.py); exit 1 if not
#   scripts/format.sh --verify-against REV   the same for an apply already made: the files now against REV
#   scripts/format.sh [MODE] FILE...         only those files
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG_FORMAT=${CLANG_FORMAT:-clang-format}
command -v "$CLANG_FORMAT" >/dev/null || { echo "format.sh: $CLANG_FORMAT not found (apt-get install clang-format)" >&2; exit 2; }
mode=check against=
case ${1:-} in
  --apply | --check-long | --verify) mode=${1#--}; shift ;;
  --verify-against) mode=verify against=${2:?"format.sh: --verify-against needs a revision"}; shift 2 ;;
esac
if (($#)); then files=("$@"); else mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc'); fi

case $mode in
  apply)
    printf '%s\0' "${files[@]}" | xargs -0 -P2 -n 40 "$CLANG_FORMAT" -i --style=file
    exit 0 ;;
  check-long) CLANG_FORMAT=$CLANG_FORMAT exec python3 scripts/format_check.py --check-long "${files[@]}" ;;
  verify) CLANG_FORMAT=$CLANG_FORMAT exec python3 scripts/format_check.py --verify ${against:+--against "$against"} "${files[@]}" ;;
esac
changed_files=0 changed_lines=0
for f in "${files[@]}"; do
  n=$("$CLANG_FORMAT" --style=file "$f" | diff -U0 "$f" - | grep -c '^-[^-]' || true)
  if ((n > 0)); then
    echo "$f: $n line(s)"
    changed_files=$((changed_files + 1)) changed_lines=$((changed_lines + n))
  fi
done
echo "format.sh: $changed_lines line(s) in $changed_files of ${#files[@]} file(s) differ from .clang-format"
((changed_lines == 0))
