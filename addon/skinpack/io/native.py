"""ctypes binding of libskinpack (native/include/skinpack.h).

All compression math lives in the C library; this module builds its ctypes structs from the
layouts generated from skinpack.h (_abi.py), loads a private copy of the library bundled with
the add-on and wraps the few whole-skin calls the add-on needs in functions that take and
return numpy arrays. No Blender here. tests/blender/test_native_layout.py compares every size
and offset with the C compiler's.
"""

import ctypes
import hashlib
import os
import sys

import numpy as np

from . import _abi  # generated from skinpack.h when the zip is built (addon/generate_abi.py)

# The library's file name inside the add-on, per platform (make_zip.py writes it so).
if sys.platform == "win32":
    LIBRARY_NAME = "skinpack.dll"
elif sys.platform == "darwin":
    LIBRARY_NAME = "libskinpack.dylib"
else:
    LIBRARY_NAME = "libskinpack.so"

CONSTANTS = _constants = _abi.CONSTANTS  # every #define SP_* of skinpack.h
SP_VERSION, SP_MAX_INPUT_INFLUENCES, SP_MAX_INFLUENCES, SP_MAX_JOINTS = (_constants[name] for name in (
    "SP_VERSION", "SP_MAX_INPUT_INFLUENCES", "SP_MAX_INFLUENCES", "SP_MAX_JOINTS"))


def _enum_names(enum, prefix):
    """Lower-case names of an enum's values by value (SP_METHOD_OSS -> 'oss'), *_COUNT left out."""
    values = sorted((value, name) for name, value in _abi.ENUMS[enum].items() if not name.endswith("_COUNT"))
    if [value for value, _ in values] != list(range(len(values))):
        raise ImportError("%s is not numbered 0..n-1 in skinpack.h" % enum)
    return tuple(name[len(prefix):].lower() for _, name in values)


METHODS = _enum_names("sp_method", "SP_METHOD_")  # index == sp_method value
MESHLET_BUILDERS = _enum_names("sp_meshlet_builder", "SP_MESHLETS_")  # index == sp_meshlet_builder value

# sp_result values the add-on reacts to (the rest are only shown as messages).
(SP_OK, SP_ERR_INVALID_ARGUMENT, SP_ERR_NONFINITE_WEIGHT, SP_ERR_NEGATIVE_WEIGHT, SP_ERR_NO_INFLUENCE,
 SP_ERR_JOINT_OUT_OF_RANGE, SP_ERR_LIMIT_EXCEEDED) = (_abi.ENUMS["sp_result"][name] for name in (
    "SP_OK", "SP_ERR_INVALID_ARGUMENT", "SP_ERR_NONFINITE_WEIGHT", "SP_ERR_NEGATIVE_WEIGHT", "SP_ERR_NO_INFLUENCE",
    "SP_ERR_JOINT_OUT_OF_RANGE", "SP_ERR_LIMIT_EXCEEDED"))
# Results whose error_vertex names a vertex (the others are about parameters).
PER_VERTEX_ERRORS = (SP_ERR_NONFINITE_WEIGHT, SP_ERR_NEGATIVE_WEIGHT, SP_ERR_NO_INFLUENCE, SP_ERR_JOINT_OUT_OF_RANGE)

_SCALARS = {"uint8_t": ctypes.c_uint8, "uint16_t": ctypes.c_uint16, "uint32_t": ctypes.c_uint32,
            "uint64_t": ctypes.c_uint64, "int": ctypes.c_int, "float": ctypes.c_float, "double": ctypes.c_double,
            "size_t": ctypes.c_size_t}


def _build_structs():
    """ctypes.Structure classes for every struct of skinpack.h, in header order."""
    built = {}
    for name, kind in _abi.TYPES.items():
        if kind != "struct":
            continue
        fields = []
        for field, type_name, pointers, length in _abi.STRUCTS[name]:
            ctype = _SCALARS.get(type_name) or built.get(type_name)
            if ctype is None:  # an enum: C gives it the size of int here
                ctype = ctypes.c_int
            for _ in range(pointers):
                ctype = ctypes.POINTER(ctype)
            fields.append((field, ctype * length if length else ctype))
        built[name] = type(name, (ctypes.Structure,), {"_fields_": fields})
    return built


