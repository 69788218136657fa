"""Layout of the packed vehicle-parameter vector used by compiled kernels.

A vehicle is passed to compiled code as one ``float64`` array ``vp`` of length ``VP_SIZE``:

====  ==========  ===========================================  ======
index  name        meaning                                      unit
====  ==========  ===========================================  ======
0-4    m           diagonal inertia m11, m22, m33, m44, m55     kg, kg, kg, kg m^2, kg m^2
5-9    d           linear damping d11, d22, d33, d44, d55       N s/m (0-2), N m s/rad (3-4)
10     wgml        restoring coefficient rho*g*nabla*GM_L       N m
11     l           virtual-point offset ell (eq. 2)             m
12     c_scale     Coriolis scale: C = c_scale * C0(nu)         -
====  ==========  ===========================================  ======

The nominal model seen by controllers has ``c_scale = 1``; the true plant carries the
uncertainty (e.g. Delta C = 10 % C0 gives ``c_scale = 1.1``).
"""
M0, D0, WGML, ELL, CSCALE = 0, 5, 10, 11, 12
VP_SIZE = 13
