#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang-15, ASan + UBSan) and runs each one for a
# bounded time on its seed corpus (generated from ../shared/data by the build) plus what earlier
# runs found. Any crash, sanitizer report, leak or timeout fails the script; the input is left in
# build/fuzz/artifacts/<target>/ - add it to tests/fuzz/regressions/<target>/ with the fix.
#
#   bash tests/fuzz/run.sh [seconds per target, default 30] [target ...]
#   bash tests/fuzz/run.sh 3600 capi        # the longer run documented in docs/robustness.md
# Environment: DRAPE_FUZZ_JOBS (parallel jobs per target, default 1), DRAPE_FUZZ_ARGS (extra
# libFuzzer flags).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
seconds="${1:-30}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(recording obj capi)

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$(nproc)"

build="$root/build/fuzz/tests/fuzz"
cd "$root/build/fuzz"   # libFuzzer -jobs writes fuzz-<n>.log into the working directory
status=0
for t in "${targets[@]}"; do
  corpus="$root/build/fuzz/corpus/$t"      # grows across runs (not committed)
  artifacts="$root/build/fuzz/artifacts/$t"
  mkdir -p "$corpus" "$artifacts"
  dirs=("$corpus" "$build/seeds/$t")
  # Committed crash inputs (git keeps no empty folder, so it may be absent).
  if [[ -d "$root/tests/fuzz/regressions/$t" ]]; then dirs+=("$root/tests/fuzz/regressions/$t"); fi
  echo "drape: fuzzing $t for ${seconds}s"
  log="$root/build/fuzz/fuzz_$t.log"
  case "$t" in
    obj) max_len=262144 ;;   # a MakeHuman garment is 170-230 KB
    capi) max_len=8192 ;;    # a program of up to 96 operations
    *) max_len=65536 ;;
  esac
  jobs=()
  if ((${DRAPE_FUZZ_JOBS:-1} > 1)); then jobs=(-jobs="$DRAPE_FUZZ_JOBS" -workers="$DRAPE_FUZZ_JOBS"); fi
  # -timeout: one input may take at most 10 s (the OBJ target dresses a 2 000-vertex garment);
  # -rss_limit_mb: the readers must not need more than 2 GB for any input.
  if ! ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:allocator_may_return_null=1" \
       UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
       "$build/drape_fuzz_$t" "${dirs[@]}" \
         -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" "${jobs[@]}" \
         -artifact_prefix="$artifacts/" -print_final_stats=1 ${DRAPE_FUZZ_ARGS:-} >"$log" 2>&1; then
    echo "drape: fuzz_$t FAILED; the last lines of $log:" >&2
    tail -40 "$log" >&2
    status=1
  else
    grep -E '^(stat::number_of_executed_units|stat::new_units_added|stat::peak_rss_mb)' "$log" | tr '\n' ' '
    echo
  fi
done
exit $status
