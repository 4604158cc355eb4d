"""Mutation test of the library's reader entry point on compressed real meshes.

    python3 mutate_packed.py SKINPACK_CLI LIBSKINPACK_SO WORK_DIR ASSET.glb...

Each asset is compressed by the CLI with several methods and modes (32-bit OSS, Any at 12 bits,
64-bit Fixed, POT with meshlets, compact Cube); then, per packed primitive, the stored data and
declared properties are mutated (bytes of the words, the tuple table and every meshlet array
flipped; arrays truncated; every property edited, including values of 2^32 and above;
accessors retargeted to another primitive's or file's data) and each mutant is handed to
sp_validate_packed through ctypes. Every mutant must either be refused with a non-empty message
that names a property, or decode to joints that are all below the skin's joint count and
distinct wherever weighted, with weights in [0, 1] summing to 1. The ctypes mirrors below are
checked against sp_struct_size first, so a layout change fails loudly instead of silently.
"""
import ctypes
import os
import random
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'cli'))
import gltf_read  # noqa: E402

u8p, u16p, u32p = ctypes.POINTER(ctypes.c_uint8), ctypes.POINTER(ctypes.c_uint16), ctypes.POINTER(ctypes.c_uint32)


class Codec(ctypes.Structure):
    _fields_ = [('method', ctypes.c_uint32), ('influences', ctypes.c_uint32), ('bits', ctypes.c_uint32),
                ('component_bits', ctypes.c_uint32 * 4), ('n', ctypes.c_uint64), ('axis_samples', ctypes.c_uint64 * 3),
                ('scale', ctypes.c_uint64), ('max_code', ctypes.c_uint64), ('code_bits', ctypes.c_double),
                ('max_spacing', ctypes.c_double), ('max_error', ctypes.c_double)]


class Params(ctypes.Structure):
    _fields_ = [('method', ctypes.c_uint32), ('influences', ctypes.c_uint64), ('joint_count', ctypes.c_uint64),
                ('weight_bits', ctypes.c_uint64), ('tuple_bits', ctypes.c_uint64), ('n', ctypes.c_uint64),
                ('axis_samples', ctypes.c_uint64 * 3), ('axis_sample_count', ctypes.c_uint32),
                ('has_max_error', ctypes.c_uint32), ('max_error', ctypes.c_double)]


class Meshlets(ctypes.Structure):
    _fields_ = [('meshlet_count', ctypes.c_size_t), ('offsets', u32p), ('counts', u32p),
                ('vertex_entries', ctypes.c_size_t), ('vertices', u32p), ('vertex_tuples', u8p),
                ('triangle_bytes', ctypes.c_size_t), ('triangles', u8p), ('joint_entries', ctypes.c_size_t),
                ('joints', u16p), ('tuple_count', ctypes.c_size_t), ('tuples', u8p),
                ('max_vertices', ctypes.c_uint32), ('max_triangles', ctypes.c_uint32), ('max_joints', ctypes.c_uint32)]


class Primitive(ctypes.Structure):
    _fields_ = [('params', Params), ('words', u32p), ('vertex_count', ctypes.c_size_t),
                ('words_per_vertex', ctypes.c_uint32), ('primitive_vertex_count', ctypes.c_size_t), ('lut', u16p),
                ('lut_size', ctypes.c_size_t), ('lut_components', ctypes.c_uint32),
                ('lut_component_bytes', ctypes.c_uint32), ('skin_joint_count', ctypes.c_size_t),
                ('meshlets', ctypes.POINTER(Meshlets))]


class Validation(ctypes.Structure):
    _fields_ = [('result', ctypes.c_int), ('field', ctypes.c_uint32), ('index', ctypes.c_size_t),
                ('value', ctypes.c_uint64), ('limit', ctypes.c_uint64), ('slot', ctypes.c_uint32),
                ('other_slot', ctypes.c_uint32), ('codec', Codec)]


STRUCT_IDS = {0: Codec, 10: Params, 11: Meshlets, 12: Primitive, 13: Validation}  # sp_struct_id values
METHODS = ['fixed', 'cube', 'pot', 'any', 'oss']
CONFIGS = [('oss32', ['--method', 'oss']), ('any12', ['--method', 'any', '--vertex-bits', '12']),
           ('fixed64', ['--method', 'fixed', '--vertex-bits', '64']),
           ('pot_meshlets', ['--method', 'pot', '--meshlets']), ('cube_compact', ['--method', 'cube', '--compact'])]


