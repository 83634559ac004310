#!/usr/bin/env bash
# The Debian package end to end (issue 25, docs/packaging.md): cpack builds it from the tree already built; its
# contents are held to the source tree's install rules, its Depends to the libraries objdump finds in its binaries;
# lintian judges it; then it is installed with apt into a throwaway Debian chroot made by mmdebstrap from the
# archive, where the fleet's programs (colorlab-ship, colorlab-central) answer --help and --version, every unit
# passes systemd-analyze verify and none is enabled, the installed colorlabd runs its embedded simulated lab as the
# colorlab user and the installed colorlab runs a campaign; a second build with a higher version upgrades it (data
# and configuration kept); it is removed and purged, and the chroot's file list afterwards differs from before only
# by the measured data.
# Nothing outside build/packaging-test changes: the chroot has its own mount, PID and network namespaces.
#
#   deb_package_test.sh BUILD_DIR SOURCE_DIR CPACK
# Needs root. Exit 77 (skipped) without root outside CI; every missing tool fails.
set -euo pipefail
export LC_ALL=C  # sort orders, and so the chroot cache key, must not depend on the locale
export PATH="$PATH:/usr/sbin:/sbin"  # chroot, ip, ldconfig: root's tools, whatever PATH ctest was given
build=$(realpath "$1")
source_dir=$(realpath "$2")
cpack=$3
work=$build/packaging-test
root=$work/root

fail() { echo "FAIL: $*" >&2; exit 1; }
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
started=$(now)
step() { echo "== [$(elapsed "$started" "$(now)") s] $*"; }  # the offsets are docs/PERFORMANCE.md's breakdown
# shellcheck source=chroot.sh
source "$(dirname "$0")/chroot.sh"

if [[ $(id -u) -ne 0 ]]; then
  [[ -n ${CI:-} ]] && fail "needs root (mmdebstrap, chroot, mounts in a private namespace); CI runs as root"
  echo "SKIP: needs root (mmdebstrap, chroot, mounts in a private namespace)"
  exit 77
fi
for tool in "$cpack" dpkg-deb dpkg-shlibdeps dpkg-query mmdebstrap lintian unshare chroot ip objdump readelf ldconfig \
            sha256sum tar; do
  command -v "$tool" >/dev/null || fail "$tool is missing: scripts/setup.sh installs it (run it as root)"
done

mkdir -p "$work"
cleanup() {
  # The chroot's mounts live in namespaces that died with their processes; only files remain.
  [[ -d $root ]] && rm -rf --one-file-system "$root"
  return 0
}
trap cleanup EXIT

# --- 1. The package, twice: the second build, one Debian revision higher, is the upgrade. -------------------------
step "cpack: two builds of the package from $build"
rm -rf "$work/pkg"
t0=$(now)
"$cpack" --config "$build/CPackConfig.cmake" -B "$work/pkg/1" >"$work/cpack-1.log" 2>&1 ||
  { cat "$work/cpack-1.log"; fail "cpack failed"; }
t1=$(now)
"$cpack" --config "$build/CPackConfig.cmake" -B "$work/pkg/2" -D CPACK_DEBIAN_PACKAGE_RELEASE=2 \
  >"$work/cpack-2.log" 2>&1 || { cat "$work/cpack-2.log"; fail "cpack (second build) failed"; }
t2=$(now)
echo "building the package took $(elapsed "$t0" "$t1") s (the second build $(elapsed "$t1" "$t2") s)"
shopt -s nullglob
debs1=("$work"/pkg/1/colorlab_*.deb)
debs2=("$work"/pkg/2/colorlab_*.deb)
shopt -u nullglob
((${#debs1[@]} == 1 && ${#debs2[@]} == 1)) || fail "expected one colorlab_*.deb per build, got: ${debs1[*]} ${debs2[*]}"
deb1=${debs1[0]}
deb2=${debs2[0]}
v1=$(dpkg-deb -f "$deb1" Version)
v2=$(dpkg-deb -f "$deb2" Version)
dpkg --compare-versions "$v2" gt "$v1" || fail "the second build's version $v2 is not above $v1"
echo "packages: $(basename "$deb1") ($(du -k "$deb1" | cut -f1) KiB), $(basename "$deb2")"

# --- 2. Contents, against the source tree's install rules. ---------------------------------------------------------
step "contents"
x=$work/extracted
rm -rf "$x"
mkdir -p "$x"
dpkg-deb -x "$deb1" "$x"
files=$(cd "$x" && find . ! -type d | sed 's|^\.||' | sort)
has() { grep -qxF "$1" <<<"$files" || fail "the package lacks $1"; }

# Every executable an install(TARGETS …) rule names, in bin/ or sbin/ as the rule says.
executables=()
while read -r name dir; do
  case $dir in
    *SBINDIR*) path=/usr/sbin/$name ;;
    *BINDIR*) path=/usr/bin/$name ;;
    *) fail "install(TARGETS $name) into $dir: this test knows bin and sbin only" ;;
  esac
  has "$path"
  executables+=("$path")
