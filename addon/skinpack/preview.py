"""Error heat map: a colour attribute coloured from per-vertex errors the library reports.

The colour-attribute, viewport and clear helpers here are shared with the meshlet preview
(meshlet_preview.py).

WEIGHT mode shows the library's per-vertex quantisation error (L-inf over the vertex's
weights, `per_vertex_error` of sp_compress_skin) as stored with the result. POSE mode shows
how far each vertex moves in the current pose when it is skinned with the decoded instead of
the original weights: Blender's own depsgraph evaluates the object twice (weights swapped in
and restored bit-exactly), so the skinning is exactly the one the artist sees.
"""

import numpy as np

from . import gather
from .io import storage

ATTRIBUTE_NAME = "skinpack_error"
MESHLET_ATTRIBUTE_NAME = "skinpack_meshlets"  # written by meshlet_preview.py
# Every colour attribute a preview writes: one preview is shown at a time, Clear removes them
# all and the glTF export hook keeps them out of COLOR_0.
ATTRIBUTE_NAMES = (ATTRIBUTE_NAME, MESHLET_ATTRIBUTE_NAME)

# Colour ramp of the heat map (linear RGBA), from no error to the legend's maximum.
RAMP = (
    (0.02, 0.05, 0.60, 1.0),  # dark blue
    (0.00, 0.55, 0.85, 1.0),  # cyan
    (0.10, 0.75, 0.10, 1.0),  # green
    (0.95, 0.80, 0.00, 1.0),  # yellow
    (0.90, 0.05, 0.02, 1.0),  # red
)

MODE_LABELS = {'WEIGHT': "Weight error (L\u221e), scale = codec bound",
               'POSE': "Deformation error (%s) at frame %d, scale = 99th percentile"}

# Length units for the pose error: metres per unit and the label, by scene unit system.
LENGTH_UNITS = {'METRIC': (0.001, "mm"), 'IMPERIAL': (0.0254, "in")}


def length_unit(scene):
    """(factor from Blender units to the shown unit, its label): millimetres in metric scenes
    (Unit Scale applied), inches in imperial ones, plain scene units without a unit system."""
    units = scene.unit_settings
    if units.system not in LENGTH_UNITS:
        return 1.0, "scene units"
    metres, label = LENGTH_UNITS[units.system]
    return units.scale_length / metres, label


def mode_label(info):
    """The legend's title for a stored preview (PREVIEW_KEY entry)."""
    if info["mode"] == 'POSE':
        return MODE_LABELS['POSE'] % (info.get("unit", "scene units"), info.get("frame", 0))
    return MODE_LABELS[info["mode"]]


def ramp_ticks(scale, number_format):
    """One label per ramp colour: the value at which the ramp reaches it (0, scale/4, ...,
    scale); the last colour also stands for everything above the scale. The panel's legend and
    the rendered pictures' legend both use these."""
    steps = len(RAMP) - 1
    labels = [number_format % (scale * index / steps) if index else "0" for index in range(len(RAMP))]
    labels[-1] = "\u2265 " + labels[-1]
    return labels


class PreviewError(Exception):
    pass


def heat_colors(values, maximum):
    """(V, 4) float32 colours: values / maximum mapped linearly onto RAMP."""
    ramp = np.array(RAMP, dtype=np.float32)
    t = np.clip(values / maximum if maximum > 0 else np.zeros_like(values), 0.0, 1.0) * (len(RAMP) - 1)
    lower = np.minimum(np.floor(t).astype(np.int64), len(RAMP) - 2)
    fraction = (t - lower)[:, None].astype(np.float32)
    return ramp[lower] * (1.0 - fraction) + ramp[lower + 1] * fraction


# What a preview replaces and Clear puts back, kept in the mesh's PREVIEW_KEY entry.
_PREVIOUS_KEYS = ("previous_color_type", "previous_active_color", "previous_render_color")


def _color_name(mesh, index):
    colors = mesh.color_attributes
    return colors[index].name if 0 <= index < len(colors) else ""


def _select_colors(mesh, active_name, render_name):
    """Sets the active and render colour attributes by name ('' or a missing name: left as is)."""
    names = [attribute.name for attribute in mesh.color_attributes]
    if active_name in names:
        mesh.color_attributes.active_color_index = names.index(active_name)
    if render_name in names:
        mesh.color_attributes.render_color_index = names.index(render_name)


