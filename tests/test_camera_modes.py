"""The paper's two camera conditions are the defaults; the old one-camera names still work, with a warning."""

import pytest

from lerobot_tavis.envs.env import TavisEnv
from lerobot_tavis.envs.modes import CAMERA_MODES, PAPER_CONDITIONS, resolve_camera_mode
from lerobot_tavis.eval.env_config import TavisEnvConfig
from lerobot_tavis.eval.protocol import ENV_DEFAULTS, ProtocolConfig
from lerobot_tavis.policy_configs import preset_path

PAPER_HEADCAM = ("head", "left_wrist", "right_wrist")


def test_the_paper_conditions_are_head_or_fixed_camera_plus_both_wrists():
    assert CAMERA_MODES[PAPER_CONDITIONS["headcam"]] == PAPER_HEADCAM
    assert CAMERA_MODES[PAPER_CONDITIONS["fixedcam"]] == ("fixed", "left_wrist", "right_wrist")


def test_every_entry_point_defaults_to_the_papers_headcam_condition(tmp_path):
    assert TavisEnv().camera_names == PAPER_HEADCAM
    config = TavisEnvConfig()
    assert config.camera_mode == "head_wrist"
    assert sorted(k for k in config.features if k.startswith("pixels/")) == sorted(f"pixels/{c}" for c in PAPER_HEADCAM)
    assert ProtocolConfig(out_dir=tmp_path, expert=True).camera_mode == "head_wrist"
    assert ENV_DEFAULTS["camera_mode"] == "head_wrist"  # tavis eval, when the checkpoint does not say otherwise


@pytest.mark.parametrize("old,new,cameras", [("headcam", "head_only", ("head",)),
                                             ("fixedcam", "fixed_only", ("fixed",))])
def test_old_names_keep_their_meaning_with_a_deprecation_warning(old, new, cameras, tmp_path):
    message = f"camera mode '{old}' is now called '{new}' .* the paper's {old} condition is"
    with pytest.warns(FutureWarning, match=message):
        assert resolve_camera_mode(old) == new
    with pytest.warns(FutureWarning, match=message):
        assert TavisEnv(camera_mode=old).camera_names == cameras
    with pytest.warns(FutureWarning, match=message):
        assert TavisEnvConfig(camera_mode=old).camera_mode == new
    with pytest.warns(FutureWarning, match=message):
        assert ProtocolConfig(out_dir=tmp_path, expert=True, camera_mode=old).camera_mode == new
    with pytest.warns(FutureWarning, match=message):
        assert preset_path(f"diffusion_{old}").name == f"diffusion_{new}.json"


def test_an_unknown_mode_names_the_valid_ones():
    with pytest.raises(ValueError, match=r"camera_mode must be one of \['head_wrist', 'fixed_wrist', 'head_only'"):
        TavisEnvConfig(camera_mode="stereo")
