"""balloon-cg: nonlinear mechanics of inflatable magnetoelastic membranes."""
__version__ = "0.1.0"
