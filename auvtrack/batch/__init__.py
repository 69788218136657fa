"""Machinery that runs many simulations: the batch runner, Dask sweeps and the benchmark harness.

The science (reproduce, ablation, fixed-time, realism, robustness, tuning) lives in
:mod:`auvtrack.studies` and uses these.
"""
