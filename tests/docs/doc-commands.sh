#!/usr/bin/env bash
# doc-commands.sh: the documentation and the programs cannot drift apart.
# Every command line that passes arguments to one of canmotion's programs is
# run with those arguments in the program's check mode, which parses them
# (and, for canmotiond, loads the configuration and script) and exits:
#
#   - lines of fenced code blocks in every README.md (`$ ` prompts, `sudo`,
#     pipes, `&`, comments, `\` continuations and commands quoted inside
#     another command, e.g. `-x 'canmotiond ...'`, are understood);
#   - comment lines of config/examples/* that show a command;
#   - ExecStart= of the units as configured in the build tree, with
#     $CIA402_EMU_ARGS from cia402-emu-example.conf;
#   - every CIA402_EMU_ARGS="..." in those files, the units and the conf;
#   - the Examples: section of each program's --help.
#
# canmotiond, cia402-emu, cantrace and rt-latency run with --check-args (exit
# 0 = valid). canmotionctl has no check mode: it runs against a socket that
# does not exist, and its documented exit status 2 ("bad arguments", with
# "Try 'canmotionctl --help'") is the failure.
#
# Synopsis lines (with [optional] parts) and inline `program --option` spans
# of the Markdown files are checked more weakly: each option they name must
# be an option the program's --help lists.
#
# Before the real check, a fixture with known mistakes (the old `--iface`)
# must be reported, so the test can fail.
#
# Usage: doc-commands.sh SOURCE_DIR BUILD_DIR   (exit 0 = everything matches)
set -uo pipefail
[[ $# -eq 2 ]] || { sed -n '2,28p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd)
programs=(canmotiond canmotionctl cia402-emu cantrace rt-latency)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

bin_of() { echo "$build/tools/$1/$1"; }
for p in "${programs[@]}"; do
  [[ -x $(bin_of "$p") ]] || { echo "doc-commands: $(bin_of "$p") not built" >&2; exit 2; }
done

# Paths the documentation uses that exist only on an installed system or after
# another command: the file in the tree that stands for them.
map_path() {
  case $1 in
    */canmotion/canmotiond.yaml) printf '%s\n' "$src/config/examples/canmotiond.yaml" ;;  # the default configuration, wherever installed
    /tmp/demo-vcan.yaml) printf '%s\n' "$src/config/examples/demo.yaml" ;;  # tests/demo/README.md: demo.yaml with vcan buses
    *) printf '%s\n' "$1" ;;
  esac
}

# Options each program's --help lists (lines starting with "-" in its options).
declare -A known=()
for p in "${programs[@]}"; do
  known[$p]=" $("$(bin_of "$p")" --help 2>&1 | sed -n 's/^[[:space:]]*\(-.*\)$/\1/p' | sed 's/   *.*//' |
    grep -oE '(^|[ ,])--?[A-Za-z][A-Za-z0-9-]*' | tr -d ' ,' | sort -u | tr '\n' ' ') "
done

fails=0 checked=0
report() {  # report ok|FAIL ORIGIN TEXT [DETAIL]
  if [[ $1 == ok ]]; then
    echo "ok    $2: $3"
  else
    echo "FAIL  $2: $3"; [[ -n ${4:-} ]] && sed 's/^/        /' <<<"$4"; fails=$((fails + 1))
  fi
  checked=$((checked + 1))
}

