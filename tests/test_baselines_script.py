"""benchmarks/baselines.sh, the table's one command, run with stand-ins for the GPU work (recording, training,
evaluation, the model card) that record how they were called; `tavis table-add` is the real one. What is checked:
a cell's folders and baselines.json entries, the skip on a second run, the refusal of another recipe, a lost
condition trained again alone, two (robot, task) cells at once on four GPUs, each suite's recipe, and a failed
training left out."""

import json
import os
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "baselines.sh"
REPO = SCRIPT.parents[1]

LOG_CALL = 'echo "$(basename "$0") $* | gpu=${CUDA_VISIBLE_DEVICES:-} egl=${MUJOCO_EGL_DEVICE_ID:-}" >> "$CALLS"\n'
# tavis: the GPU work stood in for; every other subcommand is the real one.
TAVIS = LOG_CALL + """value() {  # the argument after $FLAG
  local previous; for arg in "$@"; do [ "${previous:-}" = "$FLAG" ] && echo "$arg"; previous=$arg; done; }
case $1 in
  record) out=${@: -1}; mkdir -p "$out"; echo '{"episodes": []}' > "$out/manifest.json" ;;
  presets) python3 -m lerobot_tavis.cli presets "$2" ;;  # the real file: train_baseline reads its budget
  convert) "$PYTHON" - "$@" <<'PY'  # the conversion log alone: what tells a later call the dataset is current
import json, os, sys
raw, args = sys.argv[2], sys.argv[3:]
value = lambda flag: args[args.index(flag) + 1]
log = {"raw_dir": os.path.abspath(raw), "fps": int(value("--fps")),
       "image_size": [int(n) for n in value("--image-size").split("x")], "cameras": value("--cameras").split(","),
       "zero_neck": "--zero-neck" in args, "episodes": []}
os.makedirs(os.path.join(value("--root"), "meta"), exist_ok=True)
json.dump(log, open(os.path.join(value("--root"), "meta", "tavis_conversion.json"), "w"))
PY
    ;;
  curve|cache-frames) ;;
  eval) out=${@: -1}; mkdir -p "$out/tavis_head__id/videos" "$out/.tavis_head__id.chunks"
    "$PYTHON" - "$out" "$(FLAG=--tasks value "$@")" "$(FLAG=--robot value "$@")" "$(FLAG=--camera-mode value "$@")" \\
      <<'PY'  # results.json, and the episodes `tavis ablation` pairs: seed 1000 succeeds, 1001 fails
import json, os, sys
out, task, robot, mode = sys.argv[1:]
json.dump({"cells": [{"task": task, "split": "id", "successes": 1, "n": 2}],
           "sources": [{"robots": [robot], "camera_modes": [mode]}]}, open(os.path.join(out, "results.json"), "w"))
cell = os.path.join(out, "tavis_head__id")
json.dump({"per_task": [{"task_group": "tavis_head", "task_id": 0, "metrics": {"successes": [True, False]}}]},
          open(os.path.join(cell, "eval_info.json"), "w"))
with open(os.path.join(cell, "episodes.jsonl"), "w") as log:
    for seed, success in ((1000, True), (1001, False)):
        log.write(json.dumps({"robot": robot, "suite": "tavis_head", "task": task, "task_id": 0, "split": "id",
                              "camera_mode": mode, "seed": seed, "success": success}) + "\\n")
PY
    ;;
  push-policy) out=$(FLAG=--out value "$@"); mkdir -p "$out"; echo "card of $(FLAG=--repo-id value "$@")" \\
      > "$out/README.md" ;;
  *) exec "$PYTHON" -m lerobot_tavis.cli "$@" ;;
esac
"""
# lerobot-train: one checkpoint, at the last step, as train_baseline.sh's SAVE_FREQ=STEPS asks; none with NO_CHECKPOINT.
LEROBOT_TRAIN = LOG_CALL + """for arg in "$@"; do
  case $arg in --output_dir=*) out=${arg#*=} ;; --steps=*) steps=${arg#*=} ;; esac
done
[ -n "${NO_CHECKPOINT:-}" ] && exit 1
step=$(printf %06d "$steps"); mkdir -p "$out/checkpoints/$step/pretrained_model"
echo '{}' > "$out/checkpoints/$step/pretrained_model/train_config.json"; ln -sfn "$step" "$out/checkpoints/last"
echo weights > "$out/checkpoints/$step/pretrained_model/model.safetensors"
"""


