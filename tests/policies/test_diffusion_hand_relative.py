"""`diffusion_hand_relative`: Diffusion Policy trained on horizons in the hand frame of the current step's raw state
and giving back absolute actions; what its network sees of the state, its time input, configuration checks,
checkpoints and registration with LeRobot (the lerobot-train and `tavis eval` path: tests/test_policy_configs.py)."""

from types import SimpleNamespace

import numpy as np
import pytest
import torch
from lerobot.configs.types import FeatureType, NormalizationMode, PolicyFeature
from lerobot.policies.diffusion.modeling_diffusion import DiffusionModel
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_STATE

from lerobot_tavis import canonical
from lerobot_tavis.policies import register_policy_types
from lerobot_tavis.policies.diffusion_hand_relative.configuration_diffusion_hand_relative import (
    DiffusionHandRelativeConfig,
)
from lerobot_tavis.policies.diffusion_hand_relative.modeling_diffusion_hand_relative import (
    DiffusionHandRelativePolicy,
)
from lerobot_tavis.policies.hand_frame import to_hand_frame
from tests.policies.conftest import made_up_episode, replay

OBS, HORIZON, EXECUTED = 2, 8, 4
IMAGE = "observation.images.head"
STATISTICS = ("absolute_min", "absolute_max", "relative_min", "relative_max", "state_min", "state_max")


def _config(**fields) -> DiffusionHandRelativeConfig:
    inputs = fields.pop("inputs", {IMAGE: PolicyFeature(FeatureType.VISUAL, (3, 16, 16)),
                                   OBS_STATE: PolicyFeature(FeatureType.STATE, (19,))})
    small = dict(n_obs_steps=OBS, horizon=HORIZON, n_action_steps=EXECUTED, down_dims=(8, 16),
                 spatial_softmax_num_keypoints=4, diffusion_step_embed_dim=8, pretrained_backbone_weights=None,
                 use_group_norm=True, noise_scheduler_type="DDIM", num_inference_steps=2, device="cpu")
    return DiffusionHandRelativeConfig(input_features=inputs,
                                       output_features={ACTION: PolicyFeature(FeatureType.ACTION, (19,))},
                                       **(small | fields))


def _policy(dataset_root, **fields) -> DiffusionHandRelativePolicy:
    root, episodes = dataset_root
    actions, states = (np.concatenate([episode[i] for episode in episodes]) for i in (0, 1))
    stats = {key: {"min": values.min(axis=0), "max": values.max(axis=0)}
             for key, values in ((ACTION, actions), (OBS_STATE, states))}
    torch.manual_seed(0)
    return DiffusionHandRelativePolicy(_config(**fields), dataset_stats=stats,
                                       dataset_meta=SimpleNamespace(root=root, fps=20))


def _min_max(values, low, high):
    """LeRobot's min/max normalisation to [-1, 1] (a span of 0, as the made-up heads and grippers have, is 1e-8)."""
    span = high - low
    return 2 * (values - low) / torch.where(span == 0, 1e-8, span) - 1


def _batch(policy, seed: int = 1, size: int = 2) -> tuple[dict, torch.Tensor]:
    """A training batch of made-up horizons (actions normalised as the processors do, states raw) and its
    absolute horizons."""
    rng = np.random.default_rng(seed)
    episodes = [made_up_episode(rng, HORIZON) for _ in range(size)]
    absolute = torch.tensor(np.stack([actions for actions, _ in episodes]), dtype=torch.float32)
    states = torch.tensor(np.stack([states[:OBS] for _, states in episodes]), dtype=torch.float32)
    return {IMAGE: torch.rand(size, OBS, 3, 16, 16), OBS_STATE: states,
            ACTION: _min_max(absolute, policy.absolute_min, policy.absolute_max),
            "action_is_pad": torch.zeros(size, HORIZON, dtype=torch.bool)}, absolute


