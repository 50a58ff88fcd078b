#!/usr/bin/env bash
# Runs every benchmark program (build/bin/bench_*) and whole-pipeline timing scripts
# (bench/*.sh). Usage: scripts/bench.sh [BUILD_DIR]
set -euo pipefail
BUILD="${1:-build}"
shopt -s nullglob
found=0
for b in "$BUILD"/bin/bench_*; do
  found=1
  echo "== $(basename "$b")"
  "$b" --benchmark_counters_tabular=true
done
for s in bench/*.sh; do
  found=1
  echo "== $s"
  bash "$s" "$BUILD"
done
[ $found = 1 ] || echo "no benchmarks built yet"
