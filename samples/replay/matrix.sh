#!/usr/bin/env bash
# The quality matrix: drape-replay over every take x garment, one stats.json per run, for
# comparing two trees or two settings with matrix_compare.py (docs/replay.md, "Quality matrix").
#
#   samples/replay/matrix.sh OUT_DIR [drape-replay options...]
#
# Extra options go to every run (e.g. --garment-fit skeleton, --substeps 20). Environment:
#   TAKES      recordings, space-separated (default: the eight shared takes: the four Kinect v2
#              takes and the four CMU BVH takes of ../shared/data, those present)
#   GARMENTS   default "tshirt longsleeve skirt dress trousers"
#   PARTICLES  template resolutions, space-separated (default: drape-replay's; each run once).
#              Several (e.g. "1500 2000 2500") run every take x garment at each, named
#              <take>_<garment>_<N>.json: per-run openings and worst frames are chaotic, and a
#              change judged over several resolutions is judged on more than one draw.
#   FRAMES     frames per run (default 300; shorter takes run whole)
#   MEASURE    --measure-every (default 3)
#   JOBS       runs at once (default: nproc)
#   REPLAY     the drape-replay binary (default build/release/samples/drape-replay)
# Writes OUT_DIR/<take>_<garment>[_<N>].json and OUT_DIR/args.txt (what the runs were given).
set -euo pipefail
if [[ $# -lt 1 || "$1" == -* ]]; then
  sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="$1"
shift
replay="${REPLAY:-$root/build/release/samples/drape-replay}"
[[ -x "$replay" ]] || { echo "matrix.sh: no drape-replay at $replay (build it, or set REPLAY)" >&2; exit 2; }
if [[ -z "${TAKES:-}" ]]; then
  shared="${DRAPE_SHARED:-$root/../shared}/data"
  TAKES=""
  for t in kinect_v2_msft_labanotation/Ges01_wavehand.csv kinect_v2_msft_labanotation/Ges02_balancinghands.csv \
           kinect_v2_msft_labanotation/Ges04_comehere.csv kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv \
           cmu_mocap_bvh/131_01.bvh cmu_mocap_bvh/131_03.bvh cmu_mocap_bvh/scaled_131_01.bvh cmu_mocap_bvh/scaled_131_03.bvh; do
    [[ -f "$shared/$t" ]] && TAKES="$TAKES $shared/$t"
  done
  [[ -n "$TAKES" ]] || { echo "matrix.sh: no shared takes under $shared (set TAKES or DRAPE_SHARED)" >&2; exit 2; }
fi
garments="${GARMENTS:-tshirt longsleeve skirt dress trousers}"
mkdir -p "$out"
printf 'frames %s, measure every %s, particles %s, extra: %s\n' "${FRAMES:-300}" "${MEASURE:-3}" \
  "${PARTICLES:-default}" "$*" > "$out/args.txt"
export REPLAY_BIN="$replay" OUT_DIR="$out" RUN_FRAMES="${FRAMES:-300}" RUN_MEASURE="${MEASURE:-3}"
# Each run gets the extra options, then its take, garment and resolution (xargs appends those
# three; "-" for drape-replay's own).
for t in $TAKES; do
  for g in $garments; do
    for n in ${PARTICLES:--}; do
      printf '%s\0%s\0%s\0' "$t" "$g" "$n"
    done
  done
done | xargs -0 -n 3 -P "${JOBS:-$(nproc)}" bash -c '
  take="${@: -3:1}"; garment="${@: -2:1}"; particles="${@: -1}"; set -- "${@:1:$#-3}"
  name="$(basename "$take")"; name="${name%.*}_${garment}"
  res=()
  if [[ "$particles" != "-" ]]; then name="${name}_${particles}"; res=(--particles "$particles"); fi
  "$REPLAY_BIN" --recording "$take" --garment "$garment" "${res[@]}" --frames "$RUN_FRAMES" \
    --measure-every "$RUN_MEASURE" --no-obj --no-render --fidelity-every 0 --quiet --stats "$OUT_DIR/$name.json" "$@" \
    || { echo "matrix.sh: $name failed" >&2; exit 255; }
' _ "$@"
echo "matrix.sh: $(ls "$out"/*.json | wc -l) runs in $out"