def test_a_horizon_learned_in_the_hand_frame_comes_back_as_the_same_absolute_actions(dataset_root, monkeypatch):
    """Absolute horizon -> the network's target in the hand frame of the current (last observed) raw state -> that
    target as the network's prediction -> the executed absolute actions from the current step on, wherever the hands
    have moved meanwhile; the same from a dataset batch (`predict_action_chunk` offline)."""
    policy = _policy(dataset_root)
    batch, absolute = _batch(policy)
    current = batch[OBS_STATE][:, -1]
    seen = {}
    monkeypatch.setattr(DiffusionModel, "compute_loss", lambda self, batch: seen.update(batch) or torch.zeros(()))
    policy.forward(batch)
    target = seen[ACTION]
    expected = _min_max(to_hand_frame(absolute, current), policy.relative_min, policy.relative_max)
    torch.testing.assert_close(target, expected, atol=1e-5, rtol=0)
    assert target.abs().max() > 0.1 and torch.equal(seen[OBS_STATE], torch.zeros_like(batch[OBS_STATE]))

    monkeypatch.setattr(DiffusionModel, "generate_actions",
                        lambda self, batch, noise=None: target[:, OBS - 1:OBS - 1 + EXECUTED])
    policy.reset()
    steps = [current] + [current + 0.05 * step for step in range(1, EXECUTED)]  # the hands move
    executed = torch.stack([policy.select_action({IMAGE: torch.rand(2, 3, 16, 16), OBS_STATE: state})
                            for state in steps], dim=1)
    policy.reset()
    offline = policy.predict_action_chunk({IMAGE: batch[IMAGE], OBS_STATE: batch[OBS_STATE]})
    torch.testing.assert_close(offline, executed)
    span = policy.absolute_max - policy.absolute_min
    executed = (executed + 1) / 2 * torch.where(span == 0, 1e-8, span) + policy.absolute_min
    wanted = absolute[:, OBS - 1:OBS - 1 + EXECUTED]
    for arm in canonical.ARMS:
        torch.testing.assert_close(executed[..., arm.position], wanted[..., arm.position], atol=1e-5, rtol=0)
        alignment = (executed[..., arm.quaternion] * wanted[..., arm.quaternion]).sum(-1).abs()
        torch.testing.assert_close(alignment, torch.ones_like(alignment), atol=1e-5, rtol=0)
    torch.testing.assert_close(executed[..., 14:], wanted[..., 14:], atol=1e-5, rtol=0)


@pytest.mark.parametrize("state_input", ["invariant", "absolute"])
def test_the_network_sees_the_head_and_grippers_or_the_whole_state_normalised(dataset_root, monkeypatch,
                                                                              state_input):
    policy = _policy(dataset_root, state_input=state_input)
    batch, _ = _batch(policy)
    seen = {}
    monkeypatch.setattr(DiffusionModel, "compute_loss", lambda self, batch: seen.update(batch) or torch.zeros(()))
    policy.forward(batch)
    normalised = _min_max(batch[OBS_STATE], policy.state_min, policy.state_max)
    kept = [*range(14), 17, 18] if state_input == "absolute" else [17, 18]  # head angles: 14-16, constant here
    torch.testing.assert_close(seen[OBS_STATE][..., kept], normalised[..., kept], atol=1e-5, rtol=0)
    if state_input == "invariant":
        assert torch.equal(seen[OBS_STATE][..., :14], torch.zeros(2, OBS, 14))


def test_the_time_input_is_each_observations_time_in_training_and_counted_steps_when_acting(dataset_root,
                                                                                             monkeypatch):
    policy = _policy(dataset_root, time_input=True)
    assert policy.config.input_features[OBS_ENV_STATE] == PolicyFeature(FeatureType.ENV, (1,))
    batch, _ = _batch(policy, size=3)
    loss, _ = policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5, 9.0])})
    assert torch.isfinite(loss)
    seen = []
    monkeypatch.setattr(DiffusionModel, "compute_loss", lambda self, batch: seen.append(batch) or torch.zeros(()))
    policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5, 9.0])})
    # the step before: 1/20 s earlier, held at 0 before the episode began; over TIME_SCALE_S (10 s)
    torch.testing.assert_close(seen[-1][OBS_ENV_STATE], torch.tensor([[[0.0], [0.0]], [[0.145], [0.15]],
                                                                      [[0.895], [0.9]]]))
    monkeypatch.setattr(DiffusionModel, "generate_actions",
                        lambda self, batch, noise=None: seen.append(batch) or torch.zeros(1, EXECUTED, 19))
    seen.clear()
    policy.reset()
    observation = {IMAGE: torch.rand(1, 3, 16, 16), OBS_STATE: batch[OBS_STATE][:1, -1]}
    for _ in range(EXECUTED + 1):
        policy.select_action(observation)
    # chunks planned at steps 0 (the queue filled with that step) and 4, at 20 steps per second
    torch.testing.assert_close(torch.stack([planned[OBS_ENV_STATE].flatten() for planned in seen]),
                               torch.tensor([[0.0, 0.0], [0.015, 0.02]]))


