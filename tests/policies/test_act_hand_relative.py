"""`act_hand_relative`: ACT trained on hand-frame chunks and giving back absolute actions anchored on the state each
chunk was planned from; its statistics, configuration checks, checkpoints and registration with LeRobot (the
lerobot-train and `tavis eval` path: tests/test_policy_configs.py)."""

from types import SimpleNamespace

import numpy as np
import pytest
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.policies.act.modeling_act import ACTPolicy
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.envs.tasks.catalog import BENCHMARK_TASKS, task_info
from lerobot_tavis.envs.transforms import matrix_from_quat, quat_multiply
from lerobot_tavis.errors import InputError
from lerobot_tavis.policies import register_policy_types
from lerobot_tavis.policies.act_hand_relative.configuration_act_hand_relative import ACTHandRelativeConfig
from lerobot_tavis.policies.act_hand_relative.modeling_act_hand_relative import ACTHandRelativePolicy
from lerobot_tavis.policies.hand_frame import to_hand_frame
from lerobot_tavis.policies.hand_frame_statistics import hand_frame_statistics
from lerobot_tavis.policies.hand_relative import EPS
from tests.policies.conftest import made_up_episode, replay

CHUNK = 4
IMAGE = "observation.images.head"


@pytest.mark.parametrize("offsets", [range(CHUNK), range(-1, CHUNK - 1)])  # ACT's; Diffusion Policy's
def test_the_statistics_cover_every_chunk_action_inside_its_episode(dataset_root, offsets):
    """Actions t+k (k in `offsets`) inside the episode, in the hand frame of the state at t."""
    root, episodes = dataset_root
    values = []
    for actions, states in episodes:
        for t in range(len(actions)):
            for action in (actions[t + k] for k in offsets if 0 <= t + k < len(actions)):
                relative = action.copy()
                for arm in canonical.ARMS:
                    hand = states[t, arm.quaternion] / np.linalg.norm(states[t, arm.quaternion])  # made-up: not unit
                    relative[arm.position] = matrix_from_quat(hand).T @ (action[arm.position] - states[t, arm.position])
                    turn = quat_multiply(hand * [1, -1, -1, -1], action[arm.quaternion])
                    relative[arm.quaternion] = turn * np.sign(turn[0])
                values.append(relative)
    statistics = hand_frame_statistics(root, offsets)
    for key, reference in (("mean", np.mean), ("std", np.std), ("min", np.min), ("max", np.max)):
        np.testing.assert_allclose(statistics[key], reference(values, axis=0), atol=1e-9)


def _config(**fields) -> ACTHandRelativeConfig:
    inputs = {IMAGE: PolicyFeature(FeatureType.VISUAL, (3, 32, 32)), **fields.pop("inputs", {})}
    small = dict(chunk_size=CHUNK, n_action_steps=CHUNK, dim_model=32, n_heads=2, dim_feedforward=64,
                 n_encoder_layers=1, n_decoder_layers=1, latent_dim=8, pretrained_backbone_weights=None, device="cpu")
    return ACTHandRelativeConfig(input_features=inputs,
                                 output_features={ACTION: PolicyFeature(FeatureType.ACTION, (19,))},
                                 **(small | fields))


def _action_stats(episodes) -> dict:
    actions = np.concatenate([a for a, _ in episodes])
    return {ACTION: {"mean": actions.mean(axis=0), "std": actions.std(axis=0)}}


@pytest.fixture
def policy(dataset_root):
    root, episodes = dataset_root
    torch.manual_seed(0)
    return ACTHandRelativePolicy(_config(), dataset_stats=_action_stats(episodes),
                                 dataset_meta=SimpleNamespace(root=root, fps=20))


def _batch(rng, policy, size: int) -> tuple[dict, torch.Tensor]:
    """A training batch of `size` made-up chunks (normalised as LeRobot's processors do) and its absolute chunks."""
    absolute = torch.tensor(np.stack([made_up_episode(rng, CHUNK)[0] for _ in range(size)]), dtype=torch.float32)
    return {IMAGE: torch.rand(size, 3, 32, 32),
            OBS_STATE: torch.tensor(np.stack([made_up_episode(rng, 1)[1][0] for _ in range(size)]),
                                    dtype=torch.float32),
            ACTION: (absolute - policy.absolute_mean) / (policy.absolute_std + EPS),
            "action_is_pad": torch.zeros(size, CHUNK, dtype=torch.bool)}, absolute


