"""End-to-end checks of the skinpack CLI on one glTF asset.

    python3 check_asset.py CHECK --skinpack BIN --node NODE --validator tools/validate.mjs \
        --work DIR ASSET [compress options...]

CHECK is one of
  validate   compact and fallback outputs and the decompressed file pass the Khronos validator
             with 0 errors (and the input itself does)
  roundtrip  compress -> decompress keeps every joint and keeps every weight within the codec's
             bound (maxError) of the input prepared as docs/format.md says; the observed error
             matches what compress --json reported; both modes, .glb and .gltf output
  info       info --json on the compressed file agrees with compress --json, and on the input
             with compress's influence histogram
  meshlets   compress --meshlets: every source triangle is in exactly one meshlet (same winding),
             every meshlet vertex's palette joints are the decoded joints of its source vertex,
             limits hold, and the stored counts match compress --json
  meshopt    compress --meshopt (compact and fallback, .glb and .gltf): decompressed, the file is byte
             for byte the decompressed file of compress without --meshopt; the packed words are an
             EXT_meshopt_compression view (required, data-less fallback buffer) that the npm
             meshoptimizer decoder turns into the words of the file without --meshopt; validator 0
             errors; an input using KHR_meshopt_compression gets KHR_meshopt_compression
--reference PLAIN.glb: ASSET as decoded by another decoder (gltfpack -cc files: meshopt), read as
the reference instead of ASSET. Anything after ASSET is passed to skinpack compress (e.g. --method pot --weight-bits 20).
"""
import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_read  # noqa: E402

FLOAT_SLACK = 2e-6  # float32 rounding of decoded weights and of the reference


def run(cmd):
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit("FAILED (%d): %s\n%s%s" % (result.returncode, " ".join(cmd), result.stdout, result.stderr))
    return result.stdout


# What issue 3 asks compress --json to report, at least.
REQUIRED_PRIMITIVE_KEYS = ["mesh", "primitive", "vertices", "joints", "unique_tuples", "tuple_bits", "weight_bits",
                           "lut_bits_per_vertex", "bits_per_vertex", "max_weight_error", "rms_weight_error",
                           "max_pruning_error"]
REQUIRED_TOP_KEYS = ["primitives", "input_bits_per_vertex", "output_bits_per_vertex", "input_bytes", "output_bytes"]


def compress(args, mode, out, extra):
    report = json.loads(run([args.skinpack, "compress", args.asset, "-o", out, "--" + mode, "--json"] + extra))
    if not report["primitives"]:
        raise SystemExit("no skinned primitive compressed in %s" % args.asset)
    missing = [k for k in REQUIRED_TOP_KEYS if k not in report]
    missing += [k for p in report["primitives"] for k in REQUIRED_PRIMITIVE_KEYS if k not in p]
    if missing:
        raise SystemExit("compress --json lacks %s" % sorted(set(missing)))
    if report["output_bytes"] != os.path.getsize(out) or report["input_bytes"] != os.path.getsize(args.asset):
        raise SystemExit("compress --json byte counts differ from the files")
    return report


def outputs(args, extra):
    name = os.path.splitext(os.path.basename(args.asset))[0]
    tag = "_".join(a.strip("-") for a in extra) or "default"
    base = os.path.join(args.work, "%s_%s" % (name, tag))
    return base


