#!/usr/bin/env bash
# doc-commands.sh: the documentation and the programs cannot drift apart.
# Every command line that passes arguments to one of canmotion's programs is
# run with those arguments in the program's check mode, which parses them
# (and, for canmotiond, loads the configuration and script) and exits:
#
#   - lines of fenced code blocks in every Markdown file of the tree (the
#     READMEs, BENCHMARKS.md and every other .md, so every .md the package
#     installs in /usr/share/doc/canmotion too): `$ ` prompts, pipes, `&`,
#     comments, `\` continuations, commands quoted inside another command
#     (e.g. `-x 'canmotiond ...'`), and commands behind wrappers with their
#     own options (sudo, env, exec, timeout, chrt, taskset, nice, ionice,
#     perf stat/record, time and /usr/bin/time, valgrind, strace, setpriv,
#     stdbuf, nohup, watch, gdb --args, tools/vcan-vm) are understood;
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
# Before the real check, a fixture with known mistakes (the old `--iface`,
# wrong flags behind each wrapper) must be reported, and its correct lines
# must pass, so the test can fail and does not fail for nothing.
#
# Usage: doc-commands.sh SOURCE_DIR BUILD_DIR   (exit 0 = everything matches)
set -uo pipefail
[[ $# -eq 2 ]] || { sed -n '2,34p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
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
    c8.yaml|c8.script) printf '%s\n' "$tmp/$1" ;;  # the benchmark notes' 8 axes: tests/bench_runtime/gen-config.sh 8 1 4 c8
    *) printf '%s\n' "$1" ;;
  esac
}

# The benchmark notes' generated configuration (BENCHMARKS.md, tests/bench_runtime/*.md).
"$src/tests/bench_runtime/gen-config.sh" 8 1 4 "$tmp/c8" ||
  { echo "doc-commands: tests/bench_runtime/gen-config.sh 8 1 4 failed" >&2; exit 2; }

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

# Wrappers: programs that run a command given after their own options and
# positional arguments. For each, the options that take their value as the
# next word (--opt=value and -xVALUE are one word anyway); wrap_pos: how many
# positional arguments come before the command (timeout 5 CMD, chrt -f 80
# CMD, taskset -c 2 CMD). chrt, taskset and ionice with -p act on a running
# process: no command to check. perf runs a command after stat, record or
# trace; gdb only after --args.
declare -A wrap_vals=(
  [sudo]="-u -g -C -D -h -p -r -t -T -U --user --group --close-from --chdir --host --prompt --role --type --command-timeout --other-user"
  [env]="-u -C -S --unset --chdir --split-string"
  [exec]="-a"
  [timeout]="-s -k --signal --kill-after"
  [chrt]="-T -P -D --sched-runtime --sched-period --sched-deadline"
  [taskset]=""
  [nice]="-n --adjustment"
  [ionice]="-c -n --class --classdata"
  [perf]="-e -r -o -C -G -x -I -M -D -F -m --event --repeat --output --cpu --cgroup --field-separator --interval-print --metrics --delay --freq --mmap-pages --call-graph --pre --post"
  [time]="-f -o --format --output"
  [valgrind]=""
  [strace]="-o -e -s -u -E -a -b -P -I -X -O -S --output --string-limit --user --env --columns --detach-on --trace-path --interruptible --const-print-style --summary-sort-by"
  [setpriv]="--reuid --regid --ruid --rgid --euid --egid --groups --inh-caps --ambient-caps --bounding-set --securebits --pdeathsig --selinux-label --apparmor-profile --landlock-access --landlock-rule --seccomp-filter"
  [stdbuf]="-i -o -e --input --output --error"
  [nohup]=""
  [watch]="-n -q --interval --equexit"
  [gdb]=""
  [vcan-vm]="-n -w -m -c -t --ifaces --rw --memory --cpus --timeout --cache"
)
declare -A wrap_pos=([timeout]=1 [chrt]=1 [taskset]=1)

