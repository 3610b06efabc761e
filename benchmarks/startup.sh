#!/usr/bin/env bash
# Start-up of the tool: the shared libraries it loads, those only the bag /
# MCAP / rosbag2 readers need, and the dynamic loader's time, for
# `gravcal --version` and a CSV calibration.
# Usage: benchmarks/startup.sh GRAVCAL_BUILD [CSV CONFIG]
set -euo pipefail
g=$(cd "$1" && pwd)/gravcal
[ -x "$g" ] || { echo "startup: $g is missing" >&2; exit 1; }
libs() { ldd "$1" | awk '$1 !~ /linux-vdso/ {print $1}' | sort -u; }
all=$(libs "$g")
# What each library the tool names (NEEDED) pulls in, split between the
# format readers' libraries and the others.
readers='^(librosbag_storage|libroscpp_serialization|librostime|libcpp_common|libroslz4|libbz2|libsqlite3|libzstd|liblz4)[.]'
formats=""
others=""
for name in $(readelf -d "$g" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
  path=$(ldd "$g" | awk -v l="$name" '$1 == l {print $3}')
  [ -n "$path" ] || continue
  set_=$'\n'"$(libs "$path")"$'\n'"$name"
  if [[ $name =~ $readers ]]; then formats+=$set_; else others+=$set_; fi
done
only_formats=$(comm -23 <(echo "$formats" | sed '/^$/d' | sort -u) <(echo "$others" | sed '/^$/d' | sort -u))
echo "libraries loaded: $(echo "$all" | wc -l)"
echo "needed only by the format readers: $(echo "$only_formats" | sed '/^$/d' | wc -l)"
echo "$only_formats" | sed '/^$/d' | tr '\n' ' '; echo
echo "gravcal --version, loader statistics:"
LD_DEBUG=statistics "$g" --version 2>&1 | grep -E "total startup time|time needed for relocation" |
  sed 's/^ *[0-9]*: *//'
if [ $# -ge 3 ]; then
  echo "gravcal calibrate $2, loader statistics and wall time:"
  start=$(date +%s%N)
  LD_DEBUG=statistics "$g" calibrate --input "$2" --config "$3" --output /dev/null 2>&1 |
    grep -E "total startup time" | sed 's/^ *[0-9]*: *//'
  echo "wall: $((($(date +%s%N) - start) / 1000000)) ms"
fi
