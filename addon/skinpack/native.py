"""ctypes binding of libskinpack (native/include/skinpack.h).

All compression math lives in the C library; this module only mirrors its structs, loads it
from the add-on's own folder and wraps the few whole-skin calls the add-on needs in functions
that take and return numpy arrays. The structs below must match skinpack.h field by field:
tests/blender/test_native_layout.py compares every size and offset with the C compiler's.
"""

import ctypes
import os

import numpy as np

LIBRARY_NAME = "libskinpack.so"

SP_MAX_INPUT_INFLUENCES = 8
SP_MAX_INFLUENCES = 4
SP_MAX_JOINTS = 65535
SP_ERROR_HISTOGRAM_BINS = 16

METHODS = ("fixed", "cube", "pot", "any", "oss")  # index == sp_method value

# sp_result values the add-on reacts to (the rest are only shown as messages).
SP_OK = 0
SP_ERR_INVALID_ARGUMENT = 1
SP_ERR_NONFINITE_WEIGHT = 3
SP_ERR_NEGATIVE_WEIGHT = 4
SP_ERR_NO_INFLUENCE = 5
SP_ERR_JOINT_OUT_OF_RANGE = 6
SP_ERR_LIMIT_EXCEEDED = 13
# Results whose error_vertex names a vertex (the others are about parameters).
PER_VERTEX_ERRORS = (SP_ERR_NONFINITE_WEIGHT, SP_ERR_NEGATIVE_WEIGHT, SP_ERR_NO_INFLUENCE, SP_ERR_JOINT_OUT_OF_RANGE)


class PrepareStats(ctypes.Structure):
    _fields_ = [
        ("vertex_count", ctypes.c_size_t),
        ("pruned_vertices", ctypes.c_size_t),
        ("renormalized_vertices", ctypes.c_size_t),
        ("merged_duplicates", ctypes.c_size_t),
        ("influence_histogram", ctypes.c_size_t * (SP_MAX_INPUT_INFLUENCES + 1)),
        ("max_pruning_error", ctypes.c_float),
        ("rms_pruning_error", ctypes.c_double),
        ("error_vertex", ctypes.c_size_t),
        ("error_joint", ctypes.c_uint32),
    ]


class Codec(ctypes.Structure):
    _fields_ = [
        ("method", ctypes.c_uint32),
        ("influences", ctypes.c_uint32),
        ("bits", ctypes.c_uint32),
        ("component_bits", ctypes.c_uint32 * SP_MAX_INFLUENCES),
        ("n", ctypes.c_uint64),
        ("axis_samples", ctypes.c_uint64 * (SP_MAX_INFLUENCES - 1)),
        ("scale", ctypes.c_uint64),
        ("max_code", ctypes.c_uint64),
        ("code_bits", ctypes.c_double),
        ("max_spacing", ctypes.c_double),
        ("max_error", ctypes.c_double),
    ]


class ErrorStats(ctypes.Structure):
    _fields_ = [
        ("max_error", ctypes.c_double),
        ("rms_error", ctypes.c_double),
        ("mean_error", ctypes.c_double),
        ("worst_vertex", ctypes.c_size_t),
        ("histogram_max", ctypes.c_double),
        ("histogram", ctypes.c_size_t * SP_ERROR_HISTOGRAM_BINS),
        ("vertices_over_bound", ctypes.c_size_t),
    ]


class CompressOptions(ctypes.Structure):
    _fields_ = [
        ("method", ctypes.c_int),  # enum sp_method
        ("max_influences", ctypes.c_uint32),
        ("vertex_bits", ctypes.c_uint32),
        ("weight_bits", ctypes.c_uint32),
        ("max_spacing", ctypes.c_double),
        ("merge_dont_care", ctypes.c_int),
        ("sum_tolerance", ctypes.c_float),
        ("max_error", ctypes.c_double),  # mirrors skinpack.h (issue 11); issue 13 generates this file
    ]


class CompressedSkin(ctypes.Structure):
    _fields_ = [
        ("codec", Codec),
        ("influences", ctypes.c_uint32),
        ("tuple_bits", ctypes.c_uint32),
        ("weight_bits", ctypes.c_uint32),
        ("words_per_vertex", ctypes.c_uint32),
        ("joint_bytes", ctypes.c_uint32),
        ("vertex_count", ctypes.c_size_t),
        ("joint_count", ctypes.c_size_t),
        ("lut_size", ctypes.c_size_t),
        ("lut_bits_per_vertex", ctypes.c_double),
        ("bits_per_vertex", ctypes.c_double),
        ("prepare", PrepareStats),
        ("quantization", ErrorStats),
    ]