def load_library(path):
    lib = ctypes.CDLL(path)
    lib.sp_struct_size.restype = ctypes.c_size_t
    lib.sp_struct_size.argtypes = [ctypes.c_int]
    for sid, cls in STRUCT_IDS.items():
        if lib.sp_struct_size(sid) != ctypes.sizeof(cls):
            sys.exit('FAIL: struct %s is %d bytes in the library, %d here' % (cls.__name__, lib.sp_struct_size(sid),
                                                                             ctypes.sizeof(cls)))
    lib.sp_validate_packed.restype = ctypes.c_int
    lib.sp_validate_packed.argtypes = [ctypes.POINTER(Primitive), u16p, ctypes.POINTER(ctypes.c_float),
                                       ctypes.POINTER(Validation)]
    lib.sp_format_validation.restype = ctypes.c_size_t
    lib.sp_format_validation.argtypes = [ctypes.POINTER(Validation), ctypes.c_char_p, ctypes.c_size_t]
    lib.sp_field_name.restype = ctypes.c_char_p
    lib.sp_field_name.argtypes = [ctypes.c_uint32]
    return lib


def array(ctype, values):
    return (ctype * max(1, len(values)))(*values)


class Packed:
    """One packed primitive as plain Python lists (the mutable state of a mutant)."""

    def __init__(self, doc, mesh, prim, ext):
        self.params = {k: ext[k] for k in ('influences', 'jointCount', 'weightBits', 'tupleBits')}
        self.params['method'] = METHODS.index(ext['method'])
        self.params['n'] = int(ext['n'])
        self.params['axisSamples'] = [int(q) for q in ext.get('axisSamples', [])]
        self.params['maxError'] = ext.get('maxError')
        words = doc.accessor(ext['vertices'])
        self.words_per_vertex = len(words[0])
        self.words = [w for row in words for w in row]
        self.vertex_count = len(words)
        lut_accessor = doc.json['accessors'][ext['tupleTable']]
        self.lut = [j for row in doc.accessor(ext['tupleTable']) for j in row]
        self.lut_size = lut_accessor['count']
        self.lut_components = gltf_read.TYPE[lut_accessor['type']]
        self.lut_bytes = 1 if lut_accessor['componentType'] == 5121 else 2
        self.primitive_vertex_count = doc.json['accessors'][prim['attributes']['POSITION']]['count']
        self.skin_joints = skin_joint_count(doc.json, mesh)
        self.meshlets = None
        if 'meshlets' in ext:
            m = ext['meshlets']
            flat = lambda key: [x for row in doc.accessor(m[key]) for x in row]
            self.meshlets = {key: flat(key) for key in ('offsets', 'counts', 'vertices', 'vertexTuples', 'triangles',
                                                         'joints', 'tuples')}
            self.meshlet_limits = [m.get('maxVertices', 0), m.get('maxTriangles', 0), m.get('maxJoints', 0)]

    def copy(self):
        other = Packed.__new__(Packed)
        other.__dict__ = {k: (dict(v) if isinstance(v, dict) else list(v) if isinstance(v, list) else v)
                          for k, v in self.__dict__.items()}
        if self.meshlets:
            other.meshlets = {k: list(v) for k, v in self.meshlets.items()}
        return other


def skin_joint_count(document, mesh):
    counts = [len(document['skins'][node['skin']]['joints']) for node in document.get('nodes', [])
              if node.get('mesh') == mesh and 'skin' in node]
    return min(counts) if counts else 0


