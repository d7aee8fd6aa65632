#!/usr/bin/env bash
# The data of the report's figures after the paper's Figs. 9/10 and A.12-14 (issue 18 item 10),
# from the repository root: bash data/paper_figures/generate.sh. Each command is resumable on its
# own (a finished folder is skipped); the report (validation/report_data.py) draws from these files.
set -euo pipefail
cd "$(dirname "$0")/../.."
PY=.venv/bin/python
OUT=data/paper_figures
# Fig. 10: the plate's centerline against the best rod centreline, Eq. (13), per L/W and dW/L
[ -f $OUT/centerline_error/centerline_error.csv ] || \
  $PY -m ddg centerline-error --width-ratios 0.5,0.3333,0.1667,0.08333,0.05 --shear-ratios 0.1,0.3,0.5 \
      --resolution 2000 --out $OUT/centerline_error
# Figs. A.12-14: curvature profiles k1 (geodesic), k2 (normal), tau along s at U, US and S states,
# W/L = 1/20, dL/L = 1/2, for the rod, the Sadowsky ribbon and the plate
for model in rod ribbon plate; do
  [ -f $OUT/curvatures_$model/curvatures.csv ] || \
    $PY -m ddg curvatures --model $model --width-ratio 0.05 --compression-ratio 0.5 --shear-ratios 0.2,0.45,0.6 \
        --out $OUT/curvatures_$model
done
# Fig. A.11: H_mid/L against dW/L at dL/L = 1/2 from the rod, the plate, the Sadowsky ribbon from the
# flat strip ("direct") and the Sadowsky ribbon relaxed from each rod equilibrium ("rod", DAR-Sadowsky)
for width in 0.05 0.1667; do
  for spec in "rod rod --resolution 100" "plate plate --resolution 2000" "ribbon_direct ribbon --ribbon-init direct" \
              "ribbon_rod ribbon --ribbon-init rod"; do
    set -- $spec
    name=$1; model=$2; shift 2
    folder=$OUT/a11/W$width/$name
    if [ ! -f $folder/summary.json ] || ! grep -q '"status": "complete"' $folder/summary.json; then
      $PY -m ddg simulate --model $model "$@" --width-ratio $width --compression-ratio 0.5 --no-branches --quiet \
          --out $folder || true   # a stopped run is kept as it is (its summary says why)
      find $folder -type f ! -name path.csv ! -name summary.json -delete   # the figure needs the path only
    fi
  done
done
# Fig. 9a (the deformed plates and their centreline rendering) and Fig. 9b (the centreline approximation's
# error delta(s, w) over the plate): validation/paper_figures.py
$PY -m validation.paper_figures --out $OUT --quiet
