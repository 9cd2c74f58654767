"""The discrete problem: Legendre (optionally wire-mapped) basis, quadrature, Ritz residual and Hessian."""
