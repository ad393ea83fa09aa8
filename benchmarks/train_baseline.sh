#!/usr/bin/env bash
# One baseline cell within 30 minutes on one GPU: demonstrations -> dataset -> compact policy -> evaluation
# of every checkpoint (96 episodes each, Wilson intervals and GALT by `tavis eval`'s report).
#
#   benchmarks/train_baseline.sh pair|cell|data|prepare|train|eval|overfit
#
# Settings (environment variables): CONDITION (head_wrist: head + both wrist cameras, the paper's "headcam";
# fixed_wrist: fixed + both wrists, its "fixedcam"), TASK (conditional_pick; a comma-separated list, e.g.
# peeking_box,occluded_reach: one policy trained on all of them, EPISODES each, and evaluated on each; with
# TRAIN_OPTIONS=--policy.prompt_input=true it reads which task from the prompt), ROBOT (gr1t2), EPISODES (160 kept
# demonstrations, as many as the reference's datasets hold per task), STEPS, SAVE_FREQ and BATCH (the preset's, 6000,
# 2000 and 64), SEED (lerobot-train's, 1000 as its default: another seed trains a replicate), WORKERS (recording,
# conversion and loading processes: all cores), EVAL_EPISODES (96), EVAL_JOBS and EVAL_BATCH (4 and 12: an
# evaluation's jobs sharing the GPU, each playing EVAL_EPISODES / EVAL_JOBS episodes in batches of EVAL_BATCH envs),
# FILM (episodes filmed per evaluation: 2, as each filmed sub-env also renders the overview), EVAL_OPTIONS (more
# `tavis eval` arguments, e.g. "--policy-option temporal_ensemble_coeff=0.01 --policy-option n_action_steps=1" for
# ACT's temporal ensembling), TRAIN_OPTIONS (more lerobot-train arguments, e.g. "--policy.chunk_size=40
# --policy.n_action_steps=20"), EVAL_NAME (the evaluations' folder under WORK: eval_<RUN>), CHECKPOINTS (which
# `eval` takes: all, last, or one training step such as 1600), STATE_INPUT (on; off: the policy sees its cameras
# alone, a copy of the preset without the observation.state input written to WORK, to tell a policy that copies its
# own pose from one that needs it; off is the default with ACTIONS=hand_relative and the only value it takes),
# STATE_NOISE (empty: off; POSITION_M,ROTATION_DEG, e.g. 0.02,5: `train` reads a copy of the dataset whose
# observation.state hand poses carry fixed per-frame Gaussian noise of those standard deviations, metres per axis and
# degrees per rotation-vector component, heads, grippers and actions exact: $WORK/dataset_<CONDITION>_state_noise,
# made once by `tavis noise-state` with seed SEED; needs STATE_INPUT=on; `overfit` ignores it), ACTIONS (absolute;
# hand_relative: the `act_hand_relative_<CONDITION>_compact` preset, ACT whose chunks hold the arm poses in the frame
# of the hand as measured when the chunk is planned, observation.state read as that anchor alone, with the time
# since the episode began as an input; its own budget unless set: STEPS 3200, SAVE_FREQ 800, BATCH 128, LR 1e-4;
# another BATCH, or GPUS > 1, keeps the preset's samples (3200 x 128) and rescales what is not set by the ratio r of
# BATCH x GPUS, the samples per optimiser step, to the preset's batch: STEPS / r, SAVE_FREQ / r, LR x sqrt(r), the
# square-root rule for Adam-type optimisers, which keeps the size of the optimiser's noise per sample, where the
# linear rule, SGD's, would take BATCH 512 to 4e-4; e.g. BATCH=256: 1600 steps, a checkpoint every 400, lr 1.41e-4),
# LR (ACTIONS=hand_relative: the peak learning rate, `--optimizer.lr`, and ACT's backbone's,
# `--policy.optimizer_lr_backbone`),
# POLICY (act; diffusion: with ACTIONS=hand_relative, the only actions it takes, the
# `diffusion_hand_relative_<CONDITION>_compact` preset, Diffusion Policy denoising horizons in the hand frame on the
# same budget, its network seeing no state, with the time input; TRAIN_S 1500 s unless set; its training and
# evaluations go to train_diffusion_<CONDITION> and eval_diffusion_<CONDITION>, so it shares WORK's recording and
# datasets with the ACT runs: RUN below is diffusion_<CONDITION>, else <CONDITION>),
# GPUS (1; N > 1, not with `pair`: `train` runs lerobot-train data-parallel in N processes of `accelerate launch`,
# one per visible GPU, each with BATCH and WORKERS / N loader workers, so a step trains N x BATCH samples: divide STEPS
# and SAVE_FREQ by N for the one-GPU budget, which ACTIONS=hand_relative does itself), FRAME_CACHE (off; on: `train`
# writes the dataset's frame cache once, `tavis cache-frames`, and reads the frames from it, TAVIS_FRAME_CACHE=1;
# docs/training.md, "Training at scale"),
# SPLITS (id: the splits each evaluation plays, comma-separated; table: id for fixed_wrist and id, ood_spatial and
# ood_init_pose for head_wrist, the baselines table's protocol), DEVICE (cuda; cpu: training and evaluation without
# a GPU and without AMP, for tiny runs that test the pipeline), VIDEO_BACKEND (how training decodes the dataset's
# videos: torchcodec where it loads, else pyav), WORK (/tmp/tavis_baseline).
#
# - pair: both conditions of TASK at once from one recording, each a `cell` with half the cores, each on its own
#   GPU where two or more are visible (CUDA_VISIBLE_DEVICES, else all: a two-GPU slot gives both arms of the
#   comparison); logs in $WORK/cell_<condition>.log.
# - cell: the whole cell within one 30-minute GPU slot: data, then STEPS (4800; ACTIONS=hand_relative: 3200) steps of
#   BATCH 128 with SAVE_FREQ 1600 (800) unless set (loaders: WORKERS - 2; the preset anneals the lr to 0 at the last
#   step; about 13 minutes with 16 cores and an evaluation beside, 10 for hand_relative; TRAIN_S, 960 s, only guards
#   the slot; POLICY=diffusion, not yet timed on a GPU: 1500 s), the checkpoints evaluated at low CPU priority as
#   they appear, and those left after training ends side by side. It fails (exit 1, saying which) when the training
#   stopped early (a NaN loss, TRAIN_S) or an evaluation failed, after evaluating what the training saved; `pair`
#   fails when either condition's `cell` does, naming its log.
# - data: records the demonstrations once (both conditions share them) and converts them at 120x160 with the
#   condition's cameras (`--zero-neck` for fixed_wrist, as its env holds the neck at 0), unless WORK already holds
#   that conversion of that recording (its meta/tavis_conversion.json says so): then the dataset is kept. A recording
#   of several tasks is converted task by task side by side, WORKERS shared, and merged with `lerobot-edit-dataset`
#   (the samples of one conversion, docs/datasets.md; one conversion's single writer bounds it).
# - prepare: data, then (FRAME_CACHE=on) the dataset's frame cache: the CPU work `train` needs done, which can run
#   ahead while another cell trains.
# - train: lerobot-train with the `act_<CONDITION>_compact` preset (ACTIONS=hand_relative:
#   `<POLICY>_hand_relative_<CONDITION>_compact`); decodes with torchcodec when FFmpeg's libraries can be found (PyAV's
#   bundled copy, tools/pyav_ffmpeg.sh), else with PyAV. A run whose logged loss becomes NaN (float16 AMP
#   overflowing: three ACT trainings in docs/results; the hand-frame preset runs its network in bfloat16 under AMP
#   for that reason) is stopped there and fails (exit 3) instead of spending the slot on NaN checkpoints.
# - eval: `tavis eval --policy` (LeRobot's evaluation loop, EVAL_JOBS runs of it sharing the GPU: one loop over
#   48 envs stepped about 200 envs/s on 16 cores) on every complete checkpoint not yet evaluated (or the last
#   alone: CHECKPOINTS=last; one step's: CHECKPOINTS=1600), seeds from 1000, side by side; it can run beside
#   `train`, which marks a checkpoint complete by pointing `checkpoints/last` at it, and beside another `eval` call,
#   which skips the checkpoints that one is evaluating. Then `tavis curve` puts every finished checkpoint's success
#   and GALT in one table and plot by training step: $WORK/$EVAL_NAME/checkpoints.md and checkpoints.png; exit 1
#   when one of its evaluations failed.
# - overfit: the pipeline sanity check. Trains on 8 demonstrations (seeds 100000-100007) for OVERFIT_STEPS (3000) and
#   evaluates on those same seeds and on 8 new ones: a policy that cannot do better on the scenes it was trained
#   on points at a data or alignment bug, not at too little training.
set -euo pipefail
CONDITION=${CONDITION:-head_wrist}
TASK=${TASK:-conditional_pick}
ROBOT=${ROBOT:-gr1t2}
EPISODES=${EPISODES:-160}
WORKERS=${WORKERS:-$(nproc)}
EVAL_EPISODES=${EVAL_EPISODES:-96}
EVAL_JOBS=${EVAL_JOBS:-4}
EVAL_BATCH=${EVAL_BATCH:-12}
FILM=${FILM:-2}
SEED=${SEED:-1000}
CHECKPOINTS=${CHECKPOINTS:-all}
ACTIONS=${ACTIONS:-absolute}
POLICY=${POLICY:-act}
if [ "$ACTIONS" = hand_relative ]; then STATE_INPUT=${STATE_INPUT:-off}; else STATE_INPUT=${STATE_INPUT:-on}; fi
STATE_NOISE=${STATE_NOISE:-}
GPUS=${GPUS:-1}
FRAME_CACHE=${FRAME_CACHE:-off}
SPLITS=${SPLITS:-id}
DEVICE=${DEVICE:-cuda}
read -ra eval_options <<< "${EVAL_OPTIONS:-}"  # its words; EVAL_OPTIONS stays a string for the modes run again below
read -ra train_options <<< "${TRAIN_OPTIONS:-}"
WORK=${WORK:-/tmp/tavis_baseline}
export MUJOCO_GL=${MUJOCO_GL:-egl}
case "$CONDITION" in
  head_wrist) CAMERAS=head,left_wrist,right_wrist; NECK=() ;;
  fixed_wrist) CAMERAS=fixed,left_wrist,right_wrist; NECK=(--zero-neck) ;;
  *) echo "CONDITION must be head_wrist or fixed_wrist, got '$CONDITION'" >&2; exit 2 ;;