# tokenize LINE: shell words into WORDS (quotes and backslashes as the shell
# reads them, nothing expanded); | ; & && || become the word $'\x01' (a
# separator); a redirection and its target are dropped; an unquoted # that
# starts a word ends the line.
tokenize() {
  local s=$1 i=0 n=${#1} c w="" inw=0 q="" drop=0
  WORDS=()
  flush() {
    if ((inw)); then
      if ((drop)); then drop=0; else WORDS+=("$w"); fi
    fi
    w="" inw=0
  }
  while ((i < n)); do
    c=${s:i:1}
    if [[ -n $q ]]; then
      if [[ $c == "$q" ]]; then q=""
      elif [[ $q == '"' && $c == \\ ]]; then i=$((i + 1)); w+=${s:i:1}
      else w+=$c; fi
    else
      case $c in
        \'|\") q=$c; inw=1 ;;
        \\) i=$((i + 1)); w+=${s:i:1}; inw=1 ;;
        ' '|$'\t') flush ;;
        '#') if ((inw)); then w+=$c; else break; fi ;;
        '|'|';'|'&')
          flush; WORDS+=($'\x01')
          while [[ ${s:i+1:1} == '|' || ${s:i+1:1} == '&' ]]; do i=$((i + 1)); done ;;
        '>'|'<')
          [[ $w =~ ^[0-9]+$ ]] && { w="" inw=0; }  # 2>...
          flush; drop=1
          while [[ ${s:i+1:1} == '>' || ${s:i+1:1} == '&' ]]; do i=$((i + 1)); done ;;
        *) w+=$c; inw=1 ;;
      esac
    fi
    i=$((i + 1))
  done
  flush
}

