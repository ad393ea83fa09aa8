#!/usr/bin/env bash
# A single-task Diffusion Policy run (headcam): demonstrations -> dataset -> training -> 96-episode evaluation.
#
#   benchmarks/diffusion_single_task.sh data|train|eval
#
# Settings (environment variables): TASK (conditional_pick), ROBOT (gr1t2), EPISODES (200 kept demonstrations),
# STEPS (training steps, 5000), SAVE_FREQ (checkpoint every so many steps, 1000), BATCH (64), WORKERS (parallel
# recording / data loading processes, 16), EVAL_EPISODES (96), WORK (/tmp/tavis_run). `eval` evaluates the latest
# checkpoint (`checkpoints/last`), so a time-boxed run may stop training early and evaluate what it has. The stages run one after the other on one machine; each prints its
# wall-clock time. Uses the `diffusion_headcam` preset with only the data, step and batch settings overridden.
set -euo pipefail
TASK=${TASK:-conditional_pick}
ROBOT=${ROBOT:-gr1t2}
EPISODES=${EPISODES:-200}
STEPS=${STEPS:-5000}
SAVE_FREQ=${SAVE_FREQ:-1000}
BATCH=${BATCH:-64}
WORKERS=${WORKERS:-16}
EVAL_EPISODES=${EVAL_EPISODES:-96}
WORK=${WORK:-/tmp/tavis_run}
export MUJOCO_GL=${MUJOCO_GL:-egl}
REPO_ID=local/tavis-${TASK}-${ROBOT}
PRESET=$(tavis presets diffusion_headcam)

case "${1:-}" in
  data)
    time tavis record --robot "$ROBOT" --tasks "$TASK" --episodes-per-task "$EPISODES" --workers "$WORKERS" \
      --out "$WORK/raw"
    time tavis convert "$WORK/raw" --repo-id "$REPO_ID" --root "$WORK/dataset" --fps 20 --image-size 240x320 \
      --cameras head --overwrite
    ;;
  train)
    time lerobot-train --config_path="$PRESET" --dataset.repo_id="$REPO_ID" --dataset.root="$WORK/dataset" \
      --env.task="$TASK" --env.robot="$ROBOT" --policy.device=cuda --policy.use_amp=true \
      --steps="$STEPS" --save_freq="$SAVE_FREQ" --batch_size="$BATCH" --num_workers="$WORKERS" --env_eval_freq=0 \
      --log_freq=250 --output_dir="$WORK/train"
    ;;
  eval)
    time lerobot-eval --policy.path="$WORK/train/checkpoints/last/pretrained_model" --policy.device=cuda \
      --policy.use_amp=true --env.type=tavis --env.task="$TASK" --env.robot="$ROBOT" --env.camera_mode=headcam \
      --env.image_size=[240,320] --eval.n_episodes="$EVAL_EPISODES" --eval.batch_size=32 \
      --eval.use_async_envs=true --output_dir="$WORK/eval"
    tavis report "$WORK/eval"
    ;;
  *)
    echo "usage: $0 data|train|eval" >&2
    exit 2
    ;;
esac
