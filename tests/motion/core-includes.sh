#!/usr/bin/env bash
# The planner's core includes no instruction family (issue 27 item 5): the
# files of the core (motion/core.hpp, core.cpp, cycle.cpp) and every motion/
# header they include, directly or not, include nothing from motion/instr/.
# The families include the core; the core reaches them only through the
# generator interface (motion/generator.hpp) and the hooks (motion/hooks.hpp).
#   core-includes.sh REPOSITORY_ROOT
# Follows `#include "motion/..."` lines (the project's only include style for
# its own headers). Checks itself first on a probe tree that must fail.
set -euo pipefail
[[ $# == 1 ]] || { echo "usage: core-includes.sh REPOSITORY_ROOT" >&2; exit 2; }
fail() { echo "core-includes: FAIL: $*" >&2; exit 1; }

# closure ROOT FILE...: every motion/ file reached from FILE... through
# `#include "motion/..."`, one per line, "INCLUDER -> INCLUDED"
closure() {
  local root=$1; shift
  local -A seen=()
  local queue=("$@") f inc
  while ((${#queue[@]})); do
    f=${queue[0]}; queue=("${queue[@]:1}")
    [[ -n "${seen[$f]:-}" ]] && continue
    seen[$f]=1
    [[ -f "$root/$f" ]] || fail "$f (included) not found under $root"
    while read -r inc; do
      echo "$f -> $inc"
      queue+=("$inc")
    done < <(sed -nE 's/^[[:space:]]*#[[:space:]]*include[[:space:]]+"(motion\/[^"]+)".*/\1/p' "$root/$f")
  done
}

core=(motion/core.hpp motion/core.cpp motion/cycle.cpp)

# self-check: a core that includes a family through a header must be caught
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/motion/instr"
printf '#include "motion/generator.hpp"\n' > "$tmp/motion/core.hpp"
printf '#include "motion/core.hpp"\n' > "$tmp/motion/core.cpp"
printf '#include "motion/core.hpp"\n' > "$tmp/motion/cycle.cpp"
printf '  #include "motion/instr/move.hpp"  // a generator type there\n' > "$tmp/motion/generator.hpp"
printf '#include "motion/core.hpp"\n' > "$tmp/motion/instr/move.hpp"
probe=$(closure "$tmp" "${core[@]}")
grep -q -- '-> motion/instr/' <<< "$probe" ||
  fail "the checker does not find motion/instr/move.hpp included through motion/generator.hpp"

root=$(cd "$1" && pwd -P)
edges=$(closure "$root" "${core[@]}")
bad=$(grep -- '-> motion/instr/' <<< "$edges" || true)
[[ -z "$bad" ]] || fail "the core includes instruction families:"$'\n'"$bad"
files=$( { printf '%s\n' "${core[@]}"; sed 's/.* -> //' <<< "$edges"; } | sort -u)
echo "core-includes: the core and the $(wc -l <<< "$files") motion/ files it reaches include no motion/instr/ header:"
tr '\n' ' ' <<< "$files"; echo
echo "core-includes: PASS"
