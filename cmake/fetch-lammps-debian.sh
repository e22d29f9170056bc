#!/usr/bin/env bash
# Obtain a supported LAMMPS release from Debian's source package and unpack it.
#
#   fetch-lammps-debian.sh <cache-dir> [<release>]
#
#   release   20260704 (default: 4Jul2026, Debian forky/sid)   20250204 (4Feb2025, Debian trixie)
#
# Uses a private apt configuration (a deb-src entry for the release's suite, with the archive URI
# taken from this machine's own apt sources), so the system's apt state is untouched.
# The orig tarball is verified by sha256 (apt-get may fail on the .dsc and still exit 0).
# The unpacked tree is moved into place only after every check passed, and a stamp file
# written last marks it as complete: a later build trusts the tree only with the stamp.
set -euo pipefail

release=${2:-20260704}
case $release in
  20260704)
    suite=sid
    DEB_VERSION="20260704+dfsg-2"
    ORIG_TARBALL="lammps_20260704+dfsg.orig.tar.gz"
    sha=cddbc45a047416bd48a4a0b87f24a5b61b3446982b74d18cafe619c22b17eb62 ;;
  20250204)
    suite=trixie
    DEB_VERSION="20250204+dfsg.1-2"
    ORIG_TARBALL="lammps_20250204+dfsg.1.orig.tar.xz"
    sha=3671165bd52fad36734e0a9136c5bc5ecb225e03988f8c89aa13366a8b53b1c7 ;;
  *)
    echo "ERROR: LAMMPS release '$release' is not supported; supported: 20260704 (4Jul2026), 20250204 (4Feb2025)" >&2
    exit 1 ;;
esac
# GC_LAMMPS_ORIG_SHA256 exists only to exercise the checksum-failure path (doc/build.md)
readonly ORIG_SHA256="${GC_LAMMPS_ORIG_SHA256:-$sha}"
readonly TREE_NAME="lammps-$release"

fail() {
  local step=$1; shift
  {
    echo "ERROR: obtaining LAMMPS from Debian failed at step '${step}': $*"
    echo "  Instead, point the build at your own LAMMPS checkout (4Feb2025 or 4Jul2026):"
    echo "    cmake -S . -B build -D LAMMPS_SOURCE_DIR=/path/to/lammps"
    echo "  or: make test LAMMPS_SOURCE_DIR=/path/to/lammps"
  } >&2
  exit 1
}

[[ $# -ge 1 && $# -le 2 ]] || fail "arguments" "usage: $0 <cache-dir> [20260704|20250204]"
cache=$1
mkdir -p "$cache" || fail "create cache" "cannot create $cache"
cache=$(cd "$cache" && pwd)
tree="$cache/$TREE_NAME"
stamp="$tree/.granular-charged-complete"

if [[ -f $stamp ]]; then
  echo "$tree"
  exit 0
fi
# a tree without stamp is a leftover of an interrupted run: never trust it
rm -rf "$tree"

command -v apt-get >/dev/null || fail "apt-get" "apt-get not found (not a Debian system?)"

mirror=${LAMMPS_DEBIAN_MIRROR:-}
if [[ -z $mirror ]]; then
  # first Debian archive URI (not the security archive) from the machine's apt sources
  mirror=$( { cat /etc/apt/sources.list.d/*.sources 2>/dev/null | sed -n 's/^URIs:[[:space:]]*//p' | tr ' ' '\n'
              cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null \
                | sed -n 's/^deb\(-src\)\?[[:space:]]\+\(\[[^]]*\][[:space:]]\+\)\?\([^[:space:]]\+\).*/\3/p'; } \
            | grep -E '/debian/?$' | grep -v security | head -n 1 || true)
fi
[[ -n $mirror ]] || fail "find archive URI" \
  "no Debian archive URI in /etc/apt/sources.list*; set LAMMPS_DEBIAN_MIRROR=http://<host>/debian"

work="$cache/.fetch.$$"
rm -rf "$work"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lists/partial" "$work/download" "$work/unpack"
echo "deb-src [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $mirror $suite main" \
  > "$work/sources.list"
apt_opts=(-o "Dir::Etc::SourceList=$work/sources.list" -o "Dir::Etc::SourceParts=/dev/null"
          -o "Dir::State::Lists=$work/lists" -o "APT::Get::List-Cleanup=0"
          -o "APT::Sandbox::User=root")

echo "-- LAMMPS: reading the $suite source index from $mirror" >&2
apt-get "${apt_opts[@]}" -q update >&2 || fail "apt-get update (deb-src $suite at $mirror)" \
  "the archive could not be reached"
# apt-get update exits 0 even when every fetch failed: the source index must be there
compgen -G "$work/lists/*Sources*" >/dev/null || fail "apt-get update (deb-src $suite at $mirror)" \
  "no source index was downloaded (archive unreachable, or no $suite suite there)"
echo "-- LAMMPS: downloading source package lammps=$DEB_VERSION" >&2
# apt-get may report a missing .dsc (HTTP 404) yet have the tarball: the checksum decides
(cd "$work/download" && apt-get "${apt_opts[@]}" -q source --download-only "lammps=$DEB_VERSION" >&2) || true
[[ -f "$work/download/$ORIG_TARBALL" ]] || fail "apt-get source lammps=$DEB_VERSION" \
  "$ORIG_TARBALL was not downloaded"
sum=$(sha256sum "$work/download/$ORIG_TARBALL" | cut -d' ' -f1)
[[ $sum == "$ORIG_SHA256" ]] || fail "verify sha256 of $ORIG_TARBALL" \
  "got $sum, expected $ORIG_SHA256"
echo "-- LAMMPS: sha256 verified, unpacking" >&2
tar -xf "$work/download/$ORIG_TARBALL" -C "$work/unpack" || fail "unpack $ORIG_TARBALL" "tar failed"
# the 4Feb2025 tarball has one top-level folder, the 4Jul2026 one has the tree at its top
src="$work/unpack"
if [[ ! -d $src/src && $(find "$src" -mindepth 1 -maxdepth 1 | wc -l) -eq 1 ]]; then
  src=$(find "$src" -mindepth 1 -maxdepth 1 -type d)
fi
for f in cmake/CMakeLists.txt src/version.h src/GRANULAR/granular_model.h python/lammps/core.py; do
  [[ -f "$src/$f" ]] || fail "check unpacked tree" "$f is missing"
done
mv "$src" "$tree"
date -u +"%Y-%m-%dT%H:%M:%SZ $ORIG_SHA256" > "$stamp"
echo "$tree"
