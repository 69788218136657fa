"""Speed benchmarks of the compiled closed loop (``auvtrack bench``): reported figures; nothing depends on this package."""
