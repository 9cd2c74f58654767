"""The tube over (S, φ): a cylinder's deformed surface in Legendre(S) × Fourier(φ), the sibling of the sphere's
surface/ (docs/tubes.md "The tube over (S, φ)"), a case of the engine over any meridian (analysis/surface/meridian/).
In reading order:

- ``basis``: the unknowns per azimuthal order (the interval basis of galerkin/interval.py at m = 0, the m ≥ 1
  blocks' (R, T, Z) of tube/azimuthal.py above it) and their node maps on Gauss(S) × uniform(φ)
- ``switching``: one point of the branch born at a located m ≥ 1 zero along its critical mode
- ``resolution``: a state's error estimate and the refinement of the basis along the branch
- ``branch``: that branch traced in P from the switched point (``[surface] branches``)
"""
