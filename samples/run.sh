#!/usr/bin/env bash
# The main job: install what is missing, build Drape, replay the bundled real Kinect v2 recording
# on the default body, dressed in the default T-shirt (2 000 particles, XPBD), and write body and
# garment OBJ frames, pictures (render_NNNNN.png every 5th frame, contact_sheet.png, replay.gif, and
# replay.mp4 when ffmpeg is on PATH) + stats into ./drape-out (or the folder given with --out).
# Extra arguments go to drape-replay (see `drape-replay --help`), e.g. --garment dress.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash .ci/install-deps.sh --runtime-only
if [[ -f build/release/CMakeCache.txt ]]; then
  # Already configured (a developer's tree): keep its options (tests, benchmarks) as they are.
  cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
else
  cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DDRAPE_BUILD_TESTS=OFF -DDRAPE_BUILD_BENCHMARKS=OFF >/dev/null
fi
cmake --build build/release -j"$(nproc)" --target drape-replay
out="drape-out"
./build/release/samples/drape-replay --out "$out" --stats "$out/stats.json" "$@"