def _remove_previews(mesh):
    for existing in ATTRIBUTE_NAMES:
        attribute = mesh.color_attributes.get(existing)
        if attribute is not None:
            mesh.color_attributes.remove(attribute)


def write_color_attribute(mesh, name, domain, colors):
    """Replaces every preview attribute with a float colour attribute `name` on `domain`
    ('POINT' or 'CORNER': the domains Workbench colours by) and makes it the active colour,
    which is what Workbench shows. The render colour (what exporters write as COLOR_0) stays
    the user's: it is remembered with the active one and both are put back by name, as Clear
    does. colors: (element count, 4) float32."""
    info = dict(mesh.get(storage.PREVIEW_KEY, {}))
    if "previous_render_color" not in info:
        colors_now = mesh.color_attributes
        info["previous_active_color"] = _color_name(mesh, colors_now.active_color_index)
        info["previous_render_color"] = _color_name(mesh, colors_now.render_color_index)
        mesh[storage.PREVIEW_KEY] = info
    _remove_previews(mesh)
    attribute = mesh.color_attributes.new(name, 'FLOAT_COLOR', domain)
    attribute.data.foreach_set("color", np.ascontiguousarray(colors, dtype=np.float32).ravel())
    # Re-fetch by name: adding attributes can reallocate, leaving older references stale. The
    # first colour attribute of a mesh becomes the render colour by itself: that is undone too.
    _select_colors(mesh, name, info["previous_render_color"])


def remember_preview(mesh, info):
    """Stores what the preview shows (info: mode and legend values) on the mesh, keeping what
    the preview replaced (scene colour type, active and render colour) for Clear."""
    previous = mesh.get(storage.PREVIEW_KEY, {})
    kept = {key: previous[key] for key in _PREVIOUS_KEYS if key in previous}
    mesh[storage.PREVIEW_KEY] = dict(info, **kept)
    mesh.update()


def write_heat_map(obj, values, maximum, mode, extra=None):
    """Writes the colour attribute, makes it the active colour, stores the legend (extra: more
    legend values, e.g. the pose error's unit and frame)."""
    mesh = obj.data
    write_color_attribute(mesh, ATTRIBUTE_NAME, 'POINT', heat_colors(np.asarray(values, dtype=np.float32), maximum))
    remember_preview(mesh, dict(extra or {}, **{
        "mode": mode,
        "minimum": float(np.min(values)) if len(values) else 0.0,
        "maximum": float(np.max(values)) if len(values) else 0.0,
        "scale": float(maximum),
    }))


def show_in_viewports(context, mesh):
    """Solid shading coloured by the active colour attribute in every 3D view and for Workbench
    renders; remembers the scene's previous colour type so Clear can put it back."""
    scene_shading = context.scene.display.shading
    info = mesh[storage.PREVIEW_KEY]
    if not info.get("previous_color_type"):
        info["previous_color_type"] = scene_shading.color_type
    scene_shading.color_type = 'VERTEX'
    screen = context.screen
    for area in (screen.areas if screen else ()):
        if area.type != 'VIEW_3D':
            continue
        for space in area.spaces:
            if space.type == 'VIEW_3D':
                # Only Solid shading can colour by attribute (Wireframe offers Single/Object/Random).
                space.shading.type = 'SOLID'
                space.shading.color_type = 'VERTEX'
        area.tag_redraw()


def clear(context, obj):
    """Removes the preview and puts back exactly what it replaced."""
    mesh = obj.data
    _remove_previews(mesh)
    info = mesh.get(storage.PREVIEW_KEY)
    if info is not None:
        _select_colors(mesh, info.get("previous_active_color", ""), info.get("previous_render_color", ""))
        previous = info.get("previous_color_type")
        if previous:
            context.scene.display.shading.color_type = previous
        del mesh[storage.PREVIEW_KEY]
    mesh.update()


def legend(mesh):
    """(mode label, minimum, maximum, scale) of the current preview, or None."""
    info = mesh.get(storage.PREVIEW_KEY) if mesh is not None else None
    if info is None or mesh.color_attributes.get(ATTRIBUTE_NAME) is None or info["mode"] not in MODE_LABELS:
        return None
    return mode_label(info), info["minimum"], info["maximum"], info["scale"]


