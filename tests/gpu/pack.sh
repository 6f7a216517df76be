#!/usr/bin/env bash
# Packs the Release binaries that the GPU check runs, with the shared libraries the device image
# lacks (the OpenCL ICD loader, giflib, ...), into .gpu/ (ignored by git through
# .git/info/exclude). The device tool carries that folder: `carry: [".gpu"]`, then
# `bash tests/gpu/run_on_device.sh`. Build first: cmake --preset release && cmake --build --preset release
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >>.git/info/exclude
rm -rf .gpu && mkdir -p .gpu/bin .gpu/lib
b=build/release
cp "$b/tests/drape_tests" "$b/tests/drape_benchmarks" "$b/samples/drape-replay" .gpu/bin/
cp -P "$b"/native/libdrape.so* .gpu/lib/ 2>/dev/null || true
# Every non-glibc library the binaries load, resolved here (Debian 12); the device image has its own
# glibc and libstdc++ (newer), so those stay out.
for f in .gpu/bin/*; do
  ldd "$f" | awk '/=> \//{print $3}'
done | sort -u | grep -Ev '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|ld-linux[^/]*)\.so' |
  while read -r lib; do cp -L "$lib" .gpu/lib/; done
strip --strip-debug .gpu/bin/* .gpu/lib/* 2>/dev/null || true
# The data the OpenCL tests read (the Kinect takes, 0.7 MB; the tests skip without them), from
# ../shared beside the checkout when it is there: the device tool carries the checkout alone.
shared="$root/../shared/data"
if [[ -d "$shared/kinect_v2_msft_labanotation" ]]; then
  mkdir -p .gpu/shared/data && cp -r "$shared/kinect_v2_msft_labanotation" .gpu/shared/data/
else
  echo "pack.sh: $shared not found; the OpenCL tests on the Kinect takes will skip on the device"
fi
du -sh .gpu
