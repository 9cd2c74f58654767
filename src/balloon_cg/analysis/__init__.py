"""Branches and what is read off them: tracing with adaptive resolution, stability, bifurcations, codim 2."""
