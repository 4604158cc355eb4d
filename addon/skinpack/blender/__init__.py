"""Blender glTF integration, laid out like io_scene_gltf2 (exp = exporter, imp = importer)."""