esac
case "$CHECKPOINTS" in
  all|last) ;;
  *[!0-9]*) echo "CHECKPOINTS must be all, last or a training step, got '$CHECKPOINTS'" >&2; exit 2 ;;
esac
case "$STATE_INPUT" in
  on|off) ;;
  *) echo "STATE_INPUT must be on or off, got '$STATE_INPUT'" >&2; exit 2 ;;
esac
case "$ACTIONS" in
  absolute) ;;
  hand_relative) if [ "$STATE_INPUT" = on ]; then
      echo "ACTIONS=hand_relative takes STATE_INPUT=off alone: act_hand_relative reads observation.state only as" \
        "the anchor of its chunks, never as a network input" >&2
      exit 2
    fi ;;
  *) echo "ACTIONS must be absolute or hand_relative, got '$ACTIONS'" >&2; exit 2 ;;
esac
case "$POLICY" in
  act) ;;
  diffusion) if [ "$ACTIONS" != hand_relative ]; then
      echo "POLICY=diffusion takes ACTIONS=hand_relative alone (its preset is" \
        "diffusion_hand_relative_<CONDITION>_compact), got ACTIONS=$ACTIONS" >&2
      exit 2
    fi ;;
  *) echo "POLICY must be act or diffusion, got '$POLICY'" >&2; exit 2 ;;