MIRRORED_STRUCTS = _build_structs()
(PrepareStats, Codec, ErrorStats, CompressOptions, CompressedSkin, MeshletOptions, Meshlet, MeshletSizes,
 MeshletBuffers, MeshletStats, PackedParams, PackedMeshlets, PackedPrimitive, Validation) = (
    MIRRORED_STRUCTS[name] for name in (
        "sp_prepare_stats", "sp_codec", "sp_error_stats", "sp_compress_options", "sp_compressed_skin",
        "sp_meshlet_options", "sp_meshlet", "sp_meshlet_sizes", "sp_meshlet_buffers", "sp_meshlet_stats",
        "sp_packed_params", "sp_packed_meshlets", "sp_packed_primitive", "sp_validation"))


class SkinpackError(Exception):
    """A library call failed; code is the sp_result, vertex the first offending vertex if known."""

    def __init__(self, message, code=None, vertex=None):
        super().__init__(message)
        self.code = code
        self.vertex = vertex


_lib = None
_load_error = None
_loaded_path = None


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
    lib.sp_method_from_name.restype = ctypes.c_int
    lib.sp_method_from_name.argtypes = [ctypes.c_char_p]
    lib.sp_codec_from_max_error.restype = ctypes.c_int
    lib.sp_codec_from_max_error.argtypes = [ctypes.c_int, ctypes.c_uint32, ctypes.c_double, P(Codec)]
    lib.sp_joint_bytes.restype = ctypes.c_uint32
    lib.sp_joint_bytes.argtypes = [ctypes.c_size_t]
    lib.sp_parse_decimal.restype = ctypes.c_int
    lib.sp_parse_decimal.argtypes = [ctypes.c_char_p, ctypes.c_size_t, P(ctypes.c_uint64)]
    lib.sp_packed_params_equal.restype = ctypes.c_int
    lib.sp_packed_params_equal.argtypes = [P(PackedParams), P(PackedParams)]
    lib.sp_validate_packed.restype = ctypes.c_int
    lib.sp_validate_packed.argtypes = [P(PackedPrimitive), P(ctypes.c_uint16), P(ctypes.c_float), P(Validation)]
    lib.sp_format_validation.restype = ctypes.c_size_t
    lib.sp_format_validation.argtypes = [P(Validation), ctypes.c_char_p, ctypes.c_size_t]
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
    """The library as installed with the add-on (an install or update may overwrite it)."""
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), LIBRARY_NAME)


_cache_dir = None


def set_cache_dir(path):
    """Where load() keeps its private copy of the library (the Blender side passes a user folder)."""
    global _cache_dir
    _cache_dir = path


def _private_copy(path):
    """A copy of the library named by its content hash, in a folder no add-on install touches.

    Reinstalling the zip while the library is mapped (this session or another Blender) rewrites
    library_path() in place, which crashes the process at its next call into it. A copy named
    by its content is never rewritten: a new build gets a new name, the same build the same
    (complete) file, written under a temporary name and renamed into place."""
    with open(path, "rb") as handle:
        data = handle.read()
    stem, extension = os.path.splitext(LIBRARY_NAME)
    folder = _cache_dir or os.path.join(os.path.expanduser("~"), ".cache", "skinpack")
    target = os.path.join(folder, "%s-%s%s" % (stem, hashlib.sha256(data).hexdigest()[:16], extension))
    if not os.path.isfile(target):
        os.makedirs(folder, exist_ok=True)
        temporary = "%s.%d.tmp" % (target, os.getpid())
        with open(temporary, "wb") as handle:
            handle.write(data)
        os.replace(temporary, target)
    return target


def _struct_sizes():
    """ctypes sizes of the mirrors in sp_struct_id order (SP_STRUCT_CODEC -> sp_codec, ...)."""
    ids = sorted((value, name) for name, value in _abi.ENUMS["sp_struct_id"].items() if name != "SP_STRUCT_COUNT")
    return [ctypes.sizeof(MIRRORED_STRUCTS["sp_" + name[len("SP_STRUCT_"):].lower()]) for _, name in ids]


