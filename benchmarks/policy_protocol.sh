#!/usr/bin/env bash
# Wall clock, CPU and memory of the whole policy protocol on one GPU machine: `tavis eval --policy` over TAVIS-Head
# x (id, ood_spatial, ood_init_pose) x 96 episodes = 1,440 episodes, through benchmarks/command_footprint.py.
#
#   benchmarks/policy_protocol.sh checkpoint|protocol
#
# - checkpoint: the worst case for time. The `diffusion_head_wrist` preset (240x320, head + both wrists) trained
#   for one step on eight conditional_pick demonstrations: it never succeeds, so every episode runs its full 20 s.
#   Eight, so that both arms move in them: a state dimension that never changes (the idle arm of two left-hand
#   picks) is normalised by a range of 0 (LeRobot divides by 1e-8), so the first episode that moves it
#   (ood_init_pose) feeds the policy values near 1e7, past float16's range under AMP, and gets NaN actions back.
# - protocol: the protocol with that checkpoint (or CHECKPOINT), DDIM with STEPS (10) denoising steps and AMP on
#   DEVICE (cuda), WORKERS (3) jobs sharing the GPU, BATCH (32) envs per job, FILM (4) filmed episodes per task
#   and split; writes $WORK/protocol/ and $WORK/protocol_footprint.json. 3 jobs of 32 step about as many envs per
#   second as 8 jobs of 12 (docs/results/history.md, "Speed and memory"), so the default is the one with fewer
#   policy copies on the GPU.
#
# Settings (environment variables): WORK (/tmp/tavis_protocol), SPLITS ("id ood_spatial ood_init_pose"), EPISODES
# (96), and those above.
set -euo pipefail
WORK=${WORK:-/tmp/tavis_protocol}
CHECKPOINT=${CHECKPOINT:-$WORK/train/checkpoints/last/pretrained_model}
export MUJOCO_GL=${MUJOCO_GL:-egl}
HERE=$(cd "$(dirname "$0")" && pwd)

case "${1:-}" in
  checkpoint)
    [ -f "$WORK/raw/manifest.json" ] || tavis record --robot gr1t2 --tasks conditional_pick --episodes-per-task 8 \
      --workers 8 --out "$WORK/raw"
    tavis convert "$WORK/raw" --repo-id local/protocol-probe --root "$WORK/dataset" --fps 20 --image-size 240x320 \
      --cameras head,left_wrist,right_wrist --workers 8 --overwrite
    python3 - "$WORK/dataset/meta/stats.json" <<'PY'
import json, sys
stats = json.load(open(sys.argv[1]))["observation.state"]
constant = [i for i, (low, high) in enumerate(zip(stats["min"], stats["max"])) if high - low < 1e-6]
if constant:
    sys.exit(f"checkpoint: state dimensions {constant} never change (by 1e-6) in the probe's demonstrations")
PY
    lerobot-train --config_path="$(tavis presets diffusion_head_wrist)" --dataset.repo_id=local/protocol-probe \
      --dataset.root="$WORK/dataset" --policy.device="${DEVICE:-cuda}" --steps=1 --save_freq=1 --batch_size=2 \
      --num_workers=0 --env_eval_freq=0 --output_dir="$WORK/train"
    ;;
  protocol)
    # shellcheck disable=SC2086  # SPLITS is a list
    python3 "$HERE/command_footprint.py" --out "$WORK/protocol_footprint.json" -- tavis eval --policy "$CHECKPOINT" \
      --suite tavis_head --splits ${SPLITS:-id ood_spatial ood_init_pose} --episodes "${EPISODES:-96}" \
      --device "${DEVICE:-cuda}" --workers "${WORKERS:-3}" --batch-size "${BATCH:-32}" --film-episodes "${FILM:-4}" \
      --policy-option noise_scheduler_type=DDIM --policy-option "num_inference_steps=${STEPS:-10}" \
      --policy-option use_amp=true --out "$WORK/protocol"
    ;;
  *)
    echo "usage: $0 checkpoint|protocol" >&2
    exit 2
    ;;
esac
