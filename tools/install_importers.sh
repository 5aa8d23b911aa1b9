#!/usr/bin/env bash
# The independent FMU importer of tests/integration/test_fmu_importers.py (issue 13): fmi-sim, a
# pure-Rust FMI 2.0/3.0 simulator (Model Exchange and Co-Simulation) from crates.io, written outside
# this project. This script owns its pinned version and where it lives.
#
#   bash tools/install_importers.sh          install it if it is not there; print the binary's path
#   bash tools/install_importers.sh --where  print the binary's path only (what the tests run)
#
# It is built from source by `cargo install --locked` (the crate's own Cargo.lock) into a cache outside
# the clone, kept between runs on one machine: $TCSIM_IMPORTERS_DIR, default
# ${XDG_CACHE_HOME:-$HOME/.cache}/tcsim/importers, one folder per version. Without the cache it
# installs from scratch (a few minutes on 2 cores; it needs only cargo and crates.io).
set -euo pipefail
FMI_SIM_VERSION=0.7.0
root="${TCSIM_IMPORTERS_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/tcsim/importers}/fmi-sim-$FMI_SIM_VERSION"
bin="$root/bin/fmi-sim"

if [ "${1:-}" = "--where" ]; then
    echo "$bin"
    exit 0
elif [ $# -gt 0 ]; then
    echo "usage: bash tools/install_importers.sh [--where]" >&2
    exit 2
fi
if [ -x "$bin" ] && [ "$("$bin" --version 2>/dev/null)" = "fmi-sim $FMI_SIM_VERSION" ]; then
    echo "fmi-sim $FMI_SIM_VERSION is installed: $bin" >&2
    echo "$bin"
    exit 0
fi
start=$SECONDS
echo "installing fmi-sim $FMI_SIM_VERSION into $root (cargo install --locked; minutes on 2 cores)" >&2
CARGO_BUILD_JOBS="${CARGO_BUILD_JOBS:-2}" cargo install --locked --force --version "$FMI_SIM_VERSION" \
    --root "$root" fmi-sim >&2
if [ "$("$bin" --version)" != "fmi-sim $FMI_SIM_VERSION" ]; then
    echo "error: $bin --version: expected fmi-sim $FMI_SIM_VERSION, got $("$bin" --version)" >&2
    exit 1
fi
echo "installed fmi-sim $FMI_SIM_VERSION in $((SECONDS - start)) s: $bin" >&2
echo "$bin"
