#!/usr/bin/env bash
# motion.size_limits (issue 13): no source file in motion/ over 800 lines and
# no function over 100 lines.
#   size-limits.sh MOTION_DIR
# Function extents come from universal-ctags (function definitions, from the
# line of the name to the line of the closing brace; a lambda counts in the
# function that holds it). A parser rather than brace counting, so that braces
# in strings, characters and comments do not count. The script first checks
# that it finds a 101-line function in a file of its own (it can fail).
set -euo pipefail
dir="$1"
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

mapfile -t files < <(find "$dir" -type f \( -name '*.cpp' -o -name '*.hpp' \) | sort)
[[ ${#files[@]} -gt 10 ]] || fail "only ${#files[@]} source files found under $dir"
bad=0
while read -r n f; do
  [[ $f == total ]] && continue
  if (( n > max_file )); then echo "size-limits: $f has $n lines (> $max_file)" >&2; bad=1; fi
done < <(wc -l "${files[@]}")
while IFS=$'\t' read -r n where name; do
  if (( n > max_fn )); then echo "size-limits: function $name at $where has $n lines (> $max_fn)" >&2; bad=1; fi
done < <(functions "${files[@]}")
echo "size-limits: ${#files[@]} files; largest:"
wc -l "${files[@]}" | grep -v ' total$' | sort -rn | awk 'NR <= 3' | sed "s#$dir/#motion/#; s/^/  /"
echo "size-limits: $(functions "${files[@]}" | wc -l) functions; longest:"
functions "${files[@]}" | sort -t$'\t' -k1,1nr | awk 'NR <= 5' | sed "s#$dir/#motion/#; s/^/  /"
[[ $bad == 0 ]] || fail "limits: files <= $max_file lines, functions <= $max_fn lines"
echo "size-limits: PASS"