# Meshlets (skinpack.h section "Meshlets", docs/meshlets.md).
MESHLET_BUILDERS = ("naive", "common", "skin")  # index == sp_meshlet_builder value


class MeshletOptions(ctypes.Structure):
    _fields_ = [
        ("builder", ctypes.c_uint32),
        ("max_vertices", ctypes.c_uint32),
        ("max_triangles", ctypes.c_uint32),
        ("max_joints", ctypes.c_uint32),
        ("min_group_triangles", ctypes.c_uint32),
        ("joint_cost", ctypes.c_float),
        ("tuple_cost", ctypes.c_float),
    ]


class Meshlet(ctypes.Structure):
    _fields_ = [
        ("vertex_offset", ctypes.c_uint32),
        ("triangle_offset", ctypes.c_uint32),
        ("joint_offset", ctypes.c_uint32),
        ("tuple_offset", ctypes.c_uint32),
        ("vertex_count", ctypes.c_uint16),
        ("triangle_count", ctypes.c_uint16),
        ("joint_count", ctypes.c_uint16),
        ("tuple_count", ctypes.c_uint16),
        ("tuple_bits", ctypes.c_uint32),
        ("center", ctypes.c_float * 3),
        ("radius", ctypes.c_float),
        ("cone_apex", ctypes.c_float * 3),
        ("cone_axis", ctypes.c_float * 3),
        ("cone_cutoff", ctypes.c_float),
    ]


class MeshletSizes(ctypes.Structure):
    _fields_ = [
        ("meshlets", ctypes.c_size_t),
        ("vertices", ctypes.c_size_t),
        ("triangles", ctypes.c_size_t),
        ("joints", ctypes.c_size_t),
        ("tuples", ctypes.c_size_t),
        ("scratch_bytes", ctypes.c_size_t),
    ]


class MeshletBuffers(ctypes.Structure):
    _fields_ = [
        ("meshlets", ctypes.POINTER(Meshlet)),
        ("vertices", ctypes.POINTER(ctypes.c_uint32)),
        ("vertex_tuples", ctypes.POINTER(ctypes.c_uint8)),
        ("triangles", ctypes.POINTER(ctypes.c_uint8)),
        ("joints", ctypes.POINTER(ctypes.c_uint16)),
        ("tuples", ctypes.POINTER(ctypes.c_uint8)),
        ("triangle_meshlet", ctypes.POINTER(ctypes.c_uint32)),
        ("capacity", MeshletSizes),
    ]


class MeshletStats(ctypes.Structure):
    _fields_ = [
        ("meshlet_count", ctypes.c_size_t),
        ("vertex_count", ctypes.c_size_t),
        ("triangle_count", ctypes.c_size_t),
        ("joint_count", ctypes.c_size_t),
        ("tuple_count", ctypes.c_size_t),
        ("max_vertices", ctypes.c_uint32),
        ("max_triangles", ctypes.c_uint32),
        ("max_joints", ctypes.c_uint32),
        ("mean_vertices", ctypes.c_double),
        ("mean_triangles", ctypes.c_double),
        ("mean_joints", ctypes.c_double),
        ("global_tuples", ctypes.c_size_t),
        ("global_tuple_bits", ctypes.c_uint32),
        ("local_tuple_bits_mean", ctypes.c_double),
        ("local_tuple_bits_max", ctypes.c_uint32),
        ("error_triangle", ctypes.c_size_t),
    ]


MIRRORED_STRUCTS = {
    "sp_prepare_stats": PrepareStats,
    "sp_codec": Codec,
    "sp_error_stats": ErrorStats,
    "sp_compress_options": CompressOptions,
    "sp_compressed_skin": CompressedSkin,
    "sp_meshlet_options": MeshletOptions,
    "sp_meshlet": Meshlet,
    "sp_meshlet_sizes": MeshletSizes,
    "sp_meshlet_buffers": MeshletBuffers,
    "sp_meshlet_stats": MeshletStats,
}


