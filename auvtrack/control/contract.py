"""The controller contract: what a compiled law receives and returns (shared by every controller).

Every controller's compiled law has the signature

    control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work) -> int status

=======  ==============================================================================
t        time (s)
eta, nu  measured state, 5-tuples (x, y, z, theta, psi) (m, rad) and (u, v, w, q, r) (m/s,
         rad/s) (see :mod:`auvtrack.vehicle.kinematics`); with a 6-DOF plant the projection of
         its state (roll neither measured nor controlled)
att      attitude(eta[3], eta[4]) = (cos theta, sin theta, cos psi, sin psi) of the measured
         state, computed by the engine (in continuous mode the 5-DOF plant shares it)
xc       the controller's own internal state (its ``xc0`` evolved), read only
refm     (3, 3) rows eta_d, eta_d_dot, eta_d_ddot of the virtual point's reference
vp       packed *nominal* 5-DOF vehicle (the controller never sees the true plant)
cp       packed controller parameters
tau      output (3,): commanded [tau_u (N), tau_q (N m), tau_r (N m)]
dxc      output: d/dt of xc
aux      output: extra logged channels (the controller's ``AUX_NAMES``)
work     scratch (float64, length WORK_SIZE) for variable-size temporaries
status   0 = ok, otherwise a code of :data:`CONTROLLER_STATUS` or of the controller's ``STATUS``
=======  ==============================================================================

The engine calls the law at every RK4 stage (continuous mode) or once per control sample
(sampled-data mode, its tau and dxc then held).  Arrays are passed whole and indexed: slicing in
the hot path creates reference-counted views that cost more than the arithmetic.
"""
WORK_SIZE = 512  # length of the scratch array the engine hands to a controller

CONTROLLER_STATUS = {
    1: "envelope violated: |e_i| >= rho_i (the error transformation is undefined)",
    2: "start on or outside the envelope and widen_start is off",
    3: "controller produced a non-finite input",
}
"""Status codes shared by every controller (1-9 are reserved for these)."""