def check_validate(args, extra):
    base = outputs(args, extra)
    files = [args.asset]
    for mode in ("compact", "fallback"):
        compress(args, mode, base + "_%s.glb" % mode, extra)
        run([args.skinpack, "decompress", base + "_%s.glb" % mode, "-o", base + "_%s_decoded.glb" % mode])
        files += [base + "_%s.glb" % mode, base + "_%s_decoded.glb" % mode]
    compress(args, "compact", base + "_compact.gltf", extra)
    files.append(base + "_compact.gltf")
    print(run([args.node, args.validator] + files))
    for f in files[1:]:
        doc = gltf_read.Gltf(f)
        used = doc.json.get("extensionsUsed", [])
        required = doc.json.get("extensionsRequired", [])
        packed = any(gltf_read.EXTENSION in p.get("extensions", {}) for _, _, p in doc.primitives())
        decoded = f.endswith("_decoded.glb")
        if decoded and (packed or gltf_read.EXTENSION in used):
            raise SystemExit("%s: decompressed file still uses the extension" % f)
        if not decoded:
            compact = "_compact" in f
            if not packed or gltf_read.EXTENSION not in used or (gltf_read.EXTENSION in required) != compact:
                raise SystemExit("%s: extension not declared as %s mode requires" % (f, "compact" if compact else
                                                                                     "fallback"))


def check_roundtrip(args, extra):
    base = outputs(args, extra)
    original = gltf_read.Gltf(args.reference or args.asset)
    for mode, ext in (("compact", ".glb"), ("fallback", ".glb"), ("compact", ".gltf")):
        packed_path = base + "_rt_%s%s" % (mode, ext)
        decoded_path = base + "_rt_%s_decoded%s" % (mode, ext)
        report = compress(args, mode, packed_path, extra)
        run([args.skinpack, "decompress", packed_path, "-o", decoded_path])
        packed = gltf_read.Gltf(packed_path)
        decoded = gltf_read.Gltf(decoded_path)
        by_primitive = {(r["mesh"], r["primitive"]): r for r in report["primitives"]}
        # Primitives that shared JOINTS_0/WEIGHTS_0 share the packed accessors (compressed once).
        shared = {}
        for m, p, prim in original.primitives():
            if "JOINTS_0" in prim["attributes"]:
                key = (prim["attributes"]["JOINTS_0"], prim["attributes"]["WEIGHTS_0"])
                ext = packed.json["meshes"][m]["primitives"][p]["extensions"][gltf_read.EXTENSION]
                if shared.setdefault(key, (ext["vertices"], ext["tupleTable"])) != (ext["vertices"], ext["tupleTable"]):
                    raise SystemExit("mesh %d primitive %d: shared attributes were compressed twice" % (m, p))
        checked = 0
        for m, p, prim in original.primitives():
            reference = original.influences(prim)
            if reference is None:
                continue
            ext = packed.json["meshes"][m]["primitives"][p]["extensions"][gltf_read.EXTENSION]
            k, bound = ext["influences"], ext["maxError"]
            got = decoded.influences(decoded.json["meshes"][m]["primitives"][p])
            if got is None or len(got) != len(reference):
                raise SystemExit("%s mesh %d primitive %d: decoded vertex count differs" % (decoded_path, m, p))
            worst = 0.0
            for v, (ref, dec) in enumerate(zip(reference, got)):
                expected = gltf_read.prepare(ref, k)
                for j in dec:
                    if j not in expected:
                        raise SystemExit("%s mesh %d primitive %d vertex %d: joint %d was not an influence (had %s)"
                                         % (decoded_path, m, p, v, j, sorted(expected)))
                for j, w in expected.items():
                    if w > bound + FLOAT_SLACK and j not in dec:
                        raise SystemExit("%s mesh %d primitive %d vertex %d: joint %d (weight %g) lost"
                                         % (decoded_path, m, p, v, j, w))
                    error = abs(w - dec.get(j, 0.0))
                    if error > bound + FLOAT_SLACK:
                        raise SystemExit("%s mesh %d primitive %d vertex %d: joint %d weight %g decoded as %g, "
                                         "error %g > bound %g" % (decoded_path, m, p, v, j, w, dec.get(j, 0.0),
                                                                  error, bound))
                    worst = max(worst, error)
            reported = by_primitive[(m, p)]["max_weight_error"]
            if abs(worst - reported) > 1e-5:
                raise SystemExit("%s mesh %d primitive %d: observed max error %g, compress reported %g"
                                 % (packed_path, m, p, worst, reported))
            print("%s mesh %d prim %d: %d vertices, K=%d, max error %.3g <= bound %.3g" %
                  (os.path.basename(packed_path), m, p, len(reference), k, worst, bound))
            checked += 1
        if checked == 0:
            raise SystemExit("no skinned primitive checked")


