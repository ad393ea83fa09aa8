"""The protocol runner (demonstrators and a policy checkpoint through LeRobot's eval) and lerobot-eval itself."""

import json
import logging
import os
import re
import subprocess
import sys

import pytest

from lerobot_tavis.cli import main
from lerobot_tavis.envs.tasks.catalog import suite_tasks
from lerobot_tavis.errors import FieldError, InputError
from lerobot_tavis.eval import protocol
from lerobot_tavis.eval.cell_runs import run_cells
from lerobot_tavis.eval.protocol import Cell, ProtocolConfig, run_protocol
from lerobot_tavis.eval.report import write_report
from lerobot_tavis.eval.run_identity import run_identity

pytestmark = pytest.mark.slow  # conftest.py: its file starts first

SHORT_S = 2.0  # seconds per demonstrator episode where a test compares runs, not outcomes


def test_expert_protocol_writes_cells_and_report_resumes_and_ignores_workers_and_chunking(tmp_path, capsys):
    """A cell and its report, kept by a second run; then the cell played again over 2 workers in chunks of one seed
    (finishing in any order) is the cell one process wrote."""
    common = dict(expert=True, robot="gr1t2", suites=("tavis_hands",), splits=("id",), n_episodes=2,
                  episode_length_s=SHORT_S)
    one = tmp_path / "one"
    cfg = ProtocolConfig(out_dir=one, workers=1, **common)
    written = {p.name for p in run_protocol(cfg)}
    assert {"results.md", "results.json", "success_rates.png"} <= written
    cell = one / "tavis_hands__id"
    info = json.loads((cell / "eval_info.json").read_text())
    assert [t["task_id"] for t in info["per_task"]] == [0, 1, 2]
    records = [json.loads(line) for line in (cell / "episodes.jsonl").read_text().splitlines()]
    assert sorted((r["task"], r["seed"]) for r in records) == sorted(
        (task, seed) for task in suite_tasks("tavis_hands") for seed in (1000, 1001))
    results = json.loads((one / "results.json").read_text())
    assert sum(c["n"] for c in results["cells"]) == 6
    before = (cell / "eval_info.json").stat().st_mtime_ns
    run_protocol(cfg)
    out = capsys.readouterr().out
    assert "tavis_hands__id: done already, skipped" in out
    assert re.search(r"episodes played in \d+\.\d s, report written in \d+\.\d s", out)
    assert (cell / "eval_info.json").stat().st_mtime_ns == before
    assert not list(one.glob(".*partial*"))
    run_protocol(ProtocolConfig(out_dir=tmp_path / "two", workers=2, chunk_episodes=1, **common))
    assert _cell_files(one) == _cell_files(tmp_path / "two")
    assert not list((tmp_path / "two").glob(".*"))  # the chunks are gone once the cell is written


def test_tasks_play_only_those_tasks_and_a_cell_of_other_tasks_is_not_reused(tmp_path):
    cfg = ProtocolConfig(out_dir=tmp_path, expert=True, robot="gr1t2", splits=("id",), tasks=("occluded_reach",),
                         n_episodes=2, episode_length_s=SHORT_S)
    assert cfg.suites == ("tavis_hands",)  # the task's suite
    run_protocol(cfg)
    assert [path.name for path in tmp_path.glob("*__*")] == ["tavis_hands__id"]
    cell = tmp_path / "tavis_hands__id"
    info = json.loads((cell / "eval_info.json").read_text())
    assert [t["task_id"] for t in info["per_task"]] == [suite_tasks("tavis_hands").index("occluded_reach")]
    records = [json.loads(line) for line in (cell / "episodes.jsonl").read_text().splitlines()]
    assert [(r["task"], r["seed"]) for r in records] == [("occluded_reach", 1000), ("occluded_reach", 1001)]
    with pytest.raises(InputError, match="holds the tasks \\['occluded_reach'\\], not those asked for"):
        run_protocol(ProtocolConfig(out_dir=tmp_path, expert=True, robot="gr1t2", suites=("tavis_hands",),
                                    splits=("id",), n_episodes=2, episode_length_s=SHORT_S))


