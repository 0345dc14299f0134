#!/usr/bin/env bash
# Build r.stone (GRASS GIS add-on, GPL-2.0-or-later) into the local GRASS GIS, for
# tests/export/test_rstone_real.py (see README.md beside this script).
#
#   tools/r.stone/install.sh            # install GRASS if it can, build r.stone
#   tools/r.stone/install.sh --force    # rebuild an r.stone already there
#
# Without GRASS and without the rights to install it (root and apt-get), it says
# why and exits 0: the tests that need r.stone are then skipped, with the reason.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
force="${1:-}"

can_apt() { [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; }

apt_install() {
    echo "install.sh: apt-get install $*"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$@"
}

if ! command -v grass >/dev/null 2>&1; then
    if can_apt; then
        apt_install grass-core grass-dev gdal-bin make gcc libc6-dev
    else
        echo "install.sh: GRASS GIS is not installed and cannot be (needs root and" \
             "apt-get): r.stone not built; tests/export/test_rstone_real.py will skip"
        exit 0
    fi
fi
topdir="$(grass --config path)"
if [ ! -f "$topdir/include/Make/Module.make" ]; then
    if can_apt; then
        apt_install grass-dev make gcc libc6-dev
    else
        echo "install.sh: grass-dev (GRASS's build files) is not installed and" \
             "cannot be: r.stone not built; tests/export/test_rstone_real.py will skip"
        exit 0
    fi
fi
program="$topdir/bin/r.stone"
if [ -x "$program" ] && [ "$force" != "--force" ]; then
    echo "install.sh: r.stone already built: $program (--force rebuilds)"
    exit 0
fi
if [ ! -w "$topdir/bin" ]; then
    echo "install.sh: cannot write $topdir/bin (run as root): r.stone not built;" \
         "tests/export/test_rstone_real.py will skip"
    exit 0
fi
build="$(mktemp -d)"
trap 'rm -rf "$build"' EXIT
cp "$here"/*.c "$here"/*.h "$here"/Makefile "$build"/
touch "$build/.started"
# The last step, the HTML manual ("No rule to make target .../r.stone.html"),
# fails with Debian's packages after the program is linked: harmless.
make -C "$build" MODULE_TOPDIR="$topdir" >"$build/make.log" 2>&1 || true
if [ ! -x "$program" ] || [ ! "$program" -nt "$build/.started" ]; then
    tail -n 30 "$build/make.log" >&2
    echo "install.sh: the build did not produce $program" >&2
    exit 1
fi
echo "install.sh: built $program"
