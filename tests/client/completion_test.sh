#!/usr/bin/env bash
# The bash completion offers exactly what the binary's --help lists, at each level, and stays quiet when no
# daemon runs. Truth: the CLI's own help output (CLI11), independent of the completion's parsing.
set -euo pipefail
bin="$1"
script="$2"
dir="$(dirname "$bin")"
PATH="$dir:$PATH"
source "$script"

complete_words() {  # complete_words WORD... (the last is the one being completed)
  COMP_WORDS=(colorlab "$@")
  COMP_CWORD=$#
  COMPREPLY=()
  _colorlab
  printf '%s\n' "${COMPREPLY[@]}" | sort
}
help_subcommands() {
  colorlab "$@" --help | sed -n '/^Subcommands:/,/^$/p' | awk 'NR > 1 && NF { print $1 }' | sort
}
fail=0
check() {  # check NAME EXPECTED ACTUAL
  if [[ "$2" != "$3" ]]; then
    echo "FAIL: $1"; echo "  expected: $(echo $2)"; echo "  got:      $(echo $3)"; fail=1
  else
    echo "ok: $1"
  fi
}

check "top level" "$(help_subcommands)" "$(complete_words "")"
check "queue" "$(help_subcommands queue)" "$(complete_words queue "")"
check "keys" "$(help_subcommands keys)" "$(complete_words keys "")"
check "prefix r" "$(help_subcommands | grep '^r')" "$(complete_words r)"
run_options="$(complete_words run --)"
for o in --param --detach --id-only --dry-run --idempotency-key --help; do
  grep -qx -- "$o" <<<"$run_options" || { echo "FAIL: run -- lacks $o"; fail=1; }
done
locate_options="$(complete_words locate-chart --)"
for o in --blob --chart --corners --reference-run --fraction --min-confidence --json --help; do
  grep -qx -- "$o" <<<"$locate_options" || { echo "FAIL: locate-chart -- lacks $o"; fail=1; }
done
# No daemon at this socket: campaign names are simply not offered, and nothing is printed.
out="$(complete_words --socket /nonexistent/colorlab.sock run "" 2>&1)"
check "run without a daemon" "" "$out"
exit $fail
