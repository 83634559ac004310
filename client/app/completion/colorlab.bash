# bash completion for colorlab. Subcommands and options are read from the binary's own --help at the
# level being completed, so the completion never drifts from the CLI; campaign names and run ids come
# from the daemon (quietly: nothing is offered when it is not running).
_colorlab() {
  local cur="${COMP_WORDS[COMP_CWORD]}"
  local prog="${COMP_WORDS[0]}"
  local -a path=() globals=()
  local i w skip=0
  # The subcommand path typed so far, and the global options that say which daemon to ask.
  for ((i = 1; i < COMP_CWORD; i++)); do
    w="${COMP_WORDS[i]}"
    if ((skip)); then globals+=("$w"); skip=0; continue; fi
    case "$w" in
      --url|--socket|--key|--cacert) globals+=("$w"); skip=1 ;;
      --json|-h|--help) ;;
      -*) ;;
      *) path+=("$w") ;;
    esac
  done
  local help
  help="$("$prog" "${path[@]}" --help 2>/dev/null)" || help=""
  local subcommands options
  subcommands="$(printf '%s\n' "$help" | sed -n '/^Subcommands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9-]*\) .*/\1/p')"
  options="$(printf '%s\n' "$help" | sed -n 's/^  \(-[^ ]*\).*/\1/p' | tr ',' '\n' | sed -n 's/^\(--*[a-zA-Z][a-zA-Z0-9-]*\).*/\1/p')"
  if [[ "$cur" == -* ]]; then
    COMPREPLY=($(compgen -W "$options" -- "$cur"))
    return
  fi
  local words="$subcommands"
  case "${path[*]}" in
    run|"queue add")
      words="$words $("$prog" "${globals[@]}" --json campaigns 2>/dev/null | grep -o '"name": *"[^"]*"' | sed 's/.*"\([^"]*\)"$/\1/')" ;;
    show|export|report)
      words="$words $("$prog" "${globals[@]}" --json runs --limit 50 2>/dev/null | grep -o '"id": *"[^"]*"' | sed 's/.*"\([^"]*\)"$/\1/')" ;;
  esac
  COMPREPLY=($(compgen -W "$words" -- "$cur"))
}
complete -o default -F _colorlab colorlab
