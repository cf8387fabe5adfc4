# Bash completion for log2map, mapconvert and mapdiff (installed under each
# tool's name in share/bash-completion/completions). The options come from
# the tool's own --help, so they never drift from it; everything else
# completes as a file name.
_vasco_gpu_tool() {
  local cur=${COMP_WORDS[COMP_CWORD]}
  if [[ $cur == -* ]]; then
    local opts
    opts=$("${COMP_WORDS[0]}" --help 2>/dev/null | grep -oE -- '(^|[ ,])--?[A-Za-z][-A-Za-z_]*' | tr -d ' ,' | sort -u)
    COMPREPLY=($(compgen -W "$opts" -- "$cur"))
  else
    COMPREPLY=($(compgen -f -- "$cur"))
    compopt -o filenames 2>/dev/null
  fi
}
complete -F _vasco_gpu_tool log2map mapconvert mapdiff
