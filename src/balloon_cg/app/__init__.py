"""Applications: the command line, the sweep runner, the default run."""