class SkinpackError(Exception):
    """A library call failed; code is the sp_result, vertex the first offending vertex if known."""

    def __init__(self, message, code=None, vertex=None):
        super().__init__(message)
        self.code = code
        self.vertex = vertex


_lib = None
_load_error = None


def _pointer(array, ctype):
    return array.ctypes.data_as(ctypes.POINTER(ctype))


def _declare(lib):
    P = ctypes.POINTER
    lib.sp_result_string.restype = ctypes.c_char_p
    lib.sp_result_string.argtypes = [ctypes.c_int]
    lib.sp_compress_options_default.restype = None
    lib.sp_compress_options_default.argtypes = [P(CompressOptions)]
    lib.sp_compress_scratch_bound.restype = ctypes.c_size_t
    lib.sp_compress_scratch_bound.argtypes = [ctypes.c_size_t, ctypes.c_size_t]
    lib.sp_compress_skin.restype = ctypes.c_int
    lib.sp_compress_skin.argtypes = [
        P(ctypes.c_uint16), P(ctypes.c_float), ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t,
        P(CompressOptions), P(ctypes.c_uint32), P(ctypes.c_uint16), P(ctypes.c_float), P(ctypes.c_float),
        P(CompressedSkin), ctypes.c_void_p, ctypes.c_size_t]
    lib.sp_codec_from_params.restype = ctypes.c_int
    lib.sp_codec_from_params.argtypes = [ctypes.c_int, ctypes.c_uint32, ctypes.c_uint64, P(ctypes.c_uint64), P(Codec)]
    lib.sp_decompress_skin.restype = ctypes.c_int
    lib.sp_decompress_skin.argtypes = [
        P(Codec), P(ctypes.c_uint32), ctypes.c_size_t, ctypes.c_uint32, P(ctypes.c_uint16), ctypes.c_size_t,
        ctypes.c_size_t, P(ctypes.c_uint16), P(ctypes.c_float), P(ctypes.c_size_t)]
    lib.sp_codec_from_bits.restype = ctypes.c_int
    lib.sp_codec_from_bits.argtypes = [ctypes.c_int, ctypes.c_uint32, ctypes.c_uint32, P(Codec)]
    lib.sp_method_name.restype = ctypes.c_char_p
    lib.sp_method_name.argtypes = [ctypes.c_int]
    lib.sp_prepare_influences.restype = ctypes.c_int
    lib.sp_prepare_influences.argtypes = [
        P(ctypes.c_uint16), P(ctypes.c_float), ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t,
        ctypes.c_float, P(ctypes.c_uint16), P(ctypes.c_float), P(ctypes.c_float), P(PrepareStats)]
    lib.sp_meshlet_options_default.restype = None
    lib.sp_meshlet_options_default.argtypes = [P(MeshletOptions)]
    lib.sp_meshlets_bound.restype = None
    lib.sp_meshlets_bound.argtypes = [ctypes.c_size_t, ctypes.c_size_t, ctypes.c_size_t, P(MeshletOptions),
                                      P(MeshletSizes)]
    lib.sp_build_meshlets.restype = ctypes.c_int
    lib.sp_build_meshlets.argtypes = [
        P(ctypes.c_uint32), ctypes.c_size_t, P(ctypes.c_float), ctypes.c_size_t, ctypes.c_size_t,
        P(ctypes.c_uint16), P(ctypes.c_float), ctypes.c_size_t, P(MeshletOptions), P(MeshletBuffers),
        ctypes.c_void_p, ctypes.c_size_t, P(MeshletStats)]


def library_path():
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), LIBRARY_NAME)


def load():
    """Loads the library once; returns it, or None (load_error() says why)."""
    global _lib, _load_error
    if _lib is not None or _load_error is not None:
        return _lib
    path = library_path()
    try:
        lib = ctypes.CDLL(path)
        _declare(lib)
    except (OSError, AttributeError) as error:
        _load_error = "Cannot load %s: %s" % (path, error)
        return None
    _lib = lib
    return _lib


def load_error():
    load()
    return _load_error


def _require():
    lib = load()
    if lib is None:
        raise SkinpackError(_load_error)
    return lib


def result_string(code):
    return _require().sp_result_string(code).decode("utf-8", "replace")


def default_options():
    options = CompressOptions()
    _require().sp_compress_options_default(ctypes.byref(options))
    return options


