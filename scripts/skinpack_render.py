"""Headless Workbench renders of the heat map (the demo and tests/blender/test_heatmap_render.py)."""

import math

import bpy
import mathutils
import numpy as np


def frame_camera(scene, obj, direction=(0.0, 1.0, -0.15), margin=1.15):
    """A camera looking along direction (world space; +Y: at the front of a character facing -Y)
    at obj's evaluated bounding box."""
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
    view = mathutils.Vector(direction).normalized()
    camera.location = center - view * (size.length * 2 + 1)
    camera.rotation_euler = view.to_track_quat('-Z', 'Y').to_euler()
    camera_data.clip_end = size.length * 10 + 10
    scene.camera = camera
    return camera


def render_workbench(path, obj, resolution=(480, 640)):
    """Renders the scene with Workbench, colouring by the active colour attribute, to a PNG."""
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
    frame_camera(scene, obj)
    bpy.ops.render.render(write_still=True)
    return path


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