def test_a_task_outside_the_suites_is_refused(tmp_path):
    with pytest.raises(FieldError, match="tasks \\['conditional_pick'\\] are not tasks of the suites"):
        ProtocolConfig(out_dir=tmp_path, expert=True, suites=("tavis_hands",), tasks=("conditional_pick",))


def _cell_files(root, cell="tavis_hands__id"):
    return ((root / cell / "episodes.jsonl").read_text(), json.loads((root / cell / "eval_info.json").read_text()))


def test_finished_chunks_of_a_killed_run_are_kept(tmp_path):
    """A chunk whose `done` record exists is not played again: its stored outcome is what the cell reports."""
    cfg = ProtocolConfig(out_dir=tmp_path, expert=True, robot="gr1t2", suites=("tavis_hands",), splits=("id",),
                         n_episodes=1, chunk_episodes=1, episode_length_s=SHORT_S)
    work = tmp_path / ".tavis_hands__id.chunks"
    work.mkdir(parents=True)
    (work / "run.json").write_text(json.dumps(run_identity(cfg)))  # what the killed run wrote when it began
    stored = {"robot": "gr1t2", "suite": "tavis_hands", "task": "peeking_box", "task_id": 0, "split": "id",
              "camera_mode": "head_wrist", "seed": 1000, "success": False, "length_steps": 400, "prompt": "stored"}
    (work / "00_peeking_box_0001000.jsonl").write_text(json.dumps(stored) + "\n")
    (work / "00_peeking_box_0001000.done.json").write_text(json.dumps(
        {"successes": [False], "sum_rewards": [0.0], "max_rewards": [0.0]}))
    (work / "01_occluded_reach_0001000.jsonl").write_text("half a line of a killed chunk")  # no done record
    run_protocol(cfg)
    log, info = _cell_files(tmp_path)
    records = [json.loads(line) for line in log.splitlines()]
    assert [r["task"] for r in records] == list(suite_tasks("tavis_hands"))
    assert records[0]["prompt"] == "stored" and info["per_task"][0]["metrics"]["successes"] == [False]
    assert records[1]["prompt"] != "stored" and not work.exists()


def _trained_checkpoint(path, env, cameras=None, image_size=(120, 160)):
    """A checkpoint's two config files (no weights): its policy reads `cameras` at `image_size`, its training ran
    with the env `env`."""
    path.mkdir(parents=True)
    images = {f"observation.images.{camera}": {"type": "VISUAL", "shape": [3, *image_size]} for camera in cameras or ()}
    (path / "config.json").write_text(json.dumps({"type": "diffusion", "input_features": images}))
    (path / "train_config.json").write_text(json.dumps({"env": env, "policy": {"type": "diffusion"}}))
    return path


@pytest.mark.parametrize("extra,expected,warned", [
    ([], ("reachy2", "fixed_wrist", (120, 160)), []),  # all from the checkpoint's training config
    (["--camera-mode", "head_only", "--image-size", "96x128"], ("reachy2", "head_only", (96, 128)),  # given wins,
     ["trained with camera mode fixed_wrist; --camera-mode asks for head_only",  # with a warning for each
      "trained on 120x160 images; --image-size asks for 96x128 (leave --image-size out"]),
])
def test_tavis_eval_takes_robot_camera_mode_and_image_size_from_the_checkpoint(tmp_path, monkeypatch, caplog, extra,
                                                                                expected, warned):
    checkpoint = _trained_checkpoint(tmp_path / "pretrained_model", {
        "type": "tavis", "robot": "reachy2", "camera_mode": "fixed_wrist", "image_size": [120, 160]})
    seen = []
    monkeypatch.setattr(protocol, "run_protocol", lambda cfg: seen.append(cfg) or [])
    with caplog.at_level(logging.WARNING):
        main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out"), *extra])
    (cfg,) = seen
    assert (cfg.robot, cfg.camera_mode, cfg.image_size) == expected
    assert len(caplog.records) == len(warned)
    assert all(text in record.getMessage() for text, record in zip(warned, caplog.records))