esac
if [ "$POLICY" = diffusion ]; then RUN=diffusion_$CONDITION; else RUN=$CONDITION; fi  # names its train_ and eval_
EVAL_NAME=${EVAL_NAME:-eval_$RUN}
if [ -n "$STATE_NOISE" ] && ! [[ "$STATE_NOISE" =~ ^[0-9]+(\.[0-9]+)?,[0-9]+(\.[0-9]+)?$ ]]; then
  echo "STATE_NOISE must be empty (off) or POSITION_M,ROTATION_DEG, two decimal numbers >= 0 such as 0.02,5;" \
    "got '$STATE_NOISE'" >&2
  exit 2
fi
if [ -n "$STATE_NOISE" ] && [ "$STATE_INPUT" = off ]; then
  echo "STATE_NOISE needs STATE_INPUT=on: with STATE_INPUT=off the policy sees no observation.state to noise" >&2
  exit 2
fi
case "$GPUS" in
  ''|*[!0-9]*|0) echo "GPUS must be a number of GPUs >= 1, got '$GPUS'" >&2; exit 2 ;;
esac
case "${BATCH:-1}" in
  *[!0-9]*|0) echo "BATCH must be a number of samples >= 1 per GPU, got '$BATCH'" >&2; exit 2 ;;
esac
if [ -n "${LR:-}" ] && { [ "$ACTIONS" != hand_relative ] || ! [[ "$LR" =~ ^[0-9]+(\.[0-9]+)?([eE]-?[0-9]+)?$ ]]; }; then
  echo "LR must be a learning rate such as 1e-4 or 0.0002, with ACTIONS=hand_relative; got '$LR'" \
    "with ACTIONS=$ACTIONS" >&2
  exit 2
