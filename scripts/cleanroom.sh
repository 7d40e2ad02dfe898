#!/usr/bin/env bash
# Proves the README's quick start from scratch: its two commands, exactly as
# the README's "Quick start" block writes them, in a clone of this
# repository's HEAD inside a minimal Debian 12 root (debootstrap
# --variant=minbase bookworm), as root. Then the package: scripts/package.sh
# in that root builds the .deb, and a second fresh root installs it with apt
# (which pulls in its dependencies) and runs the installed
# /usr/bin/bouncecheck on the installed bundled scenarios: exit 0, every
# engine module found under /usr/lib/bouncecheck, none failing to load. Then
# the C++ API: examples/cmake-consumer, copied into that root, is built
# against the package with find_package(bouncecheck CONFIG) and tested.
# Prints each command's wall time and exit status; exits 1 if any failed, 2
# on a usage or set-up problem.
#
#   scripts/cleanroom.sh
#
# Run it as root on a Debian machine (debootstrap is installed if missing);
# it needs no systemd. The root is bootstrapped once from the Debian mirrors
# this machine's apt sources name, and cached as a tarball outside the clone:
#   CLEANROOM_CACHE   the cache folder (default /var/cache/bouncecheck-cleanroom);
#                     delete it for a cold run.
#   CLEANROOM_APT_CACHE  optional: a folder kept between runs for the .deb files
#                     apt downloads inside the root (the packages are still
#                     installed from scratch; only the download is skipped).
#   CLEANROOM_WORK    where the fresh root is unpacked (default /var/tmp);
#                     the root is removed afterwards.
#
# What the clean root takes from this machine, and nothing else:
#   - /etc/resolv.conf, to resolve the mirrors' and the npm registry's names;
#   - the extra CA certificates in /usr/local/share/ca-certificates/*.crt and
#     npm's global config /etc/npmrc, when they exist: a machine that reaches
#     the registries through a proxy with its own certificate authority needs
#     them inside the root too (they take effect once the quick start installs
#     Debian's ca-certificates package, as it does on a real machine);
#   - the proxy variables http_proxy, https_proxy and no_proxy, when set.
# The commands run with an otherwise empty environment.
#
# /proc, /sys and /dev are bind-mounted into the root for the commands and
# unmounted on every way out (Ctrl-C included). The root is deleted only once
# nothing is mounted under it; otherwise the script says so and leaves it.
set -euo pipefail

SUITE=bookworm
CACHE="${CLEANROOM_CACHE:-/var/cache/bouncecheck-cleanroom}"
WORK_PARENT="${CLEANROOM_WORK:-/var/tmp}"
WORK=""      # this run's folder; the roots are inside it
ROOTFS=""    # the quick start's root
ROOTS=()     # every root made, for cleanup
MOUNTED=()   # mount points made in the root, in order

say() { echo "cleanroom: $*"; }
die() { echo "cleanroom: $*" >&2; exit 2; }