def make_options(method="oss", max_influences=4, vertex_bits=0, weight_bits=0, max_spacing=0.0):
    """Compress options with exactly one budget set (vertex_bits, weight_bits or max_spacing)."""
    options = default_options()
    options.method = METHODS.index(method)
    options.max_influences = max_influences
    options.vertex_bits = vertex_bits
    options.weight_bits = weight_bits
    options.max_spacing = max_spacing
    return options


class Compressed:
    """What sp_compress_skin returns, as numpy arrays plus the result struct."""

    def __init__(self, skin, words, lut, per_vertex_error, per_vertex_pruning):
        self.skin = skin
        self.words = words  # vertex_count * words_per_vertex u32
        self.lut = lut  # lut_size * K u16
        self.per_vertex_error = per_vertex_error
        self.per_vertex_pruning = per_vertex_pruning

    @property
    def method(self):
        return METHODS[self.skin.codec.method]

    def axis_samples(self):
        K = self.skin.influences
        return [int(q) for q in self.skin.codec.axis_samples[:max(K - 1, 0)]]

    def decode(self):
        return decompress(self.method, self.skin.influences, self.skin.codec.n, self.axis_samples(),
                          self.words, self.skin.vertex_count, self.skin.tuple_bits, self.lut,
                          self.skin.joint_count)


def compress(joints, weights, joint_count, options):
    """joints (V, S) uint16 and weights (V, S) float32, S = influences per vertex (1..8)."""
    lib = _require()
    joints = np.ascontiguousarray(joints, dtype=np.uint16)
    weights = np.ascontiguousarray(weights, dtype=np.float32)
    vertex_count, stride = weights.shape
    words = np.zeros(vertex_count * 2, dtype=np.uint32)
    lut = np.zeros(vertex_count * SP_MAX_INFLUENCES, dtype=np.uint16)
    per_vertex_error = np.zeros(vertex_count, dtype=np.float32)
    per_vertex_pruning = np.zeros(vertex_count, dtype=np.float32)
    skin = CompressedSkin()
    scratch_size = lib.sp_compress_scratch_bound(vertex_count, stride)
    scratch = np.zeros(max(scratch_size, 1), dtype=np.uint8)
    code = lib.sp_compress_skin(
        _pointer(joints, ctypes.c_uint16), _pointer(weights, ctypes.c_float), vertex_count, stride, joint_count,
        ctypes.byref(options), _pointer(words, ctypes.c_uint32), _pointer(lut, ctypes.c_uint16),
        _pointer(per_vertex_error, ctypes.c_float), _pointer(per_vertex_pruning, ctypes.c_float),
        ctypes.byref(skin), scratch.ctypes.data_as(ctypes.c_void_p), scratch_size)
    if code != SP_OK:
        raise SkinpackError(result_string(code), code, int(skin.prepare.error_vertex))
    words = words[:vertex_count * skin.words_per_vertex].copy()
    lut = lut[:skin.lut_size * skin.influences].copy()
    return Compressed(skin, words, lut, per_vertex_error, per_vertex_pruning)


def codec_from_params(method, influences, n, axis_samples=None):
    lib = _require()
    codec = Codec()
    samples = None
    if axis_samples:
        samples = (ctypes.c_uint64 * len(axis_samples))(*axis_samples)
    code = lib.sp_codec_from_params(METHODS.index(method), influences, n, samples, ctypes.byref(codec))
    if code != SP_OK:
        raise SkinpackError("invalid codec parameters (%s): %s" % (method, result_string(code)), code)
    return codec


def weight_bits_for_error(method, influences, max_error):
    """The fewest weight-code bits whose proven bound (sp_codec.max_error) is <= max_error,
    or None if even 64 bits do not reach it."""
    lib = _require()
    codec = Codec()
    for bits in range(0, 65):
        if lib.sp_codec_from_bits(METHODS.index(method), influences, bits, ctypes.byref(codec)) != SP_OK:
            continue
        if codec.max_error <= max_error:
            return bits
    return None


