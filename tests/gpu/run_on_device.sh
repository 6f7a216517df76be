#!/usr/bin/env bash
# The GPU check, run on the device machine by the device tool over the working tree with .gpu/
# carried (tests/gpu/pack.sh made it). Registers NVIDIA's OpenCL ICD with the carried ICD loader,
# runs the OpenCL tests (with the Kinect take they read, when pack.sh found ../shared), the
# backend and batching benchmarks (DRAPE_GPU_BENCH=0 skips them), and drape-replay on the bundled
# take on both backends. With a baseline build packed into .gpu-base/ (carried too), the OpenCL
# replays run interleaved with it, three times each, for a before/after on one machine.
# Everything it prints goes to $OUT as well. docs/opencl.md, "On a GPU".
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
out="${OUT:-/tmp/gpu-out}"; mkdir -p "$out"
nvidia-smi -L; nproc; grep -m1 'model name' /proc/cpuinfo
icd="$(ldconfig -p | awk '/libnvidia-opencl\.so\.1/{print $NF; exit}')"
[[ -n "$icd" ]] || icd="$(find /usr/local/nvidia /usr/lib* -name 'libnvidia-opencl.so*' 2>/dev/null | head -1)"
echo "NVIDIA OpenCL ICD: ${icd:-not found}"
mkdir -p /tmp/icd && echo "$icd" >/tmp/icd/nvidia.icd
export OCL_ICD_VENDORS=/tmp/icd
[[ -d .gpu/shared/data ]] && export DRAPE_SHARED_DATA="$PWD/.gpu/shared/data"
run() { local v="$1"; shift; LD_LIBRARY_PATH="$PWD/$v/lib" "$v/bin/$@"; }
median() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); s=d['stages_ms']; g=d['garment']
k = f\", kernels {s['device']['kernel']:.3f}\" if 'device' in s else ''
print(f\"frame {s['frame']:.3f} ms, cloth {s['cloth']:.3f}{k}; {d['backend']} {d.get('device') or ''}; p99 stretch {g['p99_stretch']:.4f}, contacts {g['contacts']}, inside {g['proxy_inside']}\")" "$1"; }

timeout 150 bash -c "$(declare -f run); run .gpu drape_tests --gtest_filter='*OpenCl*:*Backend*:*Batch*:*StepContexts*' --gtest_brief=1" 2>&1 |
  grep -vE '^(1 (error|warning)|2 warnings)' | tail -25 | tee "$out/tests.txt"
if [[ "${DRAPE_GPU_BENCH:-1}" != 0 ]]; then
  timeout 240 bash -c "$(declare -f run); run .gpu drape_benchmarks --benchmark_filter='Backend|BatchFrames' \
    --benchmark_repetitions=3 --benchmark_report_aggregates_only=true --benchmark_out='$out/bench.json'" 2>&1 |
    grep -E 'median' | tee "$out/bench.txt"
fi
versions=(.gpu); [[ -d .gpu-base ]] && versions=(.gpu-base .gpu)
for p in 2000 32000; do
  for rep in 1 2 3; do
    for v in "${versions[@]}"; do
      for be in opencl cpu; do
        [[ "$be" == cpu && ( "$rep" != 1 || "$v" != .gpu ) ]] && continue
        timeout 60 bash -c "$(declare -f run); run $v drape-replay --recording samples/data/Ges01_wavehand.csv --backend $be --particles $p --no-obj --no-render \
          --measure-every 0 --fidelity-every 0 -q --stats /tmp/r.json" >/dev/null 2>&1
        echo "$v $be particles $p run $rep: $(median /tmp/r.json)" | tee -a "$out/replay.txt"
      done
    done
  done
  timeout 60 bash -c "$(declare -f run); run .gpu drape-replay --recording samples/data/Ges01_wavehand.csv --backend opencl --particles $p --full-pipeline --no-obj \
    --no-render --measure-every 0 --fidelity-every 0 -q --stats /tmp/r.json" >/dev/null 2>&1
  echo ".gpu opencl particles $p --full-pipeline: $(median /tmp/r.json)" | tee -a "$out/replay.txt"
done
