#!/usr/bin/env bash
# The README's tracking rows of PETS09-S2L1 and TUD-Campus, as a user gets them: `pftrack track`
# with the public detections and with the built-in detector (seed 0, every default), each file
# then scored by `pftrack eval` (HOTA, MOTA, IDF1 and the rest).
#
# usage: bash experiments/measure.sh OUT
#   OUT   folder for the four track files (pets_pub, tud_pub, pets_own, tud_own .txt)
#   data: $PFTRACK_DATA, else ../shared/data
# Two runs of the same code write the same bytes: compare two OUT folders with `cmp`.
set -euo pipefail
out=${1:?usage: bash experiments/measure.sh OUT}
data=${PFTRACK_DATA:-../shared/data}
pets=$data/pets09-s2l1
tud=$data/tud-campus
mkdir -p "$out"
export OPENBLAS_NUM_THREADS=1
pf() { python -m pftrack "$@"; }
pf -q track "$pets/video.avi" --detections "$pets/det.txt" --det-scale 0.625 --out "$out/pets_pub.txt"
pf -q track "$tud/video.mp4" --detections "$tud/det.txt" --out "$out/tud_pub.txt"
pf -q track "$pets/video.avi" --out "$out/pets_own.txt"
pf -q track "$tud/video.mp4" --out "$out/tud_own.txt"
for run in pets_pub pets_own; do
  echo "== $run"
  pf eval --gt "$pets/gt.txt" --res "$out/$run.txt" --scale 0.625
done
for run in tud_pub tud_own; do
  echo "== $run"
  pf eval --gt "$tud/gt.txt" --res "$out/$run.txt"
done
