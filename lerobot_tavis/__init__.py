"""TAVIS benchmark in MuJoCo."""