def test_tavis_eval_takes_the_image_size_and_cameras_the_policy_reads(tmp_path, monkeypatch):
    """Without a tavis training config (e.g. trained on another env's config), the policy's input features say
    which cameras and which size it reads."""
    checkpoint = _trained_checkpoint(tmp_path / "pretrained_model", {"type": "aloha"},
                                     cameras=("fixed", "left_wrist", "right_wrist"), image_size=(96, 128))
    seen = []
    monkeypatch.setattr(protocol, "run_protocol", lambda cfg: seen.append(cfg) or [])
    main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out")])
    assert (seen[0].camera_mode, seen[0].image_size) == ("fixed_wrist", (96, 128))


def test_tavis_eval_of_a_hub_policy_fetches_its_settings(tmp_path, monkeypatch):
    """A published baseline (`--policy <user>/<name>`): its two config files come from the Hub (faked here)."""
    import huggingface_hub

    published = _trained_checkpoint(tmp_path / "hub", {"type": "tavis", "robot": "reachy2"},
                                     cameras=("head", "left_wrist", "right_wrist"), image_size=(96, 128))
    fetched = []
    monkeypatch.setattr(huggingface_hub, "hf_hub_download",
                        lambda repo_id, name: fetched.append((repo_id, name)) or str(published / name))
    cfg = ProtocolConfig(policy_path="someone/act", out_dir=tmp_path / "out")
    assert (cfg.robot, cfg.camera_mode, cfg.image_size) == ("reachy2", "head_wrist", (96, 128))
    assert fetched == [("someone/act", "config.json"), ("someone/act", "train_config.json")]


def test_tavis_eval_refuses_another_image_size_for_an_act_checkpoint(tmp_path):
    checkpoint = _trained_checkpoint(tmp_path / "pretrained_model", {"type": "tavis"}, cameras=("head",))
    config = json.loads((checkpoint / "config.json").read_text())
    (checkpoint / "config.json").write_text(json.dumps(config | {"type": "act"}))
    with pytest.raises(SystemExit, match=r"^tavis eval: error: the policy \(act, which does not resize its images\) "
                                         "was trained on 120x160 images, --image-size asks for 96x128: leave "
                                         "--image-size out to use the checkpoint's$"):
        main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out"), "--image-size", "96x128"])
    assert not (tmp_path / "out").exists()


def test_tavis_eval_refuses_a_camera_mode_without_the_policys_cameras(tmp_path):
    checkpoint = _trained_checkpoint(tmp_path / "pretrained_model", {"type": "tavis", "camera_mode": "fixed_wrist"},
                                     cameras=("fixed", "left_wrist", "right_wrist"))
    with pytest.raises(SystemExit, match="tavis eval: error: the policy reads the cameras fixed, left_wrist, "
                                         "right_wrist, camera mode head_wrist renders head, left_wrist, right_wrist: "
                                         "use --camera-mode fixed_wrist"):
        main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out"), "--camera-mode", "head_wrist"])


def test_expert_runs_refuse_an_image_size(tmp_path):
    with pytest.raises(SystemExit, match="tavis eval: error: --image-size does not apply to --expert: the "
                                         "demonstrators act on the simulator state and render nothing"):
        main(["eval", "--expert", "--image-size", "96x128", "--out", str(tmp_path / "out")])


def test_a_training_output_folder_names_its_checkpoint(tmp_path):
    """`tavis eval --policy <lerobot-train output>`: the one-line error names the checkpoint folder to pass."""
    train = tmp_path / "train"
    for step in ("000800", "001600"):
        _trained_checkpoint(train / "checkpoints" / step / "pretrained_model", {"type": "tavis"})
    with pytest.raises(SystemExit, match=f"^tavis eval: error: {train} holds no config.json: pass "
                                         f"{train}/checkpoints/001600/pretrained_model$"):
        main(["eval", "--policy", str(train), "--out", str(tmp_path / "out")])
    (train / "checkpoints" / "last").symlink_to("001600")
    with pytest.raises(SystemExit, match=f"pass {train}/checkpoints/last/pretrained_model$"):
        main(["eval", "--policy", str(train), "--out", str(tmp_path / "out")])
    with pytest.raises(SystemExit, match=f"pass {train}/checkpoints/000800/pretrained_model$"):
        main(["eval", "--policy", str(train / "checkpoints" / "000800"), "--out", str(tmp_path / "out")])


