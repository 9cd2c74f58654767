"""The scene files, shipped as balloon_cg.scenes (package data: ``importlib.resources.files("balloon_cg.scenes")``).

This folder is the only copy; pyproject.toml maps it into the package (package-dir), for regular and editable
installs alike. The default run (``make run``) uses spom1.toml and spom1_two_coils_M0.002.toml.
"""