def test_training_sees_the_chunk_in_the_hand_frame_normalised_by_its_statistics(policy, monkeypatch):
    batch, absolute = _batch(np.random.default_rng(1), policy, 3)
    loss, _ = policy.forward(batch)
    loss.backward()
    assert torch.isfinite(loss) and policy.model.action_head.weight.grad.abs().sum() > 0
    seen = {}
    monkeypatch.setattr(ACTPolicy, "forward", lambda self, batch: seen.update(batch) or (torch.zeros(()), {}))
    policy.forward(batch)
    expected = (to_hand_frame(absolute, batch[OBS_STATE]) - policy.relative_mean) / (policy.relative_std + EPS)
    torch.testing.assert_close(seen[ACTION], expected, atol=1e-4, rtol=0)
    assert seen[IMAGE] is batch[IMAGE]


@pytest.mark.parametrize(("amp_dtype", "autocast", "runs_in"), [
    ("bfloat16", torch.float16, torch.bfloat16), ("float16", torch.float16, torch.float16),
    ("bfloat16", None, torch.float32)])
def test_under_amp_the_network_runs_in_its_amp_dtype_whatever_autocast_asked(dataset_root, amp_dtype, autocast,
                                                                             runs_in):
    root, episodes = dataset_root
    policy = ACTHandRelativePolicy(_config(amp_dtype=amp_dtype), dataset_stats=_action_stats(episodes),
                                   dataset_meta=SimpleNamespace(root=root, fps=20))
    seen = []
    policy.model.action_head.register_forward_hook(lambda module, inputs, output: seen.append(output.dtype))
    batch, _ = _batch(np.random.default_rng(1), policy, 2)
    with torch.autocast("cpu", dtype=autocast, enabled=autocast is not None):  # as lerobot-train / lerobot-eval
        loss, _ = policy.forward(batch)
        policy.reset()
        action = policy.select_action(batch)
    assert seen == [runs_in, runs_in]
    assert torch.isfinite(loss) and action.dtype == torch.float32


def test_an_amp_dtype_other_than_bfloat16_or_float16_is_refused():
    with pytest.raises(ValueError, match="amp_dtype must be one of bfloat16, float16; got 'float32'"):
        _config(amp_dtype="float32")
    config = _config()
    config.amp_dtype = "half"  # as `tavis eval --policy-option amp_dtype=half` sets it on a loaded config
    with pytest.raises(ValueError, match="got 'half'"):
        config.validate_features()


def test_group_norm_normalises_the_resnet_trains_and_survives_a_checkpoint(dataset_root, tmp_path):
    """backbone_norm group_norm: every frozen batch norm of the ResNet becomes a trained GroupNorm (16 channels a
    group), and a checkpoint rebuilds that network with its weights."""
    from torch import nn
    from torchvision.ops.misc import FrozenBatchNorm2d

    root, episodes = dataset_root
    torch.manual_seed(0)
    policy = ACTHandRelativePolicy(_config(backbone_norm="group_norm"), dataset_stats=_action_stats(episodes),
                                   dataset_meta=SimpleNamespace(root=root, fps=20))
    norms = [m for m in policy.model.backbone.modules() if isinstance(m, (nn.GroupNorm, FrozenBatchNorm2d))]
    assert len(norms) == 20 and all(isinstance(m, nn.GroupNorm) and m.num_channels == 16 * m.num_groups
                                    for m in norms)
    batch, _ = _batch(np.random.default_rng(1), policy, 2)
    loss, _ = policy.forward(batch)
    loss.backward()
    assert torch.isfinite(loss) and all(m.weight.grad.abs().sum() > 0 for m in norms)
    with torch.no_grad():
        norms[0].weight.add_(0.5)  # a trained scale, which the checkpoint must keep
    policy.save_pretrained(tmp_path)
    loaded = ACTHandRelativePolicy.from_pretrained(tmp_path)
    assert loaded.config.backbone_norm == "group_norm"
    policy.eval(), loaded.eval()
    for each in (policy, loaded):
        each.reset()
    torch.testing.assert_close(loaded.predict_action_chunk(batch), policy.predict_action_chunk(batch))


def test_a_backbone_norm_other_than_its_two_or_group_norm_on_pretrained_weights_is_refused():
    with pytest.raises(ValueError, match="backbone_norm must be one of frozen_batch_norm, group_norm; got 'batch'"):
        _config(backbone_norm="batch")
    with pytest.raises(ValueError, match="pretrained_backbone_weights must be None, got 'ResNet18_Weights"):
        _config(backbone_norm="group_norm", pretrained_backbone_weights="ResNet18_Weights.IMAGENET1K_V1")
    config = _config()
    config.backbone_norm = "layer_norm"  # as `tavis eval --policy-option backbone_norm=layer_norm` sets it
    with pytest.raises(ValueError, match="got 'layer_norm'"):
        config.validate_features()