AGREE = ["vertices", "joints", "influences", "unique_tuples", "tuple_bits", "weight_bits", "method", "n"]
AGREE_FLOAT = ["lut_bits_per_vertex", "bits_per_vertex", "max_error_bound"]


def check_info(args, extra):
    base = outputs(args, extra)
    info_in = json.loads(run([args.skinpack, "info", args.asset, "--json"]))
    input_rows = {(r["mesh"], r["primitive"]): r for r in info_in["primitives"]}
    for mode in ("compact", "fallback"):
        path = base + "_info_%s.glb" % mode
        report = compress(args, mode, path, extra)
        info = json.loads(run([args.skinpack, "info", path, "--json"]))
        rows = {(r["mesh"], r["primitive"]): r for r in info["primitives"]}
        if len(rows) != len(report["primitives"]):
            raise SystemExit("info lists %d primitives, compress %d" % (len(rows), len(report["primitives"])))
        for c in report["primitives"]:
            key = (c["mesh"], c["primitive"])
            i = rows[key]
            for field in AGREE:
                if i[field] != c[field]:
                    raise SystemExit("%s %s: info %s=%r, compress %r" % (path, key, field, i[field], c[field]))
            for field in AGREE_FLOAT:
                if abs(i[field] - c[field]) > 1e-9 * max(1.0, abs(c[field])):
                    raise SystemExit("%s %s: info %s=%r, compress %r" % (path, key, field, i[field], c[field]))
            if input_rows[key]["influence_histogram"] != c["influence_histogram"]:
                raise SystemExit("%s: influence histogram of the input differs between info and compress" % (key,))
            if input_rows[key]["stored_bits_per_vertex"] != c["input_bits_per_vertex"]:
                raise SystemExit("%s: input bits per vertex differ between info and compress" % (key,))
            if ("meshlets" in c) != ("meshlets" in i) or ("meshlets" in c and any(
                    abs(i["meshlets"][f] - c["meshlets"][f]) > 1e-9 * max(1.0, abs(c["meshlets"][f]))
                    for f in c["meshlets"])):
                raise SystemExit("%s: meshlets differ: info %r, compress %r" % (key, i.get("meshlets"),
                                                                             c.get("meshlets")))
            if mode == "fallback" and not (i["fallback_max_difference"] <= c["max_error_bound"] + FLOAT_SLACK):
                raise SystemExit("%s: packed data and fallback attributes differ by %r" %
                                 (key, i["fallback_max_difference"]))
        print("%s: info agrees with compress on %d primitive(s)" % (os.path.basename(path), len(rows)))


def canonical(triangle):
    """The rotation of a triangle that starts with its smallest index (keeps the winding)."""
    i = triangle.index(min(triangle))
    return tuple(triangle[i:] + triangle[:i])


MESHLET_LIMITS = {"--meshlet-vertices": ("maxVertices", 64), "--meshlet-triangles": ("maxTriangles", 124),
                  "--meshlet-joints": ("maxJoints", 32)}


def requested_meshlet_limits(extra):
    """The limits the file must record: the options given, else the documented defaults."""
    limits = {field: default for field, default in MESHLET_LIMITS.values()}
    for i, a in enumerate(extra[:-1]):
        if a in MESHLET_LIMITS:
            limits[MESHLET_LIMITS[a][0]] = int(extra[i + 1])
    return limits


def index_bits(count):
    return (count - 1).bit_length()


