#!/usr/bin/env bash
# Fuzzes every harness of fuzz/ with libFuzzer (issue 18 §5): builds them with clang, ASan and
# UBSan into build-fuzz/ (Debian's clang; installed here when missing), then runs each for
# SECONDS (default 60) on a copy of its corpus (fuzz/corpus/<name>). New inputs that reach
# new code are added to fuzz/corpus/<name> (merged, minimised); a crash is saved in
# fuzz/crashes/<name>/ and the script exits 1 naming it: commit it with the fix, and
# `bash deploy/test.sh` replays it for ever after (the CTest tests fuzz.<name>).
#   deploy/fuzz.sh [SECONDS] [NAME...]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
DISPATCH_FUZZ_DEPS=1 bash deploy/setup.sh packages
export CC=clang CXX=clang++
cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDISPATCH_FUZZ=ON -DDISPATCH_BUILD_TESTS=OFF >/dev/null
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(map_json movingai_map order_file rest_body rest_paths grpc_requests robot_stream)
cmake --build build-fuzz -j "$(nproc)" --target "${names[@]/#/fuzz_}"
failed=()
for name in "${names[@]}"; do
  corpus=fuzz/corpus/$name crashes=fuzz/crashes/$name work=build-fuzz/run/$name
  rm -rf "$work" && mkdir -p "$work/corpus" "$work/crashes"
  cp "$corpus"/* "$work/corpus/"
  echo "== fuzz_$name: $seconds s from $(ls "$corpus" | wc -l) inputs"
  rc=0
  build-fuzz/fuzz/fuzz_"$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
    -artifact_prefix="$work/crashes/" "$work/corpus" >"$work/log" 2>&1 || rc=$?
  grep -E "^(stat::number_of_executed_units|stat::peak_rss_mb|#[0-9]+ +DONE)" "$work/log" || true
  if [ "$rc" -ne 0 ] || ls "$work/crashes"/* >/dev/null 2>&1; then
    mkdir -p "$crashes"
    cp "$work/crashes"/* "$crashes/" 2>/dev/null || true
    grep -E "ERROR|SUMMARY|==[0-9]+==" "$work/log" | head -20
    echo "fuzz_$name: crashed; input(s) saved in $crashes/ (log $work/log)" >&2
    failed+=("$name")
    continue
  fi
  # Keep what reached new code: merged into the committed corpus, minimised.
  mkdir -p "$work/merged"
  build-fuzz/fuzz/fuzz_"$name" -merge=1 "$work/merged" "$corpus" "$work/corpus" >"$work/merge.log" 2>&1
  rm -f "$corpus"/* && cp "$work/merged"/* "$corpus/"
  echo "   corpus now $(ls "$corpus" | wc -l) inputs"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: crashes in ${failed[*]}" >&2
  exit 1
fi
echo "fuzz: no crash in ${names[*]} ($seconds s each)"
