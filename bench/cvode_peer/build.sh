#!/bin/sh
# Build the CVODE peer of the isolated take-off (bench only; not part of the package's build).
# Needs gcc and Debian's libsundials-dev (CVODE 6.x): apt-get install -y libsundials-dev
# Usage: build.sh [OUTPUT]  (default: takeoff next to this script)
set -e
here="$(cd "$(dirname "$0")" && pwd)"
out="${1:-$here/takeoff}"
gcc -O2 -march=x86-64 -std=c11 -D_POSIX_C_SOURCE=199309L -Wall -Wextra -Werror -o "$out" "$here/takeoff.c" \
    -lsundials_cvode -lsundials_nvecserial -lsundials_sunmatrixdense -lsundials_sunlinsoldense -lm