def _check_abi(lib, path):
    """sp_check_abi: the library's version and struct sizes against the header the mirrors were
    generated from (a library from another build must not be called with these layouts)."""
    sizes = _struct_sizes()
    lib.sp_check_abi.restype = ctypes.c_int
    lib.sp_check_abi.argtypes = [ctypes.c_uint32, ctypes.POINTER(ctypes.c_size_t), ctypes.c_size_t,
                                 ctypes.POINTER(ctypes.c_uint32)]
    lib.sp_version.restype = ctypes.c_uint32
    lib.sp_version.argtypes = []
    bad = ctypes.c_uint32(0)
    code = lib.sp_check_abi(SP_VERSION, (ctypes.c_size_t * len(sizes))(*sizes), len(sizes), ctypes.byref(bad))
    if code != SP_OK:
        names = {value: name for name, value in _abi.ENUMS["sp_struct_id"].items()}
        raise OSError("%s (version %d) does not match the add-on's skinpack.h (version %d, %s); reinstall the "
                      "add-on zip" % (path, lib.sp_version(), SP_VERSION, names.get(bad.value, "?")))


def load():
    """Loads the library once (from its private copy); returns it, or None (load_error() says why)."""
    global _lib, _load_error, _loaded_path
    if _lib is not None or _load_error is not None:
        return _lib
    path = library_path()
    try:
        loaded_from = _private_copy(path)
        lib = ctypes.CDLL(loaded_from)
        _check_abi(lib, path)
        _declare(lib)
    except (OSError, AttributeError) as error:
        _load_error = "Cannot load %s: %s" % (path, error)
        return None
    _lib, _loaded_path = lib, loaded_from
    return _lib


def loaded_path():
    """The file the library was loaded from, or None."""
    load()
    return _loaded_path


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


def joint_bytes(joint_count):
    """Bytes of one JOINTS_n / tupleTable component (sp_joint_bytes): 1 up to 256 joints, 2 up
    to SP_MAX_JOINTS, 0 outside 1..SP_MAX_JOINTS."""
    return int(_require().sp_joint_bytes(int(joint_count)))


def default_options():
    options = CompressOptions()
    _require().sp_compress_options_default(ctypes.byref(options))
    return options


def make_options(method, max_influences, vertex_bits=0, weight_bits=0, max_spacing=0.0, max_error=0.0):
    """The library's default options with the method, K and exactly one budget set
    (vertex_bits, weight_bits, max_spacing or max_error: the library searches the bits)."""
    options = default_options()
    options.method = METHODS.index(method)
    options.max_influences = max_influences
    options.vertex_bits = vertex_bits
    options.weight_bits = weight_bits
    options.max_spacing = max_spacing
    options.max_error = max_error
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
    """joints (V, S) uint16 and weights (V, S) float32, S influence slots per vertex (any number:
    the library keeps the K strongest)."""
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


def codec_from_max_error(method, influences, max_error):
    """sp_codec_from_max_error: the codec the library's max-error search picks for this K."""
    codec = Codec()
    code = _require().sp_codec_from_max_error(METHODS.index(method), influences, max_error, ctypes.byref(codec))
    if code != SP_OK:
        raise SkinpackError("no %s codec for K = %d within max error %g: %s"
                            % (method, influences, max_error, result_string(code)), code)
    return codec


def json_integer(value, name, strings=False, bits=64):
    """A JSON integer property as an unsigned integer of `bits` bits, range-checked on the full
    value before it is narrowed (spec: Large integers). strings: the property may hold a value
    above 2^53 as a decimal string, which the library parses (sp_parse_decimal)."""
    lib = _require()
    parsed = ctypes.c_uint64(0)
    if isinstance(value, str) and strings:
        text = value.encode("ascii", "replace")
        if lib.sp_parse_decimal(text, len(text), ctypes.byref(parsed)) != SP_OK:
            raise SkinpackError("%s: %r is not a decimal string of an integer above 2^53" % (name, value))
        return parsed.value
    if isinstance(value, bool) or not isinstance(value, int):
        raise SkinpackError("%s: %r is not an integer" % (name, value))
    if value < 0 or value.bit_length() > bits:
        raise SkinpackError("%s: %d is outside 0..2^%d - 1" % (name, value, bits))
    text = str(value).encode("ascii")
    if lib.sp_parse_decimal(text, len(text), ctypes.byref(parsed)) == SP_OK:  # the library's 2^53 bound
        raise SkinpackError("%s: %d is above 2^53 and must be written as a string" % (name, value))
    return value