def test_lerobot_options_pass_through_to_the_policy_and_the_env(tmp_path, monkeypatch):
    checkpoint = _trained_checkpoint(tmp_path / "pretrained_model", {"type": "tavis"})
    seen = []
    monkeypatch.setattr(protocol, "run_protocol", lambda cfg: seen.append(cfg) or [])
    main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out"), "--episode-length-s", "5",
          "--policy-option", "num_inference_steps=10", "--policy-option", "use_amp=true",
          "--policy-option", "noise_scheduler_type=DDIM"])
    assert seen[0].episode_length_s == 5.0
    assert seen[0].policy_options == (("num_inference_steps", 10), ("use_amp", True), ("noise_scheduler_type", "DDIM"))
    with pytest.raises(SystemExit, match="--policy-option must be FIELD=VALUE"):
        main(["eval", "--policy", str(checkpoint), "--out", str(tmp_path / "out"), "--policy-option", "steps"])


def test_an_unknown_policy_option_names_the_field(tmp_path, diffusion_checkpoint):
    """Refused by the first job to read the checkpoint's config, here in this process (in a worker process: the
    fresh process's test below)."""
    cfg = ProtocolConfig(out_dir=tmp_path / "eval", tasks=("conditional_pick",), splits=("id",), n_episodes=1,
                         image_size=(32, 48), policy_path=str(diffusion_checkpoint), policy_options=(("denoise", 3),))
    with pytest.raises(ValueError, match="--policy-option denoise: the diffusion policy has no such field"):
        run_protocol(cfg)
    assert not any((tmp_path / "eval").iterdir())


def test_a_fresh_tavis_eval_process_reads_the_checkpoints_policy_type(tmp_path, diffusion_checkpoint):
    """In a new process nothing has imported LeRobot's policies yet: their types must be registered before the
    checkpoint's config is read (else: "Policy type 'diffusion' ... is not registered"). With two workers the
    first job reads it in a spawned worker process, whose refusal reaches the console script's error."""
    tavis = os.path.join(os.path.dirname(sys.executable), "tavis")
    done = subprocess.run([tavis, "eval", "--policy", str(diffusion_checkpoint), "--out", str(tmp_path / "eval"),
                           "--tasks", "conditional_pick", "--splits", "id", "--episodes", "1", "--image-size", "32x48",
                           "--workers", "2", "--policy-option", "denoise=3"], capture_output=True, text=True,
                          env={**os.environ, "HF_HUB_OFFLINE": "1"})
    assert done.returncode != 0
    assert "--policy-option denoise: the diffusion policy has no such field" in done.stderr, done.stderr
    assert not any((tmp_path / "eval").iterdir())


def test_a_missing_checkpoint_path_says_so(tmp_path):
    missing = tmp_path / "outputs" / "train" / "checkpoints" / "last" / "pretrained_model"
    with pytest.raises(SystemExit, match=f"--policy {missing}: no such checkpoint directory"):
        main(["eval", "--policy", str(missing), "--out", str(tmp_path / "out")])
    assert not (tmp_path / "out").exists()


@pytest.fixture(scope="module")
def diffusion_checkpoint(tmp_path_factory):
    """A tiny diffusion policy (random weights) saved as a checkpoint that reads 32x48 head images; tests only
    read it."""
    from lerobot.policies.diffusion.configuration_diffusion import DiffusionConfig
    from lerobot.policies.factory import make_policy, make_pre_post_processors

    from lerobot_tavis.eval.env_config import TavisEnvConfig

    path = tmp_path_factory.mktemp("diffusion") / "ckpt"
    config = DiffusionConfig(pretrained_backbone_weights=None, device="cpu", push_to_hub=False,
                             down_dims=(16, 32, 64), horizon=16, n_action_steps=8, num_inference_steps=2)
    policy = make_policy(config, env_cfg=TavisEnvConfig(image_size=(32, 48)))
    policy.save_pretrained(path)
    for processor in make_pre_post_processors(config, dataset_stats=None):
        processor.save_pretrained(path)
    return path


