"""The documentation pages (Markdown), installed with the package as balloon_cg.docs so that the CLI's help can
name them (``balloon-cg --help`` prints where they are)."""
