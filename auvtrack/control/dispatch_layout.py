"""Sizes shared by the engine and the compiled controllers (kept apart to avoid import cycles)."""
NX_PLANT = 10  # plant states [eta (5), nu (5)]; a controller's internal state follows in X
WORK_SIZE = 512  # length of the scratch array the engine hands to a controller