def check_meshlet_stats(stats, counts, where):
    """compress --json's per-primitive meshlet statistics against the meshlets in the file."""
    palette_entries = sum(c[2] for c in counts)
    entries = sum(c[0] for c in counts)
    local_bits = sum(c[0] * index_bits(c[3]) for c in counts) / entries
    expected = {"count": len(counts), "max_joints": max(c[2] for c in counts), "palette_entries": palette_entries,
                "mean_joints": palette_entries / len(counts), "local_tuple_bits_mean": local_bits}
    for field, value in expected.items():
        if abs(stats[field] - value) > 1e-6 * max(1.0, value):
            raise SystemExit("%s: compress --json meshlets %s=%r, the file's meshlets give %r" %
                             (where, field, stats[field], value))


def check_meshlets(args, extra):
    base = outputs(args, extra)
    limits = requested_meshlet_limits(extra)
    path = base + "_meshlets.glb"
    decoded_path = base + "_meshlets_decoded.glb"
    report = compress(args, "compact", path, extra + ["--meshlets"])
    run([args.skinpack, "decompress", path, "-o", decoded_path])
    original, packed, decoded = gltf_read.Gltf(args.reference or args.asset), gltf_read.Gltf(path), gltf_read.Gltf(decoded_path)
    rows = {(r["mesh"], r["primitive"]): r for r in report["primitives"]}
    for m, p, prim in original.primitives():
        if "JOINTS_0" not in prim["attributes"]:
            continue
        ext = packed.json["meshes"][m]["primitives"][p]["extensions"][gltf_read.EXTENSION]
        ml = ext["meshlets"]
        k = ext["influences"]
        if any(ml[field] != value for field, value in limits.items()):
            raise SystemExit("mesh %d primitive %d: limits %r in the file, %r asked for" %
                             (m, p, {f: ml[f] for f in limits}, limits))
        get = lambda name: packed.accessor(ml[name])  # noqa: E731
        offsets, counts, vertices, vtuples = get("offsets"), get("counts"), get("vertices"), get("vertexTuples")
        triangles, joints, tuples = get("triangles"), get("joints"), get("tuples")
        dprim = decoded.json["meshes"][m]["primitives"][p]["attributes"]
        djoints, dweights = decoded.accessor(dprim["JOINTS_0"]), decoded.accessor(dprim["WEIGHTS_0"])
        if "indices" in prim:
            flat = [i[0] for i in original.accessor(prim["indices"])]
        else:
            flat = list(range(len(djoints)))
        source = sorted(canonical(flat[i:i + 3]) for i in range(0, len(flat), 3))
        seen = []
        for index, ((vo, to, jo, uo), (vc, tc, jc, uc)) in enumerate(zip(offsets, counts)):
            if vc > ml["maxVertices"] or tc > ml["maxTriangles"] or jc > ml["maxJoints"]:
                raise SystemExit("meshlet %d breaks its limits" % index)
            for t in range(tc):
                local = [triangles[3 * (to + t) + c][0] for c in range(3)]
                seen.append(canonical([vertices[vo + i][0] for i in local]))
            for e in range(vo, vo + vc):
                v = vertices[e][0]
                tuple_entry = tuples[uo + vtuples[e][0]]
                for s in range(k):
                    if dweights[v][s] > 0 and joints[jo + tuple_entry[s]][0] != djoints[v][s]:
                        raise SystemExit("meshlet %d vertex %d slot %d: palette joint %d, decoded joint %d" %
                                         (index, v, s, joints[jo + tuple_entry[s]][0], djoints[v][s]))
        if sorted(seen) != source:
            raise SystemExit("mesh %d primitive %d: meshlet triangles differ from the source triangles" % (m, p))
        check_meshlet_stats(rows[(m, p)]["meshlets"], counts, "mesh %d primitive %d" % (m, p))
        print("mesh %d prim %d: %d triangles in %d meshlets within %d/%d/%d, palettes and local tuples match the "
              "decoded joints" % (m, p, len(source), len(offsets), limits["maxVertices"], limits["maxTriangles"],
                                  limits["maxJoints"]))


