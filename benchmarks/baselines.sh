#!/usr/bin/env bash
# The baselines table (docs/results/README.md) in one command, for one cell or all of them; run it again to resume.
#
#   benchmarks/baselines.sh cell ROBOT TASK   both conditions (head_wrist, fixed_wrist) of one robot and task, then
#                                             the table as `table` writes it
#   benchmarks/baselines.sh table             every robot and task not yet complete; one (robot, task) per pair of
#                                             GPUs at once (4 GPUs: two), each condition on a GPU of its own, the
#                                             pair's next cell recorded, converted and cached meanwhile; then
#                                             `tavis table` writes baselines.md and baselines.png beside BASELINES
#                                             and the table into the README.md there (docs/results/README.md),
#                                             `tavis ablation` each robot's ablation_<robot>.md beside them
#
# One recipe per suite: the `act_hand_relative_<condition>_compact` presets (their files' SHA-256 are part of the
# recipe, so an edited preset is another recipe), EPISODES (160) demonstrations, STEPS (3200) steps of BATCH (128),
# training seed SEED (1000), the last checkpoint evaluated on EVAL_EPISODES (96) episodes from seed 1000 of the id
# split, head_wrist also on ood_spatial and ood_init_pose; TAVIS-Head's policies also take the suite's policy
# options (SUITE_OPTIONS below: the prompt input, which clutter_pick_lift and multi_shelf_scan need, and a
# group-normalised ResNet). Training and evaluation are benchmarks/train_baseline.sh's
# (`pair`, or `cell` when one condition is left), one recording per (robot, task).
# A finished condition becomes RESULTS/<robot>/<task>/<condition>/: the `tavis eval` output without videos, the
# training config (train_config.json), the run's log (log.txt, each progress bar's last state), the model card
# (model_card.md) and recipe.json (the recipe, the commit, the machine, the command). That folder is moved into
# place whole, then its entry is added to BASELINES (`tavis table-add`). A condition whose folder exists is
# skipped; one whose folder records another recipe stops the command with a message naming it: one table, one
# recipe. On the machine of an interrupted run, a training that reached its last step is evaluated again (`tavis
# eval` resuming its finished chunks), not retrained.
# WORK/<robot>_<task>/ keeps the recording, datasets, checkpoints, logs and the upload-ready model folders
# (model_<condition>/: checkpoint, card, results; `huggingface-cli upload <repo id> <folder>`).
#
# Settings: ROOT (the repository root, where RESULTS and BASELINES lie: this script's), RESULTS
# (docs/results/baselines), BASELINES (docs/results/baselines.json), WORK (/tmp/tavis_table), HUB_OWNER (the Hub
# account the model cards name: tavis), COMMIT (what recipe.json records as the code's commit: `git describe` of ROOT;
# set it where the checkout has no .git), ROBOTS and TASKS (the cells `table` runs: every robot and task, in catalog
# order), TRAIN_S (1500: seconds after which a training is stopped, and its cell fails); for tiny runs that test the
# pipeline, EPISODES, STEPS, BATCH, EVAL_EPISODES and DEVICE (cuda; cpu). WORKERS, EVAL_JOBS, EVAL_BATCH, FILM and
# VIDEO_BACKEND pass on to train_baseline.sh; its other settings are the recipe's, whatever the environment holds.
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=${ROOT:-$(dirname "$HERE")}
RESULTS=${RESULTS:-docs/results/baselines}
BASELINES=${BASELINES:-docs/results/baselines.json}
WORK=${WORK:-/tmp/tavis_table}
HUB_OWNER=${HUB_OWNER:-tavis}
export EPISODES=${EPISODES:-160} STEPS=${STEPS:-3200} BATCH=${BATCH:-128} SEED=${SEED:-1000}
export EVAL_EPISODES=${EVAL_EPISODES:-96} DEVICE=${DEVICE:-cuda} TRAIN_S=${TRAIN_S:-1500}
WORKERS=${WORKERS:-$(nproc)}
# train_baseline.sh's other settings take their defaults, whatever the environment holds: no cell of the table is
# trained or evaluated otherwise than the recipe says.
unset CONDITION ACTIONS STATE_INPUT STATE_NOISE TRAIN_OPTIONS EVAL_OPTIONS EVAL_NAME CHECKPOINTS GPUS SPLITS
# Trainings read their frames from the dataset's frame cache: the samples LeRobot's loader decodes, decoded once
# instead of at every step, which bounds two trainings side by side on the CPUs (docs/training.md).
export FRAME_CACHE=on
CONDITIONS=(head_wrist fixed_wrist)
cd "$ROOT"