def _baselines(tmp_path, *args, **settings) -> subprocess.CompletedProcess:
    """The script run with the stand-ins first on PATH, ROOT=tmp_path; calls logged in tmp_path / calls.log."""
    stubs = tmp_path / "bin"
    stubs.mkdir(parents=True, exist_ok=True)
    for name, body in (("tavis", TAVIS), ("lerobot-train", LEROBOT_TRAIN)):
        (stubs / name).write_text("#!/usr/bin/env bash\n" + body)
        (stubs / name).chmod(0o755)
    env = {**os.environ, "PATH": f"{stubs}:{Path(sys.executable).parent}:{os.environ['PATH']}",
           "PYTHONPATH": str(REPO), "PYTHON": sys.executable, "CALLS": str(tmp_path / "calls.log"),
           "ROOT": str(tmp_path), "RESULTS": "results", "BASELINES": "baselines.json", "WORK": str(tmp_path / "work"),
           "WORKERS": "4", "STEPS": "20", "CUDA_VISIBLE_DEVICES": "0,1", "TRAIN_OPTIONS": "--steps=1",
           "VIDEO_BACKEND": "pyav", **settings}
    return subprocess.run(["bash", str(SCRIPT), *args], env=env, capture_output=True, text=True, timeout=600)


def _calls(tmp_path, tool: str) -> list[str]:
    log = tmp_path / "calls.log"
    return [call for call in log.read_text().splitlines() if call.startswith(tool)] if log.exists() else []


