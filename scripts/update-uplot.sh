#!/usr/bin/env bash
# Re-fetches the vendored uPlot (the dashboard's plotting library, embedded
# into host-sim) from the npm registry with npm, checks the package's
# sha256 against the pinned one, and copies the files the page uses into
# host-sim/assets/dashboard/vendor/uplot/. To move to another version, set
# VERSION and SHA256 (of the npm tarball) here and in that folder's README.
#   scripts/update-uplot.sh
set -euo pipefail
VERSION=1.6.32
SHA256=4b8a8191e425658e3ea8c8c1314b0fc679c861ee3a1af2b20c7b16ba50b5133d
cd "$(dirname "$0")/.."
dest=host-sim/assets/dashboard/vendor/uplot
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "uplot@$VERSION" >/dev/null)
tarball="$work/uplot-$VERSION.tgz"
echo "$SHA256  $tarball" | sha256sum --check --quiet \
  || { echo "error: uplot-$VERSION.tgz does not have the pinned sha256" >&2; exit 1; }
tar -xzf "$tarball" -C "$work"
cp "$work/package/dist/uPlot.iife.min.js" "$work/package/dist/uPlot.min.css" \
   "$work/package/LICENSE" "$dest/"
echo "uplot $VERSION (sha256 $SHA256) copied into $dest"
