import numpy as np
import pytest

from lerobot_tavis import canonical


def test_layout_matches_the_reference():
    assert len(canonical.ACTION_NAMES) == canonical.ACTION_DIM == 19
    assert canonical.ACTION_NAMES[14:17] == ("head_roll", "head_pitch", "head_yaw")
    assert (canonical.LEFT.gripper, canonical.RIGHT.gripper) == (17, 18)
    assert canonical.ACTION_NAMES[canonical.RIGHT.position.start] == "right_ee_x"
    assert canonical.ACTION_NAMES[canonical.RIGHT.quaternion.start] == "right_ee_qw"


def test_rest_action():
    rest = canonical.rest_action()
    np.testing.assert_allclose(rest[0:3], (0.3, 0.2, 0.3))
    np.testing.assert_allclose(rest[7:10], (0.3, -0.2, 0.3))
    np.testing.assert_allclose(rest[14:17], 0.0)
    np.testing.assert_allclose(rest[17:], -1.0)
    for arm in canonical.ARMS:
        assert np.linalg.norm(rest[arm.quaternion]) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("shape", [(18,), (20,), (1, 19), ()])
def test_wrong_shape_is_rejected(shape):
    with pytest.raises(ValueError, match=r"shape \(19,\)"):
        canonical.validate_action(np.zeros(shape))


@pytest.mark.parametrize("index,value", [(0, np.nan), (5, np.inf), (16, -np.inf), (18, np.nan)])
def test_non_finite_value_is_rejected_with_its_index(index, value):
    action = canonical.rest_action()
    action[index] = value
    with pytest.raises(ValueError, match=rf"action\[{index}\] \({canonical.ACTION_NAMES[index]}\)"):
        canonical.validate_action(action)


def test_zero_quaternion_is_rejected():
    action = canonical.rest_action()
    action[10:14] = 0.0
    with pytest.raises(ValueError, match=r"action\[10:14\] \(right"):
        canonical.validate_action(action)