def decompress(method, influences, n, axis_samples, words, vertex_count, tuple_bits, lut, joint_count):
    """Returns (joints (V, K) uint16, weights (V, K) float32); validates everything."""
    lib = _require()
    codec = codec_from_params(method, influences, n, axis_samples)
    words = np.ascontiguousarray(words, dtype=np.uint32)
    lut = np.ascontiguousarray(lut, dtype=np.uint16)
    K = influences
    joints = np.zeros((vertex_count, K), dtype=np.uint16)
    weights = np.zeros((vertex_count, K), dtype=np.float32)
    error_vertex = ctypes.c_size_t(0)
    code = lib.sp_decompress_skin(
        ctypes.byref(codec), _pointer(words, ctypes.c_uint32), vertex_count, tuple_bits,
        _pointer(lut, ctypes.c_uint16), len(lut) // max(K, 1), joint_count,
        _pointer(joints, ctypes.c_uint16), _pointer(weights, ctypes.c_float), ctypes.byref(error_vertex))
    if code != SP_OK:
        raise SkinpackError("cannot decode vertex %d: %s" % (error_vertex.value, result_string(code)),
                            code, error_vertex.value)
    return joints, weights


def stats_dict(compressed):
    """The numbers the panel, the CLI comparison and the export report show. The "before" size is
    what glTF stores for the same skin uncompressed: JOINTS_0 (u8, or u16 above 256 joints) and
    WEIGHTS_0 (float), VEC4 each."""
    s = compressed.skin
    input_bits_per_vertex = 4 * (8 * s.joint_bytes + 32)
    return {
        "vertices": int(s.vertex_count),
        "joint_count": int(s.joint_count),
        "method": compressed.method,
        "n": int(s.codec.n),
        "axis_samples": compressed.axis_samples(),
        "influences": int(s.influences),
        "unique_tuples": int(s.lut_size),
        "tuple_bits": int(s.tuple_bits),
        "weight_bits": int(s.weight_bits),
        "words_per_vertex": int(s.words_per_vertex),
        "lut_bits_per_vertex": float(s.lut_bits_per_vertex),
        "bits_per_vertex": float(s.bits_per_vertex),
        "input_bits_per_vertex": float(input_bits_per_vertex),
        "ratio": float(input_bits_per_vertex / s.bits_per_vertex) if s.bits_per_vertex > 0 else 0.0,
        "max_error": float(s.quantization.max_error),
        "rms_error": float(s.quantization.rms_error),
        "error_bound": float(s.codec.max_error),
        "pruned_vertices": int(s.prepare.pruned_vertices),
        "max_pruning_error": float(s.prepare.max_pruning_error),
        "renormalized_vertices": int(s.prepare.renormalized_vertices),
    }


def prepare_influences(joints, weights, joint_count, max_influences, sum_tolerance=1e-3):
    """sp_prepare_influences: (V, S) joints/weights -> (V, K) sorted by descending weight,
    K = min(max_influences, S). Raises SkinpackError naming the first bad vertex."""
    lib = _require()
    joints = np.ascontiguousarray(joints, dtype=np.uint16)
    weights = np.ascontiguousarray(weights, dtype=np.float32)
    vertex_count, stride = weights.shape
    K = min(max_influences, stride, SP_MAX_INFLUENCES)
    out_joints = np.zeros((vertex_count, K), dtype=np.uint16)
    out_weights = np.zeros((vertex_count, K), dtype=np.float32)
    stats = PrepareStats()
    code = lib.sp_prepare_influences(
        _pointer(joints, ctypes.c_uint16), _pointer(weights, ctypes.c_float), vertex_count, stride, joint_count, K,
        sum_tolerance, _pointer(out_joints, ctypes.c_uint16), _pointer(out_weights, ctypes.c_float), None,
        ctypes.byref(stats))
    if code != SP_OK:
        raise SkinpackError(result_string(code), code, int(stats.error_vertex))
    return out_joints, out_weights


def meshlet_options(builder="skin", max_vertices=64, max_triangles=124, max_joints=32):
    """sp_meshlet_options: the library's defaults with the builder and the three limits set."""
    options = MeshletOptions()
    _require().sp_meshlet_options_default(ctypes.byref(options))
    options.builder = MESHLET_BUILDERS.index(builder)
    options.max_vertices = max_vertices
    options.max_triangles = max_triangles
    options.max_joints = max_joints
    return options


class MeshletError(SkinpackError):
    """sp_build_meshlets failed; triangle is stats.error_triangle where the result names one."""

    def __init__(self, message, code, triangle):
        super().__init__(message, code)
        self.triangle = triangle


