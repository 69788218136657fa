"""A small benchmark suite for the tests of ``auvtrack compare``: two tasks, two tiers, 1 s quick runs."""

TINY = """
name = "tiny"
version = 1
seed = 5
seeds = 3
bootstrap_resamples = 200
[base]
"vehicle.preset" = "remus100"
"sim.dt" = 0.002
"disturbance" = []
[quick]
seeds = 2
duration = 1.0
[tasks.helix]
duration = 3.0
reference = { kind = "helix", radius = 10.0, omega = 0.1, climb = -0.25, center = [0.0, 0.0, 20.0] }
[tasks.line]
duration = 2.0
reference = { kind = "line", start = [0.0, 0.0, 5.0], velocity = [1.0, 0.0, 0.0] }
[tiers.calm]
start = { lateral = 0.3 }
[tiers.model]
start = { lateral = 1.0, heading = 0.2 }
[tiers.model.random]
"uncertainty.M" = { dist = "uniform", low = -0.2, high = 0.2 }
"""
