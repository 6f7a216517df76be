#!/usr/bin/env bash
# Builds everything and runs every test: native GoogleTest suites through CTest (C header, ABI
# symbol list, samples included) and the C# xunit tests against the same native build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash .ci/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)"
ctest --preset release -j"$(nproc)"
dotnet test bindings/csharp/Drape.Tests -c Release -p:DrapeNativeDir="$root/build/release/native"