# `python3 -c "$RECIPE" TASK` prints the recipe of TASK's suite (JSON: what every cell of the suite shares); with
# `options`, the lerobot-train arguments of its policy options; with a recipe.json, compares instead and fails with a
# message when that file records another recipe; with `write FILE COMMAND`, writes a recipe.json.
RECIPE='import hashlib, json, os, platform, subprocess, sys
from lerobot_tavis.envs.tasks.catalog import task_info
from lerobot_tavis.policy_configs import preset_path
SUITE_OPTIONS = {"tavis_head": {"backbone_norm": "group_norm", "prompt_input": True}}
env = os.environ
task, *args = sys.argv[1:]
presets = {condition: hashlib.sha256(preset_path(f"act_hand_relative_{condition}_compact").read_bytes()).hexdigest()
           for condition in ("head_wrist", "fixed_wrist")}
recipe = {"presets": "act_hand_relative_<condition>_compact", "preset_sha256": presets,
          "demonstrations": int(env["EPISODES"]), "steps": int(env["STEPS"]), "batch_size": int(env["BATCH"]),
          "training_seed": int(env["SEED"]), "image_size": "120x160", "device": env["DEVICE"],
          "evaluation": {"episodes": int(env["EVAL_EPISODES"]), "first_seed": 1000, "checkpoint": "last",
                         "splits": {"head_wrist": ["id", "ood_spatial", "ood_init_pose"], "fixed_wrist": ["id"]}}}
options = SUITE_OPTIONS.get(task_info(task).suite)
if options:
    recipe["policy_options"] = options
if not args:
    print(json.dumps(recipe, indent=2))
elif args[0] == "options":
    print(*(f"--policy.{key}={str(value).lower() if isinstance(value, bool) else value}"
            for key, value in (options or {}).items()))
elif args[0] == "write":
    def output(*command):
        try:
            return subprocess.run(command, capture_output=True, text=True, check=True).stdout.strip()
        except (OSError, subprocess.CalledProcessError):
            return ""
    gpus = output("nvidia-smi", "--query-gpu=name", "--format=csv,noheader").splitlines()
    machine = f"{len(gpus)} x {gpus[0]}, " if gpus else ""
    record = {"recipe": recipe, "command": args[2],
              "commit": env.get("COMMIT") or output("git", "describe", "--always", "--dirty", "--abbrev=12")
              or "not recorded: set COMMIT outside a git checkout",
              "machine": f"{machine}{os.cpu_count()} cores, {platform.node()}",
              "finished_utc": output("date", "-u", "+%Y-%m-%dT%H:%M:%SZ")}
    with open(args[1] + ".tmp", "w") as file:
        json.dump(record, file, indent=2)
        file.write("\n")
    os.replace(args[1] + ".tmp", args[1])
else:
    try:
        recorded = json.load(open(args[0]))["recipe"]
        recorded.items()
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        sys.exit(f"baselines: {args[0]} is missing or damaged: remove its folder to make the cell again")
    if recorded != recipe:
        changed = sorted(key for key in {**recipe, **recorded} if recorded.get(key) != recipe.get(key))
        changed = ", ".join(changed)
        sys.exit(f"baselines: {args[0]} was made with another recipe ({changed} differ): one table "
                 "holds one recipe; remove that folder to make the cell again with these settings")'

cell_dir() { echo "$RESULTS/$1/$2/$3"; }  # cell_dir ROBOT TASK CONDITION

complete() {  # complete ROBOT TASK CONDITION: its folder is there (and holds this recipe: else exit 2)
  local folder
  folder=$(cell_dir "$@")
  [ -d "$folder" ] || return 1
  python3 -c "$RECIPE" "$2" "$folder/recipe.json" || exit 2
}

add_entry() {  # add_entry ROBOT TASK CONDITION: its line in BASELINES (again, if a killed run left it out)
  tavis table-add --robot "$1" --task "$2" --camera-mode "$3" --policy "act_hand_relative_$3_compact" \
    --training-seed "$SEED" --results "$(cell_dir "$@")/results.json" --baselines "$BASELINES" > /dev/null
}