# The README's two quick-start commands: the first indented block under
# "## Quick start", each line without its comment.
quick_start_commands() {
  awk '
    /^## / { in_section = ($0 == "## Quick start"); next }
    !in_section || done { next }
    /^    [^ ]/ { line = $0; sub(/^    /, "", line); sub(/[ \t]+#.*$/, "", line); print line; seen = 1; next }
    seen { done = 1 }
  ' "$1"
}

# The first URI this machine's apt sources give for a suite (one-line
# sources.list entries and deb822 .sources files alike).
mirror_for() {
  local suite="$1" f
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    # deb [options] URI SUITE COMPONENTS...
    awk -v s="$suite" '$1 == "deb" { gsub(/\[[^]]*\]/, ""); $0 = $0; if ($3 == s) print $2 }' "$f"
  done
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk -v s="$suite" '
      function flush() { if (types ~ /(^| )deb( |$)/ && (" " suites " ") ~ (" " s " ") && uri != "") print uri
                         types = ""; suites = ""; uri = "" }
      /^[ \t]*$/ { flush(); next }
      /^Types:/  { sub(/^Types:[ \t]*/, ""); types = $0 }
      /^Suites:/ { sub(/^Suites:[ \t]*/, ""); suites = $0 }
      /^URIs:/   { sub(/^URIs:[ \t]*/, ""); uri = $1 }
      END { flush() }' "$f"
  done | head -n 1
}

# Paths mounted at or under $1, deepest first (mountinfo field 5; octal
# escapes such as \040 for a space are left as they are: our paths have none).
mounts_under() { awk -v d="$1" '$5 == d || index($5, d "/") == 1 { print $5 }' /proc/self/mountinfo | sort -r; }

# Removes a folder only when nothing is mounted under it: rm -rf through a
# bind mount of /dev would delete the machine's own device nodes.
remove_tree() {
  local dir="$1"
  [ -n "$dir" ] && [ -e "$dir" ] || return 0
  if [ -n "$(mounts_under "$dir")" ]; then
    echo "cleanroom: NOT removing $dir: still mounted under it:" >&2
    mounts_under "$dir" >&2
    return 1
  fi
  rm -rf --one-file-system "$dir"
}

# Bootstraps the minimal Debian 12 root into the tarball $1, once.
bootstrap_root() {
  local tarball="$1" mirror security_mirror staging started
  mirror="$(mirror_for "$SUITE")"
  security_mirror="$(mirror_for "$SUITE-security")"
  [ -n "$mirror" ] || die "no apt source for $SUITE on this machine to bootstrap Debian 12 from"
  say "bootstrapping Debian 12 ($SUITE, minbase) from $mirror (once; cached as $tarball)"
  staging="$(mktemp -d "$CACHE/bootstrap.XXXXXX")"
  WORK="$staging"  # cleaned up on every way out, as a run's root is
  started=$SECONDS
  debootstrap --variant=minbase "$SUITE" "$staging/root" "$mirror" > "$staging/debootstrap.log" 2>&1 \
    || { tail -n 40 "$staging/debootstrap.log" >&2; die "debootstrap failed (log above)"; }
  # A fresh Debian 12 machine's apt sources: the release, its updates and
  # its security updates, from the same mirrors as this machine.
  {
    echo "deb $mirror $SUITE main"
    echo "deb $mirror $SUITE-updates main"
    [ -z "$security_mirror" ] || echo "deb $security_mirror $SUITE-security main"
  } > "$staging/root/etc/apt/sources.list"
  # No init system in a chroot: packages must not try to start services.
  printf '#!/bin/sh\nexit 101\n' > "$staging/root/usr/sbin/policy-rc.d"
  chmod 755 "$staging/root/usr/sbin/policy-rc.d"
  tar -C "$staging/root" --numeric-owner -czf "$staging/root.tar.gz" .
  mv "$staging/root.tar.gz" "$tarball"
  remove_tree "$staging"
  WORK=""
  say "bootstrapped in $((SECONDS - started)) s"
}

# Every way out: stop what still runs in the root, unmount, and delete the
# folder only if nothing is left mounted under it.
cleanup() {
  local link pid i
  local r
  for r in "${ROOTS[@]}"; do
    for link in /proc/[0-9]*/root; do
      [ "$(readlink "$link" 2>/dev/null)" = "$r" ] || continue
      pid="${link#/proc/}"
      kill -KILL "${pid%/root}" 2>/dev/null || true
    done
  done
  for ((i = ${#MOUNTED[@]} - 1; i >= 0; i--)); do
    umount -R "${MOUNTED[i]}" 2>/dev/null || umount -R -l "${MOUNTED[i]}" 2>/dev/null || true
  done
  remove_tree "$WORK" || true
}

# Runs $3 in the root $1 from its folder $2, timed; appends a line to RESULTS.
run_in_root() {
  local rootfs="$1" dir="$2" command="$3" started seconds status=0 environment var
  environment=(HOME=/root LANG=C.UTF-8 TERM="${TERM:-dumb}" PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin)
  for var in http_proxy https_proxy no_proxy HTTP_PROXY HTTPS_PROXY NO_PROXY; do
    [ -z "${!var:-}" ] || environment+=("$var=${!var}")
  done
  say "\$ $command"
  started=$(date +%s.%N)
  # In the background and waited for, so that a signal to this script is
  # handled at once (cleanup stops what runs in the root), not after it.
  chroot "$rootfs" /usr/bin/env -i "${environment[@]}" /bin/bash -c "cd $dir && $command" &
  wait $! || status=$?
  seconds=$(echo "$(date +%s.%N) $started" | awk '{ printf "%.0f", $1 - $2 }')
  RESULTS+=("$(printf '%-16s exit %d  %d min %02d s' "${4:-$command}" "$status" $((seconds / 60)) $((seconds % 60)))")
  return "$status"
}

# A fresh root at $1 from the tarball $2, with what it takes from this
# machine (see the opening comment) and /proc, /sys and /dev mounted.
make_root() {
  local rootfs="$1" tarball="$2" crt fs carried=()
  mkdir -p "$rootfs"
  ROOTS+=("$rootfs")
  tar -C "$rootfs" --numeric-owner -xzf "$tarball"
  cp -L /etc/resolv.conf "$rootfs/etc/resolv.conf"
  for crt in /usr/local/share/ca-certificates/*.crt; do
    [ -f "$crt" ] || continue
    mkdir -p "$rootfs/usr/local/share/ca-certificates"
    cp "$crt" "$rootfs/usr/local/share/ca-certificates/"
    carried+=("$crt")
  done
  [ ! -f /etc/npmrc ] || { cp /etc/npmrc "$rootfs/etc/npmrc"; carried+=(/etc/npmrc); }
  ((${#carried[@]} == 0)) || say "carried into $rootfs: ${carried[*]}"
  for fs in proc sys dev; do
    mkdir -p "$rootfs/$fs"
    MOUNTED+=("$rootfs/$fs")
    mount --rbind "/$fs" "$rootfs/$fs"
    mount --make-rslave "$rootfs/$fs"  # unmounting ours must not unmount the machine's
  done
  if [ -n "${CLEANROOM_APT_CACHE:-}" ]; then
    mkdir -p "$CLEANROOM_APT_CACHE"
    MOUNTED+=("$rootfs/var/cache/apt/archives")
    mount --bind "$CLEANROOM_APT_CACHE" "$rootfs/var/cache/apt/archives"
  fi
}

# In the installed root: the package's own binary, modules and scenarios.
INSTALLED_CHECK='set -e
bouncecheck list > list.txt
grep -q "^engine modules (/usr/lib/bouncecheck/engines):" list.txt || { cat list.txt; echo "modules not under /usr/lib/bouncecheck"; exit 1; }
! grep -q "(missing)" list.txt || { cat list.txt; echo "an engine module is missing"; exit 1; }
grep -q "^bundled scenarios (/usr/share/bouncecheck/scenarios):" list.txt || { cat list.txt; exit 1; }
bouncecheck run --out out > run.txt 2>&1 || { status=$?; cat run.txt; exit $status; }
! grep -q "cannot load" run.txt || { cat run.txt; echo "an engine did not load"; exit 1; }
grep -q "(node: /usr/lib/bouncecheck/node/jolt.mjs)" run.txt && ! grep -q "Node.js is not on PATH\|is missing: run scripts/setup.sh" run.txt \
  || { cat run.txt; echo "the Node-hosted engines did not run from /usr/lib/bouncecheck/node"; exit 1; }
test -f out/report.html && test -f /usr/share/man/man1/bouncecheck.1.gz
echo "installed bouncecheck: every module under /usr/lib/bouncecheck/engines, the Node-hosted engines under /usr/lib/bouncecheck/node, the bundled run exit 0"'

# In the installed root: examples/cmake-consumer built against the package
# with find_package(bouncecheck CONFIG) alone, its tests run (its wrong toy's
# failure among them, as a test that expects it), and the wrong toy run on
# its own: it must fail, showing the harness's table.
CONSUMER_CHECK='set -e
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends build-essential cmake libgtest-dev \
  libeigen3-dev libfmt-dev nlohmann-json3-dev libtomlplusplus-dev > apt-consumer.log 2>&1 || { tail -n 30 apt-consumer.log; exit 1; }
cmake -S cmake-consumer -B consumer-build > consumer.log 2>&1 || { cat consumer.log; exit 1; }
cmake --build consumer-build -j "$(nproc)" >> consumer.log 2>&1 || { tail -n 40 consumer.log; exit 1; }
ctest --test-dir consumer-build --output-on-failure
status=0
consumer-build/consumer_tests --gtest_also_run_disabled_tests --gtest_filter="*WrongAlpha*" > wrong.log 2>&1 || status=$?
[ "$status" -ne 0 ] && grep -q "apex err" wrong.log || { cat wrong.log; echo "the wrong toy did not fail with the table"; exit 1; }
echo "examples/cmake-consumer: built against the package, its tests pass, the wrong toy fails with the table"'

main() {
  local root commands tarball fs failed=0 deb
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
  (($# == 0)) || die "usage: scripts/cleanroom.sh (no arguments; see its opening comment)"
  [ "$(id -u)" -eq 0 ] || die "must run as root (debootstrap, chroot and mount need it)"
  command -v debootstrap >/dev/null || "$root/scripts/packages.sh" debootstrap
  for fs in git tar chroot mount umount flock; do
    command -v "$fs" >/dev/null || die "$fs is missing on this machine"
  done
  mapfile -t commands < <(quick_start_commands "$root/README.md")
  ((${#commands[@]} == 2)) || die "README.md's Quick start should hold exactly two commands, found ${#commands[@]}"
  git -C "$root" rev-parse --verify -q HEAD >/dev/null || die "$root has no commit to clone"

  trap cleanup EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  trap 'exit 129' HUP

  mkdir -p "$CACHE"
  tarball="$CACHE/debian12-minbase-$(dpkg --print-architecture).tar.gz"
  exec 9>"$CACHE/.lock"
  flock 9  # one bootstrap at a time; a second run waits, then finds the tarball
  if [ ! -f "$tarball" ]; then bootstrap_root "$tarball"; fi
  flock -u 9

  # A fresh root for this run.
  WORK="$(mktemp -d "$WORK_PARENT/bouncecheck-cleanroom.XXXXXX")"
  ROOTFS="$WORK/root"
  make_root "$ROOTFS" "$tarball"
  git clone -q "$root" "$ROOTFS/root/bouncecheck"
  say "clone of $(git -C "$ROOTFS/root/bouncecheck" rev-parse --short HEAD) at /root/bouncecheck in a fresh root ($WORK)"

  RESULTS=()
  for command in "${commands[@]}"; do
    run_in_root "$ROOTFS" /root/bouncecheck "$command" || failed=1
  done
  # The package, built where the quick start built, installed in a second fresh root.
  if ((failed == 0)) && run_in_root "$ROOTFS" /root/bouncecheck scripts/package.sh; then
    deb="$(ls "$ROOTFS"/root/bouncecheck/build/bouncecheck_*.deb | head -n 1)"
    make_root "$WORK/installed" "$tarball"
    cp "$deb" "$WORK/installed/root/"
    run_in_root "$WORK/installed" /root "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
      --no-install-recommends ./$(basename "$deb") > apt.log 2>&1 || { tail -n 30 apt.log; exit 1; }" \
      "apt-get install ./$(basename "$deb")" || failed=1
    ((failed == 0)) && { run_in_root "$WORK/installed" /root "$INSTALLED_CHECK" "installed bouncecheck run" || failed=1; }
    if ((failed == 0)); then
      cp -r "$ROOTFS/root/bouncecheck/examples/cmake-consumer" "$WORK/installed/root/cmake-consumer"
      run_in_root "$WORK/installed" /root "$CONSUMER_CHECK" "cmake-consumer" || failed=1
    fi
  else
    failed=1
  fi
  say "the README's quick start and the package on a fresh Debian 12 ($SUITE minbase):"
  printf '  %s\n' "${RESULTS[@]}"
  ((failed == 0)) || { say "FAILED"; exit 1; }
  say "passed"
}

# Defined whole before it runs: an edit to this file during a run (which
# takes minutes) cannot change what the run does.
main "$@"