def test_policy_protocol_runs_through_lerobot_eval_under_one_progress_bar(tmp_path, diffusion_checkpoint, capsys):
    tasks = ("conditional_pick", "wait_then_act")
    cfg = ProtocolConfig(out_dir=tmp_path / "eval", suites=("tavis_head",), tasks=tasks,
                         splits=("ood_init_pose",), n_episodes=1, image_size=(32, 48), episode_length_s=0.5,
                         policy_path=str(diffusion_checkpoint), policy_options=(("num_inference_steps", 1),))
    capsys.readouterr()
    run_protocol(cfg)
    results = json.loads((tmp_path / "eval" / "results.json").read_text())
    assert [(c["task"], c["split"], c["n"]) for c in results["cells"]] == [
        (task, "ood_init_pose", 1) for task in tasks]
    bars = {line.split(":")[0] for line in re.split(r"[\r\n]+", capsys.readouterr().err) if "|" in line}
    assert bars == {"policy"}  # the run's own bar; none of lerobot-eval's batch and rollout bars


def _tiny_policy_cell(checkpoint, out, suite: str, tasks: tuple[str, ...], **settings):
    """The id cell of `suite` (2 episodes of each of `tasks`) played by the tiny diffusion `checkpoint`."""
    run_protocol(ProtocolConfig(out_dir=out, suites=(suite,), tasks=tasks, splits=("id",), n_episodes=2,
                                image_size=(32, 48), episode_length_s=0.5, policy_path=str(checkpoint),
                                policy_options=(("num_inference_steps", 1),), **settings))
    return _cell_files(out, f"{suite}__id")


def test_policy_chunks_share_workers_without_changing_results_and_keep_the_first_videos(tmp_path,
                                                                                        diffusion_checkpoint):
    """Each chunk is one lerobot-eval run seeded with its first seed: two workers give the cell of one. One task's
    two chunks (the cell's order over tasks, whatever the finishing order: the demonstrators' test above). The
    filmed chunk's videos are annotated as it finishes (by the annotator's processes while the next chunk plays), so
    the cell of one worker, played without a report, holds its copies."""
    cfg = ProtocolConfig(out_dir=tmp_path / "one", suites=("tavis_head",), tasks=("conditional_pick",), splits=("id",),
                         n_episodes=2, image_size=(32, 48), episode_length_s=0.5,
                         policy_path=str(diffusion_checkpoint), policy_options=(("num_inference_steps", 1),),
                         workers=1, chunk_episodes=1)
    run_cells(cfg, [Cell("tavis_head", "id")], run_identity(cfg))
    cell = tmp_path / "one" / "tavis_head__id"
    video = cell / "videos" / "tavis_head_0" / "eval_episode_0.mp4"
    copy = cell / "videos_annotated" / "tavis_head_0" / "eval_episode_0.mp4"
    assert video.stat().st_size > 0 and copy.stat().st_mtime_ns > video.stat().st_mtime_ns
    assert sorted(path.name for path in cell.rglob("*.mp4")) == ["eval_episode_0.mp4"] * 2
    one = _cell_files(tmp_path / "one", "tavis_head__id")
    assert one == _tiny_policy_cell(diffusion_checkpoint, tmp_path / "two", "tavis_head", ("conditional_pick",),
                                    workers=2, chunk_episodes=1)
    records = [json.loads(line) for line in one[0].splitlines()]
    assert [(r["task_id"], r["seed"]) for r in records] == [(0, 1000), (0, 1001)]
    videos = one[1]["per_task"][0]["metrics"]["video_paths"]
    assert videos == ["videos/tavis_head_0/eval_episode_0.mp4"]  # from the chunk of seed 1000 only
    assert not [path for path in write_report(tmp_path / "one") if path.suffix == ".mp4"]