def weight_errors(obj, result):
    """The library's per-vertex quantisation errors and the codec's bound as the scale."""
    if storage.is_stale(obj.data, result):
        raise PreviewError("%s: the stored result does not match the mesh any more; compress again" % obj.name)
    return result.per_vertex_error, result.stats["error_bound"], {}


def _evaluated_world_positions(context, obj):
    depsgraph = context.evaluated_depsgraph_get()
    depsgraph.update()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        if len(mesh.vertices) != len(obj.data.vertices):
            raise PreviewError("%s: a modifier changes the vertex count (%d -> %d); the deformation error "
                               "needs a one-to-one evaluated mesh" % (obj.name, len(obj.data.vertices),
                                                                      len(mesh.vertices)))
        positions = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", positions)
    finally:
        evaluated.to_mesh_clear()
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    positions = positions.reshape(-1, 3)
    return positions @ matrix[:3, :3].T + matrix[:3, 3]


def pose_errors(context, obj, result):
    """Per-vertex distance (in length_unit(), mm in a metric scene) between the vertex skinned
    with the original and with the decoded weights in the current pose, the 99th percentile as
    the scale, and the legend's unit and frame. The mesh's weights are swapped only for the
    second evaluation and always written back bit-exactly."""
    if storage.showing_decoded(obj.data):
        raise PreviewError("%s shows the decoded weights (A/B); switch back to the originals first" % obj.name)
    if storage.is_stale(obj.data, result):
        raise PreviewError("%s: the stored result does not match the mesh any more; compress again" % obj.name)
    skin = gather.gather(obj)
    if not storage.matches_weights(result, skin):
        raise PreviewError("%s: the weights or deform bones changed since compression; compress again" % obj.name)
    decoded_joints, decoded_weights = result.decode()
    decoded = gather.decoded_element_weights(skin, decoded_joints, decoded_weights)
    original_positions = _evaluated_world_positions(context, obj)
    try:
        gather.write_element_weights(obj.data, skin.element_counts, decoded, skin.element_weights)
        obj.data.update()
        decoded_positions = _evaluated_world_positions(context, obj)
    finally:
        gather.write_element_weights(obj.data, skin.element_counts, skin.element_weights, decoded)
        obj.data.update()
    factor, unit = length_unit(context.scene)
    distances = (np.linalg.norm(decoded_positions - original_positions, axis=1) * factor).astype(np.float32)
    # A few pruned vertices usually dominate the maximum; scaling the ramp to the 99th
    # percentile keeps the rest of the mesh readable (the legend shows both, red = scale and above).
    scale = float(np.percentile(distances, 99)) if len(distances) else 0.0
    if scale <= 0.0:
        scale = float(distances.max()) if len(distances) else 0.0
    return distances, scale, {"unit": unit, "frame": int(context.scene.frame_current)}


# --- keeping previews out of exported files ---------------------------------------------------

def detach_previews(meshes):
    """Takes every preview attribute off the meshes for the length of an export, so that no
    exporter setting (render colour as COLOR_0, 4.2+'s every colour attribute as COLOR_n,
    custom attributes) writes a visualisation into the file. The user's active and render
    colours are kept by name. Returns what reattach_previews() puts back."""
    detached = []
    for mesh in meshes:
        if mesh.library is not None:
            continue  # linked data cannot carry a preview (it is never written to)
        for name in ATTRIBUTE_NAMES:
            attribute = mesh.color_attributes.get(name)
            if attribute is None:
                continue
            colors = mesh.color_attributes
            active = _color_name(mesh, colors.active_color_index)
            render = _color_name(mesh, colors.render_color_index)
            values = np.empty(len(attribute.data) * 4, dtype=np.float32)
            attribute.data.foreach_get("color", values)
            domain = attribute.domain
            colors.remove(attribute)
            _select_colors(mesh, active, render)
            detached.append((mesh, name, domain, values, active, render))
    return detached


def reattach_previews(detached):
    """Puts detached previews back as they were (attribute, active and render colour)."""
    while detached:
        mesh, name, domain, values, active, render = detached.pop()
        if mesh.color_attributes.get(name) is None:
            attribute = mesh.color_attributes.new(name, 'FLOAT_COLOR', domain)
            attribute.data.foreach_set("color", values)
        _select_colors(mesh, active, render)
