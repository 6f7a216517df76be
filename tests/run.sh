#!/usr/bin/env bash
# Builds everything and runs every test: native GoogleTest suites through CTest (C header, ABI
# symbol list, samples, stress scenarios, fuzz regressions included) and the C# xunit tests against
# the same native build; then the native suite again under AddressSanitizer + UndefinedBehavior-
# Sanitizer, and a bounded run of each libFuzzer target (docs/robustness.md).
# Environment: DRAPE_SKIP_ASAN=1 / DRAPE_SKIP_FUZZ=1 skip those stages; DRAPE_FUZZ_SECONDS sets
# the time per fuzz target (default 20).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash .ci/install-deps.sh
stage() { echo "drape: ---- $* ($(date +%T)) ----"; }

stage "release build and tests"
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)"
ctest --preset release -j"$(nproc)"   # the `long` label (one simulated hour) is left out
dotnet test bindings/csharp/Drape.Tests -c Release -p:DrapeNativeDir="$root/build/release/native"
# The same binding tests under Mono, the Unity editor's runtime (docs/csharp.md, "Mono").
dotnet build bindings/csharp/Drape.Tests.Mono -c Release -p:DrapeNativeDir="$root/build/release/native"
mono bindings/csharp/Drape.Tests.Mono/bin/Release/netstandard2.1/MonoTestRunner.exe

if [[ "${DRAPE_SKIP_ASAN:-0}" != 1 ]]; then
  stage "ASan + UBSan build and tests"
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j"$(nproc)"
  ctest --preset asan -j"$(nproc)"      # leaves out `long` and `loop` (see CMakePresets.json)
fi

if [[ "${DRAPE_SKIP_FUZZ:-0}" != 1 ]]; then
  stage "libFuzzer targets, ${DRAPE_FUZZ_SECONDS:-20} s each"
  bash tests/fuzz/run.sh "${DRAPE_FUZZ_SECONDS:-20}"
fi
stage "all passed"