def test_the_prompt_input_follows_the_time_at_every_observation_step(dataset_root, monkeypatch):
    policy = _policy(dataset_root, time_input=True, prompt_input=True, prompts=["Lift the can.", "Lift the box."])
    assert policy.config.input_features[OBS_ENV_STATE] == PolicyFeature(FeatureType.ENV, (3,))
    batch, _ = _batch(policy, size=2)
    seen = []
    monkeypatch.setattr(DiffusionModel, "compute_loss", lambda self, batch: seen.append(batch) or torch.zeros(()))
    policy.forward({**batch, "timestamp": torch.tensor([0.0, 1.5]), "task": ["Lift the box.", "Lift the can."]})
    torch.testing.assert_close(seen[-1][OBS_ENV_STATE], torch.tensor([[[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]],
                                                                      [[0.145, 1.0, 0.0], [0.15, 1.0, 0.0]]]))
    monkeypatch.setattr(DiffusionModel, "generate_actions",
                        lambda self, batch, noise=None: seen.append(batch) or torch.zeros(1, EXECUTED, 19))
    seen.clear()
    policy.reset()
    policy.select_action({IMAGE: torch.rand(1, 3, 16, 16), OBS_STATE: batch[OBS_STATE][:1, -1],
                          "task": ["Lift the box."]})
    torch.testing.assert_close(seen[-1][OBS_ENV_STATE], torch.tensor([[[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]]))


def test_under_amp_the_network_runs_in_bfloat16_whatever_autocast_asked(dataset_root):
    policy = _policy(dataset_root)
    seen = []
    policy.diffusion.unet.final_conv.register_forward_hook(lambda module, inputs, output: seen.append(output.dtype))
    batch, _ = _batch(policy)
    with torch.autocast("cpu", dtype=torch.float16):  # as lerobot-train / lerobot-eval
        loss, _ = policy.forward(batch)
        policy.reset()
        action = policy.select_action({IMAGE: batch[IMAGE][:, -1], OBS_STATE: batch[OBS_STATE][:, -1]})
    assert set(seen) == {torch.bfloat16} and torch.isfinite(loss) and action.dtype == torch.float32


@pytest.mark.parametrize(("fields", "refused"), [
    ({"inputs": {IMAGE: PolicyFeature(FeatureType.VISUAL, (3, 16, 16))}},
     "anchors its chunks on TAVIS's 19-D observation.state, which policy.input_features must hold; got None"),
    ({"normalization_mapping": {"VISUAL": NormalizationMode.MEAN_STD, "STATE": NormalizationMode.MIN_MAX,
                                "ACTION": NormalizationMode.MIN_MAX}},
     "normalization_mapping.STATE must be IDENTITY"),
    ({"normalization_mapping": {"VISUAL": NormalizationMode.MEAN_STD, "STATE": NormalizationMode.IDENTITY,
                                "ACTION": NormalizationMode.QUANTILES}},
     "with MEAN_STD or MIN_MAX; normalization_mapping.ACTION is QUANTILES"),
    ({"state_input": "hands"}, "state_input must be one of none, invariant, absolute; got 'hands'"),
])
def test_a_config_it_cannot_anchor_or_normalise_is_refused(fields, refused):
    with pytest.raises(ValueError, match=refused):
        _config(**fields).validate_features()


def test_without_the_dataset_statistics_it_refuses_to_act():
    policy = DiffusionHandRelativePolicy(_config())
    with pytest.raises(RuntimeError, match="diffusion_hand_relative has no absolute_min"):
        policy.select_action({IMAGE: torch.rand(1, 3, 16, 16), OBS_STATE: torch.zeros(1, 19)})


def test_a_checkpoint_keeps_the_statistics_and_lerobot_finds_the_policy_and_its_processors(dataset_root, tmp_path):
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.policies.factory import get_policy_class, make_pre_post_processors

    policy = _policy(dataset_root, state_input="invariant", time_input=True)
    policy.save_pretrained(tmp_path)
    register_policy_types()
    config = PreTrainedConfig.from_pretrained(tmp_path)
    assert type(config) is DiffusionHandRelativeConfig and get_policy_class(config.type) is DiffusionHandRelativePolicy
    assert (config.state_input, config.time_input) == ("invariant", True)
    loaded = DiffusionHandRelativePolicy.from_pretrained(tmp_path, config=config)
    for buffer in STATISTICS:
        assert torch.isfinite(getattr(policy, buffer)).all()
        torch.testing.assert_close(getattr(loaded, buffer), getattr(policy, buffer))
    stats = {ACTION: {"min": policy.absolute_min.numpy(), "max": policy.absolute_max.numpy()},
             OBS_STATE: {"min": policy.state_min.numpy(), "max": policy.state_max.numpy()}}
    preprocessor, postprocessor = make_pre_post_processors(config, dataset_stats=stats)
    raw_state = torch.rand(1, 19)
    processed = preprocessor({IMAGE: torch.rand(1, 3, 16, 16), OBS_STATE: raw_state})
    torch.testing.assert_close(processed[OBS_STATE], raw_state)  # the anchor reaches the policy un-normalised
    torch.testing.assert_close(postprocessor(torch.zeros(1, 19)),
                               ((policy.absolute_min + policy.absolute_max) / 2).unsqueeze(0))


def test_horizons_planned_on_recorded_states_land_on_the_recorded_actions_when_anchored_on_the_env(demonstration,
                                                                                                   tmp_path,
                                                                                                   monkeypatch):
    """The anchor a policy learns on (the dataset's current observation.state) is the one it acts on (the env's
    agent_pos, which the checkpoint's processors leave raw), and the executed actions are the horizon's from the
    current step on: an oracle network that plans every horizon from the recorded actions and states, executed by a
    checkpoint in `PolicyDriver`, repeats the demonstration."""
    from lerobot.policies.factory import make_pre_post_processors

    actions, states = demonstration.actions, demonstration.states
    stats = {key: {"min": values.min(0).values.numpy(), "max": values.max(0).values.numpy()}
             for key, values in ((ACTION, actions), (OBS_STATE, states))}
    stats[IMAGE] = {"mean": np.full((3, 1, 1), 0.5), "std": np.full((3, 1, 1), 0.25)}
    horizon, executed = 16, 8
    policy = DiffusionHandRelativePolicy(
        _config(horizon=horizon, n_action_steps=executed, inputs={
            IMAGE: PolicyFeature(FeatureType.VISUAL, (3, 32, 32)), OBS_STATE: PolicyFeature(FeatureType.STATE, (19,))}),
        dataset_stats=stats, dataset_meta=SimpleNamespace(root=demonstration.root, fps=20))
    policy.save_pretrained(tmp_path / "checkpoint")
    for pipeline in make_pre_post_processors(policy.config, dataset_stats=stats):
        pipeline.save_pretrained(tmp_path / "checkpoint")

    def oracle(self, batch, noise=None):  # the horizon the demonstrator executed, from the step before this one
        start = len(planned) * executed
        planned.append(start)
        indices = torch.clamp(torch.arange(start - (OBS - 1), start - (OBS - 1) + horizon), 0, len(actions) - 1)
        relative = to_hand_frame(actions[indices].unsqueeze(0), states[start].unsqueeze(0))
        return _min_max(relative, policy.relative_min, policy.relative_max)[:, OBS - 1:OBS - 1 + executed]

    planned = []
    monkeypatch.setattr(DiffusionModel, "generate_actions", oracle)
    success, error_m = replay(tmp_path / "checkpoint", demonstration)
    assert success and error_m < 0.015, (success, error_m)  # verify-dataset's replay tolerance
