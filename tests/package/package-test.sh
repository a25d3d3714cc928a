#!/usr/bin/env bash
# package-test.sh: the Debian package as a user gets it. Builds it with CPack
# from the build tree the other tests use (no second build), then:
#   1. file list (dpkg-deb -c): every program, man page, unit, networkd and
#      sysusers file, the conffile, examples and documentation, at /usr paths;
#      nothing under /usr/local, no build paths, no test programs;
#   2. metadata (dpkg-deb -f / -I): name, version, architecture, Depends
#      computed by dpkg-shlibdeps (it names the package of every shared
#      library the programs link: readelf NEEDED, ldd, dpkg -S), maintainer
#      scripts and the conffile;
#   3. unpacked into a scratch root (dpkg -x): the programs need no library of
#      ours (static) and no build path; the installed canmotiond runs
#      `--sim --config <installed example> --duration 1`, the default
#      configuration moves nothing, every program answers --help, the man
#      pages are there; every installed unit's ExecStart= names an installed
#      program and its arguments pass the program's --check-args;
#   4. systemd/verify-units.sh on the installed units (systemd-analyze verify
#      and security, exposure thresholds);
#   5. the maintainer scripts with DPKG_ROOT=<scratch root> (as root only):
#      postinst creates the user and group and sets /etc/canmotion
#      root:canmotion 0750 without touching systemd; prerm/postrm purge clean up.
# Prints the time each step took.
#
# Usage: package-test.sh SOURCE_DIR BUILD_DIR VERSION   (exit 0 = all good)
set -uo pipefail
[[ $# -eq 3 ]] || { sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd) version=$3
work=$build/package-test
rm -rf "$work"
mkdir -p "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
t_start=$(date +%s%N) t_step=$t_start
step() {
  local now; now=$(date +%s%N)
  [[ -n ${step_name:-} ]] && printf '   (%s: %d ms)\n' "$step_name" $(((now - t_step) / 1000000))
  t_step=$now step_name=$1
  echo "== $1"
}

step "cpack (DEB) in $build"
if ! cpack --config "$build/CPackConfig.cmake" -B "$work" >"$work/cpack.log" 2>&1; then
  cat "$work/cpack.log"; echo "FAIL: cpack failed"; exit 1
fi
debs=("$work"/canmotion_*.deb)
[[ ${#debs[@]} -eq 1 && -f ${debs[0]} ]] || { cat "$work/cpack.log"; echo "FAIL: expected one canmotion_*.deb in $work"; exit 1; }
deb=${debs[0]}
echo "$(basename "$deb"): $(stat -c %s "$deb") bytes"

step "file list (dpkg-deb -c)"
dpkg-deb -c "$deb" | awk '{ print $6 }' | sed 's|^\./|/|; s|/$||' | sort >"$work/files.txt"
required=(
  /usr/bin/canmotiond /usr/bin/canmotionctl /usr/bin/cia402-emu /usr/bin/cantrace /usr/bin/rt-latency
  /usr/share/man/man1/canmotiond.1.gz /usr/share/man/man1/canmotionctl.1.gz /usr/share/man/man1/cia402-emu.1.gz
  /usr/share/man/man1/cantrace.1.gz /usr/share/man/man1/rt-latency.1.gz
  /etc/canmotion/canmotiond.yaml
  /usr/share/doc/canmotion/README.md /usr/share/doc/canmotion/BENCHMARKS.md
  /usr/share/canmotion/examples/canmotiond.yaml /usr/share/canmotion/examples/demo.yaml
  /usr/share/canmotion/examples/demo.script /usr/share/canmotion/examples/mapc.script
  /usr/share/canmotion/examples/cia402-emu-example.conf
)
# systemd's directories from pkg-config, as the install rules use them.
unitdir=$(pkg-config --variable=systemdsystemunitdir systemd 2>/dev/null || echo /usr/lib/systemd/system)
sysusersdir=$(pkg-config --variable=sysusersdir systemd 2>/dev/null || echo /usr/lib/sysusers.d)
networkdir=$(pkg-config --variable=systemdutildir systemd 2>/dev/null || echo /usr/lib/systemd)/network
udevdir=$(dirname "$(pkg-config --variable=systemdutildir systemd 2>/dev/null || echo /usr/lib/systemd)")/udev/rules.d
required+=("$unitdir/canmotiond.service" "$unitdir/cia402-emu@.service" "$unitdir/canmotion-vcan@.service"
           "$sysusersdir/canmotion.conf" "$networkdir/80-vcan0.netdev" "$networkdir/80-vcan0.network"
           "$udevdir/60-canmotion-cpu-dma-latency.rules")
# Every example of the source tree (EDS files included, wherever they are kept) is in the package.
while IFS= read -r f; do required+=("/usr/share/canmotion/examples/${f#"$src"/config/examples/}"); done < <(
  find "$src/config/examples" -type f \( -name '*.yaml' -o -name '*.script' -o -iname '*.eds' \))
for d in config/eds fieldbus/eds; do
  [[ -d $src/$d ]] || continue
  while IFS= read -r f; do required+=("/usr/share/canmotion/examples/${f#"$src/$d"/}"); done < <(
    find "$src/$d" -type f -iname '*.eds')
done
for f in "${required[@]}"; do grep -qxF "$f" "$work/files.txt" || fail "$f missing from the package"; done
if grep -nE '^/usr/local|/tests?/|fieldbus-demo|vcan-vm|\.a$|/include/|_test$|_bench$' "$work/files.txt"; then
  fail "files that do not belong in the package (above)"
fi
echo "$(wc -l <"$work/files.txt") entries; ${#required[@]} required files present unless reported"

step "metadata (dpkg-deb -f, -I)"
field() { dpkg-deb -f "$deb" "$1"; }
[[ $(field Package) == canmotion ]] || fail "Package: $(field Package)"
[[ $(field Version) == "$version" ]] || fail "Version: '$(field Version)', expected $version"
[[ $(field Architecture) == "$(dpkg --print-architecture)" ]] || fail "Architecture: $(field Architecture)"
depends=$(field Depends)
echo "Depends: $depends"
# Depends names the Debian package of every shared library the installed
# programs need (their NEEDED entries, resolved by ldd, owned per dpkg -S):
# so no list of libraries is kept here to drift.
dpkg-deb -x "$deb" "$work/deps-root"
declare -A lib_users=() owner_of=()
for p in canmotiond canmotionctl cia402-emu cantrace rt-latency; do
  b=$work/deps-root/usr/bin/$p
  resolved=$(ldd "$b")
  while read -r soname; do
    path=$(awk -v so="$soname" '$1 == so && $3 ~ /^\// { print $3; exit }' <<<"$resolved")
    [[ -n $path ]] || { fail "$p: NEEDED $soname not resolved by ldd"; continue; }
    lib_users[$path]+="$p:$soname "
  done < <(readelf -d "$b" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
done
# One dpkg -S for all of them (it is slow), each path also as /lib <-> /usr/lib (merged /usr).
cands=()
for path in "${!lib_users[@]}"; do
  cands+=("$path" "$(realpath "$path")" "${path/#\/usr\/lib\//\/lib\/}" "${path/#\/lib\//\/usr\/lib\/}")
done
while IFS= read -r line; do
  owner_of[${line#*: }]=${line%%[:,]*}
done < <(dpkg -S "${cands[@]}" 2>/dev/null)
declare -A lib_pkgs=()
for path in "${!lib_users[@]}"; do
  owner=""
  for cand in "$path" "$(realpath "$path")" "${path/#\/usr\/lib\//\/lib\/}" "${path/#\/lib\//\/usr\/lib\/}"; do
    owner=${owner_of[$cand]:-} && [[ -n $owner ]] && break
  done
  [[ -n $owner ]] || { fail "no Debian package owns $path (${lib_users[$path]% })"; continue; }
  lib_pkgs[$owner]+="${lib_users[$path]}"
done
# The names Depends gives (versions and alternatives dropped).
dep_names=" $(sed 's/([^)]*)//g; s/[,|]/ /g' <<<"$depends" | tr -s ' ') "
for pkg in "${!lib_pkgs[@]}"; do
  # The package itself, or a name it provides (libspdlog1.10 provides libspdlog1.10-fmt9, which its shlibs file names).
  names=("$pkg")
  read -ra provided <<<"$(dpkg-query -W -f='${Provides}' "$pkg" 2>/dev/null | sed 's/([^)]*)//g; s/,/ /g')"
  names+=("${provided[@]}")
  found=0
  for n in "${names[@]}"; do [[ $dep_names == *" $n "* ]] && found=1; done
  ((found)) || fail "Depends lacks ${names[*]} (needed by ${lib_pkgs[$pkg]% }; dpkg-shlibdeps did not run?)"
done
echo "packages of the libraries the programs link (each checked in Depends): $(printf '%s\n' "${!lib_pkgs[@]}" | sort | tr '\n' ' ')"
rm -rf "$work/deps-root"
for f in Maintainer Description Section Priority Installed-Size Homepage; do
  [[ -n $(field "$f") ]] || fail "control field $f empty"
done
dpkg-deb -e "$deb" "$work/control"
for s in postinst prerm postrm; do
  [[ -x $work/control/$s ]] || { fail "maintainer script $s missing or not executable"; continue; }
  sh -n "$work/control/$s" || fail "$s: syntax error"
done
[[ $(cat "$work/control/conffiles" 2>/dev/null) == /etc/canmotion/canmotiond.yaml ]] ||
  fail "conffiles: '$(cat "$work/control/conffiles" 2>/dev/null)', expected /etc/canmotion/canmotiond.yaml"
grep -q 'systemd-sysusers' "$work/control/postinst" || fail "postinst does not run systemd-sysusers"
grep -q 'udevadm control --reload' "$work/control/postinst" || fail "postinst does not reload udev's rules"
grep -q 'daemon-reload' "$work/control/postinst" || fail "postinst does not run daemon-reload"
grep -q '/run/systemd/system' "$work/control/postinst" || fail "postinst calls systemctl unguarded"

step "unpacked (dpkg -x) and run from the scratch root"
root=$work/root
dpkg -x "$deb" "$root"
for p in canmotiond canmotionctl cia402-emu cantrace rt-latency; do
  b=$root/usr/bin/$p
  if ldd "$b" | grep -q 'not found'; then ldd "$b"; fail "$p: missing shared libraries"; fi
  if readelf -d "$b" | grep -qE 'RPATH|RUNPATH'; then fail "$p: has an RPATH/RUNPATH"; fi
  if ldd "$b" | grep -qE "$build|canmotion"; then fail "$p: links a library of ours or from the build tree"; fi
  "$b" --help >"$work/$p.help" 2>&1 || fail "$p --help exited $?"
  grep -qi 'usage' "$work/$p.help" || fail "$p --help printed no usage"
  zcat "$root/usr/share/man/man1/$p.1.gz" >"$work/$p.1" 2>/dev/null || fail "$p.1.gz is not gzip"
  grep -q "^\.TH \"\{0,1\}${p^^}" "$work/$p.1" && grep -q '^\.SH OPTIONS' "$work/$p.1" ||
    fail "$p.1 is not the man page of $p"
done
echo "cantrace --help: $(head -1 "$work/cantrace.help")"
if out=$("$root/usr/bin/canmotiond" --sim --config "$root/usr/share/canmotion/examples/demo.yaml" --duration 1 2>&1); then
  grep -q '^summary: .* cycles' <<<"$out" || fail "canmotiond --sim printed no summary: $out"
  echo "canmotiond --sim --config <root>/usr/share/canmotion/examples/demo.yaml --duration 1: $(grep -m1 '^summary' <<<"$out")"
else
  echo "$out"; fail "installed canmotiond --sim --config demo.yaml --duration 1 failed"
fi
# The default configuration (the conffile): valid, no bus, and nothing moves.
if out=$("$root/usr/bin/canmotiond" --sim --config "$root/etc/canmotion/canmotiond.yaml" --duration 1 2>&1); then
  grep -q ' 0 buses' <<<"$out" || fail "the default configuration declares a bus: $out"
  moved=$(grep '^summary: axis' <<<"$out" | grep -vc 'final position 0.0000')
  [[ $moved == 0 ]] || fail "the default configuration moved an axis on its own: $out"
  echo "default /etc/canmotion/canmotiond.yaml: $(grep -m1 '^canmotiond:' <<<"$out"); no axis moved"
else
  echo "$out"; fail "installed canmotiond on the default configuration failed"
fi
# Units: ExecStart= names an installed program; its arguments pass --check-args
# (paths rewritten into the scratch root, $CIA402_EMU_ARGS from the example).
emu_args=$(sed -n 's/^CIA402_EMU_ARGS="\(.*\)"$/\1/p' "$root/usr/share/canmotion/examples/cia402-emu-example.conf")
for u in "$root$unitdir"/*.service; do
  while IFS= read -r line; do
    line=$(sed -E 's/^ExecStart=[-@:+!]*//' <<<"$line")
    line=${line//\$CIA402_EMU_ARGS/$emu_args}
    read -ra words <<<"$line"
    exe=${words[0]}
    [[ $exe == /* ]] || continue  # ip: the system's
    [[ -x $root$exe ]] || { fail "${u##*/}: ExecStart=$exe is not in the package"; continue; }
    args=()
    for a in "${words[@]:1}"; do if [[ $a == /* && -e $root$a ]]; then args+=("$root$a"); else args+=("$a"); fi; done
    if out=$("$root$exe" --check-args "${args[@]}" 2>&1); then
      echo "${u##*/}: ExecStart=$line: $out"
    else
      fail "${u##*/}: ExecStart=$line: --check-args failed: $out"
    fi
  done < <(grep '^ExecStart=' "$u")
done

step "systemd-analyze verify and security on the installed units"
units=$work/units
mkdir -p "$units"
cp "$root$unitdir"/*.service "$root$networkdir"/80-vcan0.* "$root/usr/share/canmotion/examples/cia402-emu-example.conf" "$units/"
"$src/systemd/verify-units.sh" "$units" || fail "verify-units.sh on the installed units"

step "maintainer scripts with DPKG_ROOT=<scratch root>"
if [[ $(id -u) != 0 ]]; then
  echo "skipped: not root (postinst sets ownership; run the test as root to check it)"
else
  mkdir -p "$root/var/lib/dpkg" "$root/var/lib/canmotion" "$root/var/log/canmotion"
  if DPKG_ROOT=$root sh "$work/control/postinst" configure; then
    grep -q '^canmotion:' "$root/etc/passwd" || fail "postinst: no user canmotion in the root's /etc/passwd"
    gid=$(awk -F: '$1 == "canmotion" { print $3 }' "$root/etc/group")
    [[ -n $gid ]] || fail "postinst: no group canmotion in the root's /etc/group"
    [[ $(stat -c '%a %u:%g' "$root/etc/canmotion") == "750 0:$gid" ]] ||
      fail "/etc/canmotion is $(stat -c '%a %u:%g' "$root/etc/canmotion"), expected 750 0:$gid"
    [[ $(stat -c '%a %u:%g' "$root/etc/canmotion/canmotiond.yaml") == "640 0:$gid" ]] ||
      fail "canmotiond.yaml is $(stat -c '%a %u:%g' "$root/etc/canmotion/canmotiond.yaml"), expected 640 0:$gid"
    echo "postinst configure: user and group canmotion (gid $gid), /etc/canmotion 0750, canmotiond.yaml 0640"
  else
    fail "postinst configure exited $?"
  fi
  DPKG_ROOT=$root sh "$work/control/prerm" remove || fail "prerm remove exited $?"
  DPKG_ROOT=$root sh "$work/control/postrm" remove || fail "postrm remove exited $?"
  DPKG_ROOT=$root sh "$work/control/postrm" purge || fail "postrm purge exited $?"
  [[ ! -e $root/var/lib/canmotion && ! -e $root/var/log/canmotion ]] || fail "postrm purge left /var/lib or /var/log/canmotion"
  echo "prerm remove, postrm remove and purge: ok"
fi

step done
total=$((($(date +%s%N) - t_start) / 1000000))
if [[ $fails -gt 0 ]]; then echo "package-test: $fails failure(s) ($total ms)"; exit 1; fi
echo "package-test: ok ($total ms)"
