"""Linear viscoelastic contact along the normal only: N n with N = k_n delta - gamma_n u_n (not conservative on a curved plate).

The force as the product computed it before the conservative contact became the default,
kept to reproduce earlier results.  On a curved plate in fixed axes the elastic force
k_n delta n, with delta measured to the tangent line, is not the gradient of any
potential: its curl is -2 k_n delta sin a da/dx, and it pumps energy into a block held on
a flank (docs/physics.md, Sec. 9).  On a flat plate and in the tangent frame it is the
same law as ``linear``.
"""
from numba import njit

from . import contact_linear

ID = 1
LINEAR = True  # linear in (delta, u_n): event_driven's closed-form flows run it
CONSERVATIVE = False  # no curvature term: the force stays along the normal

force = contact_linear.force
elastic = contact_linear.elastic
dissipation = contact_linear.dissipation
potential = contact_linear.potential  # the energy the balance books (its defect shows in the residual)
rest = contact_linear.rest
