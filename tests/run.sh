#!/usr/bin/env bash
# Builds everything and runs every test: native GoogleTest suites through CTest (C header, ABI
# symbol list, samples, stress scenarios, fuzz regressions included) and the C# xunit tests against
# the same native build; then the native suite again under AddressSanitizer + UndefinedBehavior-
# Sanitizer (clang), and a bounded run of each libFuzzer target, built in that same sanitizer tree
# (docs/robustness.md).
# Environment: DRAPE_SKIP_ASAN=1 / DRAPE_SKIP_FUZZ=1 skip those stages; DRAPE_FUZZ_SECONDS sets
# the wall time of the fuzz targets, which run side by side (default 30: on two cores each gets
# about 20 s of CPU).
#
# Time (docs/robustness.md, "CI time"): CI runs on 2 cores, and the stages are CPU-bound, so the
# savings come from less compiling and from filling the cores the serial stages leave idle. Less
# compiling: one clang sanitizer tree gives both the ASan + UBSan tests and the libFuzzer targets
# (a gcc tree and a clang tree were built before, and clang compiles the instrumented Eigen code
# faster), with line tables instead of full debug info and precompiled headers; the test files
# compile in unity batches with precompiled headers in both trees (cmake/ci_build_speed.cmake).
# Idle cores: the sanitizer tree builds in the background while the release tests, `dotnet test`
# and Mono run (each has a single-threaded tail), and the three fuzz targets share the cores
# instead of taking turns on one.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash .ci/install-deps.sh
stage() { echo "drape: ---- $* ($(date +%T)) ----"; }

logs="$root/build/ci-logs"
mkdir -p "$logs"

stage "release build"
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)"

# The ASan + UBSan build runs in the background, in its own process group (setsid) so that an
# early failure of the foreground stages stops it with everything it started (trap below). Its
# output goes to a log file; the ASan stage below prints its end, or the errors when it failed.
asan_build_pid=""
if [[ "${DRAPE_SKIP_ASAN:-0}" != 1 ]]; then
  stage "ASan + UBSan build started in the background (log: build/ci-logs/asan-build.log)"
  setsid -w bash -c 'cmake --preset asan >/dev/null && cmake --build --preset asan -j"$(nproc)"' \
    >"$logs/asan-build.log" 2>&1 </dev/null &
  asan_build_pid=$!
  trap 'if [[ -n "$asan_build_pid" ]]; then kill -- "-$asan_build_pid" "$asan_build_pid" 2>/dev/null || true; fi' EXIT
fi

stage "release tests"
ctest --preset release -j"$(nproc)"   # the `long` label (one simulated hour) is left out
stage "C# tests on .NET"
dotnet test bindings/csharp/Drape.Tests -c Release -p:DrapeNativeDir="$root/build/release/native"
# The same binding tests under Mono, the Unity editor's runtime (docs/csharp.md, "Mono").
stage "C# tests on Mono"
dotnet build bindings/csharp/Drape.Tests.Mono -c Release -p:DrapeNativeDir="$root/build/release/native"
mono bindings/csharp/Drape.Tests.Mono/bin/Release/netstandard2.1/MonoTestRunner.exe

if [[ -n "$asan_build_pid" ]]; then
  stage "ASan + UBSan build (waiting for the background build) and tests"
  asan_rc=0
  wait "$asan_build_pid" || asan_rc=$?
  asan_build_pid=""
  if ((asan_rc != 0)); then
    echo "drape: the ASan + UBSan build FAILED (exit $asan_rc); its errors, then the end of $logs/asan-build.log:" >&2
    grep -E -A3 '(error|Error|FAILED)' "$logs/asan-build.log" | head -80 >&2 || true
    echo "..." >&2
    tail -30 "$logs/asan-build.log" >&2
    exit 1
  fi
  tail -3 "$logs/asan-build.log"
  ctest --preset asan -j"$(nproc)"      # leaves out `long`, `loop` and `asan_slow` (CMakePresets.json)
fi

if [[ "${DRAPE_SKIP_FUZZ:-0}" != 1 ]]; then
  stage "libFuzzer targets, side by side for ${DRAPE_FUZZ_SECONDS:-30} s"
  bash tests/fuzz/run.sh "${DRAPE_FUZZ_SECONDS:-30}"
fi
stage "all passed"
