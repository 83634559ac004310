# shellcheck shell=bash
# Sourced by deb_package_test.sh: the throwaway chroot at $root (set there), entered in namespaces of its own.
# shellcheck disable=SC2154

# Runs the script on stdin as root in the chroot, with /proc, a private /dev/pts and /run and its own loopback.
in_chroot() {
  unshare --mount --pid --net --fork --kill-child -- bash -c '
    set -e
    root=$1
    ip link set lo up
    mount -t proc proc "$root/proc"
    mount -t devpts -o newinstance,ptmxmode=0666,mode=0620,gid=5 devpts "$root/dev/pts"
    [ -L "$root/dev/ptmx" ] || mount --bind "$root/dev/pts/ptmx" "$root/dev/ptmx"
    mount -t tmpfs -o mode=0755 tmpfs "$root/run"
    exec chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LC_ALL=C.UTF-8 \
      DEBIAN_FRONTEND=noninteractive bash -s' _ "$root"
}
# File names in the chroot, without what dpkg, apt and the kernel keep for themselves.
listing() {
  (cd "$root" && find . -xdev \( -path ./proc -o -path ./dev -o -path ./run -o -path ./tmp -o -path ./var/lib/dpkg \
     -o -path ./var/lib/apt -o -path ./var/cache/apt -o -path ./var/cache/debconf -o -path ./var/cache/ldconfig \
     -o -path ./var/log/apt -o -path ./var/log/dpkg.log \) -prune -o -print | sort)
}
