"""barymesh application layer: the command line (``barymesh.app.cli``) and the desktop window."""
