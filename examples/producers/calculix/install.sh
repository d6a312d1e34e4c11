#!/usr/bin/env bash
# Build CalculiX ccx 2.20 from Debian's source package with infsup-contact's dump of the mortar
# coupling (infsup_dump.c, inserted into contactmortar.c at located anchors), for
# examples/producers/calculix/export.py. Run by `make producers-calculix` (root: apt).
#
#   examples/producers/calculix/install.sh [BUILD_DIR]     (default: .calculix in the repository)
#
# The fetched source stays in BUILD_DIR/src (git-ignored, never committed); the binary is
# BUILD_DIR/bin/ccx_infsup. Steps: deb-src for bookworm main in a sources file of our own,
# apt-get build-dep, apt-get source, the insertion (fails loudly when an anchor is missing),
# the package's own Makefile with Debian's defines (-DSPOOLES -DARPACK -DMATRIXSTORAGE -DUSE_MT=1).
set -euo pipefail

VERSION=2.20
HERE="$(cd "$(dirname "$0")" && pwd)"
BUILD="$(mkdir -p "${1:-$HERE/../../../.calculix}" && cd "${1:-$HERE/../../../.calculix}" && pwd)"
SOURCES=/etc/apt/sources.list.d/infsup-deb-src.sources
say() { echo "producers-calculix: $*"; }

if [ -x "$BUILD/bin/ccx_infsup" ] && [ "$BUILD/bin/ccx_infsup" -nt "$HERE/infsup_dump.c" ] \
   && [ "$BUILD/bin/ccx_infsup" -nt "$HERE/install.sh" ]; then
  say "$BUILD/bin/ccx_infsup is up to date"; exit 0
fi
[ "$(id -u)" = 0 ] || { echo "producers-calculix: needs root (apt-get build-dep, apt-get source)" >&2; exit 1; }

say "[1/5] deb-src for Debian bookworm main ($SOURCES)"
if ! apt-cache showsrc "calculix-ccx=$VERSION-1" 2>/dev/null | grep -q "^Version: $VERSION-1"; then
  cat > "$SOURCES" <<'EOF'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  apt-get update -qq
fi

say "[2/5] build dependencies (apt-get build-dep calculix-ccx)"
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends dpkg-dev make >/dev/null
DEBIAN_FRONTEND=noninteractive apt-get build-dep -y -qq calculix-ccx >/dev/null

say "[3/5] Debian's source package calculix-ccx $VERSION-1 into $BUILD/src"
rm -rf "$BUILD/src" && mkdir -p "$BUILD/src" "$BUILD/bin"
(cd "$BUILD/src" && apt-get source -qq "calculix-ccx=$VERSION-1" >/dev/null 2>&1)
SRC="$BUILD/src/calculix-ccx-$VERSION/ccx_$VERSION/src"
[ -f "$SRC/contactmortar.c" ] || { echo "producers-calculix: $SRC/contactmortar.c missing after apt-get source" >&2; exit 1; }

say "[4/5] inserting infsup_dump.c into contactmortar.c"
/usr/bin/python3 - "$SRC/contactmortar.c" "$HERE/infsup_dump.c" <<'EOF'
import sys
from pathlib import Path

target, ours = Path(sys.argv[1]), Path(sys.argv[2]).read_text()
text = target.read_text()
# (anchor, what goes after it): the definitions after the includes, the call right after
# bdfill has assembled Bd/Dd (before the segmentation's fields are freed)
include = '#include "mortar.h"\n'
free = "    SFREE(imastsurf);SFREE(pmastsurf);SFREE(gapmints);SFREE(pslavsurf);"
call = ("    infsup_ccx_dump(nk,ntie,nslavnode,islavnode,islavact,iflagdualquad,Bd,irowb,jqb,"
        "Dd,irowd,jqd,Bpgd,irowbpg,jqbpg,Dpgd,irowdpg,jqdpg); /* infsup-contact */\n")
for anchor in (include, free):
    if text.count(anchor) != 1:
        sys.exit(f"producers-calculix: anchor {anchor.strip()!r} found {text.count(anchor)} times "
                 f"in {target} (expected once): CalculiX changed, the insertion needs updating")
text = text.replace(include, include + ours, 1).replace(free, call + free, 1)
target.write_text(text)
EOF

say "[5/5] make -j2 ccx_$VERSION (about a minute on 2 cores)"
start=$(date +%s)
make -s -C "$SRC" -j"${JOBS:-2}" "ccx_$VERSION" \
  CFLAGS='-O2 -Wall -I/usr/include/spooles -DARCH="Linux" -DSPOOLES -DARPACK -DMATRIXSTORAGE -DUSE_MT=1' \
  FFLAGS='-O2 -fallow-argument-mismatch' LDFLAGS='' > "$BUILD/build.log" 2>&1 \
  || { tail -20 "$BUILD/build.log" >&2; echo "producers-calculix: the build failed (log: $BUILD/build.log)" >&2; exit 1; }
install -m 755 "$SRC/ccx_$VERSION" "$BUILD/bin/ccx_infsup"
say "built $BUILD/bin/ccx_infsup in $(( $(date +%s) - start )) s"
