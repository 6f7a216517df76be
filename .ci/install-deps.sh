#!/usr/bin/env bash
# Installs the Debian packages Drape builds and tests with, only those that are missing.
# Usage: bash .ci/install-deps.sh [--runtime-only]
#   --runtime-only: just what building and running the samples needs (no test frameworks).
set -euo pipefail

# libstb-dev (stb_image_write) and libgif-dev (giflib): drape-replay's PNG pictures and animated GIF.
packages=(cmake g++ make libeigen3-dev ocl-icd-opencl-dev opencl-headers pocl-opencl-icd libstb-dev libgif-dev)
# libbullet-dev: drape-bench's peer (Bullet's soft-body cloth in the same run); gnuplot-nox: its
# run-time-vs-error PNGs (pngcairo terminal). Both optional to the build (docs/benchmarks.md).
packages+=(libbullet-dev gnuplot-nox)
if [[ "${1:-}" != "--runtime-only" ]]; then
  # clang-15 brings libFuzzer (libclang-common-15-dev) for the fuzz targets tests/run.sh runs.
  packages+=(googletest libgtest-dev libbenchmark-dev clang-15)
  # python3: the quality matrix's comparer, which CTest replay_matrix runs (samples/replay), and
  # replay_default's JSON check; both are skipped where it is absent.
  packages+=(python3)
fi

[[ "${1:-}" == "--runtime-only" ]] || packages+=(mono-complete)  # C# tests under Mono (docs/csharp.md)

missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "drape: installing Debian packages: ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if ! command -v dotnet >/dev/null 2>&1 && [[ "${1:-}" != "--runtime-only" ]]; then
  echo "drape: the .NET SDK (dotnet) is required for the C# tests and is not on PATH" >&2
  exit 1
fi
