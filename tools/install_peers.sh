#!/usr/bin/env bash
# The compiled peer of tests/integration/test_cvode_peer.py and bench/bench_transient.py (issue 16):
# the C + SUNDIALS CVODE take-off of bench/cvode_peer, built with gcc against Debian's
# libsundials-dev. This script installs that package when its CVODE header is missing (CI runs it,
# so that the peer's tests run instead of being skipped). Nothing else of the project needs it.
set -euo pipefail
if [ -f /usr/include/cvode/cvode.h ] && command -v gcc >/dev/null; then
    echo "libsundials-dev and gcc are installed" >&2
    exit 0
fi
echo "installing libsundials-dev and gcc (Debian) for the CVODE peer" >&2
{ apt-get install -y -qq libsundials-dev gcc || { apt-get update -qq && apt-get install -y -qq libsundials-dev gcc; }; } >&2
test -f /usr/include/cvode/cvode.h