MESHOPT_NAMES = ("EXT_meshopt_compression", "KHR_meshopt_compression")


def view_bytes(doc, accessor):
    """The bytes of an accessor's bufferView (uncompressed files)."""
    view = doc.json["bufferViews"][doc.json["accessors"][accessor]["bufferView"]]
    data = doc.buffers[view["buffer"]]
    return bytes(data[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]])


MUST_PAY_BYTES = 4096  # packed words this large always shrink by more than the JSON a meshopt view needs


def check_meshopt_layout(path, name, report):
    """The packed views that are meshopt-compressed are so as EXT_meshopt_compression asks, named
    `name`; returns how many are. Words of MUST_PAY_BYTES or more must be."""
    doc = gltf_read.Gltf(path)
    compressed = 0
    other = [n for n in MESHOPT_NAMES if n != name][0]
    if other in doc.json.get("extensionsUsed", []) and other not in gltf_read.Gltf(report["input"]).json.get(
            "extensionsUsed", []):
        raise SystemExit("%s: %s was added, the input uses %s" % (path, other, name))
    stored, seen = 0, set()
    for m, p, prim in doc.primitives():
        ext = prim.get("extensions", {}).get(gltf_read.EXTENSION)
        for field in ("vertices", "tupleTable") if ext else ():
            if ext[field] in seen:  # primitives sharing the packed accessors
                continue
            seen.add(ext[field])
            accessor = doc.json["accessors"][ext[field]]
            view = doc.json["bufferViews"][accessor["bufferView"]]
            meshopt = view.get("extensions", {}).get(name)
            if meshopt is None:
                if field == "vertices" and view["byteLength"] >= MUST_PAY_BYTES:
                    raise SystemExit("%s mesh %d primitive %d: the words view is not %s" % (path, m, p, name))
                stored += view["byteLength"]
                continue
            compressed += 1
            element = {5121: 1, 5123: 2, 5125: 4}[accessor["componentType"]] * gltf_read.TYPE[accessor["type"]]
            if (meshopt["mode"], meshopt["byteStride"], meshopt["count"]) != ("ATTRIBUTES", element, accessor["count"]):
                raise SystemExit("%s: %s view %r does not describe accessor %r" % (path, field, meshopt, accessor))
            if view["byteLength"] != element * accessor["count"] or "byteStride" in view:
                raise SystemExit("%s: %s view %r is not the tightly packed accessor" % (path, field, view))
            fallback = doc.json["buffers"][view["buffer"]]
            if "uri" in fallback or fallback.get("extensions", {}).get(name) != {"fallback": True}:
                raise SystemExit("%s: %s view's buffer %r is not a data-less %s fallback" % (path, field, fallback, name))
            stored += meshopt["byteLength"]
    if sum(r["stored_packed_bytes"] for r in report["primitives"] if r["shared_with"] < 0) != stored:
        raise SystemExit("%s: compress --json stored_packed_bytes differ from the file (%d)" % (path, stored))
    for v in doc.json["bufferViews"]:  # EXT_meshopt_compression: a fallback buffer only holds compressed views
        if doc.json["buffers"][v["buffer"]].get("extensions", {}).get(name) and name not in v.get("extensions", {}):
            raise SystemExit("%s: view %r lies in the meshopt fallback buffer uncompressed" % (path, v))
    if compressed:
        for key in ("extensionsUsed", "extensionsRequired"):
            if name not in doc.json.get(key, []):
                raise SystemExit("%s: %s not in %s" % (path, name, key))
    return compressed


