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
check "analyze" "$(help_subcommands analyze)" "$(complete_words analyze "")"
grep -qx stability <<<"$(complete_words analyze st)" || { echo "FAIL: analyze st does not offer stability"; fail=1; }
stability_options="$(complete_words analyze stability --)"
for o in --train --test --other-lamp --methods --tolerance --noise --exposures --sizes --per-patch --json --help; do
  grep -qx -- "$o" <<<"$stability_options" || { echo "FAIL: analyze stability -- lacks $o"; fail=1; }
done
# The global --json before report, study and download: the subcommand's own options are still offered.
for o in --output --help; do
  grep -qx -- "$o" <<<"$(complete_words --json report --)" || { echo "FAIL: --json report -- lacks $o"; fail=1; }
done
for o in --dry-run --small --set --state-file --resume --output; do
  grep -qx -- "$o" <<<"$(complete_words --json study --)" || { echo "FAIL: --json study -- lacks $o"; fail=1; }
done
grep -qx -- "--output" <<<"$(complete_words --json download --)" || { echo "FAIL: --json download -- lacks --output"; fail=1; }
# No daemon at this socket: campaign names are simply not offered, and nothing is printed.
out="$(complete_words --socket /nonexistent/colorlab.sock run "" 2>&1)"
check "run without a daemon" "" "$out"
exit $fail
