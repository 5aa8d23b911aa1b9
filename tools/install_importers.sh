#!/usr/bin/env bash
# The independent FMU importer of tests/integration/test_fmu_importers.py (issue 13): fmi-sim, a
# pure-Rust FMI 2.0/3.0 simulator (Model Exchange and Co-Simulation) from crates.io, written outside
# this project. This script owns its pinned version and where it lives.
#
#   bash tools/install_importers.sh          install it if it is not there (and the CVODE peer's
#                                            libsundials-dev, tools/install_peers.sh); print its path
#   bash tools/install_importers.sh --where  print the binary's path only (what the tests run)
#
# It is built from source by `cargo install --locked` (the crate's own Cargo.lock) into a cache outside
# the clone, kept between runs on one machine: $TCSIM_IMPORTERS_DIR, default
# ${XDG_CACHE_HOME:-$HOME/.cache}/tcsim/importers, one folder per version. Without the cache it
# installs from scratch (a few minutes on 2 cores; it needs only cargo and crates.io).
set -euo pipefail
FMI_SIM_VERSION=0.7.0
# The other independent implementation the tests compare against: the C + CVODE peer (its own script)
if [ "${1:-}" != "--where" ]; then
    bash "$(dirname "$0")/install_peers.sh"
fi
root="${TCSIM_IMPORTERS_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/tcsim/importers}/fmi-sim-$FMI_SIM_VERSION"
bin="$root/bin/fmi-sim"

if [ "${1:-}" = "--where" ]; then
    echo "$bin"
    exit 0
elif [ $# -gt 0 ]; then
    echo "usage: bash tools/install_importers.sh [--where]" >&2
    exit 2
fi
# (fmi-sim 0.7.0 prints its version as an error: "Error: fmi-sim 0.7.0" on stderr, exit 1)
installed() {
    [ -x "$bin" ] || return 1
    local said
    said=$("$bin" --version 2>&1 || true)
    grep -qx "\(Error: \)\?fmi-sim $FMI_SIM_VERSION" <<<"$said"
}
if installed; then
    echo "fmi-sim $FMI_SIM_VERSION is installed: $bin" >&2
    echo "$bin"
    exit 0
fi
start=$SECONDS
# fmi-sys (fmi-sim's C bindings) runs bindgen at build time, which needs libclang: Debian's libclang-dev.
# (libclang-cpp, the C++ interface some machines have alone, is not it: bindgen skips it.)
have_libclang() {
    local d
    for d in /usr/lib/llvm-*/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib; do
        compgen -G "$d/libclang.so*" >/dev/null || compgen -G "$d/libclang-[0-9]*.so*" >/dev/null && return 0
    done
    return 1
}
if [ -z "${LIBCLANG_PATH:-}" ] && ! have_libclang; then
    echo "installing libclang-dev (Debian) for bindgen" >&2
    { apt-get install -y -qq libclang-dev || { apt-get update -qq && apt-get install -y -qq libclang-dev; }; } >&2
fi
echo "installing fmi-sim $FMI_SIM_VERSION into $root (cargo install --locked; minutes on 2 cores)" >&2
CARGO_BUILD_JOBS="${CARGO_BUILD_JOBS:-2}" cargo install --locked --force --version "$FMI_SIM_VERSION" \
    --root "$root" fmi-sim >&2
if ! installed; then
    echo "error: $bin --version: expected fmi-sim $FMI_SIM_VERSION, got $("$bin" --version 2>&1 | head -1)" >&2
    exit 1
fi
echo "installed fmi-sim $FMI_SIM_VERSION in $((SECONDS - start)) s: $bin" >&2
echo "$bin"
