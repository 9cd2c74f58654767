"""Is a state stable: the second variation's axisymmetric and m ≥ 1 blocks, a brute-force second method for m = 1, and the eigenvalue crossings followed along a branch with the degree each needs."""
