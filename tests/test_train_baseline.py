"""benchmarks/train_baseline.sh's orchestration, run with stand-ins for tavis and lerobot-train that record how
they were called: which GPU each condition gets, that every checkpoint is evaluated once, that a failed training or
evaluation fails the command, and how a list of tasks is converted (side by side, then merged) and evaluated."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from lerobot_tavis.policy_configs import preset_path

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "train_baseline.sh"

# Each stand-in logs "<tool> <arguments> | gpu=<CUDA_VISIBLE_DEVICES> egl=<MUJOCO_EGL_DEVICE_ID>".
LOG_CALL = 'echo "$(basename "$0") $* | gpu=${CUDA_VISIBLE_DEVICES:-} egl=${MUJOCO_EGL_DEVICE_ID:-}" >> "$CALLS"\n'
TAVIS = LOG_CALL + """case $1 in
  record) out=${@: -1}; mkdir -p "$out"; echo '{}' > "$out/manifest.json" ;;
  presets) echo "${PRESET_FILE:-/dev/null}" ;;
  eval) out=${@: -1}; [ -z "${EVAL_FAILS:-}" ] || exit 1; mkdir -p "$out"; echo '{}' > "$out/results.json" ;;
  noise-state) mkdir -p "$4/meta"  # noise-state SOURCE --out OUT --position-m P --rotation-deg R --seed S
    printf '{"position_m": %s, "rotation_deg": %s, "seed": %s}' "$6" "$8" "${10}" > "$4/meta/state_noise.json" ;;
