"""barymesh application layer: the command line (``app.cli``) and the desktop window."""
