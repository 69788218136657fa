"""Layout of the packed 5-DOF vehicle-parameter vector ``vp`` read by compiled code.

====  ========  ===========================================  ======
index field     meaning                                      unit
====  ========  ===========================================  ======
0-4   m         diagonal inertia m11, m22, m33, m44, m55     kg, kg, kg, kg m^2, kg m^2
5-9   d         linear damping d11, d22, d33, d44, d55       N s/m (0-2), N m s/rad (3-4)
10    wgml      restoring coefficient rho*g*nabla*GM_L       N m
11    ell       virtual-point offset l (eq. 2)               m
12    cscale    Coriolis scale: C = cscale * C0(nu)          -
====  ========  ===========================================  ======

The nominal model seen by controllers has ``cscale = 1``; the true plant carries the
uncertainty (e.g. Delta C = 10 % C0 gives ``cscale = 1.1``).  Compiled code indexes with
:data:`VP` (``vp[VP.m + 3]`` is m44).
"""
from ..packing import packed_layout

VP = packed_layout("Vehicle5", m=5, d=5, wgml=1, ell=1, cscale=1)
"""Offsets of the fields of ``vp`` (``VP.size`` = 13)."""