esac
"""
LEROBOT_TRAIN = LOG_CALL + """for arg in "$@"; do case $arg in --output_dir=*) out=${arg#*=} ;; esac; done
for step in 001500 003000; do mkdir -p "$out/checkpoints/$step"; ln -sfn $step "$out/checkpoints/last"; done
exit "${TRAIN_STATUS:-0}"
"""


# `accelerate launch ... -m lerobot.scripts.lerobot_train ...` stands in for lerobot-train and logs the cache switch.
ACCELERATE = ('echo "accelerate $* | cache=${TAVIS_FRAME_CACHE:-}" >> "$CALLS"\n'
              + LEROBOT_TRAIN.removeprefix(LOG_CALL))


def _stubbed(tmp_path, mode, **settings) -> subprocess.CompletedProcess:
    """The script run in `mode` with the stand-ins first on PATH; their calls go to tmp_path / "calls.log"."""
    stubs = tmp_path / "bin"
    stubs.mkdir(parents=True)
    for name, body in (("tavis", TAVIS), ("lerobot-train", LEROBOT_TRAIN), ("accelerate", ACCELERATE)):
        (stubs / name).write_text("#!/usr/bin/env bash\n" + body)
        (stubs / name).chmod(0o755)
    env = {**os.environ, "PATH": f"{stubs}:{os.environ['PATH']}", "CALLS": str(tmp_path / "calls.log"),
           "WORK": str(tmp_path / "work"), "WORKERS": "4", "TRAIN_S": "60", **settings}
    return subprocess.run(["bash", str(SCRIPT), mode], env=env, capture_output=True, text=True, timeout=300)


def _run(tmp_path, mode, **settings) -> list[str]:
    _stubbed(tmp_path, mode, **settings).check_returncode()
    return (tmp_path / "calls.log").read_text().splitlines()


def test_pair_trains_each_condition_on_its_own_visible_gpu_and_evaluates_every_checkpoint_once(tmp_path):
    calls = _run(tmp_path, "pair", CUDA_VISIBLE_DEVICES="2,3")
    assert sum(call.startswith("tavis record") for call in calls) == 1  # both conditions share the recording
    trains = sorted((re.search(r"--output_dir=\S*/train_(\w+)", call)[1], call.split(" | ")[1])
                    for call in calls if call.startswith("lerobot-train"))
    assert trains == [("fixed_wrist", "gpu=3 egl=3"), ("head_wrist", "gpu=2 egl=2")]
    evals = sorted(call.split(" --out ")[1] for call in calls if call.startswith("tavis eval"))
    work = tmp_path / "work"
    assert evals == [f"{work}/eval_{condition}/step_{step} | gpu={gpu} egl={gpu}"
                     for condition, gpu in (("fixed_wrist", 3), ("head_wrist", 2)) for step in (1500, 3000)]
    assert all("--tasks conditional_pick --splits id --episodes 96" in call for call in calls if "tavis eval" in call)
    curves = {call.split(" | ")[0] for call in calls if call.startswith("tavis curve")}
    assert curves == {f"tavis curve {work}/eval_{condition}" for condition in ("fixed_wrist", "head_wrist")}


def test_a_task_list_is_recorded_trained_and_evaluated_as_one_multi_task_cell(tmp_path):
    calls = _run(tmp_path, "cell", TASK="peeking_box,occluded_reach")
    assert [call.split(" --episodes-per-task")[0] for call in calls if call.startswith("tavis record")] == [
        "tavis record --robot gr1t2 --tasks peeking_box,occluded_reach"]
    assert all("--env.task=peeking_box,occluded_reach " in call for call in calls if call.startswith("lerobot-train"))
    evals = [call for call in calls if call.startswith("tavis eval")]
    assert len(evals) == 2 and all("--tasks peeking_box occluded_reach --splits id" in call for call in evals)


@pytest.mark.parametrize(("mode", "settings", "message"), [
    ("cell", {"EVAL_FAILS": "1"}, "train_baseline: an evaluation of head_wrist failed"),
    ("cell", {"TRAIN_STATUS": "3"}, "train_baseline: the training of head_wrist stopped with status 3"),
    ("eval", {"EVAL_FAILS": "1"}, "train_baseline: an evaluation of head_wrist failed"),
    ("pair", {"EVAL_FAILS": "1"}, "train_baseline: head_wrist failed: "),
])
def test_a_failed_training_or_evaluation_fails_the_command_with_a_message(tmp_path, mode, settings, message):
    if mode == "eval":  # a checkpoint to evaluate
        _run(tmp_path / "trained", "train", WORK=str(tmp_path / "work"))
    failed = _stubbed(tmp_path, mode, **settings)
    assert failed.returncode == 1 and message in failed.stderr
    if mode == "cell" and "TRAIN_STATUS" in settings:  # what the training saved is evaluated all the same
        assert len([call for call in (tmp_path / "calls.log").read_text().splitlines()
                    if call.startswith("tavis eval")]) == 2


def test_eval_options_reach_tavis_eval_and_its_folder_is_eval_name(tmp_path):
    calls = _run(tmp_path, "cell", EVAL_NAME="eval_te",
                 EVAL_OPTIONS="--policy-option temporal_ensemble_coeff=0.01 --policy-option n_action_steps=1")
    evals = sorted(call.split(" | ")[0] for call in calls if call.startswith("tavis eval"))
    assert len(evals) == 2
    assert all(call.endswith("--policy-option temporal_ensemble_coeff=0.01 --policy-option n_action_steps=1 "
                             f"--out {tmp_path}/work/eval_te/step_{step}") for call, step in zip(evals, (1500, 3000)))


@pytest.mark.parametrize("checkpoints, step", [("last", 3000), ("1500", 1500), ("001500", 1500)])
def test_checkpoints_picks_the_last_or_one_steps_checkpoint(tmp_path, checkpoints, step):
    _run(tmp_path, "train")
    calls = _run(tmp_path / "again", "eval", WORK=str(tmp_path / "work"), CHECKPOINTS=checkpoints,
                 EVAL_NAME="eval_te")
    evals = [call.split(" | ")[0].split(" --out ")[1] for call in calls if call.startswith("tavis eval")]
    assert evals == [f"{tmp_path}/work/eval_te/step_{step}"]


@pytest.mark.parametrize("checkpoints", ["first", "16o0", "-1600"])
def test_checkpoints_other_values_are_refused(checkpoints):
    refused = subprocess.run(["bash", str(SCRIPT), "eval"], env={**os.environ, "CHECKPOINTS": checkpoints},
                             capture_output=True, text=True)
    assert refused.returncode == 2
    assert f"CHECKPOINTS must be all, last or a training step, got '{checkpoints}'" in refused.stderr


def test_seed_reaches_lerobot_train_and_defaults_to_its_own(tmp_path):
    def train_seeds(folder, **settings):
        return [re.search(r"--seed=(\S+)", call)[1] for call in _run(folder, "train", **settings)
                if call.startswith("lerobot-train")]

    assert train_seeds(tmp_path / "default") == ["1000"]
    assert train_seeds(tmp_path / "replicate", SEED="2000") == ["2000"]


def test_train_options_reach_lerobot_train_before_the_modes_own_arguments(tmp_path):
    calls = _run(tmp_path, "train", TRAIN_OPTIONS="--policy.chunk_size=40 --policy.n_action_steps=20", STEPS="800")
    trains = [call.split(" | ")[0] for call in calls if call.startswith("lerobot-train")]
    assert len(trains) == 1
    assert "--policy.chunk_size=40 --policy.n_action_steps=20 --steps=800" in trains[0]


def test_state_input_off_trains_from_a_copy_of_the_preset_without_the_state(tmp_path):
    shipped = preset_path("act_head_wrist_compact")
    (train,) = [call for call in _run(tmp_path, "train", STATE_INPUT="off", PRESET_FILE=str(shipped))
                if call.startswith("lerobot-train")]
    copy = Path(re.search(r"--config_path=(\S+)", train)[1])
    assert copy.parent == tmp_path / "work" and not list(copy.parent.glob("*.tmp"))
    expected = json.loads(shipped.read_text())
    del expected["policy"]["input_features"]["observation.state"]
    assert json.loads(copy.read_text()) == expected  # the cameras and everything else as shipped
    assert sorted(expected["policy"]["input_features"]) == ["observation.images.head",
                                                            "observation.images.left_wrist",
                                                            "observation.images.right_wrist"]
    (train,) = [call for call in _run(tmp_path / "default", "train", PRESET_FILE=str(shipped))
                if call.startswith("lerobot-train")]
    assert f"--config_path={shipped} " in train
    refused = subprocess.run(["bash", str(SCRIPT), "train"], env={**os.environ, "STATE_INPUT": "no"},
                             capture_output=True, text=True)
    assert refused.returncode == 2 and "STATE_INPUT must be on or off, got 'no'" in refused.stderr


def test_hand_relative_actions_train_the_hand_frame_preset_on_its_own_budget(tmp_path):
    shipped = preset_path("act_hand_relative_head_wrist_compact")
    calls = _run(tmp_path, "cell", ACTIONS="hand_relative", PRESET_FILE=str(shipped))
    assert "tavis presets act_hand_relative_head_wrist_compact | gpu= egl=" in calls
    (train,) = [call for call in calls if call.startswith("lerobot-train")]
    assert f"--config_path={shipped} " in train  # the shipped preset itself, no copy
    assert not re.search(r"--(steps|save_freq|batch_size)=", train)  # the preset's 3200 / 800 / 128
    (train,) = [call for call in _run(tmp_path / "set", "train", ACTIONS="hand_relative", STEPS="1600",
                                      PRESET_FILE=str(shipped)) if call.startswith("lerobot-train")]
    assert "--steps=1600" in train and not re.search(r"--(save_freq|batch_size)=", train)
    (train,) = [call for call in _run(tmp_path / "absolute", "cell", PRESET_FILE=str(shipped))
                if call.startswith("lerobot-train")]
    assert re.search(r"--steps=4800 --save_freq=1600 --batch_size=128( |$)", train.split(" | ")[0])


def test_policy_diffusion_trains_the_hand_frame_diffusion_preset_on_its_budget(tmp_path):
    shipped = preset_path("diffusion_hand_relative_fixed_wrist_compact")
    calls = _run(tmp_path, "cell", POLICY="diffusion", ACTIONS="hand_relative", CONDITION="fixed_wrist",
                 PRESET_FILE=str(shipped))
    assert "tavis presets diffusion_hand_relative_fixed_wrist_compact | gpu= egl=" in calls
    (train,) = [call for call in calls if call.startswith("lerobot-train")]
    assert f"--config_path={shipped} " in train and not re.search(r"--(steps|save_freq|batch_size)=", train)
    # beside the ACT runs of the same WORK: its own training and evaluation folders
    assert f"--output_dir={tmp_path}/work/train_diffusion_fixed_wrist " in train
    evals = sorted(call.split(" | ")[0].split(" --out ")[1] for call in calls if call.startswith("tavis eval"))
    assert evals == [f"{tmp_path}/work/eval_diffusion_fixed_wrist/step_{step}" for step in (1500, 3000)]


@pytest.mark.parametrize(("settings", "budget"), [
    (dict(BATCH="256"), "--steps=1600 --save_freq=400 --batch_size=256 --optimizer.lr=0.000141 "
                        "--policy.optimizer_lr_backbone=0.000141"),  # the preset's 409,600 samples, lr x sqrt(2)
    (dict(GPUS="4"), "--steps=800 --save_freq=200 --optimizer.lr=0.0002 --policy.optimizer_lr_backbone=0.0002"),
    (dict(BATCH="64", STEPS="5000", LR="5e-5"), "--steps=5000 --save_freq=1600 --batch_size=64 --optimizer.lr=5e-5 "
                                                "--policy.optimizer_lr_backbone=5e-5"),  # what is set wins
    (dict(BATCH="128", LR="2e-4"), "--batch_size=128 --optimizer.lr=2e-4 --policy.optimizer_lr_backbone=2e-4"),
])
def test_hand_relative_batch_keeps_the_presets_samples_with_the_square_root_learning_rate(tmp_path, settings,
                                                                                         budget):
    calls = _run(tmp_path, "train", ACTIONS="hand_relative", PRESET_FILE=str(preset_path(
        "act_hand_relative_head_wrist_compact")), **settings)
    (train,) = [call.split(" | ")[0] for call in calls if call.startswith(("lerobot-train", "accelerate"))]
    assert train.endswith(f" --output_dir={tmp_path}/work/train_head_wrist {budget}")


@pytest.mark.parametrize(("settings", "message"), [
    (dict(BATCH="0"), "BATCH must be a number of samples >= 1 per GPU, got '0'"),
    (dict(BATCH="12x"), "BATCH must be a number of samples >= 1 per GPU, got '12x'"),
    (dict(ACTIONS="hand_relative", LR="fast"), "LR must be a learning rate such as 1e-4 or 0.0002, with "
                                               "ACTIONS=hand_relative; got 'fast' with ACTIONS=hand_relative"),
    (dict(LR="1e-4"), "LR must be a learning rate such as 1e-4 or 0.0002, with ACTIONS=hand_relative; got '1e-4' "
                      "with ACTIONS=absolute"),
])
def test_a_bad_batch_or_learning_rate_is_refused_before_anything_runs(tmp_path, settings, message):
    refused = _stubbed(tmp_path, "train", **settings)
    assert refused.returncode == 2 and message in refused.stderr
    assert not (tmp_path / "calls.log").exists()


@pytest.mark.parametrize(("settings", "message"), [
    (dict(ACTIONS="hand_relative", STATE_INPUT="on"), "ACTIONS=hand_relative takes STATE_INPUT=off alone"),
    (dict(ACTIONS="relative", STATE_INPUT="off"), "ACTIONS must be absolute or hand_relative, got 'relative'"),
    (dict(POLICY="diffusion"), "POLICY=diffusion takes ACTIONS=hand_relative alone (its preset is "
                               "diffusion_hand_relative_<CONDITION>_compact), got ACTIONS=absolute"),
    (dict(POLICY="pi0", ACTIONS="hand_relative"), "POLICY must be act or diffusion, got 'pi0'"),
])
def test_hand_relative_actions_with_the_state_input_or_unknown_actions_or_policies_are_refused(tmp_path, settings, message):
    refused = _stubbed(tmp_path, "train", **settings)
    assert refused.returncode == 2 and message in refused.stderr
    assert not (tmp_path / "calls.log").exists()


def test_state_noise_trains_on_a_noisy_copy_made_once_with_the_training_seed(tmp_path):
    work = tmp_path / "work"
    dataset, copy = work / "dataset_head_wrist", work / "dataset_head_wrist_state_noise"
    calls = _run(tmp_path / "first", "train", WORK=str(work), STATE_NOISE="0.02,5", SEED="7")
    assert [call.split(" | ")[0] for call in calls if call.startswith("tavis noise-state")] == [
        f"tavis noise-state {dataset} --out {copy} --position-m 0.02 --rotation-deg 5 --seed 7"]
    (train,) = [call for call in calls if call.startswith("lerobot-train")]
    assert f" --dataset.repo_id=local/{copy.name} --dataset.root={copy} " in train
    calls = _run(tmp_path / "again", "train", WORK=str(work), STATE_NOISE="0.02,5", SEED="7")
    assert [call.split()[:2] for call in calls] == [["tavis", "presets"], ["lerobot-train", "--config_path=/dev/null"]]
    assert f" --dataset.root={copy} " in calls[1]
    for other in (dict(STATE_NOISE="0.03,5", SEED="7"), dict(STATE_NOISE="0.02,5", SEED="8")):
        folder = tmp_path / other["STATE_NOISE"] / other["SEED"]
        refused = _stubbed(folder, "train", WORK=str(work), **other)
        assert refused.returncode != 0 and "holds other noise than STATE_NOISE and SEED ask for" in refused.stderr
        assert not (folder / "calls.log").exists()  # neither a new copy nor a training
    (train,) = [call for call in _run(tmp_path / "off", "train", WORK=str(work)) if call.startswith("lerobot-train")]
    assert f" --dataset.root={dataset} " in train


@pytest.mark.parametrize("value", ["0.02", "0.02,5,1", "-0.02,5", "0.02,-5", ".02,5", "0.02;5", "two,5", " "])
def test_a_bad_state_noise_is_refused_before_anything_runs(tmp_path, value):
    refused = _stubbed(tmp_path, "train", STATE_NOISE=value)
    assert refused.returncode == 2
    assert f"STATE_NOISE must be empty (off) or POSITION_M,ROTATION_DEG, two decimal numbers >= 0 such as 0.02,5; " \
           f"got '{value}'" in refused.stderr
    assert not (tmp_path / "calls.log").exists()


def test_state_noise_with_state_input_off_is_refused(tmp_path):
    refused = _stubbed(tmp_path, "train", STATE_NOISE="0.02,5", STATE_INPUT="off")
    assert refused.returncode == 2 and "STATE_NOISE needs STATE_INPUT=on" in refused.stderr
    assert not (tmp_path / "calls.log").exists()


# `tavis record` writes a recording of two tasks (occluded_reach listed first), `tavis convert` the conversion log of
# its --task's episodes after half a second (its start and end logged), `lerobot-edit-dataset` the merged folder.
MULTI_TASK_TAVIS = """echo "tavis $*" >> "$CALLS"
case $1 in
  record) out=${@: -1}; mkdir -p "$out"; echo '{"episodes": [{"task": "occluded_reach", "file": "o0.npz"},
    {"task": "peeking_box", "file": "p0.npz"}, {"task": "peeking_box", "file": "p1.npz"}]}' > "$out/manifest.json" ;;
  convert) echo "start ${@: -1}" >> "$CALLS"; sleep 0.5
    "$PYTHON" - "$@" <<'PY'
