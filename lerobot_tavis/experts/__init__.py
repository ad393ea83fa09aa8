"""Scripted demonstrators: they act only through the canonical 19-D action."""
