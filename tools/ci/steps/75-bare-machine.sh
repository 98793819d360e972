#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The main job on a bare Debian 12: a minimal root (debootstrap, variant
# minbase) gets a clean checkout of HEAD and runs the README's main-job command
# under chroot, as root, exactly as a new user would on a fresh machine. Passes
# when the command passes and the packages it installed are those of the 'sim'
# profile (tools/setup/deps.sh) and their dependencies, nothing else.
#
# The root is built once and cached under HRG_BARE_CACHE (default
# /var/cache/hrg-bare), keyed by the suite, the variant and this step's package
# list; every run works on a fresh copy. Next to it are kept apt's downloaded
# packages (apt-get still resolves and installs every package; it only skips
# downloading a .deb it already has). The build inside uses the host's compiler
# cache (ccache's own: same compiler, same headers, same paths give the same
# object) with the checkout at the host's path; without ccache on the host it
# gets its own cache next to the root. Neither changes what is installed or
# built, both shorten the run.
set -euo pipefail
[ "$(id -u)" -eq 0 ] || { echo "bare-machine: needs root (debootstrap, chroot)" >&2; exit 1; }
command -v debootstrap >/dev/null ||
  { echo "bare-machine: debootstrap missing (apt-get install debootstrap)" >&2; exit 1; }

suite=bookworm
variant=minbase
extra_pkgs=()  # nothing beyond minbase: the main job must bring what it needs
cache=${HRG_BARE_CACHE:-/var/cache/hrg-bare}
work=${HRG_BARE_DIR:-build/bare}
src=$(pwd)