def packed_params(extension):
    """sp_packed_params of a SKINPACK_packed_skin JSON object (a dict as json.loads returns it).
    Only the JSON layer is checked here (types, 64-bit range); the rules are sp_validate_packed's."""
    params = PackedParams()
    method = extension.get("method")
    params.method = _require().sp_method_from_name(method.encode("utf-8")) if isinstance(method, str) \
        else len(METHODS)
    for field, name in (("influences", "influences"), ("joint_count", "jointCount"),
                        ("weight_bits", "weightBits"), ("tuple_bits", "tupleBits")):
        if name not in extension:
            raise SkinpackError("%s is missing" % name)
        setattr(params, field, json_integer(extension[name], name, strings=False))
    params.n = json_integer(extension.get("n"), "n", strings=True)
    samples = extension.get("axisSamples", [])
    if not isinstance(samples, list) or len(samples) > len(params.axis_samples):
        raise SkinpackError("axisSamples: %r is not a list of at most %d integers"
                            % (samples, len(params.axis_samples)))
    for axis, value in enumerate(samples):
        params.axis_samples[axis] = json_integer(value, "axisSamples[%d]" % axis, strings=True)
    params.axis_sample_count = len(samples)
    if "maxError" in extension:
        max_error = extension["maxError"]
        if isinstance(max_error, bool) or not isinstance(max_error, (int, float)):
            raise SkinpackError("maxError: %r is not a number" % (max_error,))
        params.has_max_error, params.max_error = 1, float(max_error)
    return params


def params_equal(a, b):
    """sp_packed_params_equal: primitives sharing a "vertices" accessor must declare the same."""
    return bool(_require().sp_packed_params_equal(ctypes.byref(a), ctypes.byref(b)))


# sp_packed_meshlets array fields: (struct field, count field or None, numpy type, ctype).
_MESHLET_ARRAYS = (("offsets", None, np.uint32, ctypes.c_uint32), ("counts", None, np.uint32, ctypes.c_uint32),
                   ("vertices", "vertex_entries", np.uint32, ctypes.c_uint32),
                   ("vertex_tuples", "vertex_entries", np.uint8, ctypes.c_uint8),
                   ("triangles", "triangle_bytes", np.uint8, ctypes.c_uint8),
                   ("joints", "joint_entries", np.uint16, ctypes.c_uint16),
                   ("tuples", None, np.uint8, ctypes.c_uint8))


def _packed_meshlets(meshlets, influences, keep):
    """sp_packed_meshlets from a dict of arrays named as its fields (offsets and counts (M, 4),
    tuples (T, K)) and the declared limits; keep collects the arrays that must outlive the call."""
    packed = PackedMeshlets()
    for field, count_field, dtype, ctype in _MESHLET_ARRAYS:
        array = np.ascontiguousarray(meshlets[field], dtype=dtype).reshape(-1)
        keep.append(array)
        setattr(packed, field, _pointer(array, ctype))
        if count_field is not None:
            setattr(packed, count_field, len(array))
    packed.meshlet_count = np.asarray(meshlets["offsets"]).size // 4
    packed.tuple_count = np.asarray(meshlets["tuples"]).size // max(influences, 1)
    for limit in ("max_vertices", "max_triangles", "max_joints"):
        setattr(packed, limit, int(meshlets.get(limit, 0)))
    return packed