class Meshlets:
    """What sp_build_meshlets wrote, trimmed to the counts in stats (numpy views of the buffers)."""

    def __init__(self, stats, meshlets, triangle_meshlet):
        self.stats = stats  # MeshletStats
        self.meshlets = meshlets  # structured array, one sp_meshlet per meshlet
        self.triangle_meshlet = triangle_meshlet  # (T,) uint32: meshlet of each source triangle


def build_meshlets(indices, positions, joints, weights, options):
    """indices (T, 3) vertex indices, positions (V, 3) float32, joints/weights (V, K) as written by
    prepare_influences. Every output buffer is a numpy array sized by sp_meshlets_bound."""
    lib = _require()
    indices = np.ascontiguousarray(indices, dtype=np.uint32).reshape(-1)
    positions = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    joints = np.ascontiguousarray(joints, dtype=np.uint16)
    weights = np.ascontiguousarray(weights, dtype=np.float32)
    vertex_count, K = weights.shape
    sizes = MeshletSizes()
    lib.sp_meshlets_bound(len(indices), vertex_count, K, ctypes.byref(options), ctypes.byref(sizes))
    # One extra element each so that an empty array still has a valid address.
    meshlets = np.zeros(sizes.meshlets + 1, dtype=np.dtype(Meshlet))
    vertices = np.zeros(sizes.vertices + 1, dtype=np.uint32)
    vertex_tuples = np.zeros(sizes.vertices + 1, dtype=np.uint8)
    triangles = np.zeros(sizes.triangles * 3 + 1, dtype=np.uint8)
    palette = np.zeros(sizes.joints + 1, dtype=np.uint16)
    tuples = np.zeros(sizes.tuples * K + 1, dtype=np.uint8)
    triangle_meshlet = np.zeros(len(indices) // 3 + 1, dtype=np.uint32)
    scratch = np.zeros(sizes.scratch_bytes + 1, dtype=np.uint8)
    buffers = MeshletBuffers()
    buffers.meshlets = meshlets.ctypes.data_as(ctypes.POINTER(Meshlet))
    buffers.vertices = _pointer(vertices, ctypes.c_uint32)
    buffers.vertex_tuples = _pointer(vertex_tuples, ctypes.c_uint8)
    buffers.triangles = _pointer(triangles, ctypes.c_uint8)
    buffers.joints = _pointer(palette, ctypes.c_uint16)
    buffers.tuples = _pointer(tuples, ctypes.c_uint8)
    buffers.triangle_meshlet = _pointer(triangle_meshlet, ctypes.c_uint32)
    buffers.capacity = sizes
    stats = MeshletStats()
    code = lib.sp_build_meshlets(
        _pointer(indices, ctypes.c_uint32), len(indices), _pointer(positions, ctypes.c_float), vertex_count,
        12, _pointer(joints, ctypes.c_uint16), _pointer(weights, ctypes.c_float), K, ctypes.byref(options),
        ctypes.byref(buffers), scratch.ctypes.data_as(ctypes.c_void_p), sizes.scratch_bytes, ctypes.byref(stats))
    if code != SP_OK:
        triangle = int(stats.error_triangle) if code in (SP_ERR_LIMIT_EXCEEDED, SP_ERR_INVALID_ARGUMENT) else None
        raise MeshletError(result_string(code), code, triangle)
    return Meshlets(stats, meshlets[:stats.meshlet_count], triangle_meshlet[:len(indices) // 3])


def meshlet_stats_dict(stats):
    """The numbers the panel shows and the tests compare (plain Python values)."""
    return {
        "meshlet_count": int(stats.meshlet_count),
        "triangle_count": int(stats.triangle_count),
        "mean_vertices": float(stats.mean_vertices),
        "mean_triangles": float(stats.mean_triangles),
        "mean_joints": float(stats.mean_joints),
        "max_vertices": int(stats.max_vertices),
        "max_triangles": int(stats.max_triangles),
        "max_joints": int(stats.max_joints),
        "global_tuples": int(stats.global_tuples),
        "global_tuple_bits": int(stats.global_tuple_bits),
        "local_tuple_bits_mean": float(stats.local_tuple_bits_mean),
        "local_tuple_bits_max": int(stats.local_tuple_bits_max),
    }
