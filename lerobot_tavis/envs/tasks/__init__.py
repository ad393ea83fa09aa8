"""The tasks: one module each, metadata in `catalog` (no MuJoCo), classes by name in `registry`."""
