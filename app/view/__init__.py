"""3D view: the scene's datasets and actors, layers, level of detail, framing, highlights,
the current layer, the hover readout, measuring.
"""