def test_filming_changes_no_result_and_zero_films_nothing(tmp_path, diffusion_checkpoint):
    """One task's batch of two async envs, both filmed or neither (each task's first chunk is filmed alike)."""
    tasks = ("peeking_box",)
    films = _tiny_policy_cell(diffusion_checkpoint, tmp_path / "films", "tavis_hands", tasks, batch_size=2,
                              film_episodes=2)
    none = _tiny_policy_cell(diffusion_checkpoint, tmp_path / "none", "tavis_hands", tasks, batch_size=2,
                             film_episodes=0)
    assert films[0] == none[0]  # the episode logs
    assert [t["metrics"]["successes"] for t in films[1]["per_task"]] == [
        t["metrics"]["successes"] for t in none[1]["per_task"]]
    assert [len(t["metrics"]["video_paths"]) for t in films[1]["per_task"]] == [2]
    assert [t["metrics"]["video_paths"] for t in none[1]["per_task"]] == [[]]
    assert not (tmp_path / "none" / "tavis_hands__id" / "videos").exists()


def _policy_run(checkpoint, out, task, keep_workers):
    """One lerobot-eval run of `task` (2 episodes in one async batch of 2, the first filmed), as a policy chunk."""
    from types import SimpleNamespace

    from lerobot.configs.default import EvalConfig

    from lerobot_tavis.eval.cell_runs import policy_config
    from lerobot_tavis.eval.env_config import TavisEnvConfig
    from lerobot_tavis.eval.lerobot_run import evaluate, pipeline_config

    policy = policy_config(SimpleNamespace(policy_path=str(checkpoint), device="cpu",
                                           policy_options=(("num_inference_steps", 1),)))
    env = TavisEnvConfig(task=task, image_size=(32, 48), episode_length_s=0.5, filmed_envs=1,
                         episode_log=str(out / "episodes.jsonl"))
    evaluate(pipeline_config(env=env, eval=EvalConfig(n_episodes=2, batch_size=2, use_async_envs=True),
                             policy=policy, output_dir=out, seed=1000), keep_workers=keep_workers)
    info = json.loads((out / "eval_info.json").read_text())["per_task"][0]["metrics"]
    records = sorted((out / "episodes.jsonl").read_text().splitlines())  # logged in the order episodes end
    return records, [info[key] for key in ("successes", "sum_rewards", "max_rewards")]


def test_kept_env_workers_play_the_next_task_as_new_ones_would(tmp_path, diffusion_checkpoint):
    """A job's env workers outlive its run and build the next run's task in the same processes: same results."""
    from lerobot_tavis.eval import lerobot_run

    try:
        _policy_run(diffusion_checkpoint, tmp_path / "first", "wait_then_act", keep_workers=True)
        (batch,) = lerobot_run._KEPT.values()
        workers = [process.pid for process in batch._started().processes]
        kept = _policy_run(diffusion_checkpoint, tmp_path / "kept", "conditional_pick", keep_workers=True)
        assert list(lerobot_run._KEPT.values()) == [batch]
        assert [process.pid for process in batch._started().processes] == workers
        assert batch.call("task") == ("conditional_pick", "conditional_pick")
        assert (tmp_path / "kept" / "videos").is_dir()
    finally:
        lerobot_run.close_kept_envs()
    assert not lerobot_run._KEPT
    fresh = _policy_run(diffusion_checkpoint, tmp_path / "fresh", "conditional_pick", keep_workers=False)
    assert not lerobot_run._KEPT
    assert kept == fresh
    assert [(json.loads(line)["task"], json.loads(line)["seed"]) for line in kept[0]] == [
        ("conditional_pick", 1000), ("conditional_pick", 1001)]


def test_a_negative_film_count_is_refused(tmp_path):
    with pytest.raises(FieldError, match="film_episodes"):
        ProtocolConfig(out_dir=tmp_path, expert=True, film_episodes=-1)


