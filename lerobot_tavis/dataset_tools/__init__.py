"""Demonstration datasets: record raw episodes, convert to LeRobotDataset v3.0, push to and pull from the Hub, and
write copies with noisy hand poses in the state for training experiments (`state_noise`)."""
