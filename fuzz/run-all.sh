#!/bin/bash
# Runs fuzz targets one after another, each for SECONDS_PER_TARGET (default 600) under
# `nice`, with the memory limits and input sizes recorded in FUZZING.md.
#
# Usage (from anywhere): fuzz/run-all.sh [TARGET...]   (default: every target)
# New corpus entries go to $FUZZ_WORK/corpus/TARGET (default /tmp/qem-fuzz), never into
# the committed seed corpus; logs to $FUZZ_WORK/logs/TARGET.log; crash reproducers to
# fuzz/artifacts/TARGET/ (ignored by git: minimise them into fuzz/regressions/TARGET/).
set -u
cd "$(dirname "$0")"
secs=${SECONDS_PER_TARGET:-600}
work=${FUZZ_WORK:-/tmp/qem-fuzz}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(read_obj read_ply read_stl read_off read_gltf simplify_soup store_ops grid_pairs quadric_solve)
fi
mkdir -p "$work/logs"
for t in "${targets[@]}"; do
  case $t in
    read_*) len=16384 ;;
    grid_pairs) len=2048 ;;
    *) len=1024 ;;
  esac
  mkdir -p "$work/corpus/$t"
  log="$work/logs/$t.log"
  echo "=== $t start $(date -u +%FT%TZ) max_len=$len secs=$secs" > "$log"
  nice -n 10 cargo fuzz run -s none "$t" "$work/corpus/$t" "corpus/$t" -- \
    -max_total_time="$secs" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -rss_limit_mb=512 -malloc_limit_mb=512 -max_len="$len" -timeout=10 \
    >> "$log" 2>&1
  echo "=== $t end $(date -u +%FT%TZ) rc=$?" >> "$log"
  grep -a '^#[0-9]*: cov:' "$log" | tail -n 1
done
