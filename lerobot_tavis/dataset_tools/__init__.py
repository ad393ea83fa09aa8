"""Demonstration datasets: record raw episodes, convert to LeRobotDataset v3.0, push to and pull from the Hub."""
