"""barymesh desktop program and command line (Qt, pyvista); the mesher itself is in core."""