def check_meshopt(args, extra):
    base = outputs(args, extra) + "_meshopt"
    inputs = [(args.asset, "EXT_meshopt_compression")]
    source = gltf_read.Gltf(args.asset)
    if "EXT_meshopt_compression" in source.json.get("extensionsUsed", []) and args.asset.endswith(".glb"):
        # gltfpack -ce khr writes vertex codec 1, which libmeshoptimizer 0.18 cannot decode: the -cc
        # file under the KHR name (codec 0 is valid for both) stands in for it.
        renamed = json.loads(json.dumps(source.json).replace("EXT_meshopt_compression", "KHR_meshopt_compression"))
        khr = base + "_khr_input.glb"
        gltf_read.write_glb(renamed, source.bin, khr)
        inputs.append((khr, "KHR_meshopt_compression"))
    written = []
    for asset, name in inputs:
        for mode, suffix in (("compact", ".glb"), ("fallback", ".glb"), ("compact", ".gltf")):
            tag = "%s_%s_%s%s" % (base, name.split("_")[0].lower(), mode, suffix)
            reports = {}
            for variant, flags in (("plain", []), ("meshopt", ["--meshopt"])):
                out = "%s_%s%s" % (tag, variant, suffix)
                reports[variant] = json.loads(run([args.skinpack, "compress", asset, "-o", out, "--" + mode, "--json"]
                                                  + extra + flags))
                run([args.skinpack, "decompress", out, "-o", out + ".decoded" + suffix])
            plain, packed = tag + "_plain" + suffix, tag + "_meshopt" + suffix
            with open(plain + ".decoded" + suffix, "rb") as a, open(packed + ".decoded" + suffix, "rb") as b:
                if a.read() != b.read():
                    raise SystemExit("%s: decompressed differs from the decompressed file without --meshopt" % packed)
            compressed = check_meshopt_layout(packed, name, reports["meshopt"])
            with open(plain, "rb") as a, open(packed, "rb") as b:
                same = a.read() == b.read()
            if not reports["meshopt"]["meshopt"] or (compressed and os.path.getsize(packed) >= os.path.getsize(plain)) \
                    or (not compressed and not same):
                raise SystemExit("%s: %d view(s) meshopt-compressed, %d bytes vs %d without --meshopt: not smaller, "
                                 "or not the same file" % (packed, compressed, os.path.getsize(packed),
                                                           os.path.getsize(plain)))
            if compressed and suffix == ".glb" and name == "EXT_meshopt_compression":  # the npm decoder's words
                run([args.node, os.path.join(os.path.dirname(args.validator), "meshopt_unpack.mjs"), packed,
                     packed + ".npm.glb"])
                npm, reference = gltf_read.Gltf(packed + ".npm.glb"), gltf_read.Gltf(plain)
                for (_, _, a), (_, _, b) in zip(npm.primitives(), reference.primitives()):
                    ea, eb = (p.get("extensions", {}).get(gltf_read.EXTENSION) for p in (a, b))
                    for field in ("vertices", "tupleTable") if ea else ():
                        if view_bytes(npm, ea[field]) != view_bytes(reference, eb[field]):
                            raise SystemExit("%s: %s decode (npm meshoptimizer) to other bytes than without "
                                             "--meshopt" % (packed, field))
            print("%s: %d -> %d bytes with --meshopt (%d view(s) compressed); decompressed identical" %
                  (os.path.basename(packed), os.path.getsize(plain), os.path.getsize(packed), compressed))
            written.append(packed)
    print(run([args.node, args.validator] + written))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("check", choices=["validate", "roundtrip", "info", "meshlets", "meshopt"])
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--node", default="node")
    parser.add_argument("--validator", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--reference", help="the asset without EXT_meshopt_compression (tools/meshopt_unpack.mjs), "
                        "read instead of ASSET by this independent reader")
    parser.add_argument("asset")
    args, extra = parser.parse_known_args()
    os.makedirs(args.work, exist_ok=True)
    {"validate": check_validate, "roundtrip": check_roundtrip, "info": check_info,
     "meshlets": check_meshlets, "meshopt": check_meshopt}[args.check](args, extra)
    print("OK")


main()