def test_a_predicted_chunk_comes_back_absolute_anchored_on_the_state_it_was_planned_from(policy, monkeypatch):
    batch, absolute = _batch(np.random.default_rng(2), policy, 2)
    planned_from = batch[OBS_STATE]
    network_output = (to_hand_frame(absolute, planned_from) - policy.relative_mean) / (policy.relative_std + EPS)
    monkeypatch.setattr(ACTPolicy, "predict_action_chunk", lambda self, batch: network_output)
    moved = {**batch, OBS_STATE: planned_from + 0.05}  # the hands have moved by the next step
    policy.reset()
    executed = torch.stack([policy.select_action(step) for step in (batch, moved, moved, moved)], dim=1)
    executed = executed * (policy.absolute_std + EPS) + policy.absolute_mean
    for arm in canonical.ARMS:
        torch.testing.assert_close(executed[..., arm.position], absolute[..., arm.position], atol=1e-5, rtol=0)
        alignment = (executed[..., arm.quaternion] * absolute[..., arm.quaternion]).sum(-1).abs()
        torch.testing.assert_close(alignment, torch.ones_like(alignment), atol=1e-5, rtol=0)
    torch.testing.assert_close(executed[..., 14:], absolute[..., 14:], atol=1e-5, rtol=0)


def test_temporal_ensembling_averages_chunks_planned_from_different_states_as_absolute_targets(dataset_root,
                                                                                               monkeypatch):
    root, _ = dataset_root
    stats = {ACTION: {"mean": np.zeros(19), "std": np.ones(19)}}
    policy = ACTHandRelativePolicy(_config(temporal_ensemble_coeff=0.01, n_action_steps=1), dataset_stats=stats,
                                   dataset_meta=SimpleNamespace(root=root, fps=20))
    rng = np.random.default_rng(3)
    targets = torch.tensor(made_up_episode(rng, 2 * CHUNK)[0], dtype=torch.float32).unsqueeze(0)  # (1, 8, 19)
    states = torch.tensor(made_up_episode(rng, CHUNK)[1], dtype=torch.float32)  # a different hand pose at each step
    step = iter(range(CHUNK))

    def planned(self, batch):  # the chunk from this step on, in the hand frame of this step's state
        i = next(step)
        return (to_hand_frame(targets[:, i:i + CHUNK], batch[OBS_STATE]) - policy.relative_mean) / (
            policy.relative_std + EPS)

    monkeypatch.setattr(ACTPolicy, "predict_action_chunk", planned)
    policy.reset()
    executed = torch.stack([policy.select_action({IMAGE: torch.rand(1, 3, 32, 32), OBS_STATE: state[None]})
                            for state in states], dim=1)
    for arm in canonical.ARMS:
        torch.testing.assert_close(executed[..., arm.position], targets[:, :CHUNK, arm.position], atol=1e-5, rtol=0)


def test_the_time_input_is_the_timestamp_in_training_and_the_steps_since_reset_when_acting(dataset_root,
                                                                                            monkeypatch):
    root, episodes = dataset_root
    torch.manual_seed(0)
    policy = ACTHandRelativePolicy(_config(time_input=True, n_action_steps=2), dataset_stats=_action_stats(episodes),
                                   dataset_meta=SimpleNamespace(root=root, fps=10))
    assert policy.config.input_features[OBS_ENV_STATE] == PolicyFeature(FeatureType.ENV, (1,))
    assert policy.config.fps == 10.0  # the dataset's
    batch, _ = _batch(np.random.default_rng(4), policy, 3)
    observation = {IMAGE: batch[IMAGE][:1], OBS_STATE: batch[OBS_STATE][:1]}
    policy.reset()
    early = policy.predict_action_chunk(observation)
    for _ in range(50):
        policy.select_action(observation)
    late = policy.predict_action_chunk(observation)
    assert not torch.allclose(early, late)  # the network reads the time
    loss, _ = policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5, 9.0])})
    assert torch.isfinite(loss)

    seen = []
    monkeypatch.setattr(ACTPolicy, "forward", lambda self, batch: seen.append(batch) or (torch.zeros(()), {}))
    policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5, 9.0])})
    torch.testing.assert_close(seen[-1][OBS_ENV_STATE], torch.tensor([[0.0], [0.15], [0.9]]))
    monkeypatch.setattr(ACTPolicy, "predict_action_chunk",
                        lambda self, batch: seen.append(batch) or torch.zeros(1, CHUNK, 19))
    seen.clear()
    policy.reset()
    for _ in range(5):
        policy.select_action(observation)
    policy.reset()
    policy.select_action(observation)
    # chunks planned at steps 0, 2 and 4 (two executed per chunk) at 10 steps per second, then again from 0
    assert [float(planned[OBS_ENV_STATE]) * 10.0 for planned in seen] == pytest.approx([0.0, 0.2, 0.4, 0.0])


