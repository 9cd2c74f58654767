"""Balloon-free numerics: Newton with a bordering row, pseudo-arclength continuation, fold location."""
