"""Settings stored with the mesh (compression), the object (meshlet preview) and the scene (glTF export)."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty, PointerProperty,
                       StringProperty)

from . import preview
from .io import native


def _library_defaults():
    """Defaults and limits of the settings, from the library (sp_compress_options_default,
    sp_meshlet_options_default, skinpack.h's limits), never copied here. Without a loadable
    library the limits stand in (the panel then only shows why the library did not load)."""
    limits = native.CONSTANTS
    defaults = {"method": 'OSS', "budget": '32', "max_influences": limits["SP_MAX_INFLUENCES"],
                "builder": 'SKIN', "max_vertices": limits["SP_MESHLET_MAX_VERTICES"],
                "max_triangles": limits["SP_MESHLET_MAX_TRIANGLES"], "palette_size": limits["SP_MESHLET_MAX_JOINTS"],
                "palette_effort": 0}
    try:
        options, meshlets = native.default_options(), native.meshlet_options()
    except native.SkinpackError:
        return defaults
    budget = str(options.vertex_bits)
    defaults.update(method=native.METHODS[options.method].upper(), max_influences=int(options.max_influences),
                    budget=budget if budget in ('32', '48', '64') else 'CUSTOM',
                    builder=native.MESHLET_BUILDERS[meshlets.builder].upper(),
                    max_vertices=int(meshlets.max_vertices), max_triangles=int(meshlets.max_triangles),
                    palette_size=int(meshlets.max_joints), palette_effort=int(meshlets.palette_effort))
    return defaults


DEFAULTS = _library_defaults()
LIMITS = native.CONSTANTS


def meshlet_limit_properties():
    """The three meshlet limits and the palette effort as properties (the object's settings and the
    operator share them)."""
    return {
        "max_vertices": IntProperty(name="Max Vertices", default=DEFAULTS["max_vertices"], min=1,
                                    max=LIMITS["SP_MESHLET_MAX_VERTICES"],
                                    description="Vertices per meshlet (local indices are 8-bit)"),
        "max_triangles": IntProperty(name="Max Triangles", default=DEFAULTS["max_triangles"], min=1,
                                     max=LIMITS["SP_MESHLET_MAX_TRIANGLES"], description="Triangles per meshlet"),
        "palette_size": IntProperty(name="Palette Size", default=DEFAULTS["palette_size"], min=1,
                                    max=LIMITS["SP_MESHLET_MAX_JOINTS"],
                                    description="Distinct joints per meshlet (the joint palette limit)"),
        "palette_effort": IntProperty(name="Palette Effort", default=DEFAULTS["palette_effort"], min=0,
                                      max=LIMITS["SP_MESHLET_MAX_PALETTE_EFFORT"],
                                      description="Skin-Aware builder: random border moves tried per triangle after "
                                                  "the build for smaller palettes (never more meshlets or palette "
                                                  "entries; the time grows with it)"),
    }

METHOD_ITEMS = (
    ('OSS', "Optimal Simplex", "Optimal simplex sampling: the densest code for a bit budget (the paper's best)"),
    ('ANY', "Any AABB", "Independent samples per weight axis"),
    ('POT', "POT AABB", "Fixed-point weights with the always-zero high bits dropped"),
    ('CUBE', "Unit Cube", "K-1 fixed-point weights, the largest one recomputed"),
    ('FIXED', "Fixed", "K fixed-point weights, nothing recomputed"),
)

BUDGET_ITEMS = (
    ('32', "32 bits", "One 32-bit word per vertex (tuple index + weight code)"),
    ('48', "48 bits", "48 bits per vertex (stored in two words)"),
    ('64', "64 bits", "Two 32-bit words per vertex"),
    ('CUSTOM', "Custom", "A bit budget of your choice for tuple index + weight code"),
    ('ERROR', "Max Error", "The fewest weight bits whose proven error bound meets a target"),
)


class SkinpackMeshSettings(bpy.types.PropertyGroup):
    method: EnumProperty(name="Method", items=METHOD_ITEMS, default=DEFAULTS["method"],
                         description="Weight codec")
    budget: EnumProperty(name="Budget", items=BUDGET_ITEMS, default=DEFAULTS["budget"],
                         description="Bits per vertex for tuple index and weight code, or an error target")
    custom_bits: IntProperty(name="Bits per Vertex", default=40, min=1, max=LIMITS["SP_MAX_VERTEX_BITS"],
                             description="Budget for tuple index + weight code of one vertex")
    max_error: FloatProperty(name="Max Weight Error", default=0.001, min=1e-9, max=0.5, precision=5,
                             description="Largest allowed weight error (L-inf); picks the fewest weight bits "
                                         "whose proven bound meets it")
    max_influences: IntProperty(name="Max Influences", default=DEFAULTS["max_influences"], min=1,
                                max=LIMITS["SP_MAX_INFLUENCES"],
                                description="Influences kept per vertex (K); the smallest weights are pruned")

    def options_summary(self):
        return {"method": self.method.lower(), "budget": self.budget, "custom_bits": self.custom_bits,
                "max_error": self.max_error, "max_influences": self.max_influences}


class SkinpackExportSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(name="Skinpack", default=False,
                          description="Also write SKINPACK_packed_skin for every skinned primitive of this glTF "
                                      "export (off: the exporter's file is left as Blender writes it)")
    mode: EnumProperty(name="Mode", default='FALLBACK', items=(
        ('FALLBACK', "Fallback", "Keep JOINTS_0/WEIGHTS_0 so every viewer opens the file; the extension is optional"),
        ('COMPACT', "Compact", "Drop JOINTS_0/WEIGHTS_0; the extension is required to read the skin"),
    ), description="Whether the uncompressed attributes stay in the file")


def _legend_property(index):
    # Read-only swatches of the heat-map colour ramp, drawn in the panel's legend.
    return FloatVectorProperty(name="Colour %d" % index, subtype='COLOR', size=3, min=0.0, max=1.0,
                               get=lambda self: preview.RAMP[index][:3], set=lambda self, value: None)


MESHLET_BUILDER_ITEMS = (
    ('SKIN', "Skin-Aware", "Spatial growth that also keeps each meshlet's joint palette small (ours)"),
    ('COMMON', "Common Influences", "Triangles grouped by identical joint sets first (thesis listing A.2)"),
    ('NAIVE', "Naive", "Triangles in index order, a new meshlet when one does not fit (thesis listing A.1)"),
)

MESHLET_MODE_ITEMS = (
    ('MESHLET', "Meshlets", "A distinct colour per meshlet"),
    ('JOINTS', "Joints", "Heat map of the distinct joints per meshlet, from 0 to the palette size"),
)


class SkinpackMeshletSettings(bpy.types.PropertyGroup):
    """Meshlet preview settings of an object and the library's stats of its last preview."""
    builder: EnumProperty(name="Builder", items=MESHLET_BUILDER_ITEMS, default=DEFAULTS["builder"],
                          description="Meshlet builder of the library")
    max_vertices: meshlet_limit_properties()["max_vertices"]
    max_triangles: meshlet_limit_properties()["max_triangles"]
    palette_size: meshlet_limit_properties()["palette_size"]
    palette_effort: meshlet_limit_properties()["palette_effort"]

    # Stats of the preview shown (sp_meshlet_stats), read-only in the panel.
    valid: BoolProperty(default=False, options={'HIDDEN'})
    shown_builder: StringProperty(default="", options={'HIDDEN'})
    shown_mode: StringProperty(default="", options={'HIDDEN'})
    meshlet_count: IntProperty(name="Meshlets", default=0)
    mean_vertices: FloatProperty(name="Mean Vertices", default=0.0)
    mean_triangles: FloatProperty(name="Mean Triangles", default=0.0)
    mean_joints: FloatProperty(name="Mean Joints", default=0.0)
    max_joints: IntProperty(name="Max Joints", default=0)
    global_tuple_bits: IntProperty(name="Global Tuple Bits", default=0)
    local_tuple_bits_mean: FloatProperty(name="Local Tuple Bits", default=0.0)
    local_tuple_bits_max: IntProperty(name="Max Local Tuple Bits", default=0)


class SkinpackLegend(bpy.types.PropertyGroup):
    color_0: _legend_property(0)
    color_1: _legend_property(1)
    color_2: _legend_property(2)
    color_3: _legend_property(3)
    color_4: _legend_property(4)


classes = (SkinpackMeshSettings, SkinpackExportSettings, SkinpackMeshletSettings, SkinpackLegend)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Mesh.skinpack = PointerProperty(type=SkinpackMeshSettings)
    bpy.types.Scene.skinpack_export = PointerProperty(type=SkinpackExportSettings)
    bpy.types.Object.skinpack_meshlets = PointerProperty(type=SkinpackMeshletSettings)
    bpy.types.WindowManager.skinpack_legend = PointerProperty(type=SkinpackLegend)


def unregister():
    del bpy.types.WindowManager.skinpack_legend
    del bpy.types.Object.skinpack_meshlets
    del bpy.types.Scene.skinpack_export
    del bpy.types.Mesh.skinpack
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
