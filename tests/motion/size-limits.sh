#!/usr/bin/env bash
# Size limits (issue 13 for motion/, issue 27 for the whole tree): no C++
# source file over 800 lines and no function over 100 lines.
#   size-limits.sh [--exempt FILE] DIR...
# FILE lists what is exempt (data tables), one per line, `#` comments:
#   PATH                 a whole file (relative to the repository root)
#   PATH:FUNCTION        one function of it (its name as ctags gives it)
# each followed by a reason after ` -- `. An entry that matches nothing is an
# error (a stale exemption). Function extents come from universal-ctags
# (function definitions, from the line of the name to the line of the
# closing brace; a lambda counts in the function that holds it). A parser
# rather than brace counting, so that braces in strings, characters and
# comments do not count. The script first checks that it finds a 101-line
# function in a file of its own (it can fail).
set -euo pipefail
exempt_file=""
if [[ "${1:-}" == --exempt ]]; then exempt_file="$2"; shift 2; fi
[[ $# -ge 1 ]] || { echo "usage: size-limits.sh [--exempt FILE] DIR..." >&2; exit 2; }
max_file=800 max_fn=100
fail() { echo "size-limits: FAIL: $*" >&2; exit 1; }
command -v ctags >/dev/null || fail "ctags not found (apt install universal-ctags; tools/setup-deps lists it)"
ctags --version 2>/dev/null | grep -q "Universal Ctags" || fail "ctags is not Universal Ctags"
# "LENGTH<TAB>FILE:LINE<TAB>NAME" for every function definition in the files given
functions() {
  ctags -x --_xformat="%{end}	%n	%F	%N" --kinds-c++=f --fields=+ne --language-force=C++ -o - "$@" 2>/dev/null |
    awk -F'\t' '$1 ~ /^[0-9]+$/ { printf "%d\t%s:%d\t%s\n", $1 - $2 + 1, $3, $2, $4 }'
}
# self-check
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{ echo "namespace x {"; echo "int long_one(int a) {"; for i in $(seq 1 99); do echo "  a += \"}\"[0] + $i;  // }"; done; echo "}"; echo "}"; } > "$tmp/probe.cpp"
probe=$(functions "$tmp/probe.cpp")
[[ "$probe" == "101"$'\t'* ]] || fail "the checker does not measure a 101-line function as 101 lines (got '$probe')"

# The repository root: the common parent the paths in FILE are relative to.
root=$(cd "$(dirname "$1")" && pwd -P)
declare -A exempt=() used=()
if [[ -n "$exempt_file" ]]; then
  while IFS= read -r line; do
    line="${line%%#*}"
    entry="${line%% -- *}"
    entry="$(echo "$entry" | xargs)"
    [[ -z "$entry" ]] && continue
    [[ "$line" == *" -- "* ]] || fail "$exempt_file: '$entry' has no reason (PATH[:FUNCTION] -- reason)"
    exempt["$entry"]=1
  done < "$exempt_file"
fi

files=()
for d in "$@"; do
  mapfile -t -O "${#files[@]}" files < <(find "$(cd "$d" && pwd -P)" -type f \( -name '*.cpp' -o -name '*.hpp' \) | sort)
done
[[ ${#files[@]} -gt 10 ]] || fail "only ${#files[@]} source files found under $*"
rel() { echo "${1#"$root"/}"; }
bad=0
while read -r n f; do
  [[ $f == total ]] && continue
  if (( n > max_file )); then
    r=$(rel "$f")
    if [[ -n "${exempt[$r]:-}" ]]; then used["$r"]=1; continue; fi
    echo "size-limits: $r has $n lines (> $max_file)" >&2; bad=1
  fi
done < <(wc -l "${files[@]}")
while IFS=$'\t' read -r n where name; do
  if (( n > max_fn )); then
    r=$(rel "${where%:*}")
    if [[ -n "${exempt[$r:$name]:-}" ]]; then used["$r:$name"]=1; continue; fi
    if [[ -n "${exempt[$r]:-}" ]]; then used["$r"]=1; continue; fi
    echo "size-limits: function $name at $(rel "$where") has $n lines (> $max_fn)" >&2; bad=1
  fi
done < <(functions "${files[@]}")
for e in "${!exempt[@]}"; do
  [[ -n "${used[$e]:-}" ]] || { echo "size-limits: $exempt_file: '$e' is exempt but within the limits (or gone): remove it" >&2; bad=1; }
done
echo "size-limits: ${#files[@]} files under $*; largest:"
wc -l "${files[@]}" | grep -v ' total$' | sort -rn | awk 'NR <= 3' | sed "s#$root/##; s/^/  /"
echo "size-limits: $(functions "${files[@]}" | wc -l) functions; longest:"
functions "${files[@]}" | sort -t$'\t' -k1,1nr | awk 'NR <= 5' | sed "s#$root/##; s/^/  /"
[[ ${#exempt[@]} == 0 ]] || echo "size-limits: ${#exempt[@]} exemption(s) from $exempt_file"
[[ $bad == 0 ]] || fail "limits: files <= $max_file lines, functions <= $max_fn lines"
echo "size-limits: PASS"
