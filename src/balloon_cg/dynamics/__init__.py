"""The dynamics layer: natural frequencies of small oscillations about the equilibria of a branch (MODEL.md §11)."""