unwrap() {  # unwrap: strips VAR=value words and wrappers (with their options) from the front of SEG
  local w name vals
  while [[ ${#SEG[@]} -gt 0 ]]; do
    w=${SEG[0]} name=${SEG[0]##*/}
    if [[ $w =~ ^[A-Za-z_][A-Za-z0-9_]*= ]]; then SEG=("${SEG[@]:1}"); continue; fi
    is_wrapper "$name" || return 0
    vals=" ${wrap_vals[$name]} "
    if [[ $name == perf ]]; then
      [[ ${SEG[1]:-} == stat || ${SEG[1]:-} == record || ${SEG[1]:-} == trace ]] || { SEG=(); return 0; }
      SEG=("${SEG[@]:1}")
    fi
    if [[ $name == gdb ]]; then  # gdb [options] --args PROGRAM ARGS...
      local k
      for ((k = 1; k < ${#SEG[@]}; k++)); do [[ ${SEG[k]} == --args ]] && break; done
      SEG=("${SEG[@]:k+1}"); continue
    fi
    SEG=("${SEG[@]:1}")
    while [[ ${#SEG[@]} -gt 0 ]]; do  # the wrapper's options
      w=${SEG[0]}
      [[ $w == -- ]] && { SEG=("${SEG[@]:1}"); break; }
      [[ $w == -?* ]] || break
      if [[ ($name == chrt || $name == taskset || $name == ionice) && ($w == --pid || $w =~ ^-[A-Za-z]*p) ]]; then
        SEG=(); return 0  # acts on a running process
      fi
      SEG=("${SEG[@]:1}")
      [[ $w != *=* && $vals == *" $w "* && ${#SEG[@]} -gt 0 ]] && SEG=("${SEG[@]:1}")  # the option's value
    done
    SEG=("${SEG[@]:${wrap_pos[$name]:-0}}")
  done
}

is_wrapper() {  # is_wrapper WORD: true if WORD (a path or a name) is one of the wrappers above
  local b=${1##*/}
  [[ $b =~ ^[a-z][a-z-]*$ && -v "wrap_vals[$b]" ]]
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
    SEG=("${seg[@]}"); unwrap; seg=("${SEG[@]}")
    if [[ ${#seg[@]} -gt 0 ]]; then
      if program_of "${seg[0]}" >/dev/null; then
        check_command "$origin" "${seg[@]}"
      else
        local x  # a command quoted inside another one: -x 'canmotiond --config ...', watch 'canmotionctl ...'
        for x in "${seg[@]}"; do
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
    SEG=("${WORDS[@]}"); unwrap; WORDS=("${SEG[@]}")
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
    { program_of "${line%% *}" || is_wrapper "${line%% *}"; } >/dev/null && check_line "$rel:$n" "$line"
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
      check_line "${u#"$build"/} (ExecStart)" "$line"  # ours, also behind a wrapper; ip is not ours
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
    if program_of "${line%% *}" >/dev/null || is_wrapper "${line%% *}" || [[ $line == *'|'* ]]; then
      check_line "$prog --help:$n" "$line"
    fi
  done < <("$(bin_of "$prog")" --help 2>&1)
}

# ---- self-check: a fixture with known mistakes must be reported -----------------
echo "== self-check: known mistakes must be reported, correct lines must pass"
mkdir -p "$tmp/fixture/config/examples"
cp "$src/config/examples/canmotiond.yaml" "$tmp/fixture/config/examples/"  # map_path's stand-in for /etc/canmotion/canmotiond.yaml
# 21 mistakes: 6 plain ones (the old --iface in a command and in
# CIA402_EMU_ARGS, an unknown option, a bad canmotionctl command, 2 inline
# spans), 13 wrapped command lines (one per wrapper, nested ones too) and 2
# wrapped inline spans. 4 correct commands (wrapped) must pass; the chrt -p
# and taskset -p lines run no command and are not checked.
expect_fail=21 expect_ok=4
cat >"$tmp/fixture/README.md" <<'FIXTURE'
```sh
cia402-emu --iface vcan0 --node 5 &
echo 'CIA402_EMU_ARGS="--iface vcan0 --node 5"' | sudo tee /etc/canmotion/cia402-emu/x.conf
canmotiond --config /etc/canmotion/canmotiond.yaml --no-such-option
canmotionctl set OnlyATag
timeout -s INT 5 canmotiond --sim --config /etc/canmotion/canmotiond.yaml --no-such-option
sudo chrt -f 80 taskset -c 2 cia402-emu --iface vcan0 --node 5
nice -n -5 rt-latency --no-such-option
perf stat -r 5 -e task-clock -- canmotiond --sim --config /etc/canmotion/canmotiond.yaml --bogus
/usr/bin/time -v cantrace --no-such-option trace.log
valgrind --tool=callgrind canmotiond --sim --config /etc/canmotion/canmotiond.yaml --bogus
setpriv --reuid=nobody --inh-caps=+net_admin --ambient-caps +net_admin cia402-emu --iface vcan0 --node 5
stdbuf -oL -e L cantrace --no-such-option trace.log
sudo -u canmotion canmotionctl --no-such-option status
env -u HOME ionice -c 1 -n 0 strace -f -o /tmp/x rt-latency --bogus
watch -n 1 'canmotionctl --no-such-option status'
tools/vcan-vm -n 2 -- cia402-emu --iface vcan0 --node 5
gdb -q --args canmotiond --sim --config /etc/canmotion/canmotiond.yaml --bogus
timeout 10 canmotiond --sim --config /etc/canmotion/canmotiond.yaml --duration 1
sudo chrt -f 80 taskset -c 1 nice -n -5 canmotiond --sim --config /etc/canmotion/canmotiond.yaml --duration 1
perf stat -r 5 -e task-clock canmotiond --sim --config /etc/canmotion/canmotiond.yaml --duration 1
chrt -p 80 1234
taskset -pc 2 1234
```
Run `cantrace --no-such-option trace.log` and
`cia402-emu --interface vcan0
--nodes 2`, `taskset -c 3 rt-latency --no-such-option`, `perf stat -r 3 canmotiond --bogus`;
`chrt -f 80 canmotiond --sim --duration 1` is fine.
FIXTURE
saved_src=$src
src=$tmp/fixture
check_markdown "$src/README.md" >"$tmp/self.log"
check_emu_args "$src/README.md" >>"$tmp/self.log"
src=$saved_src
if [[ $fails -eq $expect_fail && $((checked - fails)) -eq $expect_ok ]]; then
  echo "ok: all $expect_fail mistakes reported (13 of them behind wrappers), the $expect_ok correct wrapped commands passed"
  fails=0 checked=0
else
  cat "$tmp/self.log"
  echo "FAIL: the fixture has $expect_fail mistakes and $expect_ok correct commands; $fails were reported" \
       "and $((checked - fails)) passed: this check is not meaningful"
  exit 1
fi

# ---- the real documentation ------------------------------------------------------
echo "== documentation, examples, units and --help examples"
mapfile -t md_files < <(find "$src" \( -name '.git' -o -name 'build*' -o -name 'vcan-artifacts' -o -name '.cache' \) \
                          -prune -o -name '*.md' -print | sort)  # READMEs, BENCHMARKS.md, tests/bench_runtime/*.md, ...
# Every .md the install rules install (the package's /usr/share/doc/canmotion)
# must be among them, wherever it is kept.
while IFS= read -r f; do
  [[ " ${md_files[*]} " == *" $f "* ]] || report FAIL "install rules" "$f" "installed, but not scanned by doc-commands.sh"
done < <(find "$build" -name cmake_install.cmake -exec grep -ho '"[^"]*\.md"' {} + | tr -d '"' | sort -u)
for f in "${md_files[@]}"; do
  check_markdown "$f"
  check_emu_args "$f"
done
for f in "$src"/config/examples/* "$src"/systemd/*.in "$src"/systemd/*.conf; do
  [[ -f $f ]] && check_comments "$f"
done
check_units "$build/systemd"
for p in "${programs[@]}"; do check_help_examples "$p"; done

echo "doc-commands: $checked commands and option lists checked, $fails failed"
[[ $fails -eq 0 ]]