# The host's Debian mirror (the first deb.debian.org-style URI of its sources).
mirror=$(sed -n 's/^URIs: *\(http[^ ]*\/debian\)\/*$/\1/p' /etc/apt/sources.list.d/*.sources \
  2>/dev/null | head -n 1)
mirror=${mirror:-http://deb.debian.org/debian}

key=$(printf '%s\n' "$suite" "$variant" "${extra_pkgs[@]}" | sha256sum | cut -c1-16)
base="$cache/root-$suite-$variant-$key"
if [ ! -x "$base/bin/bash" ]; then
  echo "bare-machine: building the $suite $variant root from $mirror (once, cached in $base)"
  t0=$(date +%s)
  rm -rf "$base.tmp"
  mkdir -p "$cache"
  include=()
  [ ${#extra_pkgs[@]} -gt 0 ] && include=(--include="$(IFS=,; echo "${extra_pkgs[*]}")")
  debootstrap --variant="$variant" "${include[@]}" "$suite" "$base.tmp" "$mirror" \
    >"$cache/debootstrap.log" 2>&1 || { tail -n 20 "$cache/debootstrap.log" >&2; exit 1; }
  rm -rf "$base.tmp/var/cache/apt/archives/"*.deb
  mv "$base.tmp" "$base"
  echo "bare-machine: root built in $(( $(date +%s) - t0 )) s"
fi

# A fresh copy of the root for this run; mounts are undone on any exit.
root="$work/root"
unmount_all() {
  for m in dev/pts dev proc var/cache/ccache var/cache/apt/archives ""; do
    mountpoint -q "$root/$m" 2>/dev/null && umount "$root/$m" || true
  done
}
trap unmount_all EXIT
unmount_all
# Never delete through a mount that is still there (/dev, the caches).
if grep -q " $(realpath -m "$root")[/ ]" /proc/mounts; then
  echo "bare-machine: mounts remain under $root; unmount them first" >&2
  exit 1
fi
rm -rf "$work"
mkdir -p "$work"
# In memory when there is room (1.5 GB once the profile is installed): the
# unpacking is faster and the root is gone when it is unmounted.
mkdir -p "$root"
avail_kb=$(awk '/^MemAvailable:/ {print $2}' /proc/meminfo)
if [ "${avail_kb:-0}" -gt $(( 6 * 1024 * 1024 )) ]; then
  mount -t tmpfs -o size=4g,mode=0755 hrg-bare "$root"
fi
t0=$(date +%s)
cp -a "$base/." "$root/"
echo "bare-machine: root copied in $(( $(date +%s) - t0 )) s ($(du -sh "$root" | cut -f1))"

# apt-get inside reaches Debian's mirror as the host does.
rm -f "$root/etc/apt/sources.list"
cp /etc/apt/sources.list.d/*.sources "$root/etc/apt/sources.list.d/" 2>/dev/null || true
[ -f /etc/apt/sources.list ] && cp /etc/apt/sources.list "$root/etc/apt/"
cp -L /etc/resolv.conf "$root/etc/resolv.conf"
printf '#!/bin/sh\nexit 101\n' >"$root/usr/sbin/policy-rc.d"  # no daemons start in the root
# A throwaway root needs no fsync per unpacked file (as sbuild/pbuilder do).
echo force-unsafe-io >"$root/etc/dpkg/dpkg.cfg.d/hrg-unsafe-io"
chmod +x "$root/usr/sbin/policy-rc.d"

# The clean checkout: HEAD as committed, nothing of this working tree, at the
# host's path.
mkdir -p "$root$src"
git -C "$src" archive --format=tar HEAD | tar -x -C "$root$src"

ccache_dir=$(ccache --get-config cache_dir 2>/dev/null || true)
[ -n "$ccache_dir" ] || ccache_dir="$cache/ccache"
mkdir -p "$ccache_dir" "$root/var/cache/ccache" "$cache/apt-archives/partial"
mount --bind "$ccache_dir" "$root/var/cache/ccache"
mount --bind "$cache/apt-archives" "$root/var/cache/apt/archives"
mount -t proc proc "$root/proc"
mount --bind /dev "$root/dev"
mount --bind /dev/pts "$root/dev/pts"

in_root() {
  chroot "$root" /usr/bin/env -i PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    HOME=/root LANG=C.UTF-8 TERM=dumb CCACHE_DIR=/var/cache/ccache \
    CCACHE_BASEDIR="${CCACHE_BASEDIR:-}" /bin/bash -c "$1"
}
packages() { in_root "dpkg-query -W -f='\${Package}\n' | sort"; }
manual() { in_root "apt-mark showmanual | sort"; }

# The README's main job: the first indented line after 'The main job'.
command=$(sed -n '/^The main job/,/^    \.\//p' README.md | sed -n 's/^    //p' | head -n 1)
[ -n "$command" ] || { echo "bare-machine: no main-job command found in README.md" >&2; exit 1; }
packages >"$work/packages-before"
manual >"$work/manual-before"
echo "bare-machine: running '$command' in the bare root"
# Each line of the log carries the seconds since the start: the install, the
# build and the run are told apart.
stamp() {
  local line
  while IFS= read -r line; do printf '%4d s  %s\n' $(( $(date +%s) - $1 )) "$line"; done
}
t0=$(date +%s)
set +e
in_root "cd '$src' && $command" 2>&1 | stamp "$t0" >"$work/main-job.log"
status=${PIPESTATUS[0]}
set -e
echo "bare-machine: main job exit status $status in $(( $(date +%s) - t0 )) s (log: $work/main-job.log)"
if [ "$status" -ne 0 ]; then
  tail -n 40 "$work/main-job.log" >&2
  exit 1
fi
grep -E '^ *[0-9]+ s  (deps:|hrg sim: .*simulated s)' "$work/main-job.log" || true

# What the main job installed: the packages asked for by name must be exactly
# the sim profile's (less those minbase already has); all others came as
# their dependencies.
packages >"$work/packages-after"
manual >"$work/manual-after"
comm -13 "$work/packages-before" "$work/packages-after" >"$work/installed"
comm -13 "$work/manual-before" "$work/manual-after" >"$work/installed-by-name"
tools/setup/deps.sh --list sim | sort >"$work/profile"
comm -23 "$work/profile" "$work/packages-before" >"$work/profile-missing-before"
echo "bare-machine: installed $(wc -l <"$work/installed") packages," \
  "$(wc -l <"$work/installed-by-name") by name: $(tr '\n' ' ' <"$work/installed-by-name")"
if ! cmp -s "$work/installed-by-name" "$work/profile-missing-before"; then
  echo "bare-machine: the packages installed by name differ from the sim profile:" >&2
  diff "$work/profile-missing-before" "$work/installed-by-name" >&2 || true
  exit 1
fi
[ -s "$work/installed" ] || { echo "bare-machine: nothing was installed (not a bare root?)" >&2; exit 1; }
# What the README says the main job writes, plots included (matplotlib).
for f in report.json telemetry.csv bias.csv allan.csv angle_error.png bias_vs_angle.png; do
  [ -s "$root$src/sim-out/$f" ] || { echo "bare-machine: sim-out/$f missing" >&2; exit 1; }
done
echo "bare-machine: ok: the main job passes on a bare $suite with the sim profile alone"
