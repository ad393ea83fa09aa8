"""`python -m lerobot_tavis.policy_configs`: rewrite the preset JSON files from `build_preset`."""

from lerobot_tavis.policy_configs import write_presets

for path in write_presets():
    print(path)