def test_the_prompt_input_is_a_one_hot_of_the_episodes_prompt_after_the_time(dataset_root, monkeypatch):
    """The vocabulary defaults to every prompt of the eight tasks (clutter_pick_lift's name the object to lift);
    the network reads which one the batch's `task` is, in training and when acting."""
    root, episodes = dataset_root
    torch.manual_seed(0)
    policy = ACTHandRelativePolicy(_config(time_input=True, prompt_input=True), dataset_stats=_action_stats(episodes),
                                   dataset_meta=SimpleNamespace(root=root, fps=10))
    prompts = list(dict.fromkeys(prompt for task in BENCHMARK_TASKS for prompt in task_info(task).prompts))
    assert policy.config.prompts == prompts and len(prompts) > len(BENCHMARK_TASKS)
    assert policy.config.input_features[OBS_ENV_STATE] == PolicyFeature(FeatureType.ENV, (1 + len(prompts),))
    soup, tuna = task_info("clutter_pick_lift").prompts[0], task_info("clutter_pick_lift").prompts[6]
    batch, _ = _batch(np.random.default_rng(4), policy, 2)
    observation = {IMAGE: batch[IMAGE][:1].expand(2, -1, -1, -1), OBS_STATE: batch[OBS_STATE][:1].expand(2, -1)}
    policy.reset()
    chunks = policy.predict_action_chunk({**observation, "task": [soup, tuna]})
    assert not torch.allclose(chunks[0], chunks[1])  # the same images, two prompts: the network reads the prompt

    seen = []
    monkeypatch.setattr(ACTPolicy, "forward", lambda self, batch: seen.append(batch) or (torch.zeros(()), {}))
    policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5]), "task": [tuna, soup]})
    expected = torch.zeros(2, 1 + len(prompts))
    expected[:, 0] = torch.tensor([0.0, 0.15])
    expected[0, 1 + prompts.index(tuna)] = expected[1, 1 + prompts.index(soup)] = 1.0
    torch.testing.assert_close(seen[-1][OBS_ENV_STATE], expected)
    with pytest.raises(InputError, match="trained on .* prompts; 'Lift the spoon.' is not one of them"):
        policy.predict_action_chunk({**observation, "task": [soup, "Lift the spoon."]})


@pytest.mark.parametrize(("fields", "shape"), [
    ({"time_input": False}, (1,)), ({"time_input": True}, (2,)),
    ({"time_input": True, "prompt_input": True, "prompts": ["a", "b"]}, (2,))])
def test_an_environment_state_other_than_the_time_and_prompt_inputs_is_refused(fields, shape):
    with pytest.raises(ValueError, match="observation.environment_state holds its time input"):
        ACTHandRelativePolicy(_config(**fields, inputs={OBS_ENV_STATE: PolicyFeature(FeatureType.ENV, shape)}))


def test_the_state_as_a_network_input_or_another_action_is_refused():
    state = {OBS_STATE: PolicyFeature(FeatureType.STATE, (19,))}
    with pytest.raises(ValueError, match="remove observation.state from policy.input_features"):
        ACTHandRelativePolicy(_config(inputs=state))
    config = _config()
    config.output_features = {ACTION: PolicyFeature(FeatureType.ACTION, (14,))}
    with pytest.raises(ValueError, match="needs TAVIS's 19-D canonical action, got \\(14,\\)"):
        ACTHandRelativePolicy(config)