import json, os, sys
raw, args = sys.argv[2], sys.argv[3:]
value = lambda flag: args[args.index(flag) + 1]
episodes = [e for e in json.load(open(os.path.join(raw, "manifest.json")))["episodes"] if e["task"] == value("--task")]
log = {"raw_dir": os.path.abspath(raw), "fps": int(value("--fps")),
       "image_size": [int(n) for n in value("--image-size").split("x")], "cameras": value("--cameras").split(","),
       "zero_neck": "--zero-neck" in args,
       "episodes": [{"episode_index": i, "raw_file": e["file"], "task": e["task"]} for i, e in enumerate(episodes)]}
os.makedirs(os.path.join(value("--root"), "meta"))
json.dump(log, open(os.path.join(value("--root"), "meta", "tavis_conversion.json"), "w"))
PY
    echo "end ${@: -1}" >> "$CALLS" ;;
esac
"""
EDIT_DATASET = """echo "lerobot-edit-dataset $*" >> "$CALLS"
for arg in "$@"; do [ "${previous:-}" = --new_root ] && mkdir -p "$arg/meta"; previous=$arg; done
"""


def test_a_recording_of_several_tasks_is_converted_task_by_task_side_by_side_and_merged(tmp_path):
    stubs = tmp_path / "bin"
    stubs.mkdir()
    for name, body in (("tavis", MULTI_TASK_TAVIS), ("lerobot-edit-dataset", EDIT_DATASET)):
        (stubs / name).write_text("#!/usr/bin/env bash\n" + body)
        (stubs / name).chmod(0o755)
    calls, work = tmp_path / "calls.log", tmp_path / "work"
    env = {**os.environ, "PATH": f"{stubs}:{os.path.dirname(sys.executable)}:{os.environ['PATH']}",
           "CALLS": str(calls), "PYTHON": sys.executable, "WORK": str(work), "WORKERS": "4",
           "TASK": "peeking_box,occluded_reach"}
    data = subprocess.run(["bash", str(SCRIPT), "data"], env=env, capture_output=True, text=True, timeout=60)
    assert data.returncode == 0, data.stderr
    log = calls.read_text().splitlines()
    converts = sorted(call for call in log if call.startswith("tavis convert"))
    dataset, parts = work / "dataset_head_wrist", f"{work}/dataset_head_wrist.parts"
    assert [call.split(" --root ")[1].split()[0] for call in converts] == [f"{parts}/occluded_reach",
                                                                         f"{parts}/peeking_box"]
    assert all(" --workers 2 --overwrite --task " in call for call in converts)  # the cores shared
    events = [call.split()[0] for call in log if call.startswith(("start ", "end "))]
    assert events == ["start", "start", "end", "end"]  # side by side
    (merge,) = [call for call in log if call.startswith("lerobot-edit-dataset")]
    assert (f"--new_repo_id local/dataset_head_wrist --new_root {dataset}.merging --operation.type merge "
            f"--operation.repo_ids ['local/peeking_box', 'local/occluded_reach'] "
            f"--operation.roots ['{parts}/peeking_box', '{parts}/occluded_reach']") in merge  # in catalog order
    merged = json.loads((dataset / "meta" / "tavis_conversion.json").read_text())
    assert [(e["episode_index"], e["raw_file"]) for e in merged["episodes"]] == [(0, "p0.npz"), (1, "p1.npz"),
                                                                                 (2, "o0.npz")]
    assert merged["raw_dir"] == str(work / "raw") and merged["cameras"] == ["head", "left_wrist", "right_wrist"]
    assert sorted(path.name for path in work.iterdir()) == ["dataset_head_wrist", "raw"]  # no parts left
    calls.unlink()
    again = subprocess.run(["bash", str(SCRIPT), "data"], env=env, capture_output=True, text=True, timeout=60)
    assert again.returncode == 0 and "holds this recording's conversion: kept" in again.stdout
    assert not calls.exists()  # nothing converted or merged again


def test_a_nan_loss_stops_the_training_run_and_fails_with_a_clear_message(tmp_path):
    stubs = tmp_path / "bin"
    stubs.mkdir()
    (stubs / "tavis").write_text("#!/usr/bin/env bash\necho /dev/null\n")
    # LeRobot's log lines, the third one NaN, then a run that would go on for a minute unless stopped.
    (stubs / "lerobot-train").write_text("""#!/usr/bin/env bash