def test_a_cell_trains_both_conditions_once_publishes_them_and_a_second_run_skips_it(tmp_path):
    run = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube")
    assert run.returncode == 0, run.stderr
    trains = sorted(call.split("--output_dir=")[1] for call in _calls(tmp_path, "lerobot-train"))
    work = tmp_path / "work" / "gr1t2_clutter_pick_cube"
    assert [train.split()[0] for train in trains] == [str(work / "train_fixed_wrist"), str(work / "train_head_wrist")]
    for train in _calls(tmp_path, "lerobot-train"):  # the recipe, whatever TRAIN_OPTIONS the environment held
        assert " --steps=20 --save_freq=20 --batch_size=128" in train and "--steps=1 " not in train
        assert "--seed=1000 " in train and "--env.robot=gr1t2 " in train
        assert "--policy.backbone_norm=group_norm --policy.prompt_input=true" in train  # TAVIS-Head's options
    assert "| TAVIS-Head | clutter_pick_cube | 50.0% [" in (tmp_path / "baselines.md").read_text()  # the table too
    ablation = (tmp_path / "ablation_gr1t2.md").read_text()  # and each robot's ablation, as far as it goes
    assert "| clutter_pick_cube | fixed_wrist | 50.0% [" in ablation
    assert "| blocked_clutter_pick_cube | head_wrist | not run |" in ablation
    assert "2 paired episodes: A 1 successes, B 1; both 1, only A 0, only B 0" in ablation  # the two conditions'
    assert "| clutter_pick_cube | head_wrist | not run |" in (tmp_path / "ablation_reachy2.md").read_text()
    caches = sorted(call.split()[2] for call in _calls(tmp_path, "tavis cache-frames"))  # trainings read frames there
    assert caches == [str(work / "dataset_fixed_wrist"), str(work / "dataset_head_wrist")]
    evals = {call.split("--camera-mode ")[1].split()[0]: call for call in _calls(tmp_path, "tavis eval")}
    assert "--splits id ood_spatial ood_init_pose --episodes 96 --seed 1000" in evals["head_wrist"]
    assert "--splits id --episodes 96 --seed 1000" in evals["fixed_wrist"]
    entries = json.loads((tmp_path / "baselines.json").read_text())
    assert entries == [{"robot": "gr1t2", "task": "clutter_pick_cube", "camera_mode": mode,
                        "policy": f"act_hand_relative_{mode}_compact", "training_seed": 1000,
                        "results": f"results/gr1t2/clutter_pick_cube/{mode}/results.json"}
                       for mode in ("head_wrist", "fixed_wrist")]
    for mode in ("head_wrist", "fixed_wrist"):
        folder = tmp_path / "results" / "gr1t2" / "clutter_pick_cube" / mode
        assert sorted(path.name for path in folder.iterdir()) == ["log.txt", "model_card.md", "recipe.json",
                                                                   "results.json", "tavis_head__id",
                                                                   "train_config.json"]
        assert not (folder / "tavis_head__id" / "videos").exists()  # the videos stay in WORK, no leftover
        card = (folder / "model_card.md").read_text()
        assert card == f"card of tavis/act_hand_relative_gr1t2_clutter_pick_cube_{mode}\n"
        recorded = json.loads((folder / "recipe.json").read_text())
        assert recorded["recipe"]["steps"] == 20
        assert recorded["recipe"]["policy_options"] == {"backbone_norm": "group_norm", "prompt_input": True}
        assert recorded["command"] == "benchmarks/baselines.sh cell gr1t2 clutter_pick_cube"
    assert not list((tmp_path / "results" / "gr1t2" / "clutter_pick_cube").glob(".*"))

    (tmp_path / "calls.log").unlink()
    again = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube")
    assert again.returncode == 0 and "gr1t2 clutter_pick_cube complete, skipped" in again.stdout
    assert not _calls(tmp_path, "lerobot-train") and not _calls(tmp_path, "tavis eval")

    other = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube", SEED="2000")
    assert other.returncode == 2
    assert "was made with another recipe (training_seed differ)" in other.stderr
    assert not _calls(tmp_path, "lerobot-train")
    recipe_file = tmp_path / "results" / "gr1t2" / "clutter_pick_cube" / "head_wrist" / "recipe.json"
    made_with = recipe_file.read_text()
    edited = json.loads(made_with)  # as if the cell had been made before a preset was edited
    edited["recipe"]["preset_sha256"]["head_wrist"] = "0" * 64
    recipe_file.write_text(json.dumps(edited))
    edited_preset = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube")
    assert edited_preset.returncode == 2
    assert "was made with another recipe (preset_sha256 differ)" in edited_preset.stderr
    recipe_file.write_text(made_with)

    lost = tmp_path / "results" / "gr1t2" / "clutter_pick_cube" / "fixed_wrist"  # the machine went mid-cell: the
    subprocess.run(["rm", "-r", str(lost), str(tmp_path / "work")], check=True)  # results kept are those committed
    resumed = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube", CUDA_VISIBLE_DEVICES="2,3")
    assert resumed.returncode == 0, resumed.stderr
    (train,) = _calls(tmp_path, "lerobot-train")  # that condition alone, on the slot's first GPU
    assert "/train_fixed_wrist " in train and train.endswith("| gpu=2 egl=2")
    assert (lost / "results.json").is_file() and json.loads((tmp_path / "baselines.json").read_text()) == entries

    # An evaluation killed after its training finished: evaluated again, not trained again.
    work = tmp_path / "work" / "gr1t2_clutter_pick_cube" / "eval_fixed_wrist"
    subprocess.run(["rm", "-r", str(lost), str(work / "step_20")], check=True)
    (work / "step_20.running").mkdir()  # the mark the killed evaluation left
    (tmp_path / "calls.log").unlink()
    resumed = _baselines(tmp_path, "cell", "gr1t2", "clutter_pick_cube")
    assert resumed.returncode == 0, resumed.stderr
    assert not _calls(tmp_path, "lerobot-train") and not _calls(tmp_path, "tavis record")
    (evaluation,) = _calls(tmp_path, "tavis eval")
    assert "--camera-mode fixed_wrist " in evaluation and "--splits id --episodes 96 " in evaluation
    assert json.loads((tmp_path / "baselines.json").read_text()) == entries


