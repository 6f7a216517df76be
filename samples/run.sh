#!/usr/bin/env bash
# The main job: install what is missing, build Drape, replay the bundled real Kinect v2 recording
# on the default body and write OBJ frames + stats into ./drape-out (or the folder given).
# Extra arguments go to drape-replay (see `drape-replay --help`).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash .ci/install-deps.sh --runtime-only
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DDRAPE_BUILD_TESTS=OFF -DDRAPE_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build/release -j"$(nproc)" --target drape-replay
out="drape-out"
./build/release/samples/drape-replay --out "$out" --stats "$out/stats.json" "$@"