fi
case "$FRAME_CACHE" in
  on|off) ;;
  *) echo "FRAME_CACHE must be on or off, got '$FRAME_CACHE'" >&2; exit 2 ;;
esac
splits=${SPLITS//,/ }  # SPLITS itself is left as given: `pair` passes it on to both conditions
if [ "$SPLITS" = table ]; then
  if [ "$CONDITION" = head_wrist ]; then splits="id ood_spatial ood_init_pose"; else splits=id; fi
fi
read -ra splits <<< "$splits"
case "${VIDEO_BACKEND:-}" in
  ''|pyav|torchcodec) ;;
  *) echo "VIDEO_BACKEND must be pyav or torchcodec (or unset: torchcodec where it loads), got '$VIDEO_BACKEND'" >&2
    exit 2 ;;
esac
case "$DEVICE" in
  cuda) AMP=true ;;
  cpu) AMP=false ;;
  *) echo "DEVICE must be cuda or cpu, got '$DEVICE'" >&2; exit 2 ;;
esac
SIZE=120x160
HERE=$(cd "$(dirname "$0")" && pwd)

scaled_budget() {  # scaled_budget PRESET: the lerobot-train arguments of STEPS, SAVE_FREQ, BATCH and LR, those
  # not set rescaled from the preset's for BATCH x GPUS samples per step (header: ACTIONS=hand_relative)
  python3 - "$1" "${BATCH:-}" "$GPUS" "${STEPS:-}" "${SAVE_FREQ:-}" "${LR:-}" <<'PY'
import json, math, sys
preset = json.load(open(sys.argv[1]))
batch, gpus, steps, save_freq, lr = sys.argv[2:]
ratio = int(batch or preset["batch_size"]) * int(gpus) / preset["batch_size"]
arguments = {"steps": steps, "save_freq": save_freq, "batch_size": batch}
if ratio != 1:
    arguments = {"steps": steps or max(1, round(preset["steps"] / ratio)),
                 "save_freq": save_freq or max(1, round(preset["save_freq"] / ratio)), "batch_size": batch}
    lr = lr or f"{preset['optimizer']['lr'] * math.sqrt(ratio):.3g}"
if lr:
    arguments["optimizer.lr"] = lr
    if "optimizer_lr_backbone" in preset["policy"]:
        arguments["policy.optimizer_lr_backbone"] = lr
print(" ".join(f"--{key}={value}" for key, value in arguments.items() if value))
PY
}

