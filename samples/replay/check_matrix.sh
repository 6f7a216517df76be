#!/usr/bin/env bash
# CTest replay_matrix: matrix.sh and matrix_compare.py on the bundled take (two garments, a few
# frames). The same settings twice must give the same numbers (drape-replay is deterministic), and
# the comparer must see a change of setting (else the first check could not fail), and --by-garment
# must give each garment its line, --by-take each take and garment.
#   check_matrix.sh DRAPE_REPLAY WORK_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
replay="$1"
work="$2"
rm -rf "$work"
export REPLAY="$replay" TAKES="$here/../data/Ges01_wavehand.csv" GARMENTS="tshirt skirt" FRAMES=8 MEASURE=2 JOBS=2
bash "$here/matrix.sh" "$work/a" --particles 400
bash "$here/matrix.sh" "$work/b" --particles 400
bash "$here/matrix.sh" "$work/c" --particles 400 --substeps 5
for run in Ges01_wavehand_tshirt Ges01_wavehand_skirt; do
  [[ -s "$work/a/$run.json" ]] || { echo "check_matrix: $run.json missing" >&2; exit 1; }
done
python3 "$here/matrix_compare.py" "$work/a" "$work/b" --fail-if-different
if python3 "$here/matrix_compare.py" "$work/a" "$work/c" --fail-if-different >/dev/null 2>&1; then
  echo "check_matrix: 5 substeps gave the same figures as 10: the comparer sees no difference" >&2
  exit 1
fi
# --by-garment: one line per garment of the runs (the runs' names take_garment), with the frames off.
per_garment="$(python3 "$here/matrix_compare.py" "$work/a" "$work/c" --by-garment)"
for garment in tshirt skirt; do
  grep -Eq "^  $garment +1 runs .*off frames [0-9]+ -> [0-9]+$" <<<"$per_garment" ||
    { echo "check_matrix: --by-garment printed no line for $garment:" >&2; echo "$per_garment" >&2; exit 1; }
done
# --by-take: one line per take and garment (here one run each), frames off and means before -> after.
per_take="$(python3 "$here/matrix_compare.py" "$work/a" "$work/c" --by-take)"
for run in Ges01_wavehand_tshirt Ges01_wavehand_skirt; do
  grep -Eq "^  $run +1 runs  off +[0-9]+ -> +[0-9]+  stretch +[0-9.]+ -> +[0-9.]+  worst +[0-9.]+ -> +[0-9.]+$" <<<"$per_take" ||
    { echo "check_matrix: --by-take printed no line for $run:" >&2; echo "$per_take" >&2; exit 1; }
done
echo "check_matrix: same settings same figures; another setting told apart; one line per garment and per take"
