#!/usr/bin/env bash
# Start-up of the tool: the shared libraries it loads (LD_DEBUG=files: every
# library the loader opens and initialises, at start and by dlopen), those
# of the bag / MCAP / rosbag2 reader module (libgravcal_formats.so, loaded
# only when such a file is read), and the dynamic loader's time.
# Usage: benchmarks/startup.sh GRAVCAL_BUILD [CSV CONFIG [BAG]]
set -euo pipefail
g=$(cd "$1" && pwd)/gravcal
[ -x "$g" ] || { echo "startup: $g is missing" >&2; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Libraries initialised by a run of the tool ("calling init" per library).
loaded() { LD_DEBUG=files "$@" 2>&1 >/dev/null | grep -c "calling init: /" || true; }
echo "libraries linked (ldd gravcal): $(ldd "$g" | grep -vc linux-vdso)"
module=$(dirname "$g")/libgravcal_formats.so
if [ -e "$module" ]; then
  echo "libraries the reader module links (ldd libgravcal_formats.so): $(ldd "$module" | grep -vc linux-vdso)"
fi
echo "libraries initialised, gravcal --version: $(loaded "$g" --version)"
echo "gravcal --version, loader statistics:"
LD_DEBUG=statistics "$g" --version 2>&1 | grep -E "total startup time|time needed for relocation" |
  sed 's/^ *[0-9]*: *//'
if [ $# -ge 3 ]; then
  echo "libraries initialised, gravcal calibrate $2: $(loaded "$g" calibrate --input "$2" --config "$3" --output "$tmp/c.json")"
  echo "gravcal calibrate $2, loader statistics and wall time:"
  start=$(date +%s%N)
  LD_DEBUG=statistics "$g" calibrate --input "$2" --config "$3" --output "$tmp/c.json" 2>&1 |
    grep -E "total startup time" | sed 's/^ *[0-9]*: *//'
  echo "wall: $((($(date +%s%N) - start) / 1000000)) ms"
fi
if [ $# -ge 4 ]; then
  echo "libraries initialised, gravcal inspect $4: $(loaded "$g" inspect --input "$4")"
fi
