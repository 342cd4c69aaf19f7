#!/bin/bash
# One time-budgeted fine-tuning stage on a machine that has torch (and a GPU) but not this project installed:
# the way 0.10.0's stages gpu3 and gpu4 ran on a lent H200 (docs/RESULTS.md). Run from a checkout:
#
#   BUDGET=440 LR=3e-4 bash scripts/gpu_stage.sh                          # stage 1, from models/vae.pt
#   RUN=/tmp/r2 INIT=/tmp/r/best.pt BUDGET=170 LR=1.2e-4 WARMUP=0.1 bash scripts/gpu_stage.sh   # stage 2
#
# Settings (environment): BUDGET seconds of training (400), LR peak (3e-4), WARMUP (0.05), NTRAIN curves (2000000),
# NVAL and NTEST (2000 and 1000: validation and test curves),
# MIX_VERSION (the latest), PARAMS (1: --spline-params, a head that learns its points' parameters; default: INIT's
# head), MATCH (index, closest, twin or mixed: what the reconstruction error measures, `curve-vae train --match`;
# mixed — index for curves at their own spacing, closest points for the rest — lets the decoder give a respaced curve
# its own shape instead of bending it to put even parameters at the points: docs/RESULTS.md), ONLY_ENCODER (1: --only-encoder), DEVICE (cuda), WORKERS drawing the data (16), INIT weights (models/vae.pt), RUN folder
# (/tmp/r), DATA cache (/tmp/d.npz: a second stage on the same curves reads it), WHEELS (a folder of wheels of
# what the machine lacks, e.g. pydantic, shapely; installed to /tmp/site without an index), OUT (/tmp/out).
# OUT receives train.log, log.jsonl, config.json and best.pt without its optimiser state (a third of the size); no
# figures are drawn on the lent machine (seconds of its time): `curve-vae evaluate` draws them from the export.
set -euo pipefail
T0=$(date +%s)
REPO=$(cd "$(dirname "$0")/.." && pwd)
OUT=${OUT:-/tmp/out} RUN=${RUN:-/tmp/r}
export OUT RUN
mkdir -p "$OUT"
if [ -n "${WHEELS:-}" ]; then
  pip install -q --no-index --no-deps --target /tmp/site "$WHEELS"/*.whl
fi
# the package from the checkout, as pyproject maps it (curve_vae/ plus the top-level folders), without installing
SRC=$(mktemp -d)
trap 'rm -rf "$SRC"' EXIT
cp -r "$REPO/curve_vae" "$SRC/"
for d in geometry inference training service models; do ln -s "$REPO/$d" "$SRC/curve_vae/$d"; done
export PYTHONPATH=/tmp/site:$SRC
cd "$SRC"  # not the checkout: python -m would import the checkout's curve_vae/ before the mapped one
mix_version=()
if [ -n "${MIX_VERSION:-}" ]; then mix_version=(--mix-version "$MIX_VERSION"); fi
params=()
if [ "${PARAMS:-}" = 1 ]; then params=(--spline-params); fi
params+=(--match "${MATCH:-index}")
if [ "${ONLY_ENCODER:-}" = 1 ]; then params+=(--only-encoder); fi
python3 -m curve_vae.cli train --run-dir "$RUN" --init-from "${INIT:-$REPO/models/vae.pt}" --mix broad \
  "${mix_version[@]}" "${params[@]}" --n-train "${NTRAIN:-2000000}" \
  --n-val "${NVAL:-2000}" --n-test "${NTEST:-1000}" --data "${DATA:-/tmp/d.npz}" --workers "${WORKERS:-16}" \
  --device "${DEVICE:-cuda}" --batch-size 512 --lr "${LR:-3e-4}" --warmup "${WARMUP:-0.05}" --epochs 1000 \
  --time-budget "${BUDGET:-400}" --snapshots 1 --no-progress --no-figures 2>&1 | tee "$OUT/train.log"
python3 - <<'PY'
import os

import torch

from curve_vae.training.checkpoint import load_checkpoint, without_resume_state

torch.save(without_resume_state(load_checkpoint(os.environ["RUN"] + "/best.pt")), os.environ["OUT"] + "/best.pt")
PY
cp "$RUN/log.jsonl" "$RUN/config.json" "$OUT/"
echo "stage done in $(($(date +%s) - T0)) s; results in $OUT"
