"""Numbers shared by the engine and every plant module (kept apart to avoid import cycles).

A plant's ``attitude_cause(x, sf)`` reads its limits from the engine's float settings ``sf`` at
these indices and returns one of these causes (0 = none).  The whole contract is in
``docs/architecture.md`` ("The plant contract").
"""
SF_THETA_LIM = 1  # |pitch| limit, rad
SF_PHI_LIM = 5  # |roll| limit, rad (6-DOF plants)
CAUSE_PITCH = 2
CAUSE_ROLL = 5
SCRATCH_SIZE = 16  # length of the scratch array ``scr`` kept between a plant's rhs calls
