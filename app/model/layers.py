"""What the 3D view can show: layer names, their titles and defaults, face colourings.

Plain data (no Qt, no VTK) that the model keeps and the scene (pyvista) and the panels (Qt) read.
"""

#: Layer names, in drawing order (bottom to top) and in the order the Layers panel lists them.
LAYERS = (
    "faces",
    "triangle_edges",
    "patch_outlines",
    "shared_edges",
    "boundary_edges",
    "junction_edges",
    "centroids",
    "labels",
)
LAYER_TITLES = {
    "faces": "Triangles (faces)",
    "triangle_edges": "Triangle edges",
    "patch_outlines": "Patch outlines",
    "shared_edges": "Shared (interior) edges",
    "boundary_edges": "Boundary edges",
    "junction_edges": "Junction edges",
    "centroids": "Centroids",
    "labels": "Triangle index labels",
}
DEFAULT_VISIBLE = {
    "faces": True,
    "triangle_edges": True,
    "patch_outlines": False,
    "shared_edges": True,
    "boundary_edges": True,
    "junction_edges": True,
    "centroids": True,
    "labels": True,
}

#: Face colourings: key -> (cell array, colour bar title). ``None``: one solid colour.
COLOR_BY = {
    "none": (None, ""),
    "patch": ("patch", "patch"),
    "region": ("region", "region"),
    "area": ("area", "area (mm²)"),
    "min_angle": ("min_angle", "min angle (°)"),
    "aspect_ratio": ("aspect_ratio", "aspect ratio"),
    "overlap": ("overlap", "patches over\neach point"),
}
COLOR_BY_TITLES = {
    "none": "Solid",
    "patch": "Patch",
    "region": "Region (ring)",
    "area": "Area",
    "min_angle": "Minimum angle",
    "aspect_ratio": "Aspect ratio",
    "overlap": "Patches over each point",
}
#: Level of detail: "auto" leaves out triangle edges, shared edges and centroids when
#: triangles are a few pixels on screen and draws dense meshes as an image; "full" draws
#: every triangle, edge and centroid at any zoom (the scene warns above 1M triangles).
DETAIL_MODES = {"auto": "Automatic", "full": "Always full"}
#: Triangle index labels are drawn for meshes up to this many triangles (paper's Fig. 10).
LABEL_LIMIT = 300
