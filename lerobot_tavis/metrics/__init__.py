"""Benchmark metrics: success statistics and GALT. Numpy only."""
