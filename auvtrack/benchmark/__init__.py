"""The controller benchmark (``auvtrack compare``): suites, execution, statistics, leaderboard and report."""
