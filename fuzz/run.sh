#!/usr/bin/env bash
# Runs the libFuzzer harnesses of a -DFV_FUZZ=ON build (make fuzz): each for SECONDS (default 600)
# from a copy of its seed corpus (fuzz/corpus/NAME), JOBS at a time (default 2), under nice, and
# prints the executions and whether it found a crash (the input goes to BUILD/fuzz/NAME/artifacts/;
# add it to fuzz/corpus/NAME/ once fixed, so that CTest replays it).
# Usage: fuzz/run.sh BUILD [SECONDS] [JOBS] [NAME...]
set -u
BUILD="$(realpath "$1")"
SECONDS_EACH="${2:-600}"
JOBS="${3:-2}"
shift $(($# < 3 ? $# : 3))
SRC="$(cd "$(dirname "$0")" && pwd)"
names=("$@")
if [ ${#names[@]} = 0 ]; then
  for d in "$SRC"/corpus/*/; do names+=("$(basename "$d")"); done
fi
run_one() {
  local name="$1" bin="$BUILD/bin/$1_fuzz" dir="$BUILD/fuzz/$1"
  if [ ! -x "$bin" ]; then echo "$name: not built ($bin)"; return 1; fi
  mkdir -p "$dir/corpus" "$dir/artifacts"
  cp -n "$SRC/corpus/$name"/* "$dir/corpus/" 2>/dev/null
  (cd "$dir" && nice -n 19 "$bin" -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -timeout=30 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$dir/artifacts/" corpus \
    >"$dir/log.txt" 2>&1)
  local rc=$?
  local execs
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$dir/log.txt" | grep -o '[0-9]*$')
  if [ $rc = 0 ]; then
    echo "$name: ${execs:-?} executions in ${SECONDS_EACH} s, no crash"
  else
    echo "$name: FOUND A PROBLEM (exit $rc) after ${execs:-?} executions: $(ls "$dir/artifacts" | head -3 | tr '\n' ' ')"
    grep -m3 -E 'ERROR|fuzz:|SUMMARY' "$dir/log.txt" | sed 's/^/  /'
  fi
  return $rc
}
status=0
running=0
for name in "${names[@]}"; do
  run_one "$name" &
  running=$((running + 1))
  if [ $running -ge "$JOBS" ]; then wait -n || status=1; running=$((running - 1)); fi
done
while [ $running -gt 0 ]; do wait -n || status=1; running=$((running - 1)); done
exit $status
