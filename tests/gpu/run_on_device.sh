#!/usr/bin/env bash
# The GPU check, run on the device machine by the device tool over the working tree with .gpu/
# carried (tests/gpu/pack.sh made it). Registers NVIDIA's OpenCL ICD with the carried ICD loader,
# runs the OpenCL tests, the backend and batching benchmarks, and drape-replay on the bundled take
# on both backends; everything it prints is also written to $OUT. docs/opencl.md, "On a GPU".
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
out="${OUT:-/tmp/gpu-out}"; mkdir -p "$out"
export LD_LIBRARY_PATH="$PWD/.gpu/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
nvidia-smi -L; nproc; grep -m1 'model name' /proc/cpuinfo
icd="$(ldconfig -p | awk '/libnvidia-opencl\.so\.1/{print $NF; exit}')"
[[ -n "$icd" ]] || icd="$(find / -xdev -name 'libnvidia-opencl.so.1' 2>/dev/null | head -1)"
[[ -n "$icd" ]] || icd="$(find /usr/local/nvidia /usr/lib* -name 'libnvidia-opencl.so*' 2>/dev/null | head -1)"
echo "NVIDIA OpenCL ICD: ${icd:-not found}"
mkdir -p /tmp/icd && echo "$icd" >/tmp/icd/nvidia.icd
export OCL_ICD_VENDORS=/tmp/icd
bin=.gpu/bin
timeout 120 "$bin/drape_tests" --gtest_filter='*OpenCl*:*Backend*:*Batch*:*StepContexts*' --gtest_brief=1 2>&1 | tail -25 | tee "$out/tests.txt"
timeout 240 "$bin/drape_benchmarks" --benchmark_filter='Backend|BatchFrames' --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true --benchmark_out="$out/bench.json" 2>&1 | grep -E 'median|Backend.*_median|^Run|CPU' | tee "$out/bench.txt"
mkdir -p /tmp/stats
for be in cpu opencl; do
  for p in 2000 32000; do
    echo "== drape-replay --backend $be --particles $p" | tee -a "$out/replay.txt"
    timeout 45 "$bin/drape-replay" --backend "$be" --particles "$p" --no-obj --no-render --measure-every 0 \
      --fidelity-every 0 --out "/tmp/replay-$be-$p" >>"$out/replay.txt" 2>&1
    echo "rc=$?" | tee -a "$out/replay.txt"
    cp "/tmp/replay-$be-$p/stats.json" "/tmp/stats/stats-$be-$p.json" 2>/dev/null
  done
done
tail -60 "$out/replay.txt"
tar czf "$out/stats.tgz" -C /tmp stats
