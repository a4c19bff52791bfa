#!/usr/bin/env bash
# The long fuzz campaign: every target (or those given) for 10 million executions without a
# sanitizer, one after another, each's final statistics appended to fuzz/long.log.
set -uo pipefail
cd "$(dirname "$0")"
targets=("$@")
[ ${#targets[@]} -eq 0 ] && mapfile -t targets < <(./run.sh --list)
for t in "${targets[@]}"; do
  start=$(date +%s)
  SANITIZER=none ./run.sh "$t" -runs=10000000 -print_final_stats=1 > "/tmp/fuzz-$t.log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "/tmp/fuzz-$t.log" | tail -1 | awk '{print $2}')
  echo "$t: exit $rc, ${runs:-?} executions in $(( $(date +%s) - start )) s, artifacts: $(ls artifacts/$t 2>/dev/null | wc -l)" | tee -a long.log
done
