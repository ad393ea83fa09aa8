"""Evaluation: the per-episode log, the report, and the 96-episode protocol runner."""
