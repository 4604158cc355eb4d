"""Imports from Blender's glTF add-on that were renamed between versions (4.3 shortened the
exporter module names; io.com.gltf2_io and io.com.gltf2_io_extensions kept theirs)."""


def gltf_io():
    from io_scene_gltf2.io.com import gltf2_io
    return gltf2_io


def extension_class():
    from io_scene_gltf2.io.com.gltf2_io_extensions import Extension
    return Extension


def binary_data_class():
    try:
        from io_scene_gltf2.io.exp.gltf2_io_binary_data import BinaryData
    except ImportError:  # Blender 4.3+
        from io_scene_gltf2.io.exp.binary_data import BinaryData
    return BinaryData