program_of() {  # program_of WORD: true if WORD runs one of ours; its name in PROG (no subshell: called often)
  local b=${1##*/} p
  for p in "${programs[@]}"; do [[ $b == "$p" ]] && { PROG=$p; return 0; }; done
  return 1
}

check_options() {  # check_options ORIGIN PROG ARGS...: every option named is one --help lists
  local origin=$1 prog=$2; shift 2
  local a o bad=()
  for a in "$@"; do
    a=${a//[\[\]]/}
    for o in ${a//|/ }; do
      [[ $o =~ ^--?[A-Za-z] ]] || continue
      o=${o%%=*}
      if [[ ${known[$prog]} != *" $o "* ]]; then
        if [[ $o =~ ^-[A-Za-z]{2,}$ ]]; then  # combined short flags: -sq
          local k ok=1
          for ((k = 1; k < ${#o}; k++)); do [[ ${known[$prog]} == *" -${o:k:1} "* ]] || ok=0; done
          ((ok)) && continue
        fi
        bad+=("$o")
      fi
    done
  done
  if [[ ${#bad[@]} -eq 0 ]]; then
    report ok "$origin" "$prog $* (options exist)"
  else
    report FAIL "$origin" "$prog $*" "unknown option(s) ${bad[*]}; $prog --help lists:${known[$prog]}"
  fi
}

run_check() {  # run_check ORIGIN PROG ARGS...: run the program in its check mode
  local origin=$1 prog=$2; shift 2
  local args=() a out rc
  for a in "$@"; do
    if [[ $a == --*=* ]]; then args+=("${a%%=*}=$(map_path "${a#*=}")"); else args+=("$(map_path "$a")"); fi
  done
  if [[ $prog == canmotionctl ]]; then
    out=$(cd "$src" && CANMOTIOND_SOCKET="$tmp/no-daemon.sock" timeout 10 "$(bin_of "$prog")" "${args[@]}" 2>&1 </dev/null)
    rc=$?
    if [[ $rc == 2 || $out == *"Try 'canmotionctl --help'"* ]]; then
      report FAIL "$origin" "$prog $*" "bad arguments (exit $rc): $out"
    else
      report ok "$origin" "$prog $* (arguments accepted, exit $rc without a daemon)"
    fi
    return
  fi
  out=$(cd "$src" && timeout 20 "$(bin_of "$prog")" --check-args "${args[@]}" 2>&1 </dev/null)
  rc=$?
  if [[ $rc == 0 ]]; then report ok "$origin" "$prog $*"; else report FAIL "$origin" "$prog $*" "exit $rc: $out"; fi
}

check_command() {  # check_command ORIGIN WORD...: a command as written; synopsis or runnable
  local origin=$1; shift
  program_of "$1" || return 0
  local prog=$PROG
  shift
  local a
  for a in "$@"; do
    if [[ $a == \[* || $a == *\] ]]; then check_options "$origin" "$prog" "$@"; return; fi
  done
  run_check "$origin" "$prog" "$@"
}

check_line() {  # check_line ORIGIN LINE: every command of ours in a shell line
  local origin=$1 line=$2
  [[ $line =~ ^[[:space:]]*\$[[:space:]]+(.*)$ ]] && line=${BASH_REMATCH[1]}  # a "$ " prompt
  tokenize "$line"
  local words=("${WORDS[@]}" $'\x01') seg=() w
  for w in "${words[@]}"; do
    if [[ $w != $'\x01' ]]; then seg+=("$w"); continue; fi
    while [[ ${#seg[@]} -gt 0 && ( ${seg[0]} == sudo || ${seg[0]} == exec || ${seg[0]} == env ||
             ${seg[0]} =~ ^[A-Za-z_][A-Za-z0-9_]*= ) ]]; do seg=("${seg[@]:1}"); done
    if [[ ${#seg[@]} -gt 0 ]]; then
      if program_of "${seg[0]}" >/dev/null; then
        check_command "$origin" "${seg[@]}"
      else
        local x  # a command quoted inside another one: -x 'canmotiond --config ...'
        for x in "${seg[@]:1}"; do
          [[ $x == *' '* ]] && program_of "${x%% *}" >/dev/null && check_line "$origin" "$x"
        done
      fi
    fi
    seg=()
  done
}

check_emu_args() {  # check_emu_args FILE: every CIA402_EMU_ARGS="..." in FILE
  local file=$1 n=0 line
  while IFS= read -r line; do
    n=$((n + 1))
    while [[ $line =~ CIA402_EMU_ARGS=\"([^\"]*)\" ]]; do
      # shellcheck disable=SC2086  # systemd splits $CIA402_EMU_ARGS on whitespace
      run_check "${file#"$src"/}:$n (CIA402_EMU_ARGS)" cia402-emu ${BASH_REMATCH[1]}
      line=${line/"${BASH_REMATCH[0]}"/}
    done
  done <"$file"
}

check_markdown() {  # check_markdown FILE: fenced code lines (run) and inline spans (options)
  local file=$1 rel=${1#"$src"/} n=0 fence=0 line joined="" start=0 synopsis_prog=""
  while IFS= read -r line; do
    n=$((n + 1))
    if [[ $line =~ ^[[:space:]]*\`\`\` ]]; then fence=$((1 - fence)); synopsis_prog=""; continue; fi
    ((fence)) || continue
    if [[ -n $synopsis_prog && $line =~ ^[[:space:]]+\[ ]]; then  # a synopsis continued on the next line
      tokenize "${line//|/ }"; check_options "$rel:$n" "$synopsis_prog" "${WORDS[@]}"; continue
    fi
    synopsis_prog=""
    if [[ $line == *\\ ]]; then [[ -z $joined ]] && start=$n; joined+="${line%\\} "; continue; fi
    if [[ -n $joined ]]; then line="$joined$line"; joined=""; else start=$n; fi
    [[ $line == *' ['* ]] && line=${line//|/ }  # a synopsis: [a | b] are alternatives, not a pipe
    check_line "$rel:$start" "$line"
    if [[ $line == *' ['* ]]; then
      tokenize "$line"; synopsis_prog=""; program_of "${WORDS[0]:-}" && synopsis_prog=$PROG
    fi
  done <"$file"
  check_spans "$rel" < <(awk '/^[[:space:]]*```/ { f = !f; next } !f { print }' "$file")
}

check_spans() {  # check_spans ORIGIN < TEXT: `program --option ...` spans (may wrap a line)
  local origin=$1 text span
  text=$(tr '\n' ' ')
  while [[ $text =~ \`([^\`]*)\` ]]; do
    span=${BASH_REMATCH[1]}
    text=${text#*"${BASH_REMATCH[0]}"}
    [[ $span == *-* ]] || continue  # no option named: nothing to check
    tokenize "$span"
    program_of "${WORDS[0]:-}" || continue
    local prog=$PROG
    [[ " ${WORDS[*]:1}" == *' -'* ]] || continue  # no option named: nothing to check
    check_options "$origin (inline)" "$prog" "${WORDS[@]:1}"
  done
}

check_comments() {  # check_comments FILE: commands in # and // comment lines; spans in comments
  local file=$1 rel=${1#"$src"/} n=0 line
  while IFS= read -r line; do
    n=$((n + 1))
    [[ $line =~ ^[[:space:]]*(#|//)[[:space:]]*(.*)$ ]] || continue
    line=${BASH_REMATCH[2]}
    program_of "${line%% *}" >/dev/null && check_line "$rel:$n" "$line"
  done <"$file"
  check_spans "$rel" < <(sed -nE 's@^[[:space:]]*(#|//)[[:space:]]?@@p' "$file")
  check_emu_args "$file"
}

check_units() {  # check_units DIR: ExecStart= of the configured units
  local dir=$1 u line emu_args
  emu_args=$(sed -n 's/^CIA402_EMU_ARGS="\(.*\)"$/\1/p' "$dir/cia402-emu-example.conf")
  for u in "$dir"/*.service; do
    while IFS= read -r line; do
      line=${line#ExecStart=}
      line=$(sed -E 's/^[-@:+!]+//' <<<"$line")
      line=${line//\$CIA402_EMU_ARGS/$emu_args}
      program_of "${line%% *}" >/dev/null && check_line "${u#"$build"/} (ExecStart)" "$line"
    done < <(grep '^ExecStart=' "$u")
  done
}

check_help_examples() {  # check_help_examples PROG: the Examples: of --help
  local prog=$1 line n=0 in=0
  while IFS= read -r line; do
    n=$((n + 1))
    if [[ $line == Examples:* ]]; then in=1; continue; fi
    ((in)) || continue
    [[ $line =~ ^[[:space:]] ]] || { [[ -z $line ]] || in=0; continue; }
    line=$(sed -E 's/^[[:space:]]+//; s/   .*//' <<<"$line")  # "cmd   description"
    if program_of "${line%% *}" >/dev/null || [[ $line == *'|'* ]]; then check_line "$prog --help:$n" "$line"; fi
  done < <("$(bin_of "$prog")" --help 2>&1)
}

# ---- self-check: a fixture with known mistakes must be reported -----------------
echo "== self-check: known mistakes must be reported"
mkdir -p "$tmp/fixture"
cat >"$tmp/fixture/README.md" <<'EOF'
```sh
cia402-emu --iface vcan0 --node 5 &
echo 'CIA402_EMU_ARGS="--iface vcan0 --node 5"' | sudo tee /etc/canmotion/cia402-emu/x.conf
canmotiond --config /etc/canmotion/canmotiond.yaml --no-such-option
canmotionctl set OnlyATag
```
Run `cantrace --no-such-option trace.log` and
`cia402-emu --interface vcan0
--nodes 2`.
EOF
saved_src=$src
src=$tmp/fixture
check_markdown "$src/README.md" >"$tmp/self.log"
check_emu_args "$src/README.md" >>"$tmp/self.log"
src=$saved_src
if [[ $fails -eq 6 ]]; then
  echo "ok: all 6 mistakes reported"
  fails=0 checked=0
else
  cat "$tmp/self.log"
  echo "FAIL: the fixture has 6 mistakes, $fails were reported: this check is not meaningful"
  exit 1
fi

# ---- the real documentation ------------------------------------------------------
echo "== documentation, examples, units and --help examples"
while IFS= read -r f; do
  check_markdown "$f"
  check_emu_args "$f"
done < <(find "$src" \( -name '.git' -o -name 'build*' -o -name 'vcan-artifacts' -o -name '.cache' \) -prune -o \
              -name README.md -print | sort)
for f in "$src"/config/examples/* "$src"/systemd/*.in "$src"/systemd/*.conf; do
  [[ -f $f ]] && check_comments "$f"
done
check_units "$build/systemd"
for p in "${programs[@]}"; do check_help_examples "$p"; done

echo "doc-commands: $checked commands and option lists checked, $fails failed"
[[ $fails -eq 0 ]]
