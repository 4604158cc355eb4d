"""Blender-free code (as io_scene_gltf2's io/): the native library binding, the stored-result
format and the extension's JSON. Nothing here imports bpy, so it runs in any Python with numpy."""