publish() {  # publish ROBOT TASK CONDITION: the evaluation of the last checkpoint into RESULTS, then BASELINES
  local work="$WORK/$1_$2" final stage checkpoint evaluation
  final=$(cell_dir "$@")
  stage="$(dirname "$final")/.$3.partial"
  evaluation="$work/eval_$3/step_$STEPS"
  checkpoint=$(readlink -e "$work/train_$3/checkpoints/last" || true)
  if [ -z "$checkpoint" ] || (( 10#$(basename "$checkpoint") != STEPS )) || [ ! -f "$evaluation/results.json" ]; then
    echo "baselines: $1 $2 $3 failed: no evaluation of the checkpoint of step $STEPS; see $work/cell_$3.log" >&2
    return 1
  fi
  rm -rf "$stage"
  mkdir -p "$(dirname "$stage")"
  cp -r "$evaluation" "$stage"
  # the videos stay in WORK; dot-named leftovers (locks, staging copies) are no results
  find "$stage" -mindepth 1 -depth \( -type d -name 'videos*' -o -name '.*' \) -exec rm -rf {} +
  cp "$checkpoint/pretrained_model/train_config.json" "$stage/train_config.json"
  awk -F'\r' '{print $NF}' "$work/cell_$3.log" > "$stage/log.txt"  # a progress bar's redraws: its last state
  tavis push-policy "$checkpoint/pretrained_model" --repo-id "$HUB_OWNER/act_hand_relative_$1_$2_$3" \
    --results "$stage/results.json" --out "$work/model_$3" > /dev/null
  cp "$work/model_$3/README.md" "$stage/model_card.md"
  python3 -c "$RECIPE" "$2" write "$stage/recipe.json" "benchmarks/baselines.sh cell $1 $2"
  mv -T "$stage" "$final"
  add_entry "$@"
  echo "baselines: $1 $2 $3 done: $final"
}

trained() {  # trained ROBOT TASK CONDITION: WORK holds the checkpoint of its training's last step
  local last
  last=$(readlink -e "$WORK/$1_$2/train_$3/checkpoints/last") || return 1
  (( 10#$(basename "$last") == STEPS )) && [ -f "$last/pretrained_model/model.safetensors" ]
}

scratch() {  # scratch ROBOT TASK: WORK's folder of the cell, emptied if another recipe made it, with this recipe.json
  local work="$WORK/$1_$2"
  if ! python3 -c "$RECIPE" "$2" "$work/recipe.json" 2> /dev/null; then rm -rf "$work"; fi
  mkdir -p "$work"
  python3 -c "$RECIPE" "$2" write "$work/recipe.json" "benchmarks/baselines.sh cell $1 $2"
}

prepare() {  # prepare ROBOT TASK: the recording, datasets and frame caches of its unfinished conditions, at a low
  # CPU priority: `table` runs it for a GPU pair's next cell while the pair trains, which leaves the CPUs idle
  local condition work="$WORK/$1_$2"
  scratch "$1" "$2"
  for condition in "${CONDITIONS[@]}"; do
    complete "$1" "$2" "$condition" && continue
    ROBOT=$1 TASK=$2 WORK=$work CONDITION=$condition nice -n 10 "$HERE/train_baseline.sh" prepare
  done
}

cell() {  # cell ROBOT TASK
  local robot=$1 task=$2 work="$WORK/$1_$2" condition status=0 todo=() train=() gpus=() index=0
  for condition in "${CONDITIONS[@]}"; do
    if complete "$robot" "$task" "$condition"; then add_entry "$robot" "$task" "$condition"
    else todo+=("$condition"); fi
  done
  if (( ${#todo[@]} == 0 )); then echo "baselines: $robot $task complete, skipped"; return 0; fi
  # The scratch folder of another recipe is removed. In that of an interrupted run, a finished training is kept
  # and evaluated (`tavis eval` resumes its chunks); one cut short is trained again; datasets and caches are kept.
  scratch "$robot" "$task"
  for condition in "${todo[@]}"; do
    rm -rf "$work/eval_$condition"/*.running  # the mark of an evaluation under way, left by a killed one
    if ! trained "$robot" "$task" "$condition"; then
      rm -rf "$work/train_$condition" "$work/eval_$condition"
      train+=("$condition")
    fi
  done
  echo "baselines: $robot $task: ${todo[*]}; training ${train[*]:-none} (logs: $work/cell_<condition>.log)"
  ( export ROBOT=$robot TASK=$task WORK=$work WORKERS ACTIONS=hand_relative SAVE_FREQ=$STEPS CHECKPOINTS=last \
      SPLITS=table TRAIN_OPTIONS="$(python3 -c "$RECIPE" "$task" options)"
    if (( ${#train[@]} == 2 )); then
      "$HERE/train_baseline.sh" pair  # one recording for both, each on a GPU of its own
    else  # each condition on a GPU of its own: trained and evaluated (`cell`), or evaluated (`eval`)
      [ -z "${CUDA_VISIBLE_DEVICES:-}" ] || IFS=, read -ra gpus <<< "$CUDA_VISIBLE_DEVICES"
      WORKERS=$(( WORKERS / ${#todo[@]} > 1 ? WORKERS / ${#todo[@]} : 1 ))
      for condition in "${todo[@]}"; do
        ( if (( ${#gpus[@]} > 1 )); then
            export CUDA_VISIBLE_DEVICES=${gpus[index]} MUJOCO_EGL_DEVICE_ID=${gpus[index]}
          fi
          mode=eval
          if [[ " ${train[*]:-} " == *" $condition "* ]]; then mode=cell; : > "$work/cell_$condition.log"; fi
          CONDITION=$condition "$HERE/train_baseline.sh" "$mode" >> "$work/cell_$condition.log" 2>&1 ) &
        index=$(( index + 1 ))
      done
      wait
    fi ) || true  # each condition's outcome is read from its folders below
  for condition in "${todo[@]}"; do publish "$robot" "$task" "$condition" || status=1; done
  return "$status"
}

robot_names() {  # the built-in robots, in catalog order
  python3 -c "from lerobot_tavis.envs.robots import robot_names; print(*robot_names())"
}

write_table() {  # the table as far as it goes, beside BASELINES and at the top of the README.md there if any; each
  # robot's wrist-only ablation (from three of its cells) beside it as ablation_<robot>.md
  local out readme robot
  out=$(dirname "$BASELINES")
  readme=$out/README.md
  tavis table --baselines "$BASELINES" --out "$out" $([ -f "$readme" ] && echo --readme "$readme")
  for robot in $(robot_names); do
    tavis ablation --robot "$robot" --baselines "$BASELINES" --out "$out/ablation_$robot.md" > /dev/null
  done
}

check_cell() {  # check_cell ROBOT TASK: both known, else exit 2
  local robots tasks
  robots=$(robot_names)
  tasks=$(python3 -c "from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS; print(*BENCHMARK_TASKS)")
  if [[ " $robots " != *" $1 "* ]] || [[ " $tasks " != *" $2 "* ]]; then
    echo "baselines: ROBOT must be one of: $robots; TASK one of: $tasks; got '$1' '$2'" >&2
    exit 2
  fi
}

case "${1:-}" in
  cell)
    if (( $# != 3 )); then echo "usage: $0 cell ROBOT TASK" >&2; exit 2; fi
    check_cell "$2" "$3"
    python3 -c "$RECIPE" "$3" > /dev/null  # a setting that is no number stops here
    status=0
    cell "$2" "$3" || status=$?
    write_table
    exit "$status"
    ;;
  table)
    ROBOTS=${ROBOTS:-gr1t2 reachy2}
    TASKS=${TASKS:-$(python3 -c "from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS as t; print(*t)")}
    cells=()
    for robot in $ROBOTS; do
      for task in $TASKS; do
        check_cell "$robot" "$task"
        python3 -c "$RECIPE" "$task" > /dev/null  # a setting that is no number stops here
        if complete "$robot" "$task" head_wrist && complete "$robot" "$task" fixed_wrist; then
          add_entry "$robot" "$task" head_wrist; add_entry "$robot" "$task" fixed_wrist
        else cells+=("$robot $task"); fi
      done
    done
    if [ -n "${CUDA_VISIBLE_DEVICES:-}" ]; then IFS=, read -ra gpus <<< "$CUDA_VISIBLE_DEVICES"
    else mapfile -t gpus < <(nvidia-smi --query-gpu=index --format=csv,noheader 2>/dev/null || true); fi
    slots=$(( ${#gpus[@]} / 2 > 1 ? ${#gpus[@]} / 2 : 1 ))
    echo "baselines: ${#cells[@]} (robot, task) cells to run, $slots at once, on GPUs: ${gpus[*]:-none}"
    pids=()
    for (( slot = 0; slot < slots; slot++ )); do
      ( status=0 ahead=""
        if (( ${#gpus[@]} > 1 )); then export CUDA_VISIBLE_DEVICES=${gpus[2 * slot]},${gpus[2 * slot + 1]}
        elif (( ${#gpus[@]} == 1 )); then export CUDA_VISIBLE_DEVICES=${gpus[0]}; fi
        export WORKERS=$(( WORKERS / slots > 1 ? WORKERS / slots : 1 ))
        for (( i = slot; i < ${#cells[@]}; i += slots )); do
          read -r robot task <<< "${cells[i]}"
          [ -z "$ahead" ] || wait "$ahead" || true  # its failure leaves the cell's own `data` to do it again
          ahead=""
          if (( i + slots < ${#cells[@]} )); then  # the next cell's CPU work, while this one trains
            read -r next_robot next_task <<< "${cells[i + slots]}"
            mkdir -p "$WORK"
            prepare "$next_robot" "$next_task" > "$WORK/prepare_${next_robot}_$next_task.log" 2>&1 &
            ahead=$!
          fi
          "$HERE/baselines.sh" cell "$robot" "$task" || status=1
        done
        exit "$status" ) &
      pids+=($!)
    done
    status=0
    for pid in "${pids[@]}"; do wait "$pid" || status=1; done
    write_table
    exit "$status"
    ;;
  *)
    echo "usage: $0 cell ROBOT TASK | $0 table" >&2
    exit 2
    ;;
esac
