#!/usr/bin/env bash
# Builds the libFuzzer targets (clang-15, ASan + UBSan: in the `asan` preset's tree, which CI has
# already built for the sanitizer tests, or with DRAPE_FUZZ_PRESET=fuzz in a tree of their own at
# -O2, which runs them faster) and runs each one for a bounded time on its seed corpus (generated
# from ../shared/data by the build) plus what earlier runs found. Any crash, sanitizer report,
# leak or timeout fails the script; the input is left in build/<preset>/artifacts/<target>/ - add
# it to tests/fuzz/regressions/<target>/ with the fix.
#
#   bash tests/fuzz/run.sh [seconds per target, default 30] [target ...]
#   DRAPE_FUZZ_PRESET=fuzz bash tests/fuzz/run.sh 3600 capi   # a longer run (docs/robustness.md)
# Environment: DRAPE_FUZZ_JOBS (parallel jobs per target, default 1), DRAPE_FUZZ_ARGS (extra
# libFuzzer flags).
# The targets run side by side, each for the given wall time (on 2 cores, 30 s side by side is
# the CPU time of 20 s one after another, in half the wall time); with DRAPE_FUZZ_JOBS > 1 or
# DRAPE_FUZZ_SIDE_BY_SIDE=0 they run one after another (libFuzzer's -jobs logs, fuzz-<n>.log in
# the working directory, would collide between targets).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
seconds="${1:-30}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(recording obj capi)

preset="${DRAPE_FUZZ_PRESET:-asan}"
tree="$root/build/$preset"
[[ -f "$tree/CMakeCache.txt" ]] || cmake --preset "$preset" >/dev/null
cmake --build "$tree" -j"$(nproc)" --target drape_fuzz_seeds "${targets[@]/#/drape_fuzz_}"

build="$tree/tests/fuzz"
cd "$tree"   # libFuzzer -jobs writes fuzz-<n>.log into the working directory
side_by_side="${DRAPE_FUZZ_SIDE_BY_SIDE:-1}"
if ((${DRAPE_FUZZ_JOBS:-1} > 1)); then side_by_side=0; fi

# Fuzzes one target; its output goes to build/<preset>/fuzz_<target>.log. Returns libFuzzer's status.
fuzz_target() {
  local t="$1"
  local corpus="$tree/corpus/$t"      # grows across runs (not committed)
  local artifacts="$tree/artifacts/$t"
  mkdir -p "$corpus" "$artifacts"
  local dirs=("$corpus" "$build/seeds/$t")
  # Committed crash inputs (git keeps no empty folder, so it may be absent).
  if [[ -d "$root/tests/fuzz/regressions/$t" ]]; then dirs+=("$root/tests/fuzz/regressions/$t"); fi
  local max_len
  case "$t" in
    obj) max_len=262144 ;;   # a MakeHuman garment is 170-230 KB
    capi) max_len=8192 ;;    # a program of up to 96 operations
    *) max_len=65536 ;;
  esac
  local jobs=()
  if ((${DRAPE_FUZZ_JOBS:-1} > 1)); then jobs=(-jobs="$DRAPE_FUZZ_JOBS" -workers="$DRAPE_FUZZ_JOBS"); fi
  # -timeout: one input may take at most 10 s (the OBJ target dresses a 2 000-vertex garment);
  # -rss_limit_mb: the readers must not need more than 2 GB for any input.
  # intercept_tls_get_addr=0: the sanitizer runtimes up to GCC 13 / LLVM 16 can misread a dynamic
  # TLS block in their __tls_get_addr interceptor and crash LeakSanitizer's tracer at exit
  # ("Tracer caught signal 11"), a rare flake with no leak behind it (docs/robustness.md).
  ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:allocator_may_return_null=1:intercept_tls_get_addr=0" \
  UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1" \
    "$build/drape_fuzz_$t" "${dirs[@]}" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" "${jobs[@]}" \
      -artifact_prefix="$artifacts/" -print_final_stats=1 ${DRAPE_FUZZ_ARGS:-} \
      >"$tree/fuzz_$t.log" 2>&1
}

# Reports one finished target: its statistics, or the end of its log when it failed.
report_target() {
  local t="$1" rc="$2" log="$tree/fuzz_$1.log"
  if ((rc != 0)); then
    echo "drape: fuzz_$t FAILED (exit $rc); the last lines of $log:" >&2
    tail -40 "$log" >&2
    return 1
  fi
  echo -n "drape: fuzz_$t: "
  grep -E '^(stat::number_of_executed_units|stat::new_units_added|stat::peak_rss_mb)' "$log" | tr '\n' ' '
  echo
}

status=0
if ((side_by_side)); then
  echo "drape: fuzzing ${targets[*]} side by side, ${seconds}s each"
  declare -A pids=()
  for t in "${targets[@]}"; do
    fuzz_target "$t" &
    pids[$t]=$!
  done
  for t in "${targets[@]}"; do
    rc=0
    wait "${pids[$t]}" || rc=$?
    report_target "$t" "$rc" || status=1
  done
else
  for t in "${targets[@]}"; do
    echo "drape: fuzzing $t for ${seconds}s"
    rc=0
    fuzz_target "$t" || rc=$?
    report_target "$t" "$rc" || status=1
  done
fi
exit $status
