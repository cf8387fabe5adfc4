# Bash completion for log2map, mapconvert, mapdiff, bag2map, bag2carmen,
# carmen2bag and vasco_map_node (installed under each tool's name in
# share/bash-completion/completions). Everything comes from the tool being
# completed, never from a list kept here, so it cannot drift from the
# installed build (a CPU-only wheel has no cuda backend):
# - option names from its --help (asked once per shell and tool, ~0.3 s);
# - an option's values from its --help entry: CLI11's and argparse's {a,b}
#   choices, a metavar a|b, a LIST option's "list of a, b"; --backend from
#   the engine's registry, which --version prints ("backends compiled in:");
# - vasco_map_node, whose arguments are ROS 2's (--ros-args -p NAME:=VALUE),
#   from the node's parameter rows, read by the Python that runs the node
#   (running the node itself would start it).
# Anything else completes as a file name.

declare -gA _vasco_gpu_help_cache 2>/dev/null

_vasco_gpu_help_of() {  # the --help and --version of command $1, cached
  local tool=$1 key
  key=$(type -P "$tool" 2>/dev/null || printf '%s' "$tool")
  if [[ -z ${_vasco_gpu_help_cache[$key]+set} ]]; then
    _vasco_gpu_help_cache[$key]=$("$tool" --help 2>&1; "$tool" --version 2>&1)
  fi
  printf '%s\n' "${_vasco_gpu_help_cache[$key]}"
}

_vasco_gpu_options_of() {  # option names in a help text (stdin): at a line's start or after [ , ( |
  grep -oE -- '(^|[][ ,(|])--?[A-Za-z][-A-Za-z_]*' | sed -E 's/^[][ ,(|]+//' | grep -v -- '-$' | sort -u
}

_vasco_gpu_values_of() {  # the values option $1 takes, from a help text (stdin); empty: no list
  local opt=$1 text
  text=$(cat)
  if [[ $opt == --backend ]]; then
    sed -n 's/^backends compiled in: *//p' <<<"$text"
    return
  fi
  local line
  line=$(grep -E -- "(^|[][ ,])${opt}[ =]" <<<"$text" | head -n 20)
  # {a,b} after the option (CLI11 TEXT:{a,b}, argparse {a,b})
  local braces
  braces=$(grep -oE -- "${opt}[ =]([A-Z]+:)?\{[^}]*\}" <<<"$line" | head -n 1)
  if [[ -n $braces ]]; then
    braces=${braces#*\{}
    printf '%s\n' "${braces%\}}" | tr ',' ' '
    return
  fi
  # a metavar a|b|c
  local bars
  bars=$(grep -oE -- "${opt}[ =][a-z][-a-z_+.]*(\|[a-z][-a-z_+.]*)+" <<<"$line" | head -n 1)
  if [[ -n $bars ]]; then
    printf '%s\n' "${bars#"$opt"?}" | tr '|' ' '
    return
  fi
  # a LIST option: "... list of a, b, c (default ...)"
  grep -E -- "${opt} LIST" <<<"$line" | grep -oE 'list of [^(]*' | head -n 1 | sed -E 's/^list of //; s/,/ /g'
}

_vasco_gpu_node_parameters() {  # "NAME [CHOICE...]" per line: the node's parameter rows
  local node python
  node=$(type -P vasco_map_node) || return
  python=$(head -n 1 "$node")
  python=${python#\#!}
  [[ -x ${python%% *} ]] || python=python3
  $python -c 'from vasco_gpu.ros.settings import NODE_PARAMETERS as rows
for p in rows: print(p.name, *getattr(p.check, "names", ()))' 2>/dev/null
}

_vasco_gpu_node() {  # vasco_map_node [--version] --ros-args -p NAME:=VALUE ...
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}
  if [[ " ${COMP_WORDS[*]:1:COMP_CWORD-1} " != *" --ros-args "* ]]; then
    COMPREPLY=($(compgen -W "--version --ros-args" -- "$cur"))
  elif [[ $prev == -p || $prev == --param ]]; then
    local rows name choices
    rows=$(_vasco_gpu_node_parameters)
    if [[ $cur == *:=* ]]; then
      name=${cur%%:=*}
      choices=$(awk -v n="$name" '$1 == n { $1 = ""; print }' <<<"$rows")
      COMPREPLY=($(compgen -P "$name:=" -W "$choices" -- "${cur#*:=}"))
    else
      COMPREPLY=($(compgen -S ":=" -W "$(awk '{ print $1 }' <<<"$rows")" -- "$cur"))
      compopt -o nospace 2>/dev/null
    fi
  elif [[ $prev == --params-file ]]; then
    COMPREPLY=($(compgen -f -- "$cur"))
    compopt -o filenames 2>/dev/null
  else
    COMPREPLY=($(compgen -W "-p --param --params-file -r --remap --log-level" -- "$cur"))
  fi
}

_vasco_gpu_tool() {
  local tool=${COMP_WORDS[0]} cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}
  # --opt=value: bash splits it at '=' (COMP_WORDBREAKS)
  if [[ $cur == = ]]; then
    cur=""
  elif [[ $prev == = ]]; then
    prev=${COMP_WORDS[COMP_CWORD-2]}
  fi
  if [[ $prev == -* ]]; then
    local values
    values=$(_vasco_gpu_help_of "$tool" | _vasco_gpu_values_of "$prev")
    if [[ -n $values ]]; then
      if [[ $prev == --formats ]]; then  # a comma-separated list: complete its last item
        local done=${cur%"${cur##*,}"}
        COMPREPLY=($(compgen -P "$done" -W "$values" -- "${cur##*,}"))
        compopt -o nospace 2>/dev/null
      else
        COMPREPLY=($(compgen -W "$values" -- "$cur"))
      fi
      return
    fi
  fi
  if [[ $cur == -* ]]; then
    COMPREPLY=($(compgen -W "$(_vasco_gpu_help_of "$tool" | _vasco_gpu_options_of)" -- "$cur"))
  elif [[ $prev == --out-dir ]]; then
    COMPREPLY=($(compgen -d -- "$cur"))
    compopt -o filenames 2>/dev/null
  else
    COMPREPLY=($(compgen -f -- "$cur"))
    compopt -o filenames 2>/dev/null
  fi
}
complete -F _vasco_gpu_tool log2map mapconvert mapdiff bag2map bag2carmen carmen2bag
complete -F _vasco_gpu_node vasco_map_node
