"""Packed layout of the disturbance tables read by compiled code.

``rows`` is a ``float64`` array of shape ``(n_components, ROW_SIZE)``, one row per component in
list order; column 0 holds the kind code, the rest the parameters:

=======  ====  ============================================================
kind     code  columns 1..7
=======  ====  ============================================================
paper    1     amplitude (-), phase (rad), 0 ...
pulse    2     start (s), end = start + duration (s, may be inf), force (5)
current  3     offset (first row in ``current``), n samples, sample_dt (s), 0 ...
=======  ====  ============================================================

``current`` is a ``float64`` array of shape ``(n_samples_total, CUR_COLS)`` with columns
``t (s), Vx, Vy, Vz (m/s, NED)``: the Gauss-Markov samples of every current component stacked
one after the other.  With no current it is a single zero row of shape ``(1, 4)`` so that the
compiled evaluator always sees the same array types.  A row with an unknown code makes the
evaluator write NaN (the engine then stops on a non-finite state).
"""
ROW_SIZE = 8
CUR_COLS = 4
KIND_PAPER, KIND_PULSE, KIND_CURRENT = 1.0, 2.0, 3.0
# paper
P_AMP, P_PHASE = 1, 2
# pulse
U_START, U_END, U_FORCE = 1, 2, 3
# current
C_OFFSET, C_N, C_DT = 1, 2, 3