def validate(lib, p):
    """Runs sp_validate_packed on p; returns (result, message, joints, weights, K)."""
    params = Params()
    params.method, params.influences, params.joint_count = p.params['method'], p.params['influences'], p.params['jointCount']
    params.weight_bits, params.tuple_bits, params.n = p.params['weightBits'], p.params['tupleBits'], p.params['n']
    axes = p.params['axisSamples'][:3]
    for i, q in enumerate(axes):
        params.axis_samples[i] = q
    params.axis_sample_count = len(p.params['axisSamples'])
    if p.params['maxError'] is not None:
        params.has_max_error, params.max_error = 1, p.params['maxError']
    keep = []
    prim = Primitive()
    prim.params = params
    words = array(ctypes.c_uint32, [w & 0xFFFFFFFF for w in p.words])
    lut = array(ctypes.c_uint16, [j & 0xFFFF for j in p.lut])
    keep += [words, lut]
    prim.words, prim.lut = ctypes.cast(words, u32p), ctypes.cast(lut, u16p)
    prim.vertex_count = min(p.vertex_count, len(p.words) // max(1, p.words_per_vertex))
    prim.words_per_vertex, prim.primitive_vertex_count = p.words_per_vertex, p.primitive_vertex_count
    prim.lut_size = min(p.lut_size, len(p.lut) // max(1, p.lut_components))
    prim.lut_components, prim.lut_component_bytes, prim.skin_joint_count = p.lut_components, p.lut_bytes, p.skin_joints
    if p.meshlets:
        m = p.meshlets
        ml = Meshlets()
        k = min(4, p.lut_components)
        arrays = {'offsets': (ctypes.c_uint32, u32p), 'counts': (ctypes.c_uint32, u32p),
                  'vertices': (ctypes.c_uint32, u32p), 'vertexTuples': (ctypes.c_uint8, u8p),
                  'triangles': (ctypes.c_uint8, u8p), 'joints': (ctypes.c_uint16, u16p), 'tuples': (ctypes.c_uint8, u8p)}
        made = {}
        for key, (ctype, pointer) in arrays.items():
            mask = (1 << (8 * ctypes.sizeof(ctype))) - 1
            made[key] = array(ctype, [x & mask for x in m[key]])
            keep.append(made[key])
        ml.meshlet_count = min(len(m['offsets']), len(m['counts'])) // 4
        ml.offsets, ml.counts = ctypes.cast(made['offsets'], u32p), ctypes.cast(made['counts'], u32p)
        ml.vertex_entries = min(len(m['vertices']), len(m['vertexTuples']))
        ml.vertices, ml.vertex_tuples = ctypes.cast(made['vertices'], u32p), ctypes.cast(made['vertexTuples'], u8p)
        ml.triangle_bytes, ml.triangles = len(m['triangles']), ctypes.cast(made['triangles'], u8p)
        ml.joint_entries, ml.joints = len(m['joints']), ctypes.cast(made['joints'], u16p)
        ml.tuple_count, ml.tuples = len(m['tuples']) // max(1, k), ctypes.cast(made['tuples'], u8p)
        ml.max_vertices, ml.max_triangles, ml.max_joints = [x & 0xFFFFFFFF for x in p.meshlet_limits]
        keep.append(ml)
        prim.meshlets = ctypes.pointer(ml)
    k = max(1, min(4, p.params['influences'] if p.params['influences'] < 2 ** 32 else 4))
    joints = (ctypes.c_uint16 * (prim.vertex_count * 4 + 1))()
    weights = (ctypes.c_float * (prim.vertex_count * 4 + 1))()
    report = Validation()
    result = lib.sp_validate_packed(ctypes.byref(prim), joints, weights, ctypes.byref(report))
    message = ctypes.create_string_buffer(256)
    lib.sp_format_validation(ctypes.byref(report), message, 256)
    field = lib.sp_field_name(report.field).decode()
    return result, message.value.decode(), field, joints, weights, k, prim.vertex_count


def check_outcome(lib, p, what, problems, counts):
    result, message, field, joints, weights, k, vertices = validate(lib, p)
    if result != 0:
        counts['refused'] += 1
        if not message or (field and not message.startswith(field)):
            problems.append('%s: refused without a message naming the property (%r)' % (what, message))
        return
    counts['accepted'] += 1
    limit = p.skin_joints or p.params['jointCount']
    for v in range(vertices):
        slots = [(joints[v * k + s], weights[v * k + s]) for s in range(k)]
        weighted = [j for j, w in slots if w > 0]
        if any(j >= limit for j in weighted) or len(set(weighted)) != len(weighted):
            problems.append('%s: accepted, vertex %d decodes to %s' % (what, v, slots))
            return
        if any(not 0 <= w <= 1 for _, w in slots) or abs(sum(w for _, w in slots) - 1) > 1e-5:
            problems.append('%s: accepted, vertex %d weights %s' % (what, v, slots))
            return


def mutants(p, other, rng):
    """(name, mutant) pairs: flipped bytes, truncations, property edits, retargeted data."""
    for i in range(40):
        m = p.copy()
        at = rng.randrange(len(m.words))
        m.words[at] ^= 0xFF << (8 * rng.randrange(4))
        yield 'words byte flip %d' % i, m
    for i in range(15):
        m = p.copy()
        at = rng.randrange(len(m.lut))
        m.lut[at] ^= 1 << rng.randrange(16 if m.lut_bytes == 2 else 8)
        yield 'tupleTable flip %d' % i, m
    m = p.copy()
    m.words = m.words[:len(m.words) - m.words_per_vertex]
    m.vertex_count -= 1
    yield 'vertices truncated by one', m
    m = p.copy()
    m.lut = m.lut[:len(m.lut) - m.lut_components]
    m.lut_size -= 1
    yield 'tupleTable truncated by one', m
    for key in ('influences', 'jointCount', 'weightBits', 'tupleBits', 'n', 'method'):
        for value in (0, 1, p.params[key] + 1, max(0, p.params[key] - 1), 2 ** 32 + p.params[key], 2 ** 53 + 1,
                      2 ** 64 - 1):
            m = p.copy()
            m.params[key] = value
            yield '%s = %d' % (key, value), m
    for value in ([], [2], [2 ** 62, 2 ** 62, 2 ** 62], [q + 1 for q in p.params['axisSamples']]):
        m = p.copy()
        m.params['axisSamples'] = value
        yield 'axisSamples = %s' % value[:3], m
    for value in (-1.0, float('nan'), 2.0):
        m = p.copy()
        m.params['maxError'] = value
        yield 'maxError = %s' % value, m
    m = p.copy()
    m.skin_joints = max(1, max(p.lut) if p.lut else 1)
    yield 'mesh used by a smaller skin', m
    m = p.copy()
    m.primitive_vertex_count += 1
    yield 'primitive has one vertex more', m
    if other is not None:
        m = p.copy()
        m.words, m.vertex_count, m.words_per_vertex = list(other.words), other.vertex_count, other.words_per_vertex
        yield 'vertices retargeted to another file', m
        m = p.copy()
        m.lut, m.lut_size, m.lut_components, m.lut_bytes = list(other.lut), other.lut_size, other.lut_components, other.lut_bytes
        yield 'tupleTable retargeted to another file', m
    if p.meshlets:
        for key in p.meshlets:
            for i in range(8):
                m = p.copy()
                if not m.meshlets[key]:
                    continue
                at = rng.randrange(len(m.meshlets[key]))
                m.meshlets[key][at] ^= 1 << rng.randrange(8)
                yield 'meshlets.%s flip %d' % (key, i), m
            m = p.copy()
            m.meshlets[key] = m.meshlets[key][:-1]
            yield 'meshlets.%s truncated' % key, m


def main():
    skinpack, library, work = sys.argv[1], sys.argv[2], sys.argv[3]
    lib = load_library(library)
    os.makedirs(work, exist_ok=True)
    rng = random.Random(11)
    problems, counts, primitives = [], {'accepted': 0, 'refused': 0}, 0
    previous = None
    for asset in sys.argv[4:]:
        for tag, options in CONFIGS:
            out = os.path.join(work, '%s_%s.glb' % (os.path.splitext(os.path.basename(asset))[0], tag))
            subprocess.run([skinpack, 'compress', asset, '-o', out] + options, check=True, stdout=subprocess.DEVNULL)
            doc = gltf_read.Gltf(out)
            for mesh, index, prim in doc.primitives():
                ext = prim.get('extensions', {}).get(gltf_read.EXTENSION)
                if not ext:
                    continue
                p = Packed(doc, mesh, prim, ext)
                primitives += 1
                result, message, _, _, _, _, _ = validate(lib, p)
                if result != 0:
                    problems.append('%s mesh %d: the unmutated primitive is refused: %s' % (out, mesh, message))
                for name, mutant in mutants(p, previous, rng):
                    check_outcome(lib, mutant, '%s mesh %d %s' % (os.path.basename(out), mesh, name), problems, counts)
                previous = p
    for line in problems[:30]:
        print(line)
    print('%d packed primitives, %d mutants refused with a message, %d accepted and decoded within the skin, '
          '%d problems' % (primitives, counts['refused'], counts['accepted'], len(problems)))
    ok = not problems and primitives > 0 and counts['refused'] > 0
    print('PASS' if ok else 'FAIL')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