choose_video_backend() {  # BACKEND=VIDEO_BACKEND if set, else torchcodec when it loads (with PyAV's FFmpeg if the
  # system has none), else pyav
  eval "$("$HERE/../tools/pyav_ffmpeg.sh" "$WORK/ffmpeg")"  # exports LD_LIBRARY_PATH for lerobot-train
  BACKEND=${VIDEO_BACKEND:-$(python3 -c "from lerobot_tavis.dataset_tools.quiet import video_backend
print(video_backend())")}
}

record() {  # the demonstrations, once: every condition of TASK converts the same ones
  [ -f "$WORK/raw/manifest.json" ] || time tavis record --robot "$ROBOT" --tasks "$TASK" \
    --episodes-per-task "$EPISODES" --workers "$WORKERS" --out "$WORK/raw"
}

converted() {  # converted DATASET_DIR: it holds WORK's recording converted as `convert` below converts it
  python3 - "$1" "$WORK/raw" "$SIZE" "$CAMERAS" "${#NECK[@]}" <<'PY'
import json, os, sys
dataset, raw, size, cameras, zero_neck = sys.argv[1:]
try:
    log = json.load(open(os.path.join(dataset, "meta", "tavis_conversion.json")))
    recorded = {entry["file"] for entry in json.load(open(os.path.join(raw, "manifest.json")))["episodes"]}
    wanted = {"raw_dir": os.path.abspath(raw), "fps": 20, "image_size": [int(n) for n in size.split("x")],
              "cameras": cameras.split(","), "zero_neck": zero_neck == "1"}
    same = {key: log[key] for key in wanted} == wanted and {e["raw_file"] for e in log["episodes"]} == recorded
except (OSError, ValueError, KeyError, TypeError):
    same = False
sys.exit(0 if same else 1)
PY
}

convert() {  # convert RAW_DIR DATASET_DIR; a recording of several tasks is converted task by task side by side
  # (one writer bounds a conversion) and merged by LeRobot, which gives the samples of one conversion (datasets.md)
  local tasks parts="$2.parts" part merging="$2.merging" status=0
  mapfile -t tasks < <(python3 -c 'import json, sys
from lerobot_tavis.envs.tasks.catalog import task_sort_key
episodes = json.load(open(sys.argv[1] + "/manifest.json"))["episodes"]
print(*sorted({episode["task"] for episode in episodes}, key=task_sort_key), sep="\n")' "$1")
  if (( ${#tasks[@]} < 2 )); then convert_tasks "$1" "$2" "$WORKERS"; return; fi
  rm -rf "$parts" "$merging"
  for part in "${tasks[@]}"; do
    convert_tasks "$1" "$parts/$part" $(( WORKERS / ${#tasks[@]} > 1 ? WORKERS / ${#tasks[@]} : 1 )) --task "$part" &
  done
  for part in "${tasks[@]}"; do wait -n || status=$?; done
  (( status == 0 )) || return "$status"
  lerobot-edit-dataset --new_repo_id "local/$(basename "$2")" --new_root "$merging" --operation.type merge \
    --operation.repo_ids "$(python3 -c 'import sys; print([f"local/{task}" for task in sys.argv[1:]])' "${tasks[@]}")" \
    --operation.roots "$(python3 -c 'import sys; print(sys.argv[1:])' "${tasks[@]/#/$parts/}")"
  python3 - "$merging" "${tasks[@]/#/$parts/}" <<'PY'  # the merged dataset's conversion log: its parts', in order
import json, sys
merged, parts = sys.argv[1], sys.argv[2:]
logs = [json.load(open(f"{part}/meta/tavis_conversion.json")) for part in parts]
log = {key: value for key, value in logs[0].items() if key != "episodes"}
assert all({key: value for key, value in other.items() if key != "episodes"} == log for other in logs), parts
episodes = (episode for part in logs for episode in part["episodes"])
log["episodes"] = [dict(episode, episode_index=index) for index, episode in enumerate(episodes)]
json.dump(log, open(f"{merged}/meta/tavis_conversion.json", "w"), indent=1)
PY
  rm -rf "$2" && mv "$merging" "$2" && rm -rf "$parts"
}

convert_tasks() {  # convert_tasks RAW_DIR DATASET_DIR WORKERS [--task TASK]
  tavis convert "$1" --repo-id "local/$(basename "$2")" --root "$2" --fps 20 --image-size "$SIZE" \
    --cameras "$CAMERAS" "${NECK[@]}" --workers "$3" --overwrite "${@:4}"
}

# Copies its input to its output as it comes; at the first NaN loss in LeRobot's log lines it stops the processes
# whose command line matches its argument (lerobot-train ignores a closed pipe) and exits 3.
PASS_UNTIL_NAN_LOSS='import os, subprocess, sys
seen = b""
while chunk := os.read(0, 1 << 16):
    os.write(1, chunk)
    if b" loss:nan " in seen[-16:] + chunk:
        subprocess.run(["pkill", "-TERM", "-f", "--", sys.argv[1]])
        sys.exit(3)
    seen = chunk'

preset() {  # prints the path of the condition's compact preset (ACTIONS=hand_relative: POLICY's hand-frame one);
  # with STATE_INPUT=off and absolute actions, of a copy without the state input
  local shipped copy="$WORK/preset_act_${CONDITION}_compact_no_state.json"
  if [ "$ACTIONS" = hand_relative ]; then tavis presets "${POLICY}_hand_relative_${CONDITION}_compact"; return; fi
  shipped=$(tavis presets "act_${CONDITION}_compact")
  if [ "$STATE_INPUT" = on ]; then echo "$shipped"; return; fi
  mkdir -p "$WORK"
  python3 - "$shipped" "$copy" <<'PY'
import json, os, sys
preset = json.load(open(sys.argv[1]))
del preset["policy"]["input_features"]["observation.state"]
with open(sys.argv[2] + ".tmp", "w") as copy:
    json.dump(preset, copy, indent=2)
os.replace(sys.argv[2] + ".tmp", sys.argv[2])
PY
  echo "$copy"
}

noisy_copy() {  # noisy_copy DATASET_DIR: makes DATASET_DIR_state_noise with STATE_NOISE and SEED once, prints it
  local copy="$1_state_noise" position_m=${STATE_NOISE%,*} rotation_deg=${STATE_NOISE#*,}
  # runs in $(...), where set -e does not hold: each failure returns
  [ -d "$copy" ] || tavis noise-state "$1" --out "$copy" --position-m "$position_m" --rotation-deg "$rotation_deg" \
    --seed "$SEED" >&2 || return
  python3 - "$copy/meta/state_noise.json" "$position_m" "$rotation_deg" "$SEED" <<'PY' || return
import json, sys
made = json.load(open(sys.argv[1]))
wanted = {"position_m": float(sys.argv[2]), "rotation_deg": float(sys.argv[3]), "seed": int(sys.argv[4])}
if {key: made[key] for key in wanted} != wanted:
    sys.exit(f"train_baseline: {sys.argv[1]} holds other noise than STATE_NOISE and SEED ask for ({wanted}); "
             "remove that copy to make a new one")
PY
  echo "$copy"
}

cache_frames() {  # cache_frames DATASET_DIR: written once per dataset; later calls find it up to date
  tavis cache-frames "$1" --workers "$WORKERS" --video-backend "$BACKEND"
}

train() {  # train DATASET_DIR OUTPUT_DIR [lerobot-train arguments...]: fails with 3, the run stopped, at a NaN loss
  local dataset=$1 out=$2 status=0 config
  shift 2
  config=$(preset)
  local launch=(lerobot-train)
  if (( GPUS > 1 )); then  # LeRobot's data-parallel path; precision stays lerobot-train's (docs/training.md)
    launch=(accelerate launch --multi_gpu --num_processes "$GPUS" --num_machines 1 --mixed_precision no
      --dynamo_backend no -m lerobot.scripts.lerobot_train)
  fi
  export TAVIS_FRAME_CACHE=0
  if [ "$FRAME_CACHE" = on ]; then
    cache_frames "$dataset"
    TAVIS_FRAME_CACHE=1
  fi
  "${launch[@]}" --config_path="$config" \
    --dataset.repo_id="local/$(basename "$dataset")" --dataset.root="$dataset" --dataset.video_backend="$BACKEND" \
    --env.task="$TASK" --env.robot="$ROBOT" --policy.device="$DEVICE" --policy.use_amp="$AMP" \
    --num_workers=$(( WORKERS / GPUS > 1 ? WORKERS / GPUS : 1 )) \
    --seed="$SEED" --log_freq=100 --output_dir="$out" "${train_options[@]}" "$@" 2>&1 \
    | python3 -c "$PASS_UNTIL_NAN_LOSS" "--output_dir=$out( |$)" || status=$?
  if (( status == 3 )); then
    echo "train_baseline: the training loss became NaN; training stopped. Train again with another SEED, or" \
      "without AMP (TRAIN_OPTIONS=--policy.use_amp=false)." >&2
  fi
  return "$status"
}

evaluate() {  # evaluate CHECKPOINT_DIR OUTPUT_DIR FIRST_SEED EPISODES: the SPLITS of TASK (each task of a list)
  local per_job=$(( ($4 + EVAL_JOBS - 1) / EVAL_JOBS )) tasks
  IFS=, read -ra tasks <<< "$TASK"
  tavis eval --policy "$1/pretrained_model" --tasks "${tasks[@]}" --splits "${splits[@]}" --episodes "$4" --seed "$3" \
    --robot "$ROBOT" --camera-mode "$CONDITION" --image-size "$SIZE" --device "$DEVICE" --policy-option "use_amp=$AMP" \
    --workers "$EVAL_JOBS" --chunk-episodes "$per_job" --batch-size $(( per_job < EVAL_BATCH ? per_job : EVAL_BATCH )) \
    --film-episodes "$FILM" "${eval_options[@]}" --out "$2"
}

case "${1:-}" in
  pair)
    if (( GPUS > 1 )); then
      echo "pair gives each condition one GPU of its own; GPUS=$GPUS applies to train, cell and overfit" >&2
      exit 2
    fi
    record
    if [ -n "${CUDA_VISIBLE_DEVICES:-}" ]; then IFS=, read -ra gpus <<< "$CUDA_VISIBLE_DEVICES"
    else mapfile -t gpus < <(nvidia-smi --query-gpu=index --format=csv,noheader 2>/dev/null || true); fi
    index=0 cells=()  # background process -> its condition
    for condition in head_wrist fixed_wrist; do
      ( if (( ${#gpus[@]} > 1 )); then  # MuJoCo's EGL follows CUDA_VISIBLE_DEVICES only where the driver maps them
          gpu=${gpus[index % ${#gpus[@]}]}
          export CUDA_VISIBLE_DEVICES=$gpu MUJOCO_EGL_DEVICE_ID=$gpu
        fi
        CONDITION=$condition WORKERS=$(( WORKERS > 1 ? WORKERS / 2 : 1 )) "$0" cell > "$WORK/cell_$condition.log" 2>&1
      ) &
      cells[$!]=$condition
      index=$(( index + 1 ))
    done
    failed=0
    for cell in "${!cells[@]}"; do
      wait "$cell" || { echo "train_baseline: ${cells[cell]} failed: $WORK/cell_${cells[cell]}.log" >&2; failed=1; }
    done
    exit "$failed"
    ;;
  cell)
    "$0" data
    stopped="$WORK/train_$RUN.stopped"
    rm -f "$stopped"
    if [ "$POLICY" = diffusion ]; then train_s=${TRAIN_S:-1500}; else train_s=${TRAIN_S:-960}; fi
    ( if [ "$ACTIONS" = absolute ]; then  # the hand-frame preset holds its own budget
        export BATCH=${BATCH:-128} SAVE_FREQ=${SAVE_FREQ:-1600} STEPS=${STEPS:-4800}
      fi
      trained=0
      WORKERS=$(( WORKERS > 4 ? WORKERS - 2 : WORKERS )) timeout -s TERM "$train_s" "$0" train || trained=$?
      echo "$trained" > "$stopped.tmp" && mv "$stopped.tmp" "$stopped" ) &  # its exit status; 124: TRAIN_S stopped it
    ( while [ ! -f "$stopped" ]; do  # training keeps the cores: evaluations take what it leaves
        nice -n 15 "$0" eval
        for _ in {1..10}; do [ -f "$stopped" ] || sleep 1; done  # a look every 10 s while training goes on
      done ) &
    while [ ! -f "$stopped" ]; do sleep 1; done
    failed=0
    "$0" eval || failed=1  # the checkpoints left, side by side with the one still being evaluated
    wait
    trained=$(cat "$stopped")
    if (( trained != 0 )); then  # what it saved is evaluated all the same
      echo "train_baseline: the training of $RUN stopped with status $trained$( (( trained == 124 )) \
        && echo " (TRAIN_S, $train_s s, reached)") (its output above)" >&2
      exit 1
    fi
    exit "$failed"
    ;;
  data)
    record
    if converted "$WORK/dataset_$CONDITION"; then
      echo "train_baseline: $WORK/dataset_$CONDITION holds this recording's conversion: kept"
    else
      time convert "$WORK/raw" "$WORK/dataset_$CONDITION"
    fi
    ;;
  prepare)
    "$0" data
    if [ "$FRAME_CACHE" = on ]; then choose_video_backend; cache_frames "$WORK/dataset_$CONDITION"; fi
    ;;
  train)
    choose_video_backend
    dataset="$WORK/dataset_$CONDITION"
    if [ -n "$STATE_NOISE" ]; then dataset=$(noisy_copy "$dataset"); fi
    if [ "$ACTIONS" = hand_relative ]; then
      budget=$(scaled_budget "$(preset)")
    else
      budget="${STEPS:+--steps=$STEPS} ${SAVE_FREQ:+--save_freq=$SAVE_FREQ} ${BATCH:+--batch_size=$BATCH}"
    fi
    read -ra budget <<< "$budget"
    time train "$dataset" "$WORK/train_$RUN" "${budget[@]}"
    ;;
  eval)  # every complete checkpoint (up to the one `last` points at), so it may run while training goes on
    link=$(readlink "$WORK/train_$RUN/checkpoints/last") 2>/dev/null || exit 0  # no checkpoint yet
    last=$(basename "$link") evaluations=()
    for checkpoint in "$WORK/train_$RUN"/checkpoints/[0-9]*; do
      (( 10#$(basename "$checkpoint") <= 10#$last )) || continue
      case "$CHECKPOINTS" in
        all) ;;
        last) [ "$(basename "$checkpoint")" = "$last" ] || continue ;;
        *) (( 10#$(basename "$checkpoint") == 10#$CHECKPOINTS )) || continue ;;
      esac
      out="$WORK/$EVAL_NAME/step_$((10#$(basename "$checkpoint")))"
      [ -f "$out/results.json" ] && continue
      mkdir -p "$(dirname "$out")"
      mkdir "$out.running" 2>/dev/null || continue  # another eval call has it
      ( trap 'rmdir "$out.running"' EXIT; time evaluate "$checkpoint" "$out" 1000 "$EVAL_EPISODES" ) &
      evaluations+=($!)
    done
    failed=0
    for evaluation in "${evaluations[@]}"; do wait "$evaluation" || failed=1; done
    if compgen -G "$WORK/$EVAL_NAME/step_*/results.json" > /dev/null; then
      tavis curve "$WORK/$EVAL_NAME"  # success by training step over every checkpoint evaluated so far
    fi
    if (( failed )); then echo "train_baseline: an evaluation of $RUN failed (its output above)" >&2; exit 1; fi
    ;;
  overfit)
    choose_video_backend
    [ -f "$WORK/overfit/raw/manifest.json" ] || tavis record --robot "$ROBOT" --tasks "$TASK" \
      --episodes-per-task 8 --workers 8 --out "$WORK/overfit/raw"
    python3 - "$WORK/overfit/raw/manifest.json" <<'PY'
import json, sys
seeds = sorted(entry["seed"] for entry in json.load(open(sys.argv[1]))["episodes"])
if seeds != list(range(100_000, 100_008)):
    sys.exit(f"overfit: the evaluation assumes training seeds 100000-100007, the recording kept {seeds}")
PY
    convert "$WORK/overfit/raw" "$WORK/overfit/dataset_$CONDITION"
    steps=${OVERFIT_STEPS:-3000}
    time train "$WORK/overfit/dataset_$CONDITION" "$WORK/overfit/train_$RUN" --steps="$steps" \
      --save_freq="$steps" --batch_size=32
    evaluate "$WORK/overfit/train_$RUN/checkpoints/last" "$WORK/overfit/eval_$RUN/train_seeds" 100000 8
    evaluate "$WORK/overfit/train_$RUN/checkpoints/last" "$WORK/overfit/eval_$RUN/new_seeds" 1000 8
    ;;
  *)
    echo "usage: $0 pair|cell|data|prepare|train|eval|overfit" >&2
    exit 2
    ;;
esac