for step in 100 200; do echo "INFO ot_train.py:641 step:$step smpl:13K loss:0.9 grdn:31.6 lr:1.0e-04" >&2; done
echo "INFO ot_train.py:641 step:300 smpl:38K loss:nan grdn:nan lr:9.9e-05" >&2
sleep 60 > /dev/null 2>&1 &
wait $!
touch "$FINISHED"
""")
    for stub in stubs.iterdir():
        stub.chmod(0o755)
    env = {**os.environ, "PATH": f"{stubs}:{os.environ['PATH']}", "WORK": str(tmp_path / "work"), "WORKERS": "4",
           "FINISHED": str(tmp_path / "finished")}
    run = subprocess.run(["bash", str(SCRIPT), "train"], env=env, capture_output=True, text=True, timeout=30)
    assert run.returncode == 3
    assert "step:200 smpl:13K loss:0.9" in run.stdout  # the log passes through up to the NaN
    assert "the training loss became NaN; training stopped" in run.stderr
    assert not (tmp_path / "finished").exists()


def test_gpus_train_data_parallel_through_accelerate_and_frame_cache_reads_a_cache_written_once(tmp_path):
    calls = _run(tmp_path, "train", GPUS="2", FRAME_CACHE="on")
    dataset = tmp_path / "work" / "dataset_head_wrist"
    (cache,) = [call.split(" | ")[0] for call in calls if call.startswith("tavis cache-frames")]
    assert re.fullmatch(rf"tavis cache-frames {dataset} --workers 4 --video-backend (pyav|torchcodec)", cache)
    (train,) = [call for call in calls if call.startswith("accelerate")]
    assert train.startswith("accelerate launch --multi_gpu --num_processes 2 --num_machines 1 --mixed_precision no "
                            "--dynamo_backend no -m lerobot.scripts.lerobot_train --config_path=")
    assert "--num_workers=2 " in train and train.endswith(" | cache=1")  # WORKERS shared by the two processes
    assert calls.index(next(call for call in calls if call.startswith("tavis cache-frames"))) < calls.index(train)
    assert not any(call.startswith("lerobot-train") for call in calls)
    (single,) = [call for call in _run(tmp_path / "one", "train") if call.startswith("lerobot-train")]
    assert "--num_workers=4 " in single


@pytest.mark.parametrize(("settings", "message"), [
    ({"GPUS": "0"}, "GPUS must be a number of GPUs >= 1, got '0'"),
    ({"GPUS": "two"}, "GPUS must be a number of GPUs >= 1, got 'two'"),
    ({"FRAME_CACHE": "1"}, "FRAME_CACHE must be on or off, got '1'"),
    ({"DEVICE": "gpu"}, "DEVICE must be cuda or cpu, got 'gpu'"),
    ({"GPUS": "2", "MODE": "pair"}, "pair gives each condition one GPU of its own; GPUS=2 applies to train, cell"),
])
def test_bad_gpus_or_frame_cache_are_refused_before_anything_runs(tmp_path, settings, message):
    refused = _stubbed(tmp_path, settings.pop("MODE", "train"), **settings)
    assert refused.returncode == 2 and message in refused.stderr
    assert not (tmp_path / "calls.log").exists()


def test_device_cpu_trains_and_evaluates_without_a_gpu_or_amp_and_splits_reach_tavis_eval(tmp_path):
    (train,) = [call for call in _run(tmp_path, "train", DEVICE="cpu") if call.startswith("lerobot-train")]
    assert " --policy.device=cpu --policy.use_amp=false " in train
    calls = _run(tmp_path / "again", "eval", WORK=str(tmp_path / "work"), DEVICE="cpu", CHECKPOINTS="last",
                 SPLITS="id,ood_spatial")
    (evaluation,) = [call for call in calls if call.startswith("tavis eval")]
    assert " --splits id ood_spatial --episodes 96 " in evaluation
    assert " --device cpu --policy-option use_amp=false " in evaluation