def test_lerobot_eval_cli_writes_eval_info_and_the_episode_log(tmp_path):
    """The console script, async envs of which one is filmed (sync envs: the checkpoint's test below)."""
    command = [os.path.join(os.path.dirname(sys.executable), "lerobot-eval"), "--env.type=tavis",
               "--env.task=wait_then_act", "--env.image_size=[32, 48]", "--env.episode_length_s=0.5",
               "--policy.type=diffusion", "--policy.pretrained_backbone_weights=null", "--policy.device=cpu",
               "--policy.down_dims=[16, 32, 64]", "--policy.num_inference_steps=2", "--eval.n_episodes=2",
               "--eval.batch_size=2", "--eval.use_async_envs=true", "--env.filmed_envs=1",
               f"--output_dir={tmp_path / 'out'}"]
    subprocess.run(command, check=True, capture_output=True, text=True, env={**os.environ, "HF_HUB_OFFLINE": "1"})
    _assert_two_episodes_of_wait_then_act(tmp_path / "out", videos=1, steps=10)


def _assert_two_episodes_of_wait_then_act(out, videos: int, steps: int):
    """What lerobot-eval wrote in `out` for 2 episodes (seeds 1000, 1001) of wait_then_act, task 1 of tavis_head."""
    info = json.loads((out / "eval_info.json").read_text())
    assert (info["per_task"][0]["task_group"], info["per_task"][0]["task_id"]) == ("tavis_head", 1)  # its index
    assert len(info["overall"]["video_paths"]) == videos
    assert all("/videos/tavis_head_1/" in path for path in info["overall"]["video_paths"])
    records = [json.loads(line) for line in (out / "episodes.jsonl").read_text().splitlines()]
    assert sorted(r["seed"] for r in records) == [1000, 1001]
    assert all("galt_s" in r and r["length_steps"] == steps and r["task_id"] == 1 for r in records)


def test_lerobot_eval_of_a_checkpoint_renders_the_size_it_was_trained_at(tmp_path, diffusion_checkpoint,
                                                                        monkeypatch, caplog):
    """The issue's case: `lerobot-eval --policy.path=<checkpoint> --env.type=tavis` without `--env.image_size`
    renders the checkpoint's size (32x48 here), not the env's default 480x640 (LeRobot's eval_main, in this
    process); sync envs film every episode."""
    from lerobot.scripts import lerobot_eval

    monkeypatch.setattr("sys.argv", [
        "lerobot-eval", "--env.type=tavis", "--env.task=wait_then_act", "--env.episode_length_s=0.2",
        f"--policy.path={diffusion_checkpoint}", "--policy.device=cpu", "--eval.n_episodes=2", "--eval.batch_size=2",
        "--eval.use_async_envs=false", f"--output_dir={tmp_path / 'out'}"])
    monkeypatch.setenv("HF_HUB_OFFLINE", "1")
    with caplog.at_level(logging.INFO, logger="lerobot_tavis.eval.env_config"):
        lerobot_eval.eval_main()
    assert "the env takes the checkpoint's image_size 32x48" in caplog.text
    _assert_two_episodes_of_wait_then_act(tmp_path / "out", videos=2, steps=4)


def test_the_eval_config_of_a_checkpoint_does_not_warn_of_random_weights(caplog):
    from lerobot.configs.eval import EvalPipelineConfig
    from lerobot.policies.diffusion.configuration_diffusion import DiffusionConfig

    from lerobot_tavis.eval.env_config import TavisEnvConfig
    from lerobot_tavis.eval.lerobot_run import pipeline_config

    policy = DiffusionConfig(pretrained_path="ckpt")
    with caplog.at_level(logging.WARNING, logger="lerobot.configs.eval"):
        EvalPipelineConfig(env=TavisEnvConfig(), policy=policy, job_name="probe")
        assert "random weights" in caplog.text  # LeRobot's own config warns: the check below can fail
        caplog.clear()
        cfg = pipeline_config(env=TavisEnvConfig(), policy=policy, job_name="probe")
    assert "random weights" not in caplog.text
    assert cfg.policy.pretrained_path == "ckpt"
    with pytest.raises(ValueError, match="pretrained_path"):
        pipeline_config(env=TavisEnvConfig(), policy=DiffusionConfig(), job_name="probe")