done < <(grep -rhoE --include=CMakeLists.txt --include='*.cmake' --exclude-dir='build*' \
           'install\(TARGETS [^)]*\)' "$source_dir" |
         awk '{ dir = /SBINDIR/ ? "SBINDIR" : /BINDIR/ ? "BINDIR" : "unknown"
                for (i = 2; i <= NF && $i !~ /^(RUNTIME|DESTINATION|LIBRARY|ARCHIVE|COMPONENT|EXPORT|PERMISSIONS)$/; i++)
                  print $i, dir }' | sort -u)
((${#executables[@]} >= 3)) || fail "found only ${#executables[@]} install(TARGETS) rules in $source_dir"
for e in "${executables[@]}"; do
  [[ -x $x$e ]] || fail "$e is not executable"
  sections=$(readelf -S "$x$e")
  grep -qF .debug_info <<<"$sections" && fail "$e carries debug info (CPACK_STRIP_FILES)"
done
echo "executables: ${executables[*]}"

# The Python client's modules, the console's files and the shipped campaigns, each one from the source tree.
while read -r f; do has "/usr/lib/python3/dist-packages/$f"; done \
  < <(cd "$source_dir/client/python" && find colorlab -name '*.py' -not -path '*/__pycache__/*')
while read -r f; do has "/usr/share/colorlab/console/$f"; done \
  < <(cd "$source_dir/client/web" && find . -type f \( -name '*.html' -o -name '*.css' -o -name '*.js' -o -name '*.svg' \) |
      sed 's|^\./||')
for f in "$source_dir"/campaigns/scripts/*.lua; do has "/usr/share/colorlab/campaigns/$(basename "$f")"; done
shopt -s nullglob
for f in "$source_dir"/systemd/*.rules "$source_dir"/udev/*.rules; do has "/usr/lib/udev/rules.d/$(basename "$f")"; done
shopt -u nullglob
units=(colorlabd.service colorlab-ship.service colorlab-central.service)
for f in "${units[@]/#//usr/lib/systemd/system/}" /usr/share/doc/colorlab/fleet.md \
         /usr/lib/sysusers.d/colorlab.conf /usr/lib/tmpfiles.d/colorlab.conf \
         /usr/share/bash-completion/completions/colorlab /usr/share/colorlab/colorlabd.default.toml \
         /usr/share/doc/colorlab/copyright /usr/share/doc/colorlab/changelog.Debian.gz \
         /usr/share/lintian/overrides/colorlab; do
  has "$f"
done
outside=$(grep -v '^/usr/' <<<"$files" || true)
[[ -z $outside ]] || fail "files outside /usr (configuration is written by postinst): $outside"
grep -q '^/usr/local/' <<<"$files" && fail "files under /usr/local"
for exec_start in 'colorlabd.service /usr/sbin/colorlabd --config /etc/colorlab/colorlabd.toml' \
                  'colorlab-ship.service /usr/sbin/colorlab-ship --config /etc/colorlab/colorlabd.toml run' \
                  'colorlab-central.service /usr/sbin/colorlab-central --config /etc/colorlab/central.toml serve'; do
  unit=$x/usr/lib/systemd/system/${exec_start%% *}
  grep -qxF "ExecStart=${exec_start#* }" "$unit" ||
    fail "${exec_start%% *}'s ExecStart does not name the packaged program: $(grep ExecStart "$unit")"
done
leaked=$(grep -rlF "$build" "$x" --exclude-dir=bin --exclude-dir=sbin || true)
[[ -z $leaked ]] || fail "files naming the build tree $build: $leaked"
control=$(dpkg-deb --ctrl-tarfile "$deb1" | tar -tv)
for script in postinst prerm postrm; do
  grep -qE "^-rwxr-xr-x .* \./$script$" <<<"$control" || fail "no executable $script"
done

# --- 3. Dependencies: every library a binary needs comes from a package the Depends name. ---------------------------
step "dependencies"
depends=$(dpkg-deb -f "$deb1" Depends)
echo "Depends: $depends"
dep_names=$(tr ',|' '\n\n' <<<"$depends" | sed 's/(.*)//; s/[[:space:]]//g' | grep -v '^$' | sort -u)
for p in adduser colord-data python3 python3-numpy python3-pandas python3-requests; do
  grep -qx "$p" <<<"$dep_names" || fail "Depends lacks $p"
done
needed_pkgs=()
libraries=$(ldconfig -p | awk '/x86-64|x86_64/ { print $1, $NF }')
# Each library once, however many binaries need it: every dpkg -S reads dpkg's whole file database.
declare -A needed_by=()
while read -r elf; do
  while read -r soname; do
    [[ -n ${needed_by[$soname]:-} ]] || needed_by[$soname]=${elf#"$x"}
  done < <(objdump -p "$elf" | awk '$1 == "NEEDED" { print $2 }')
done < <(find "$x/usr/bin" "$x/usr/sbin" -type f)
declare -A candidates=()
for soname in "${!needed_by[@]}"; do
  lib=$(awk -v s="$soname" '$1 == s && !found { print $2; found = 1 }' <<<"$libraries")
  [[ -n $lib ]] || fail "${needed_by[$soname]} needs $soname, which this machine does not have"
  # The names dpkg may know it by: merged /usr, and the file behind the soname's link.
  candidates[$soname]="$lib $(realpath "$lib") /usr${lib#/usr} ${lib#/usr}"
done
# One dpkg -S for them all ("package[:arch][, …]: path" per file it knows; the rest it reports on stderr).
declare -A owner_of=()
while IFS= read -r line; do
  [[ $line == diversion* ]] && continue
  owner_of[${line##*: }]=${line%%[:,]*}
done < <(printf '%s\n' "${candidates[@]}" | tr ' ' '\n' | sort -u | xargs dpkg -S 2>/dev/null || true)
for soname in "${!needed_by[@]}"; do
  owner=""
  for candidate in ${candidates[$soname]}; do
    owner=${owner_of[$candidate]:-}
    [[ -n $owner ]] && break
  done
  [[ -n $owner ]] || fail "no Debian package owns any of ${candidates[$soname]} ($soname, needed by ${needed_by[$soname]})"
  needed_pkgs+=("$owner")
done
for p in $(printf '%s\n' "${needed_pkgs[@]}" | sort -u); do
  grep -qx "$p" <<<"$dep_names" || fail "the binaries need a library from $p, which Depends does not name"
done
echo "the binaries' libraries come from: $(printf '%s\n' "${needed_pkgs[@]}" | sort -u | tr '\n' ' ')"

# --- 4. lintian: no error or warning; every overridden tag is explained in docs/packaging.md. -----------------------
step "lintian"
lintian --fail-on error,warning --display-info "$deb1" | tee "$work/lintian.log" ||
  fail "lintian reports errors or warnings (above)"
while read -r tag; do
  grep -qF "$tag" "$source_dir/docs/packaging.md" || fail "lintian override $tag is not explained in docs/packaging.md"
done < <(sed -n 's/^colorlab: \([a-z0-9-]*\).*/\1/p' "$source_dir/packaging/deb/lintian-overrides" | sort -u)

# --- 5. The throwaway chroot: Debian 12 from the archive plus what the Depends name, cached as a tarball. -----------
step "chroot"
include="systemd,udev,$(paste -sd, <<<"$dep_names")"
sources=/etc/apt/sources.list.d/debian.sources
[[ -s $sources ]] || sources=/etc/apt/sources.list
[[ -s $sources ]] || fail "no apt sources on this machine to build the chroot from"
key=$( (echo "bookworm apt $include"; cat "$sources") | sha256sum | cut -c1-16)
base=$work/chroot-$key.tar
if [[ ! -s $base ]]; then
  rm -f "$work"/chroot-*.tar
  t=$(now)
  mmdebstrap --variant=apt --format=tar --include="$include" bookworm "$base.partial" "$sources" >"$work/mmdebstrap.log" 2>&1 ||
    { tail -40 "$work/mmdebstrap.log"; fail "mmdebstrap could not make the chroot (log: $work/mmdebstrap.log)"; }
  mv "$base.partial" "$base"
  echo "mmdebstrap made $(basename "$base") in $(elapsed "$t" "$(now)") s"
else
  echo "cached: $(basename "$base")"
fi
rm -rf --one-file-system "$root"
mkdir -p "$root"
tar -C "$root" --numeric-owner -xf "$base"
mkdir -p "$root/tmp/debs"
cp "$deb1" "$deb2" "$root/tmp/debs/"

before=$(listing)
cp "$(dirname "$0")/in_chroot.sh" "$root/tmp/colorlab-test.sh"

# --- 6. Install: the user, the configuration, the data directory; nothing started or enabled. ---------------------
step "install $(basename "$deb1") with apt in the chroot"
t=$(now)
in_chroot <<SH
source /tmp/colorlab-test.sh
apt-get install -y --no-install-recommends /tmp/debs/$(basename "$deb1")
[[ \$(dpkg-query -W -f '\${Status} \${Version}' colorlab) == "install ok installed $v1" ]] || fail "colorlab $v1 not installed"
getent passwd colorlab | grep -q ':/var/lib/colorlabd:/usr/sbin/nologin\$' || fail "user: \$(getent passwd colorlab)"
for g in colorlab dialout plugdev; do id -nG colorlab | tr ' ' '\n' | grep -qx \$g || fail "colorlab is not in group \$g"; done
[[ \$(stat -c '%U:%G %a' /etc/colorlab/colorlabd.toml) == "root:colorlab 640" ]] || fail "config: \$(stat -c '%U:%G %a' /etc/colorlab/colorlabd.toml)"
cmp /etc/colorlab/colorlabd.toml /usr/share/colorlab/colorlabd.default.toml || fail "the first configuration is not the default"
[[ \$(stat -c '%U:%G %a' \$state) == "colorlab:colorlab 750" ]] || fail "\$state: \$(stat -c '%U:%G %a' \$state)"
[[ -z \$(daemons_running) ]] || fail "installing started colorlabd or a fleet program"
[[ -z \$(find /etc/systemd/system -name 'colorlab*.service') ]] || fail "installing enabled a colorlab unit"
for b in ${executables[*]}; do
  ldd "\$b" | grep 'not found' && fail "\$b: libraries missing in a chroot holding only what Depends names"
  true
done
python3 -c 'import colorlab; print("python client", colorlab.__version__)'
# The fleet's programs run, and their units are valid for this systemd (a unit an older or newer systemd would
# half-ignore only warns, hence "no output at all") and installed, not enabled: a bench without a fleet never
# starts them.
for p in colorlab-ship colorlab-central; do
  help=\$(/usr/sbin/\$p --help) || fail "\$p --help failed: \$help"
  grep -q -- --config <<<"\$help" || fail "\$p --help names no --config: \$help"
  [[ \$(/usr/sbin/\$p --version) == "\$p ${v1%-*}" ]] || fail "\$p --version: \$(/usr/sbin/\$p --version 2>&1)"
done
for u in ${units[*]}; do
  out=\$(systemd-analyze verify /usr/lib/systemd/system/\$u 2>&1) || fail "systemd-analyze verify \$u: \$out"
  [[ -z \$out ]] || fail "systemd-analyze verify \$u warns: \$out"
  [[ \$(systemctl is-enabled \$u || true) == disabled ]] || fail "\$u is \$(systemctl is-enabled \$u) after install"
done
bash -c 'source /usr/share/bash-completion/completions/colorlab && declare -F _colorlab >/dev/null' || fail "bash completion"
SH
echo "install took $(elapsed "$t" "$(now)") s"

# --- 7. The installed daemon on its embedded simulated lab, as the colorlab user; a campaign through the CLI. -------
step "colorlabd and a luminance-spot campaign in the chroot"
in_chroot <<SH
source /tmp/colorlab-test.sh
# The admin's own configuration: the simulated lab instead of the example's LS-110.
cat >/etc/colorlab/colorlabd.toml <<'TOML'
# this lab's configuration (written by tests/packaging/deb_package_test.sh)
state_dir = "/var/lib/colorlabd"
listen = "127.0.0.1:8765"
[simulator]
enabled = true
seed = 1
TOML
sha256sum /etc/colorlab/colorlabd.toml >/var/tmp/colorlab-config.sha256
start_daemon
[[ \$(cli status | json 'd["simulated_lab"]') == True ]] || fail "colorlabd does not run the simulated lab"
run=\$(cli run luminance-spot -p readings=3)
[[ \$(json 'd["status"]' <<<"\$run") == finished_ok ]] || fail "luminance-spot: \$run"
[[ \$(json 'd["summary"]["script"]["readings"]' <<<"\$run") == 3 ]] || fail "luminance-spot did not take 3 readings: \$run"
json 'd["id"]' <<<"\$run" >/var/tmp/colorlab-run-id
stop_daemon
echo "run \$(cat /var/tmp/colorlab-run-id) finished_ok"
SH
run_id=$(cat "$root/var/tmp/colorlab-run-id")
rm -f "$root/var/tmp/colorlab-run-id"
[[ -s $root/var/lib/colorlabd/colorlab.db ]] || fail "no colorlab.db in /var/lib/colorlabd after the run"

# --- 8. Upgrade to the second build: configuration and data kept, the run still there. -----------------------------
step "upgrade to $(basename "$deb2")"
in_chroot <<SH
source /tmp/colorlab-test.sh
apt-get install -y --no-install-recommends /tmp/debs/$(basename "$deb2")
[[ \$(dpkg-query -W -f '\${Version}' colorlab) == "$v2" ]] || fail "not upgraded to $v2"
sha256sum -c --quiet /var/tmp/colorlab-config.sha256 || fail "the upgrade changed the admin's configuration"
[[ -z \$(daemons_running) ]] || fail "the upgrade started colorlabd"
start_daemon
cli runs | json '[r["id"] for r in d["items"]]' | grep -qF "$run_id" || fail "run $run_id gone after the upgrade"
[[ \$(cli show "$run_id" | json 'd["status"]') == finished_ok ]] || fail "run $run_id unreadable after the upgrade"
stop_daemon
rm /var/tmp/colorlab-config.sha256
SH

# --- 9. Remove keeps the configuration; purge removes it and keeps the data. --------------------------------------
step "remove, then purge"
in_chroot <<SH
source /tmp/colorlab-test.sh
apt-get remove -y colorlab
[[ \$(dpkg-query -W -f '\${Status}' colorlab) == "deinstall ok config-files" ]] || fail "after remove: \$(dpkg-query -W -f '\${Status}' colorlab)"
[[ ! -e /usr/sbin/colorlabd && -e /etc/colorlab/colorlabd.toml && -s \$state/colorlab.db ]] || fail "remove: wrong files left"
apt-get purge -y colorlab
dpkg-query -W colorlab 2>/dev/null && fail "dpkg still knows colorlab after purge"
[[ ! -e /etc/colorlab ]] || fail "purge left /etc/colorlab"
[[ -s \$state/colorlab.db ]] || fail "purge removed the measured data"
getent passwd colorlab >/dev/null || fail "purge removed the user that owns the kept data"
true
SH
after=$(listing)
left=$(comm -13 <(echo "$before") <(echo "$after"))
gone=$(comm -23 <(echo "$before") <(echo "$after"))
# What may differ: the kept data, and the account databases' backups adduser and systemd-sysusers write.
unexpected=$(grep -vE '^\./var/lib/colorlabd(/|$)|^\./etc/(passwd|group|shadow|gshadow)-$' <<<"$left" || true)
[[ -z $unexpected && -z $gone ]] || fail "after purge the chroot differs from before install by more than the data:
left: $unexpected
gone: $gone"
echo "after purge, only the data is left: $(grep -c . <<<"$left") paths under /var/lib/colorlabd and account backups"

# --- 10. The adduser fallback (no systemd-sysusers), and purge with the flag file that drops the data. ------------
step "reinstall without systemd-sysusers, purge with /etc/colorlab/purge-measured-data"
in_chroot <<SH
source /tmp/colorlab-test.sh
userdel colorlab
getent group colorlab >/dev/null && groupdel colorlab
dpkg-divert --quiet --local --rename --add /usr/bin/systemd-sysusers
command -v systemd-sysusers && fail "systemd-sysusers still present"
apt-get install -y --no-install-recommends /tmp/debs/$(basename "$deb2")
getent passwd colorlab | grep -q ':/var/lib/colorlabd:/usr/sbin/nologin\$' || fail "adduser fallback: \$(getent passwd colorlab)"
for g in colorlab dialout plugdev; do id -nG colorlab | tr ' ' '\n' | grep -qx \$g || fail "adduser fallback: not in \$g"; done
touch /etc/colorlab/purge-measured-data
apt-get purge -y colorlab
[[ ! -e \$state && ! -e /etc/colorlab ]] || fail "purge with the flag file kept \$state or /etc/colorlab"
dpkg-divert --quiet --local --rename --remove /usr/bin/systemd-sysusers
SH
step "PASS"
