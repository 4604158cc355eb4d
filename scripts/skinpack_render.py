"""Headless Workbench renders of the heat map (the demo and tests/blender/test_heatmap_render.py)."""

import math
import os

import bpy
import mathutils
import numpy as np


def frame_camera(scene, obj, direction=(0.0, 1.0, -0.15), margin=1.15, bottom_band=0.0):
    """A camera looking along direction (world space; +Y: at the front of a character facing -Y)
    at obj's evaluated bounding box; bottom_band: fraction of the frame's height kept free below
    the object (for the legend)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    corners = [evaluated.matrix_world @ mathutils.Vector(c) for c in evaluated.bound_box]
    low = mathutils.Vector([min(c[i] for c in corners) for i in range(3)])
    high = mathutils.Vector([max(c[i] for c in corners) for i in range(3)])
    center, size = (low + high) / 2, (high - low)
    camera_data = bpy.data.cameras.get("skinpack_render") or bpy.data.cameras.new("skinpack_render")
    camera = bpy.data.objects.get("skinpack_render") or bpy.data.objects.new("skinpack_render", camera_data)
    if camera.name not in scene.collection.objects:
        scene.collection.objects.link(camera)
    camera_data.type = 'ORTHO'
    aspect = scene.render.resolution_x / scene.render.resolution_y
    camera_data.ortho_scale = max(size.z * aspect, size.x, size.y) * margin if aspect < 1 else \
        max(size.z, size.x / aspect) * margin * aspect
    camera_data.ortho_scale /= 1.0 - bottom_band
    view = mathutils.Vector(direction).normalized()
    camera.location = center - view * (size.length * 2 + 1)
    camera.rotation_euler = view.to_track_quat('-Z', 'Y').to_euler()
    height = camera_data.ortho_scale / max(aspect, 1.0)  # ortho_scale spans the longer side
    camera.location -= camera.rotation_euler.to_matrix() @ mathutils.Vector((0, bottom_band * height / 2, 0))
    camera_data.clip_end = size.length * 10 + 10
    scene.camera = camera
    return camera


LEGEND_BAND = 0.16  # fraction of the picture's height under the mesh that holds the legend
LEGEND_OBJECT = "skinpack_legend"


def _legend_font():
    """DejaVu Sans where installed (it has the infinity and >= signs), else Blender's own font."""
    path = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
    return bpy.data.fonts.load(path, check_existing=True) if os.path.isfile(path) else None


def _legend_text(camera, name, body, location, size, font):
    curve = bpy.data.curves.new(name, 'FONT')
    curve.body = body
    curve.size = size
    curve.align_x, curve.align_y = 'CENTER', 'CENTER'
    if font is not None:
        curve.font = font
    text = bpy.data.objects.new(name, curve)
    text.parent = camera
    text.location = location
    return text


def _legend_swatch(camera, name, color, center, width, height):
    """A flat rectangle whose colour attribute is one ramp colour: Workbench shows it exactly as
    it shows the heat map."""
    x, y, z = center
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(x - width / 2, y - height / 2, z), (x + width / 2, y - height / 2, z),
                      (x + width / 2, y + height / 2, z), (x - width / 2, y + height / 2, z)], [], [(0, 1, 2, 3)])
    attribute = mesh.color_attributes.new("legend", 'FLOAT_COLOR', 'POINT')
    attribute.data.foreach_set("color", list(color) * 4)
    swatch = bpy.data.objects.new(name, mesh)
    swatch.parent = camera
    return swatch


def add_legend(scene, camera, title, ticks, colors):
    """Title, colour swatches and one tick label under each swatch, in the picture's bottom
    band (objects parented to the orthographic camera, in front of everything)."""
    remove_legend()
    aspect = scene.render.resolution_x / scene.render.resolution_y
    height = camera.data.ortho_scale / max(aspect, 1.0)
    width = height * aspect
    bottom, depth = -height / 2, -1.0
    font = _legend_font()
    columns = len(colors)
    column = width * 0.92 / columns
    objects = [_legend_text(camera, LEGEND_OBJECT + "_title", title,
                            (0, bottom + height * 0.125, depth), height * 0.026, font)]
    for index, (color, tick) in enumerate(zip(colors, ticks)):
        x = (index - (columns - 1) / 2) * column
        objects.append(_legend_swatch(camera, "%s_swatch_%d" % (LEGEND_OBJECT, index), color,
                                      (x, bottom + height * 0.075, depth), column * 0.96, height * 0.035))
        objects.append(_legend_text(camera, "%s_tick_%d" % (LEGEND_OBJECT, index), tick,
                                    (x, bottom + height * 0.03, depth), height * 0.024, font))
    for item in objects:
        scene.collection.objects.link(item)
    return objects


def remove_legend():
    for item in [o for o in bpy.data.objects if o.name.startswith(LEGEND_OBJECT)]:
        data = item.data
        bpy.data.objects.remove(item)
        if isinstance(data, bpy.types.Mesh):
            bpy.data.meshes.remove(data)
        elif data is not None:
            bpy.data.curves.remove(data)


def render_workbench(path, obj, resolution=(480, 640), legend=None):
    """Renders the scene with Workbench, colouring by the active colour attribute, to a PNG.
    legend: (title, tick labels, ramp colours) drawn under the mesh, or None."""
    scene = bpy.context.scene
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.display.shading.light = 'STUDIO'
    scene.display.shading.color_type = 'VERTEX'
    scene.display.shading.show_shadows = False
    scene.render.image_settings.file_format = 'PNG'
    if scene.world is None:  # an empty scene renders on black; Workbench uses the world colour
        scene.world = bpy.data.worlds.new("skinpack_render")
    scene.world.color = (0.05, 0.05, 0.05)
    scene.render.filepath = path
    for other in scene.objects:  # only the subject: helper meshes would hide it
        other.hide_render = other != obj and other.type == 'MESH'
    camera = frame_camera(scene, obj, bottom_band=LEGEND_BAND if legend else 0.0)
    if legend:
        add_legend(scene, camera, *legend)
    try:
        bpy.ops.render.render(write_still=True)
    finally:
        remove_legend()
    return path


def heat_map_legend(obj):
    """(title, ticks, colours) of the heat map shown on obj, from the add-on's own legend."""
    from skinpack import preview
    from skinpack.io import storage
    info = obj.data[storage.PREVIEW_KEY]
    number_format = "%.2e" if info["mode"] == 'WEIGHT' else "%.3g"
    return preview.mode_label(info), preview.ramp_ticks(info["scale"], number_format), preview.RAMP


def image_pixels(path):
    image = bpy.data.images.load(path, check_existing=False)
    try:
        pixels = np.empty(image.size[0] * image.size[1] * image.channels, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        return pixels.reshape(image.size[1], image.size[0], image.channels)
    finally:
        bpy.data.images.remove(image)


def angle(degrees):
    return math.radians(degrees)
