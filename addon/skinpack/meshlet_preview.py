"""Meshlet preview: colours the faces of a skinned mesh by the meshlet the library puts them in.

The mesh's loop triangles (Blender's own triangulation, what the glTF exporter writes) and the
deform weights (gather.py, prepared to K influences by the library) go to sp_build_meshlets
(docs/meshlets.md); the library's per-triangle meshlet ids (`triangle_meshlet`) come back and
are mapped to colours. MESHLET mode gives every meshlet its own colour, JOINTS mode colours a
meshlet by the number of joints in its palette on the heat-map ramp, from 0 to the palette
limit. All meshlet numbers shown are the library's sp_meshlet_stats.

Colours are per face: a face corner colour attribute (Workbench colours by POINT or CORNER
attributes, and the error heat map is one too) with the same colour on every corner of a face.
An n-gon is split into several triangles that may land in different meshlets; the face then
shows the meshlet of its first triangle, so on meshes with quads a meshlet whose triangles
are all second halves of quads is not visible. On a triangulated mesh the preview is exact.
"""

import numpy as np

from . import gather, preview
from .io import native, storage

BUILDERS = {'NAIVE': "naive", 'COMMON': "common", 'SKIN': "skin"}

# Colour levels per channel of the meshlet palette, from dark to light (linear RGB).
LEVEL_LOW, LEVEL_HIGH = 0.05, 0.95


class MeshletInputs:
    """What sp_build_meshlets takes, read from a mesh object."""

    def __init__(self, indices, positions, joints, weights, triangle_polygons, polygon_count):
        self.indices = indices  # (T, 3) uint32: vertices of each loop triangle
        self.positions = positions  # (V, 3) float32: bind-pose (base mesh) positions
        self.joints = joints  # (V, K) uint16, prepared by the library
        self.weights = weights  # (V, K) float32
        self.triangle_polygons = triangle_polygons  # (T,) int64: face of each loop triangle
        self.polygon_count = polygon_count