def test_the_table_runs_two_cells_at_once_on_four_gpus_and_leaves_a_failed_training_out(tmp_path):
    run = _baselines(tmp_path, "table", ROBOTS="gr1t2", TASKS="conditional_pick clutter_pick_cube peeking_box",
                     CUDA_VISIBLE_DEVICES="0,1,2,3")
    assert run.returncode == 0, run.stderr
    assert "3 (robot, task) cells to run, 2 at once, on GPUs: 0 1 2 3" in run.stdout
    trains = sorted((call.split("--env.task=")[1].split()[0], call.split("/train_")[1].split()[0],
                     call.split(" | ")[1]) for call in _calls(tmp_path, "lerobot-train"))
    assert trains == [("clutter_pick_cube", "fixed_wrist", "gpu=3 egl=3"),
                      ("clutter_pick_cube", "head_wrist", "gpu=2 egl=2"),
                      ("conditional_pick", "fixed_wrist", "gpu=1 egl=1"),
                      ("conditional_pick", "head_wrist", "gpu=0 egl=0"),
                      ("peeking_box", "fixed_wrist", "gpu=1 egl=1"),
                      ("peeking_box", "head_wrist", "gpu=0 egl=0")]
    for train in _calls(tmp_path, "lerobot-train"):  # one recipe per suite: TAVIS-Hands' has no policy options
        assert ("--policy.prompt_input=true" in train) is ("--env.task=peeking_box" not in train)
    hands = json.loads((tmp_path / "results" / "gr1t2" / "peeking_box" / "head_wrist" / "recipe.json").read_text())
    assert "policy_options" not in hands["recipe"]
    # peeking_box, the first pair's second cell, was recorded, converted and cached while conditional_pick trained;
    # its own run kept those datasets: one recording per cell, one conversion per condition.
    assert (tmp_path / "work" / "prepare_gr1t2_peeking_box.log").is_file()
    assert sorted(call.split()[2].split("/work/")[1] for call in _calls(tmp_path, "tavis convert")) == [
        f"gr1t2_{task}/raw" for task in ("clutter_pick_cube", "conditional_pick", "peeking_box") for _ in range(2)]
    assert len(_calls(tmp_path, "tavis record")) == 3
    assert len(json.loads((tmp_path / "baselines.json").read_text())) == 6
    table = (tmp_path / "baselines.md").read_text()  # rendered at the end
    assert ("| TAVIS-Head | clutter_pick_cube | 50.0% [9.5, 90.5] | 50.0% [9.5, 90.5] | not run | not run | - | - |"
            in table)
    assert (tmp_path / "baselines.png").is_file()

    failed = _baselines(tmp_path / "failed", "cell", "reachy2", "peeking_box", NO_CHECKPOINT="1")
    assert failed.returncode == 1
    assert ("baselines: reachy2 peeking_box head_wrist failed: no evaluation of the checkpoint of step 20"
            in failed.stderr)
    assert not (tmp_path / "failed" / "results").exists() and not (tmp_path / "failed" / "baselines.json").exists()


def test_an_unknown_robot_or_task_is_refused_before_anything_runs(tmp_path):
    refused = _baselines(tmp_path, "cell", "gr1t2", "pick_everything")
    assert refused.returncode == 2 and "TASK one of: conditional_pick" in refused.stderr
    assert "got 'gr1t2' 'pick_everything'" in refused.stderr and not (tmp_path / "calls.log").exists()
