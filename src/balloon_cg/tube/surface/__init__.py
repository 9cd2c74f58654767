"""The tube over (S, φ): a cylinder's deformed surface in Legendre(S) × Fourier(φ), the sibling of the sphere's
surface/ (docs/tubes.md "The tube over (S, φ)"). In reading order:

- ``meridian``: the engine over any reference meridian R(t), Z(t) (node variables, area weight, assembly), of which
  ``basis`` (the tube: R = 1) and ``capsule`` (the capsule over θ, its poles included, and its switched point) are
  cases
- ``basis``: the unknowns per azimuthal order (the interval basis of galerkin/interval.py at m = 0, the m ≥ 1
  blocks' (R, T, Z) of tube/azimuthal.py above it) and their node maps on Gauss(S) × uniform(φ)
- ``volume``: the enclosed volume between the end planes, ½ x_h · (x_S × x_φ), and its node derivatives
- ``equilibrium``: E/(2π), its gradient (the residual) and Hessian (the exact Jacobian) in the coefficients
- ``system``: the gauged equations R(X) = 0 of a branch in P, X = (c, τ, P), and their exact Jacobian
- ``switching``: one point of the branch born at a located m ≥ 1 zero along its critical mode
- ``stability``: the lowest eigenvalues and unstable counts of a state's mirror sector (pressure, volume, gas)
- ``resolution``: a state's error estimate and the refinement of the basis along the branch
- ``branch``: that branch traced in P from the switched point (``[surface] branches``)
"""