def loop_triangles(mesh):
    """(indices (T, 3) uint32, face of each triangle (T,) int64) of Blender's triangulation."""
    mesh.calc_loop_triangles()
    count = len(mesh.loop_triangles)
    indices = np.empty(count * 3, dtype=np.uint32)
    mesh.loop_triangles.foreach_get("vertices", indices)
    polygons = np.empty(count, dtype=np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", polygons)
    return indices.reshape(-1, 3), polygons.astype(np.int64)


def read_inputs(obj, max_influences):
    """Triangles, positions and prepared influences of obj's base mesh (the bind pose the
    weights belong to). Raises gather.GatherError or native.SkinpackError with the object's name."""
    skin = gather.gather(obj)
    mesh = obj.data
    if len(mesh.polygons) == 0:
        raise gather.GatherError("%s has no faces to split into meshlets" % obj.name)
    indices, triangle_polygons = loop_triangles(mesh)
    positions = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", positions)
    try:
        joints, weights = native.prepare_influences(skin.joints, skin.weights, len(skin.joint_names), max_influences)
    except native.SkinpackError as error:
        raise native.SkinpackError("%s: %s (vertex %d)" % (obj.name, error, error.vertex), error.code, error.vertex)
    return MeshletInputs(indices, positions.reshape(-1, 3), joints, weights, triangle_polygons, len(mesh.polygons))


def build(obj, inputs, options):
    """sp_build_meshlets on the inputs; a failure names the object, the triangle and its face."""
    try:
        return native.build_meshlets(inputs.indices, inputs.positions, inputs.joints, inputs.weights, options)
    except native.MeshletError as error:
        if error.code == native.SP_ERR_LIMIT_EXCEEDED and error.triangle is not None:
            raise native.MeshletError(
                "%s: triangle %d (face %d) uses more joints than the palette size %d; raise the palette "
                "size (a triangle needs at most %d)" % (obj.name, error.triangle,
                                                       inputs.triangle_polygons[error.triangle], options.max_joints,
                                                       3 * inputs.joints.shape[1]),
                error.code, error.triangle)
        raise native.MeshletError("%s: building meshlets failed: %s" % (obj.name, error), error.code, error.triangle)


def meshlet_colors(count):
    """(count, 4) float32 colours, pairwise distinct by construction: colour i is a cell of an
    n x n x n grid of RGB levels, cells taken through a permutation of i. Grey cells (equal
    levels) are left out, as they read as an unpainted mesh; the permutation (a multiplier
    coprime to the cell count) keeps consecutive meshlets, which are usually neighbours, from
    getting similar colours."""
    levels = 2
    while levels ** 3 - levels < count:
        levels += 1
    cells = np.arange(levels ** 3, dtype=np.int64)
    digits = np.stack([cells // (levels * levels), (cells // levels) % levels, cells % levels], axis=1)
    digits = digits[~((digits[:, 0] == digits[:, 1]) & (digits[:, 1] == digits[:, 2]))]
    multiplier = next(m for m in range(len(digits) // 2 + 1, 2 * len(digits) + 2) if np.gcd(m, len(digits)) == 1)
    chosen = digits[(np.arange(count, dtype=np.int64) * multiplier) % len(digits)]
    rgb = LEVEL_LOW + (LEVEL_HIGH - LEVEL_LOW) * chosen.astype(np.float32) / (levels - 1)
    return np.concatenate([rgb, np.ones((count, 1), dtype=np.float32)], axis=1).astype(np.float32)


def polygon_meshlets(inputs, triangle_meshlet):
    """Meshlet shown by each face: the meshlet of the face's first loop triangle."""
    result = np.zeros(inputs.polygon_count, dtype=np.int64)
    polygons, first_triangles = np.unique(inputs.triangle_polygons, return_index=True)
    result[polygons] = triangle_meshlet[first_triangles]
    return result


def corner_colors(mesh, polygon_colors):
    """(loop count, 4): every corner of a face gets the face's colour."""
    totals = np.empty(len(mesh.polygons), dtype=np.int32)
    starts = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", totals)
    mesh.polygons.foreach_get("loop_start", starts)
    loop_polygons = np.empty(len(mesh.loops), dtype=np.int64)
    first_of_run = np.repeat(np.cumsum(totals) - totals, totals)
    loop_polygons[np.repeat(starts, totals) + np.arange(totals.sum()) - first_of_run] = \
        np.repeat(np.arange(len(totals)), totals)
    return polygon_colors[loop_polygons]


def write(obj, mode, inputs, meshlets, palette_size):
    """Colours obj's faces by meshlet (MESHLET) or by joints per meshlet (JOINTS) and stores the
    mode and legend with the mesh (preview.PREVIEW_KEY)."""
    if mode == 'MESHLET':
        colors = meshlet_colors(len(meshlets.meshlets))
    else:
        joint_counts = meshlets.meshlets["joint_count"].astype(np.float32)
        colors = preview.heat_colors(joint_counts, float(palette_size))
    shown = polygon_meshlets(inputs, meshlets.triangle_meshlet)
    mesh = obj.data
    preview.write_color_attribute(mesh, preview.MESHLET_ATTRIBUTE_NAME, 'CORNER', corner_colors(mesh, colors[shown]))
    preview.remember_preview(mesh, {"mode": mode, "scale": float(palette_size)})


def shown_mode(mesh):
    """'MESHLET' or 'JOINTS' while the meshlet preview is on the mesh, else None."""
    info = mesh.get(storage.PREVIEW_KEY) if mesh is not None else None
    if info is None or mesh.color_attributes.get(preview.MESHLET_ATTRIBUTE_NAME) is None:
        return None
    return info.get("mode")


def store_stats(obj, stats, builder, mode):
    """Copies the library's stats into the object's PropertyGroup (properties.py) for the panel."""
    values = native.meshlet_stats_dict(stats)
    panel_stats = obj.skinpack_meshlets
    for key in ("meshlet_count", "mean_vertices", "mean_triangles", "mean_joints", "max_joints",
                "global_tuple_bits", "local_tuple_bits_mean", "local_tuple_bits_max"):
        setattr(panel_stats, key, values[key])
    panel_stats.shown_builder = builder
    panel_stats.shown_mode = mode
    panel_stats.valid = True
    return values
