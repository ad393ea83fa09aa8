#!/usr/bin/env bash
# Wall clock, CPU and memory of the whole policy protocol on one GPU machine: `tavis eval --policy` over TAVIS-Head
# x (id, ood_spatial, ood_init_pose) x 96 episodes = 1,440 episodes, through benchmarks/command_footprint.py.
#
#   benchmarks/policy_protocol.sh checkpoint|protocol
#
# - checkpoint: the worst case for time. The `diffusion_head_wrist` preset (240x320, head + both wrists) trained
#   for one step on two conditional_pick demonstrations: it never succeeds, so every episode runs its full 20 s.
# - protocol: the protocol with that checkpoint (or CHECKPOINT), DDIM with STEPS (10) denoising steps and AMP on
#   DEVICE (cuda), WORKERS (8) jobs sharing the GPU, BATCH (12) envs per job, FILM (4) filmed episodes per task
#   and split; writes $WORK/protocol/ and $WORK/protocol_footprint.json.
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
    [ -f "$WORK/raw/manifest.json" ] || tavis record --robot gr1t2 --tasks conditional_pick --episodes-per-task 2 \
      --workers 2 --out "$WORK/raw"
    tavis convert "$WORK/raw" --repo-id local/protocol-probe --root "$WORK/dataset" --fps 20 --image-size 240x320 \
      --cameras head,left_wrist,right_wrist --workers 2 --overwrite
    lerobot-train --config_path="$(tavis presets diffusion_head_wrist)" --dataset.repo_id=local/protocol-probe \
      --dataset.root="$WORK/dataset" --policy.device="${DEVICE:-cuda}" --steps=1 --save_freq=1 --batch_size=2 \
      --num_workers=0 --env_eval_freq=0 --output_dir="$WORK/train"
    ;;
  protocol)
    # shellcheck disable=SC2086  # SPLITS is a list
    python3 "$HERE/command_footprint.py" --out "$WORK/protocol_footprint.json" -- tavis eval --policy "$CHECKPOINT" \
      --suite tavis_head --splits ${SPLITS:-id ood_spatial ood_init_pose} --episodes "${EPISODES:-96}" \
      --device "${DEVICE:-cuda}" --workers "${WORKERS:-8}" --batch-size "${BATCH:-12}" --film-episodes "${FILM:-4}" \
      --policy-option noise_scheduler_type=DDIM --policy-option "num_inference_steps=${STEPS:-10}" \
      --policy-option use_amp=true --out "$WORK/protocol"
    ;;
  *)
    echo "usage: $0 checkpoint|protocol" >&2
    exit 2
    ;;
esac
