"""Training and validation splits and a run score for the tiny suite (tests/tiny_suite.py)."""

SPLITS = ("[splits.training]\nseeds = [10, 12]\ntasks = [\"line\"]\n"
          "[splits.validation]\nseeds = [20, 21]\ntasks = [\"line\"]\n"
          "[run_score.weights]\nrmse = 1.0\nenergy = 0.1\n[run_score.scales]\nrmse = 0.5\nenergy = 100.0\n")