def validate_packed(params, words, words_per_vertex, primitive_vertex_count, lut, lut_component_bytes,
                    skin_joint_count, meshlets=None):
    """sp_validate_packed on one stored primitive, decoding it: returns (joints (V, K) uint16,
    weights (V, K) float32, sp_codec). words: the "vertices" accessor's u32 words (V * words_per_vertex);
    lut: the "tupleTable" accessor as (entries, components); skin_joint_count: joints of the
    smallest skin of the nodes that use the mesh (0 if none); meshlets: see _packed_meshlets.
    Raises SkinpackError with sp_format_validation's message."""
    lib = _require()
    words = np.ascontiguousarray(words, dtype=np.uint32).reshape(-1)
    lut = np.ascontiguousarray(lut, dtype=np.uint16)
    lut = lut.reshape(len(lut), -1) if lut.size else lut.reshape(0, 1)
    vertex_count = len(words) // max(words_per_vertex, 1)
    keep = []
    primitive = PackedPrimitive()
    primitive.params = params
    primitive.words = _pointer(words, ctypes.c_uint32)
    primitive.vertex_count = vertex_count
    primitive.words_per_vertex = words_per_vertex
    primitive.primitive_vertex_count = primitive_vertex_count
    primitive.lut = _pointer(lut, ctypes.c_uint16)
    primitive.lut_size, primitive.lut_components = lut.shape
    primitive.lut_component_bytes = lut_component_bytes
    primitive.skin_joint_count = skin_joint_count
    if meshlets is not None:
        keep.append(_packed_meshlets(meshlets, params.influences, keep))
        primitive.meshlets = ctypes.pointer(keep[-1])
    K = min(int(params.influences), SP_MAX_INFLUENCES)  # the library checks K first, then writes V * K
    joints = np.zeros((vertex_count, max(K, 1)), dtype=np.uint16)
    weights = np.zeros((vertex_count, max(K, 1)), dtype=np.float32)
    report = Validation()
    code = lib.sp_validate_packed(ctypes.byref(primitive), _pointer(joints, ctypes.c_uint16),
                                  _pointer(weights, ctypes.c_float), ctypes.byref(report))
    if code != SP_OK:
        size = lib.sp_format_validation(ctypes.byref(report), None, 0) + 1
        message = ctypes.create_string_buffer(size)
        lib.sp_format_validation(ctypes.byref(report), message, size)
        raise SkinpackError(message.value.decode("utf-8", "replace"), code,
                            int(report.index) if report.field == _abi.ENUMS["sp_field"]["SP_FIELD_VERTICES"] else None)
    return joints[:, :K], weights[:, :K], report.codec


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


def stats_dict(compressed, max_input_influences=None):
    """The numbers the panel, the CLI comparison and the export report show. The "before" size is
    what glTF stores for the same skin uncompressed: JOINTS_0 (u8, or u16 above 256 joints) and
    WEIGHTS_0 (float), VEC4 each. max_input_influences: the most non-zero influences of a vertex
    when the caller counted them (the library's histogram stops at SP_MAX_INPUT_INFLUENCES)."""
    s = compressed.skin
    input_bits_per_vertex = 4 * (8 * s.joint_bytes + 32)
    histogram = list(s.prepare.influence_histogram)
    most_influences = max((n for n, count in enumerate(histogram) if count), default=0)
    capped = most_influences == SP_MAX_INPUT_INFLUENCES  # the histogram's last bin: this many or more
    if max_input_influences is not None:  # counted by the caller, who has the input
        most_influences, capped = int(max_input_influences), False
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
        "max_input_influences": most_influences,
        "max_input_influences_capped": capped,
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


def meshlet_options(builder=None, max_vertices=None, max_triangles=None, max_joints=None, palette_effort=None):
    """sp_meshlet_options: the library's defaults with the builder, the limits and the palette
    effort that are given."""
    options = MeshletOptions()
    _require().sp_meshlet_options_default(ctypes.byref(options))
    if builder is not None:
        options.builder = MESHLET_BUILDERS.index(builder)
    for name, value in (("max_vertices", max_vertices), ("max_triangles", max_triangles), ("max_joints", max_joints),
                        ("palette_effort", palette_effort)):
        if value is not None:
            setattr(options, name, value)
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
