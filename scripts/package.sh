#!/usr/bin/env bash
# Builds the Debian package: $BUILD_DIR/bouncecheck_<version>_<arch>.deb
# (default build/), with every engine the build has, the bundled scenarios,
# the docs and the man page (help2man, from `bouncecheck --help`). Its
# dependencies are read from the libraries the binary and the engine modules
# link (dpkg-shlibdeps), so `apt-get install ./bouncecheck_*.deb` on a fresh
# Debian 12 pulls in each engine's runtime package. Arguments go to the
# configure step, as for scripts/setup.sh (e.g. -DBOUNCECHECK_WITH_DART=OFF
# for a package without DART and its dependencies). Prints the package's path.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build}"
export BUILD_DIR

# help2man writes the man page; dpkg-dev has dpkg-shlibdeps; CPack's DEB
# generator runs `file` on every installed file to find the ones
# dpkg-shlibdeps reads (a minimal Debian has no `file`).
"$ROOT/scripts/packages.sh" help2man dpkg-dev file
"$ROOT/scripts/setup.sh" "$@"
(cd "$BUILD_DIR" && cpack -G DEB > "$BUILD_DIR/package.log" 2>&1) || { cat "$BUILD_DIR/package.log"; exit 1; }
deb="$(ls -t "$BUILD_DIR"/bouncecheck_*_"$(dpkg --print-architecture)".deb | head -n 1)"
dpkg-deb --field "$deb" Depends | sed 's/^/package depends on: /'
echo "$deb"
