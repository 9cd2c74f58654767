"""A surface of revolution over (t, φ): the non-axisymmetric states and branches of any reference meridian R(t), Z(t)
(docs/tubes.md "The engine over any meridian"). Here, in analysis/surface/ below tube/, so that a capsule's picture
(analysis/picture.py) and a tube's (tube/picture.py) both use it. In reading order:

- ``basis``: the engine (node variables, area weight, assembly) of which a tube (tube/surface/basis.py: R = 1) and
  ``capsule`` are cases
- ``volume``: the enclosed volume, ½ x_h · (x_S × x_φ), and its node derivatives
- ``equilibrium``: E/(2π), its gradient (the residual) and Hessian (the exact Jacobian) in the coefficients
- ``system``: the gauged equations R(X) = 0 of a branch in P, X = (c, τ, P), and their exact Jacobian
- ``switching``: the point of amplitude ε along a located zero's critical mode
- ``stability``: the lowest eigenvalues and unstable counts of a state's mirror sector (pressure, volume, gas)
- ``trace``: the branch traced in P from its switched point, refined by its shape's resolution policy
- ``capsule``: the capsule over (θ, φ), its poles included: its basis, switched point and traced branch;
  ``capsule_resolution``: its error estimate and refinement
- ``rotation``: a branch's −φ half, its image under the rotation by π/m about the axis
"""