def test_lerobot_train_refuses_a_dataset_of_another_image_size_or_without_its_cameras():
    """lerobot-train's make_policy hands the policy config the training dataset's features: ACT would learn at the
    dataset's size while its checkpoint claimed the config's."""
    from lerobot.policies.factory import make_policy

    def dataset(cameras, size):
        images = {f"observation.images.{c}": {"dtype": "video", "shape": [*size, 3],
                                                  "names": ["height", "width", "channels"]} for c in cameras}
        vectors = {key: {"dtype": "float32", "shape": [19], "names": None} for key in (ACTION, OBS_STATE)}
        return SimpleNamespace(features=images | vectors, stats=None)

    _config().set_dataset_feature_metadata(dataset(["head", "fixed"], (32, 32)).features)  # more cameras: fine
    with pytest.raises(ValueError, match="the dataset's head images are 24x32, the policy's input_features say "
                                         "32x32 .*convert the dataset with --image-size 32x32"):
        make_policy(_config(), ds_meta=dataset(["head"], (24, 32)))
    with pytest.raises(ValueError, match="the policy reads the cameras head, the dataset has fixed: convert the "
                                         "dataset with --cameras head"):
        make_policy(_config(), ds_meta=dataset(["fixed"], (32, 32)))


def test_without_the_dataset_statistics_it_refuses_to_act():
    policy = ACTHandRelativePolicy(_config())
    with pytest.raises(RuntimeError, match="act_hand_relative has no absolute_mean"):
        policy.predict_action_chunk({IMAGE: torch.rand(1, 3, 32, 32), OBS_STATE: torch.zeros(1, 19)})


def test_a_checkpoint_keeps_the_statistics_and_lerobot_finds_the_policy_and_its_processors(policy, tmp_path):
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.policies.factory import get_policy_class, make_pre_post_processors

    policy.save_pretrained(tmp_path)
    register_policy_types()
    config = PreTrainedConfig.from_pretrained(tmp_path)
    assert type(config) is ACTHandRelativeConfig and get_policy_class(config.type) is ACTHandRelativePolicy
    loaded = ACTHandRelativePolicy.from_pretrained(tmp_path, config=config)
    for buffer in ("absolute_mean", "absolute_std", "relative_mean", "relative_std"):
        torch.testing.assert_close(getattr(loaded, buffer), getattr(policy, buffer))
    stats = {ACTION: {"mean": policy.absolute_mean.numpy(), "std": policy.absolute_std.numpy()}}
    preprocessor, postprocessor = make_pre_post_processors(config, dataset_stats=stats)
    raw_state = torch.rand(1, 19)
    processed = preprocessor({IMAGE: torch.rand(1, 3, 32, 32), OBS_STATE: raw_state})
    torch.testing.assert_close(processed[OBS_STATE], raw_state)  # the anchor reaches the policy un-normalised


def test_chunks_planned_on_recorded_states_land_on_the_recorded_actions_when_anchored_on_the_env(demonstration,
                                                                                                 tmp_path,
                                                                                                 monkeypatch):
    """The anchor a policy learns on (the dataset's observation.state) is the one it acts on (the env's agent_pos
    through LeRobot's observation conversion and the processors): an oracle network that plans every chunk from the
    recorded actions and states, executed by a checkpoint in `PolicyDriver`, repeats the demonstration."""
    from lerobot.policies.factory import make_pre_post_processors

    actions, states = demonstration.actions, demonstration.states
    stats = {ACTION: {"mean": actions.mean(0).numpy(), "std": actions.std(0).numpy()},
             IMAGE: {"mean": np.full((3, 1, 1), 0.5), "std": np.full((3, 1, 1), 0.25)}}
    chunk, executed = 20, 10
    policy = ACTHandRelativePolicy(_config(chunk_size=chunk, n_action_steps=executed), dataset_stats=stats,
                                   dataset_meta=SimpleNamespace(root=demonstration.root, fps=20))
    policy.save_pretrained(tmp_path / "checkpoint")
    for pipeline in make_pre_post_processors(policy.config, dataset_stats=stats):
        pipeline.save_pretrained(tmp_path / "checkpoint")

    def oracle(self, batch):  # the chunk the demonstrator executed from here, planned on the recorded state
        start = len(planned) * executed
        planned.append(start)
        indices = torch.clamp(torch.arange(start, start + chunk), max=len(actions) - 1)
        relative = to_hand_frame(actions[indices].unsqueeze(0), states[start].unsqueeze(0))
        return (relative - self.relative_mean) / (self.relative_std + EPS)

    planned = []
    monkeypatch.setattr(ACTPolicy, "predict_action_chunk", oracle)
    success, error_m = replay(tmp_path / "checkpoint", demonstration)
    assert success and error_m < 0.015, (success, error_m)  # verify-dataset's replay tolerance
